// A world's whole state as plain data: what World::save_state gives and World::from_state takes
// back, so that a run can be saved and resumed bit for bit. The engine does no I/O; encoding this
// for a file or the network is its callers' business.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "physics/body.h"
#include "physics/step.h"

namespace tumble {

struct WorldSettings;

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

struct BodySlotState {
  std::uint32_t generation = 0;
  bool alive = false;
  Body body;  // meaningful when alive
};

struct WorldStateData {
  std::vector<BodySlotState> slots;
  std::vector<std::uint32_t> free_slots;  // reused last first
  double time = 0;                        // s
  std::uint64_t step = 0;
  std::vector<ContactPairRecord> contact_pairs;  // sorted by (a.index, b.index), each pair once
};

}  // namespace tumble
