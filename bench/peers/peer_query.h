// One interface for every engine's penetration query, so the narrow-phase benchmark times them on
// identical pairs. Shapes are built before timing; only the queries are timed.
#pragma once

#include <string>
#include <vector>

#include "physics/math.h"

namespace tumble::bench {

struct PairSpec {
  bool hulls = false;  // false: boxes with half extents; true: hulls of the points
  Vec3 half_a, half_b;
  const std::vector<Vec3>* points_a = nullptr;
  const std::vector<Vec3>* points_b = nullptr;
  Pose pose_a, pose_b;
};

struct PeerAnswer {
  bool hit = false;
  double depth = 0;
  Vec3 normal = Vec3::Zero();  // moving B by depth * normal separates (sign fixed by calibration)
};

struct PeerRun {
  std::vector<PeerAnswer> answers;
  double seconds = 0;  // the timed loop over all pairs
};

PeerRun run_bullet_float(const std::vector<PairSpec>& pairs);
PeerRun run_bullet_double(const std::vector<PairSpec>& pairs);
PeerRun run_ccd(const std::vector<PairSpec>& pairs, double tolerance, bool mpr);

}  // namespace tumble::bench
