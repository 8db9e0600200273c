// A touching pair as the last step left it, kept from step to step (warm starting, feature reuse,
// the solver's graph colour). Private to the engine; World::save_state carries it.
#pragma once

#include <array>
#include <cstdint>

#include "physics/body.h"
#include "physics/math.h"

namespace tumble {

// One contact point of a touching pair with the impulses the last step left in it: the next
// step starts from them (warm start), matched to its points by feature id, or else by position in
// A's axes.
struct ContactPointRecord {
  std::uint64_t feature = 0;             // the pair of features that made the point (ContactPoint)
  Vec3 local_a = Vec3::Zero();           // m, from A's centre of mass, A's axes
  double normal_impulse = 0;             // N s
  Vec3 friction_impulse = Vec3::Zero();  // N s, world
};

// The graph colours a touching pair can hold (the solver's, colouring.h), and "none yet".
constexpr int kContactColours = 48;
constexpr std::uint8_t kNoContactColour = 0xff;

// A touching pair of bodies as the last step left it, kept from step to step: one record per
// manifold, which holds its impulses between steps. For two polytopes it also names the feature
// (a face of either, or a pair of edges) the separating-axis test chose, and where B was in A's
// axes then: while no point where they touch has moved by more than
// SolverSettings::manifold_reuse of the smaller body's size since, the next steps clip that
// feature again without searching all the others (the search is most of a box pair's cost).
struct ContactPairRecord {
  BodyId a, b;
  Vec3 relative_position = Vec3::Zero();         // m, B's centre in A's axes
  Quat relative_orientation = Quat::Identity();  // A's conjugate times B's
  // 0 none (not two polytopes, GJK/EPA, or an older snapshot), 1 a face of A, 2 a face of B, 3 a
  // pair of edges (A's, B's); with the shapes ordered as the narrow phase orders them (by type).
  std::uint8_t feature_kind = 0;
  std::uint32_t feature_first = 0, feature_second = 0;
  int count = 0;  // 1..4
  std::array<ContactPointRecord, 4> points;
  // Given when the pair started touching and kept while it touches, so that the solver visits a
  // resting pile's manifolds in the same order every step: below kContactColours, or
  // kNoContactColour (none free then, or an older snapshot: the next step colours it).
  std::uint8_t colour = kNoContactColour;
};

}  // namespace tumble
