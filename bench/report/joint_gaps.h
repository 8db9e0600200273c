// How far a scene's joints have come apart, read from the bodies' poses alone, the same way for
// every engine: each anchor is kept in its body's frame from the scene's start poses, and the gap
// of a ball, hinge or fixed joint is the distance between its two anchors now (a
// distance joint's: how far their distance is from its length). Sliders are measured off their
// axis only.
#pragma once

#include <vector>

#include "peers/simulation.h"
#include "scenes/scene.h"

namespace tumble::report {

class JointGaps {
 public:
  explicit JointGaps(const SceneDef& scene);
  // The largest gap of any joint in the engine's present state, m.
  double largest(const bench::Simulation& sim) const;

 private:
  struct End {
    int body = -1;  // the dynamic body's index in the engine (scene order), -1: fixed in the world
    Vec3 local = Vec3::Zero();  // the anchor in that body's frame (world frame when fixed)
  };
  struct Joint {
    JointKind kind;
    End a = {}, b = {};
    double length = 0;
    Vec3 axis_in_b = Vec3::UnitZ();  // a slider's axis, in b's frame (world when b is fixed)
  };
  Vec3 where(const bench::Simulation& sim, const End& end) const;
  std::vector<Joint> joints_;
};

}  // namespace tumble::report
