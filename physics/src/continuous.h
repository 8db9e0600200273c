// Continuous collision: the time at which two shapes moving through a step first come within a
// target distance, by conservative advancement (Mirtich, "Impulse-based dynamic simulation of
// rigid body systems", 1996, ch. 4; Zhang, Redon, Lee, Kim, "Continuous collision detection for
// articulated models using Taylor models and temporal culling", SIGGRAPH 2007, for the bound on
// rotating motion; the same scheme as Box2D's b2TimeOfImpact, which uses separating axes).
//
// Each body's motion over the step is taken as linear: its centre moves along `translation`
// and it turns by the rotation vector `rotation` (world axes), both scaled by t in [0, 1]. At the
// current t the narrow phase gives the gap and its normal; no point of B can approach A faster
// than the relative translation along that normal plus |rotation| times each body's outer radius,
// so advancing t by gap / that rate cannot step over the first contact. For convex shapes that
// only translate the gap is a convex function of t and the bound is its tangent: advancement
// then converges from below. Every loop is bounded and reports when it hits the bound.
#pragma once

#include "physics/collision.h"
#include "physics/shape.h"

namespace tumble {

struct SweptMotion {
  Pose start;
  Vec3 translation = Vec3::Zero();  // m over the step
  Vec3 rotation = Vec3::Zero();     // rad over the step, world axes
  double outer_radius = 0;          // m; 0 for a body that does not turn
};

Pose pose_at(const SweptMotion& motion, double t);

enum class ImpactStatus : std::uint8_t {
  kMiss,             // no contact within the step
  kHit,              // first within the target at `t`
  kTouchingAtStart,  // already within the target at t = 0: the contact solver's case
  kIterationLimit,   // stopped at the bound; `t` is still safe (before any contact)
};

struct ImpactResult {
  ImpactStatus status = ImpactStatus::kMiss;
  double t = 1;
  Vec3 normal = Vec3::UnitZ();  // from A to B at t
  int iterations = 0;
  // A hit of a pair touching from the start (a body whose centre would cross a terrain's surface,
  // stopped short of it): the solve already met the contact, and its velocities stand.
  bool in_contact = false;
};

// `target`: the gap (m) to stop at, > 0 so that the next step still sees a speculative contact;
// `tolerance`: how far below the target the answer may be.
ImpactResult time_of_impact(const Shape& a, const SweptMotion& motion_a, const Shape& b,
                            const SweptMotion& motion_b, double target, double tolerance,
                            int max_iterations);

}  // namespace tumble
