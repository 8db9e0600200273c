#include "colouring.h"

#include <array>
#include <bit>

namespace tumble {

void colour_manifolds(std::span<const std::uint32_t> island_links,
                      std::span<const IslandLink> links, std::span<const std::uint8_t> dynamic,
                      ColouringScratch* scratch, Colouring* out) {
  std::vector<std::uint64_t>& used = scratch->used;
  if (used.size() < dynamic.size()) used.resize(dynamic.size(), 0);
  std::vector<std::uint8_t>& colour_of = scratch->colour_of;
  colour_of.resize(island_links.size());
  constexpr int kOverflow = kMaxColours;
  std::array<std::uint32_t, kMaxColours + 1> count{};

  for (std::size_t k = 0; k < island_links.size(); ++k) {
    const IslandLink& link = links[island_links[k]];
    const bool moving_a = dynamic[link.a] != 0, moving_b = dynamic[link.b] != 0;
    const std::uint64_t taken = (moving_a ? used[link.a] : 0) | (moving_b ? used[link.b] : 0);
    int colour = std::countr_one(taken);
    if (colour >= kMaxColours) {
      colour = kOverflow;
    } else {
      const std::uint64_t bit = std::uint64_t{1} << colour;
      if (moving_a) used[link.a] |= bit;
      if (moving_b) used[link.b] |= bit;
    }
    colour_of[k] = static_cast<std::uint8_t>(colour);
    ++count[colour];
  }
  for (std::uint32_t manifold : island_links) {
    used[links[manifold].a] = 0;
    used[links[manifold].b] = 0;
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
