// Graph colouring of an island's contact manifolds, so that one island can be solved by several
// threads: manifolds of one colour share no moving body, so a team may solve them in any order
// and on any thread and every body still receives its impulses in the same order (colour by
// colour). The colouring depends only on the island, never on the thread count, so the result
// is bit-identical for any team size.
//
// Greedy colouring in manifold order as in Box2D v3's constraint graph (Catto, "Solver2D" and
// "SIMD Matters", 2024) and Tonge, Benevolenski, Voroshilov, "Mass splitting for jitter-free
// parallel rigid body simulation" (SIGGRAPH 2012) for the overflow idea: manifolds that find no
// free colour, and colours too small to be worth a barrier, form one last colour solved serially.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "islands.h"

namespace tumble {

// At most this many parallel colours (one bit each in a 64-bit mask per body).
constexpr int kMaxColours = 48;
// A colour with fewer manifolds than this joins the serial overflow colour.
constexpr std::uint32_t kSmallestColour = 8;

struct Colouring {
  // Colour c holds manifolds[colour_begin[c] .. colour_begin[c+1]); serial[c] marks the overflow.
  std::vector<std::uint32_t> manifolds;
  std::vector<std::uint32_t> colour_begin{0};
  std::vector<std::uint8_t> serial;
  std::size_t colour_count() const { return serial.size(); }
  void clear() {
    manifolds.clear();
    colour_begin.assign(1, 0);
    serial.clear();
  }
};

// Scratch for colour_manifolds, reused from call to call.
struct ColouringScratch {
  std::vector<std::uint64_t> used;  // by body; all zero between calls
  std::vector<std::uint8_t> colour_of;
};

// Appends the colours of one island's manifolds (`island_links`: manifold ids into `links`) to
// `out`. `dynamic` marks moving bodies; static ones never conflict.
void colour_manifolds(std::span<const std::uint32_t> island_links,
                      std::span<const IslandLink> links, std::span<const std::uint8_t> dynamic,
                      ColouringScratch* scratch, Colouring* out);

}  // namespace tumble
