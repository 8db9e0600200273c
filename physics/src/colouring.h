// Graph colouring of the contact manifolds, so that one island can be solved by several threads:
// manifolds of one colour share no moving body, so a team may solve them in any order and on any
// thread and every body still receives its impulses in the same order (colour by colour).
//
// A manifold is coloured when its pair starts touching and keeps that colour while it touches
// (the colour lives in the pair's record, ContactPairRecord), as in Box2D v3's constraint graph
// (Catto, "Solver2D" and "SIMD Matters", 2024): a step colours only the pairs that are new, and
// the order in which Gauss-Seidel visits a resting pile's manifolds does not change from step to
// step. Colours are given in one serial pass in contact order, so they never depend on the thread
// count. Tonge, Benevolenski, Voroshilov, "Mass splitting for jitter-free parallel rigid body
// simulation" (SIGGRAPH 2012) for the overflow idea: manifolds that find no free colour, and an
// island's colours too small to be worth a barrier, form one last colour solved serially.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "contact_record.h"
#include "islands.h"

namespace tumble {

// At most this many parallel colours (one bit each in a 64-bit mask per body).
constexpr int kMaxColours = kContactColours;
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

// A manifold without a colour: its pair is new, or found every colour taken when it last tried
// (it tries again each step).
constexpr std::uint8_t kNoColour = kNoContactColour;

// Scratch for the functions below, reused from call to call.
struct ColouringScratch {
  std::vector<std::uint64_t> used;  // by body; all zero between calls
  std::vector<std::uint8_t> colour_of;
};

// This step's colour of every manifold (`links`, one per manifold): `kept[m]` is the colour its
// pair had last step (kNoColour if none). A kept colour stays unless one of the manifold's moving
// bodies already holds it this step (two kept colours can meet at a body that did not move last
// step: asleep then, or made dynamic since); then, and for every manifold without one, the
// lowest colour free at both moving bodies, in manifold order, or kNoColour when all kMaxColours
// are taken. `dynamic` marks moving bodies; static ones never conflict.
void keep_manifold_colours(std::span<const IslandLink> links, std::span<const std::uint8_t> dynamic,
                           std::span<const std::uint8_t> kept, ColouringScratch* scratch,
                           std::span<std::uint8_t> colours);

// Appends one island's colours to `out`: its manifolds (`island_links`, manifold ids) grouped by
// `colours[m]` (keep_manifold_colours), in island order within a colour; kNoColour and colours
// of fewer than kSmallestColour manifolds form the serial overflow, last.
void colour_manifolds(std::span<const std::uint32_t> island_links,
                      std::span<const std::uint8_t> colours, ColouringScratch* scratch,
                      Colouring* out);

}  // namespace tumble
