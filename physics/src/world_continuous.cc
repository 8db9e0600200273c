// The continuous-collision stage of World::step: fast bodies swept through their motion.
#include <omp.h>

#include <algorithm>

#include "continuous.h"
#include "parallel.h"
#include "physics/world.h"
#include "step_scratch.h"
#include "world_slot.h"

namespace tumble {

// After the solve, every pair with a fast body (the broad phase already grew its bounds by the
// whole motion) is swept from the start pose to the solved end pose; each fast body then ends
// the step at its first impact, in the state it had there. Only fast bodies are moved back: a
// slow body keeps its solved pose, and its speculative contacts already covered its own motion.
void World::sweep_fast_bodies(double dt) {
  StepScratch& s = *scratch_;
  const SolverSettings& solver = settings_.solver;
  s.swept_pairs.clear();
  for (std::uint32_t k = 0; k < pairs_.size(); ++k)
    if ((fast_[pairs_[k].a] || fast_[pairs_[k].b]) &&
        (!filters_used_ ||
         bodies_[pairs_[k].a].body.filter.collides_with(bodies_[pairs_[k].b].body.filter)))
      s.swept_pairs.push_back(k);
  s.impacts.resize(s.swept_pairs.size());

  // A body that does not move this step may have no solver index: it stays where it is.
  auto motion_of = [&](std::uint32_t slot) {
    const Body& body = bodies_[slot].body;
    SweptMotion motion;
    motion.start = body.pose();
    const std::uint32_t k = s.solver_of_slot[slot];
    if (k != kNoSolverBody && s.dynamic[k]) {
      motion.translation = s.poses[k].position - body.position;
      motion.rotation = s.bodies[k].delta_angle;  // not wrapped at pi, unlike the end pose
      motion.outer_radius = body.shape.outer_radius();
    }
    if (body.carries()) {
      motion.translation = dt * body.linear_velocity;
      motion.rotation = dt * body.angular_velocity;
      motion.outer_radius = body.shape.outer_radius();
    }
    return motion;
  };
  // Half the speculative distance: the next step's narrow phase still sees the contact. Never 0,
  // which advancement would approach without reaching (both settings may be 0).
  const double target = std::max({0.5 * solver.speculative_distance, solver.slop, 1e-6});
  const std::int64_t count = static_cast<std::int64_t>(s.swept_pairs.size());
  const int threads = settings_.threads > 0 ? settings_.threads : omp_get_max_threads();
  // Sweeps differ in cost (a few to 32 advancement steps): handed out four at a time.
  for_indices(
      threads, count > 8, count,
      [&](std::int64_t k) {
        const BodyPair& pair = pairs_[s.swept_pairs[k]];
        s.impacts[k] = time_of_impact(bodies_[pair.a].body.shape, motion_of(pair.a),
                                      bodies_[pair.b].body.shape, motion_of(pair.b), target,
                                      0.25 * target, solver.continuous_iterations);
      },
      4);

  // Only moving bodies are fast: the step visits them, not every slot.
  const std::span<const std::uint32_t> awake = awake_slots();
  s.first_impact.resize(bodies_.size());
  s.impact_in_contact.resize(bodies_.size());
  for (std::uint32_t slot : awake) {
    s.first_impact[slot] = 1.0;
    s.impact_in_contact[slot] = 0;
  }
  for (std::size_t k = 0; k < s.impacts.size(); ++k) {
    const ImpactResult& impact = s.impacts[k];
    if (impact.status == ImpactStatus::kIterationLimit) ++stats_.continuous_limit_hits;
    if (impact.status != ImpactStatus::kHit && impact.status != ImpactStatus::kIterationLimit)
      continue;
    const BodyPair& pair = pairs_[s.swept_pairs[k]];
    for (std::uint32_t slot : {pair.a, pair.b}) {
      if (!fast_[slot] || impact.t > s.first_impact[slot]) continue;
      // (Of two impacts at the same time, the one in a contact: its velocities are the solve's.)
      s.impact_in_contact[slot] =
          impact.in_contact || (impact.t == s.first_impact[slot] && s.impact_in_contact[slot]);
      s.first_impact[slot] = impact.t;
    }
  }
  for (std::uint32_t slot : awake) {
    if (!fast_[slot]) continue;
    ++stats_.swept_bodies;
    if (s.first_impact[slot] >= 1) continue;
    ++stats_.continuous_impacts;
    // The body lives only the fraction t of the step: its pose and its velocities are those at t.
    // Keeping the end velocities would hand it the whole step's gravity for a part of the fall
    // (an energy gain of m g dz (1 - t) per impact).
    const double t = s.first_impact[slot];
    const Body& body = bodies_[slot].body;
    const std::uint32_t k = s.solver_of_slot[slot];  // fast bodies move: they have one
    s.poses[k] = pose_at(motion_of(slot), t);
    // Stopped in a contact it touched from the start: the solve's velocities are its answer to
    // that contact (interpolated, a body landing at 300 m/s kept most of its speed step after
    // step, stopped a little deeper each time).
    if (s.impact_in_contact[slot]) continue;
    s.bodies[k].v = body.linear_velocity + t * (s.bodies[k].v - body.linear_velocity);
    s.bodies[k].w = body.angular_velocity + t * (s.bodies[k].w - body.angular_velocity);
  }
}

}  // namespace tumble
