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

// Every manifold's colour when all pairs are new, or kept from `kept`.
std::vector<std::uint8_t> colours_of(std::span<const IslandLink> links,
                                     std::span<const std::uint8_t> dynamic,
                                     ColouringScratch* scratch,
                                     std::vector<std::uint8_t> kept = {}) {
  if (kept.empty()) kept.assign(links.size(), kNoColour);
  std::vector<std::uint8_t> colours(links.size());
  keep_manifold_colours(links, dynamic, kept, scratch, colours);
  return colours;
}

// Colours every link as one island, every pair new.
Colouring colour_all(std::span<const IslandLink> links, std::span<const std::uint8_t> dynamic,
                     ColouringScratch* scratch) {
  const std::vector<std::uint8_t> colours = colours_of(links, dynamic, scratch);
  std::vector<std::uint32_t> island(links.size());
  for (std::uint32_t m = 0; m < island.size(); ++m)
    island[m] = m;
  Colouring colouring;
  colour_manifolds(island, colours, scratch, &colouring);
  return colouring;
}

std::vector<IslandLink> random_links(std::mt19937& random, std::span<const std::uint8_t> dynamic,
                                     std::uint32_t count) {
  const std::uint32_t bodies = static_cast<std::uint32_t>(dynamic.size());
  std::vector<IslandLink> links;
  for (std::uint32_t m = 0; m < count; ++m) {
    std::uint32_t a = random() % bodies, b = random() % bodies;
    if (a == b || (!dynamic[a] && !dynamic[b])) continue;
    links.push_back({a, b});
  }
  return links;
}

TEST(Colouring, RandomContactGraphsGiveIndependentColours) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 50; ++trial) {
    const std::uint32_t bodies = 20 + random() % 400;
    std::vector<std::uint8_t> dynamic(bodies);
    for (auto& d : dynamic)
      d = random() % 10 != 0;  // a tenth static, shared freely
    const std::vector<IslandLink> links =
        random_links(random, dynamic, bodies * (1 + random() % 4));
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

// A pile at rest keeps its colours from step to step: the pairs that go on touching keep theirs
// whatever pairs come and go around them, and the new ones take colours their bodies do not hold.
TEST(Colouring, PairsKeepTheirColoursWhileTheyTouch) {
  std::mt19937 random(11);
  for (int trial = 0; trial < 30; ++trial) {
    std::vector<std::uint8_t> dynamic(50 + random() % 200);
    for (auto& d : dynamic)
      d = random() % 10 != 0;
    std::vector<IslandLink> links = random_links(random, dynamic, 3 * dynamic.size());
    ColouringScratch scratch;
    std::vector<std::uint8_t> colours = colours_of(links, dynamic, &scratch);
    for (int step = 0; step < 5; ++step) {
      // A third of the pairs part; as many new ones start touching, placed among the others.
      std::vector<IslandLink> next_links;
      std::vector<std::uint8_t> kept;
      const std::vector<IslandLink> arriving = random_links(random, dynamic, links.size() / 3);
      std::size_t next_arriving = 0;
      for (std::size_t m = 0; m < links.size(); ++m) {
        if (random() % 3 == 0) continue;
        next_links.push_back(links[m]);
        kept.push_back(colours[m]);
        if (next_arriving < arriving.size() && random() % 2 == 0) {
          next_links.push_back(arriving[next_arriving++]);
          kept.push_back(kNoColour);
        }
      }
      const std::vector<std::uint8_t> next = colours_of(next_links, dynamic, &scratch, kept);
      for (std::size_t m = 0; m < next_links.size(); ++m)
        if (kept[m] != kNoColour) {
          EXPECT_EQ(next[m], kept[m]) << "trial " << trial << " step " << step << " pair " << m;
        }
      std::vector<std::uint32_t> island(next_links.size());
      for (std::uint32_t m = 0; m < island.size(); ++m)
        island[m] = m;
      Colouring colouring;
      colour_manifolds(island, next, &scratch, &colouring);
      expect_valid(colouring, next_links, dynamic, next_links.size());
      links = std::move(next_links);
      colours = next;
    }
    for (std::uint64_t used : scratch.used)
      EXPECT_EQ(used, 0u);
  }
}

// Two pairs kept the same colour while their shared body did not move (asleep, or static): now it
// moves, so one keeps the colour and the other, later in order, takes the lowest free one.
TEST(Colouring, KeptColoursThatMeetAtAMovingBodyAreMadeApart) {
  const std::vector<std::uint8_t> dynamic(3, 1);
  const std::vector<IslandLink> links{{0, 1}, {0, 2}};
  ColouringScratch scratch;
  const std::vector<std::uint8_t> colours = colours_of(links, dynamic, &scratch, {3, 3});
  EXPECT_EQ(colours[0], 3);
  EXPECT_EQ(colours[1], 0);
}

// A pair that found every colour taken tries again each step, and takes one once it is free.
TEST(Colouring, APairWithoutAColourTakesOneWhenOneIsFree) {
  const std::uint32_t spokes = kMaxColours + 1;
  std::vector<std::uint8_t> dynamic(spokes + 1, 1);
  std::vector<IslandLink> links;
  for (std::uint32_t i = 1; i <= spokes; ++i)
    links.push_back({0, i});
  ColouringScratch scratch;
  std::vector<std::uint8_t> colours = colours_of(links, dynamic, &scratch);
  EXPECT_EQ(colours.back(), kNoColour);
  EXPECT_EQ(colours[5], 5);
  // The sixth spoke leaves the hub: the last one gets its colour.
  links.erase(links.begin() + 5);
  colours.erase(colours.begin() + 5);
  colours = colours_of(links, dynamic, &scratch, colours);
  EXPECT_EQ(colours.back(), 5);
}

}  // namespace
}  // namespace tumble
