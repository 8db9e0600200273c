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

// One contact point of a persistent pair, in the bodies' axes, with the impulses the last step
// left in it: the next step starts from them (warm start).
struct ContactPointRecord {
  std::uint64_t feature = 0;  // the pair of features that made the point (ContactPoint)
  Vec3 local_a = Vec3::Zero(), local_b = Vec3::Zero();  // m, from each centre of mass
  double normal_impulse = 0;                            // N s
  Vec3 friction_impulse = Vec3::Zero();                 // N s, world
};

// A touching pair of bodies as the narrow phase last found it, kept from step to step: one record
// per manifold. While B stays where it was in A's axes (within SolverSettings::manifold_reuse),
// the next steps take the manifold from here instead of colliding the shapes again (Jolt's body
// pair cache, with a tolerance that bounds how far any point of the pair moved); the impulses
// stay in the record either way.
struct ContactPairRecord {
  BodyId a, b;
  // Where B was in A's axes when the points were found (rotation: A's conjugate times B's).
  Vec3 relative_position = Vec3::Zero();
  Quat relative_orientation = Quat::Identity();
  Vec3 local_normal = Vec3::UnitZ();  // A's axes, from A towards B
  double depth_excess = 0;            // m: the pair's penetration beyond its deepest point's (>= 0)
  double margin = 0;                  // m: the margin the points were found with
  // False for records that carry impulses only (restored from a snapshot of an older version):
  // the narrow phase runs again and matches the points to them.
  bool reusable = true;
  int count = 0;  // 1..4
  std::array<ContactPointRecord, 4> points;
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
