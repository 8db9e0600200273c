// Stage "bodies": the step's solver bodies numbered (the moving ones, then the statics their
// contacts touch) and loaded with what the solver reads of each.
#include <algorithm>

#include "auto_solver.h"
#include "colouring.h"
#include "contact_packs.h"
#include "contact_pairs.h"
#include "contact_solver.h"
#include "islands.h"
#include "parallel.h"
#include "physics/world.h"
#include "step_scratch.h"
#include "step_stages.h"
#include "tall_stacks.h"
#include "world_slot.h"

namespace tumble {

void World::number_solver_bodies() {
  StepScratch& s = *scratch_;
  // Only the slots the last step numbered are cleared: no pass over every slot.
  for (std::uint32_t slot : s.solver_slot)
    if (slot < s.solver_of_slot.size()) s.solver_of_slot[slot] = kNoSolverBody;
  s.solver_of_slot.resize(bodies_.size(), kNoSolverBody);
  const std::span<const std::uint32_t> awake = awake_slots();
  s.solver_slot.assign(awake.begin(), awake.end());
  s.moving = static_cast<std::uint32_t>(awake.size());
  for (std::uint32_t k = 0; k < s.moving; ++k) {
    TUMBLE_ASSERT(bodies_[awake[k]].alive && bodies_[awake[k]].body.is_moving());
    s.solver_of_slot[awake[k]] = k;
  }
  for (const Contact& contact : contacts_) {
    for (const std::uint32_t slot : {contact.a.index, contact.b.index}) {
      if (s.solver_of_slot[slot] != kNoSolverBody) continue;
      s.solver_of_slot[slot] = static_cast<std::uint32_t>(s.solver_slot.size());
      s.solver_slot.push_back(slot);
    }
  }
  // The static bodies that joints hold moving bodies to.
  if (joint_count_ == 0) return;
  for (const JointSlot& joint : joints_) {
    if (!joint.alive || joint.joint.b == kWorldAnchor) continue;
    const std::uint32_t a = joint.joint.a, b = joint.joint.b;
    if (!bodies_[a].body.is_moving() && !bodies_[b].body.is_moving()) continue;
    for (const std::uint32_t slot : {a, b}) {
      if (s.solver_of_slot[slot] != kNoSolverBody) continue;
      s.solver_of_slot[slot] = static_cast<std::uint32_t>(s.solver_slot.size());
      s.solver_slot.push_back(slot);
    }
  }
}

void World::load_solver_bodies() {
  StepScratch& s = *scratch_;
  number_solver_bodies();
  const std::uint32_t solver_bodies = static_cast<std::uint32_t>(s.solver_slot.size());
  s.kinematic_contacts = false;
  if (!kinematic_.empty())
    for (std::uint32_t k = s.moving; k < solver_bodies; ++k)
      s.kinematic_contacts |= bodies_[s.solver_slot[k]].body.carries();
  resize_for_overwrite(s.bodies, solver_bodies);
  resize_for_overwrite(s.poses, solver_bodies);
  s.dynamic.resize(solver_bodies);
  s.body_of.resize(solver_bodies);
  const int threads = team_size(settings_.threads);
  for_indices(threads, worth_a_team(solver_bodies, 20), solver_bodies, [&](std::int64_t k) {
    const Body& body = bodies_[s.solver_slot[k]].body;
    SolverBody& sb = s.bodies[k];
    sb = SolverBody{};
    s.dynamic[k] = k < s.moving;
    s.body_of[k] = &body;
    s.poses[k] = body.pose();
    if (body.carries()) {  // its velocity, with no mass to change it
      sb.v = body.linear_velocity;
      sb.w = body.angular_velocity;
      sb.kinematic = true;
    }
    if (!s.dynamic[k]) return;
    sb.v = body.linear_velocity;
    sb.w = body.angular_velocity;
    sb.inverse_mass = body.inverse_mass;
    sb.inverse_inertia = body.inverse_inertia_world;
  });
}

}  // namespace tumble
