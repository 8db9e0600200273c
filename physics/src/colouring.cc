#include "colouring.h"

#include <array>
#include <bit>

namespace tumble {

namespace {

// The colours already held at a manifold's moving bodies.
std::uint64_t taken_at(const IslandLink& link, std::span<const std::uint8_t> dynamic,
                       std::span<const std::uint64_t> used) {
  return (dynamic[link.a] ? used[link.a] : 0) | (dynamic[link.b] ? used[link.b] : 0);
}

void take(const IslandLink& link, std::span<const std::uint8_t> dynamic,
          std::span<std::uint64_t> used, int colour) {
  const std::uint64_t bit = std::uint64_t{1} << colour;
  if (dynamic[link.a]) used[link.a] |= bit;
  if (dynamic[link.b]) used[link.b] |= bit;
}

}  // namespace

void keep_manifold_colours(std::span<const IslandLink> links, std::span<const std::uint8_t> dynamic,
                           std::span<const std::uint8_t> kept, ColouringScratch* scratch,
                           std::span<std::uint8_t> colours) {
  std::vector<std::uint64_t>& used = scratch->used;
  if (used.size() < dynamic.size()) used.resize(dynamic.size(), 0);
  // Kept colours first, so that a new pair never takes a colour an older one still holds.
  for (std::size_t m = 0; m < links.size(); ++m) {
    colours[m] = kNoColour;
    const int colour = kept[m];
    if (colour >= kMaxColours || (taken_at(links[m], dynamic, used) >> colour & 1) != 0) continue;
    take(links[m], dynamic, used, colour);
    colours[m] = kept[m];
  }
  for (std::size_t m = 0; m < links.size(); ++m) {
    if (colours[m] != kNoColour) continue;
    const int colour = std::countr_one(taken_at(links[m], dynamic, used));
    if (colour >= kMaxColours) continue;
    take(links[m], dynamic, used, colour);
    colours[m] = static_cast<std::uint8_t>(colour);
  }
  for (const IslandLink& link : links)
    used[link.a] = used[link.b] = 0;
}

void colour_manifolds(std::span<const std::uint32_t> island_links,
                      std::span<const std::uint8_t> colours, ColouringScratch* scratch,
                      Colouring* out) {
  std::vector<std::uint8_t>& colour_of = scratch->colour_of;
  colour_of.resize(island_links.size());
  constexpr int kOverflow = kMaxColours;
  std::array<std::uint32_t, kMaxColours + 1> count{};
  for (std::size_t k = 0; k < island_links.size(); ++k) {
    const std::uint8_t colour = colours[island_links[k]];
    colour_of[k] = colour < kMaxColours ? colour : kOverflow;
    ++count[colour_of[k]];
  }
  // Small colours cost a barrier each for little work: they join the overflow.
  std::array<std::uint8_t, kMaxColours + 1> final_colour{};
  bool merged = false;
  for (int c = 0; c <= kMaxColours; ++c) {
    final_colour[c] = static_cast<std::uint8_t>(c);
    if (c == kOverflow || count[c] == 0 || count[c] >= kSmallestColour) continue;
    final_colour[c] = kOverflow;
    count[kOverflow] += count[c];
    count[c] = 0;
    merged = true;
  }
  if (merged)
    for (std::uint8_t& colour : colour_of)
      colour = final_colour[colour];

  // Counting sort by colour; within a colour the island's order stays.
  std::array<std::uint32_t, kMaxColours + 1> cursor{};
  const std::uint32_t base = static_cast<std::uint32_t>(out->manifolds.size());
  std::uint32_t offset = base;
  for (int c = 0; c <= kMaxColours; ++c) {
    cursor[c] = offset;
    if (count[c] == 0) continue;
    offset += count[c];
    out->colour_begin.push_back(offset);
    out->serial.push_back(c == kOverflow ? 1 : 0);
  }
  out->manifolds.resize(offset);
  for (std::size_t k = 0; k < island_links.size(); ++k)
    out->manifolds[cursor[colour_of[k]]++] = island_links[k];
}

}  // namespace tumble
