// Graph colouring of contact manifolds: a colour never holds two manifolds that share a moving
// body, every manifold gets exactly one colour, and what cannot be coloured goes to one serial
// overflow colour at the end.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "colouring.h"

namespace tumble {
namespace {

void expect_valid(const Colouring& colouring, std::span<const IslandLink> links,
                  std::span<const std::uint8_t> dynamic, std::size_t manifold_count) {
  ASSERT_EQ(colouring.colour_begin.size(), colouring.colour_count() + 1);
  std::vector<int> seen(manifold_count, 0);
  for (std::size_t c = 0; c < colouring.colour_count(); ++c) {
    // Only the last colour may be the serial overflow.
    if (colouring.serial[c]) {
      EXPECT_EQ(c + 1, colouring.colour_count());
    }
    std::set<std::uint32_t> bodies;
    const std::uint32_t size = colouring.colour_begin[c + 1] - colouring.colour_begin[c];
    if (!colouring.serial[c]) {
      EXPECT_GE(size, kSmallestColour);
    }
    for (std::uint32_t k = colouring.colour_begin[c]; k < colouring.colour_begin[c + 1]; ++k) {
      const std::uint32_t m = colouring.manifolds[k];
      ++seen[m];
      if (colouring.serial[c]) continue;
      for (std::uint32_t body : {links[m].a, links[m].b}) {
        if (!dynamic[body]) continue;
        EXPECT_TRUE(bodies.insert(body).second) << "colour " << c << " body " << body;
      }
    }
  }
  for (std::size_t m = 0; m < manifold_count; ++m)
    EXPECT_EQ(seen[m], 1) << "manifold " << m;
}

// Colours every link as one island.
Colouring colour_all(std::span<const IslandLink> links, std::span<const std::uint8_t> dynamic,
                     ColouringScratch* scratch) {
  std::vector<std::uint32_t> island(links.size());
  for (std::uint32_t m = 0; m < island.size(); ++m)
    island[m] = m;
  Colouring colouring;
  colour_manifolds(island, links, dynamic, scratch, &colouring);
  return colouring;
}

TEST(Colouring, RandomContactGraphsGiveIndependentColours) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 50; ++trial) {
    const std::uint32_t bodies = 20 + random() % 400;
    std::vector<std::uint8_t> dynamic(bodies);
    for (auto& d : dynamic)
      d = random() % 10 != 0;  // a tenth static, shared freely
    std::vector<IslandLink> links;
    const std::uint32_t count = bodies * (1 + random() % 4);
    for (std::uint32_t m = 0; m < count; ++m) {
      std::uint32_t a = random() % bodies, b = random() % bodies;
      if (a == b || (!dynamic[a] && !dynamic[b])) continue;
      links.push_back({a, b});
    }
    ColouringScratch scratch;
    const Colouring colouring = colour_all(links, dynamic, &scratch);
    expect_valid(colouring, links, dynamic, links.size());
    // The scratch masks are left clear for the next island.
    for (std::uint64_t used : scratch.used)
      EXPECT_EQ(used, 0u);
  }
}

TEST(Colouring, ABodyWithMoreContactsThanColoursOverflows) {
  // A hub touching 200 bodies: each manifold needs its own colour; 48 fit, the rest (and every
  // colour smaller than kSmallestColour, here all of them) are solved serially.
  const std::uint32_t spokes = 200;
  std::vector<std::uint8_t> dynamic(spokes + 1, 1);
  std::vector<IslandLink> links;
  for (std::uint32_t i = 1; i <= spokes; ++i)
    links.push_back({0, i});
  ColouringScratch scratch;
  const Colouring colouring = colour_all(links, dynamic, &scratch);
  expect_valid(colouring, links, dynamic, links.size());
  ASSERT_EQ(colouring.colour_count(), 1u);
  EXPECT_TRUE(colouring.serial[0]);
}

TEST(Colouring, StaticBodiesDoNotConflict) {
  // 100 boxes on one static floor (body 0): one colour.
  std::vector<std::uint8_t> dynamic(101, 1);
  dynamic[0] = 0;
  std::vector<IslandLink> links;
  for (std::uint32_t i = 1; i <= 100; ++i)
    links.push_back({0, i});
  ColouringScratch scratch;
  const Colouring colouring = colour_all(links, dynamic, &scratch);
  ASSERT_EQ(colouring.colour_count(), 1u);
  EXPECT_FALSE(colouring.serial[0]);
  expect_valid(colouring, links, dynamic, links.size());
}

}  // namespace
}  // namespace tumble
