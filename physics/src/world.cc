#include "physics/world.h"
#include "world_slot.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "broad_phase.h"
#include "buffer_growth.h"
#include "parallel.h"
#include "query_index.h"
#include "step_scratch.h"

namespace tumble {
namespace {

// Below this many bodies sorting on one axis beats building grids (one thread, median broad-phase
// ms of 300 steps at one substep, grid / sweep and prune: ragdolls:8 0.024 / 0.012, chain:100
// 0.024 / 0.005, pile:125 0.024 / 0.014, compound-pile:125 0.083 / 0.053; pile:200 0.033 / 0.034).
constexpr std::size_t kSweepAndPruneBelow = 128;

int thread_count(int requested) {
  return requested > 0 ? requested : omp_get_max_threads();
}

std::pair<Vec3, Vec3> velocities_after_impulse(const Body& body, const Vec3& impulse,
                                               const Vec3* point) {
  Vec3 w = body.angular_velocity;
  if (point != nullptr) w += body.inverse_inertia_world * (*point - body.position).cross(impulse);
  return {body.linear_velocity + body.inverse_mass * impulse, w};
}

// The gap below which a resting body has contacts: the solver's speculative distance, but never
// more than a quarter of the body's outer radius, so that bodies reaching 8 cm from their centre
// (a 1 m plate however thin) keep the full distance. A fixed 2 cm around boxes of 20 µm made
// every box of a pile a neighbour of every other (300 of them: 60,000 contact points against
// 1,200 for the same pile of 1 m boxes); scaled, they have about the neighbours 1 m boxes have
// (the TinyBodies test).
double rest_margin(const Shape& shape, const SolverSettings& solver) {
  return std::min(solver.speculative_distance, 0.25 * shape.outer_radius());
}

// How close two bodies may come within the step, by what their velocities say of them together:
// a pair's speculative contacts need that gap, not the sum of each body's own reach. Two boxes
// falling side by side at 10 m/s are no closer at the end of the step; counted apart, each
// reached 17 cm and they had contacts all the way down (two thirds of a falling pile's
// manifolds). The pull of gravity (and held forces) over the step counts once: the solver may hold one of the two and not
// the other. Fast bodies keep their own reach (the sweep covers the rest).
double pair_reach(const Body& a, const Body& b, double reach_a, double reach_b, double gravity,
                  double dt) {
  const auto velocity = [](const Body& body) -> Vec3 {
    return body.is_moving() ? body.linear_velocity : Vec3::Zero();
  };
  const auto turn = [](const Body& body) {
    return body.is_moving() ? body.angular_velocity.norm() * body.shape.outer_radius() : 0.0;
  };
  const double pull = std::max(a.pull(gravity), b.pull(gravity));
  const double together =
      ((velocity(a) - velocity(b)).norm() + pull * dt + turn(a) + turn(b)) * dt;
  return std::min(reach_a + reach_b, together);
}

// The force and torque a body holds after `motion` (World::set_motion).
std::pair<Vec3, Vec3> held_forces(const Body& body, const BodyMotion& motion) {
  const Vec3 force = motion.force.value_or(body.force);
  Vec3 torque = motion.torque.value_or(body.torque);
  if (motion.force_point)
    torque = motion.torque.value_or(Vec3::Zero()) + (*motion.force_point - body.position).cross(force);
  return {force, torque};
}

Status check_vector(const std::optional<Vec3>& v, const char* field) {
  if (v && !is_finite(*v)) return Status::error(std::string(field) + ": must be finite");
  return Status::ok();
}

}  // namespace

World::World(const WorldSettings& settings)
    : settings_(settings),
      scratch_(std::make_unique<StepScratch>()),
      query_index_(std::make_unique<QueryIndex>()) {}
World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

Status validate(const WorldSettings& s) {
  if (!is_finite(s.gravity)) return Status::error("gravity: must be finite");
  if (Status t = validate(s.limits); !t) return t.within("limits.");
  // One step of gravity alone may not take a body past the speed limit.
  if (s.gravity.norm() * s.limits.max_time_step > s.limits.max_linear_speed)
    return Status::error(
        "gravity: |gravity| x limits.max_time_step is above "
        "limits.max_linear_speed");
  if (s.threads < 0) return Status::error("threads: must be >= 0");
  if (!(s.collision.margin >= 0) || !std::isfinite(s.collision.margin))
    return Status::error("collision.margin: must be finite and >= 0");
  const SolverSettings& v = s.solver;
  if (v.iterations < 1 || v.iterations > 1000)
    return Status::error("solver.iterations: must be in [1, 1000]");
  if (v.soft_iterations < 1 || v.soft_iterations > 1000)
    return Status::error("solver.soft_iterations: must be in [1, 1000]");
  if (v.relax_iterations < 1 || v.relax_iterations > 1000)
    return Status::error("solver.relax_iterations: must be in [1, 1000]");
  if (v.substeps < 1 || v.substeps > 1000)
    return Status::error("solver.substeps: must be in [1, 1000]");
  if (v.position_iterations < 0 || v.position_iterations > 1000)
    return Status::error("solver.position_iterations: must be in [0, 1000]");
  if (v.joint_position_passes < 0 || v.joint_position_passes > 1000)
    return Status::error("solver.joint_position_passes: must be in [0, 1000]");
  if (v.exact_max_points < 0) return Status::error("solver.exact_max_points: must be >= 0");
  if (v.friction_directions < 4 || v.friction_directions > 32)
    return Status::error("solver.friction_directions: must be in [4, 32]");
  if (v.lemke_pivots_per_unknown < 1)
    return Status::error("solver.lemke_pivots_per_unknown: must be >= 1");
  if (v.exact_max_island_points < 1 || v.exact_max_island_points > 256)
    return Status::error("solver.exact_max_island_points: must be in [1, 256]");
  if (!(v.exact_velocity_tolerance > 0) || !std::isfinite(v.exact_velocity_tolerance))
    return Status::error("solver.exact_velocity_tolerance: must be finite and > 0");
  auto non_negative = [](double x) { return std::isfinite(x) && x >= 0; };
  if (!non_negative(v.velocity_tolerance))
    return Status::error("solver.velocity_tolerance: must be finite and >= 0");
  if (!non_negative(v.sleep_linear_speed))
    return Status::error("solver.sleep_linear_speed: must be finite and >= 0");
  if (!non_negative(v.sleep_angular_speed))
    return Status::error("solver.sleep_angular_speed: must be finite and >= 0");
  if (!non_negative(v.sleep_delay))
    return Status::error("solver.sleep_delay: must be finite and >= 0");
  if (!non_negative(v.slop)) return Status::error("solver.slop: must be finite and >= 0");
  if (!non_negative(v.speculative_distance))
    return Status::error("solver.speculative_distance: must be finite and >= 0");
  if (!non_negative(v.restitution_threshold))
    return Status::error("solver.restitution_threshold: must be finite and >= 0");
  if (!(v.manifold_reuse >= 0 && v.manifold_reuse <= 0.01))
    return Status::error("solver.manifold_reuse: must be in [0, 0.01]");
  if (!(v.contact_hertz > 0) || !std::isfinite(v.contact_hertz))
    return Status::error("solver.contact_hertz: must be finite and > 0");
  if (!non_negative(v.contact_damping_ratio))
    return Status::error("solver.contact_damping_ratio: must be finite and >= 0");
  if (!(v.max_push_velocity > 0) || !std::isfinite(v.max_push_velocity))
    return Status::error("solver.max_push_velocity: must be finite and > 0");
  if (!non_negative(v.max_correction))
    return Status::error("solver.max_correction: must be finite and >= 0");
  if (!(v.continuous_fraction > 0) || !std::isfinite(v.continuous_fraction))
    return Status::error("solver.continuous_fraction: must be finite and > 0");
  if (v.continuous_iterations < 1 || v.continuous_iterations > 1000)
    return Status::error("solver.continuous_iterations: must be in [1, 1000]");
  if (!(v.baumgarte >= 0 && v.baumgarte <= 1))
    return Status::error("solver.baumgarte: must be in [0, 1]");
  return Status::ok();
}

Status World::set_settings(const WorldSettings& settings) {
  if (Status s = validate(settings); !s) return s;
  for (std::uint32_t i = 0; i < bodies_.size(); ++i)
    if (bodies_[i].alive)
      if (Status s = check_limits(bodies_[i].body, settings.limits); !s)
        return s.within("limits: the body in slot " + std::to_string(i) + " is beyond them: ");
  const bool sleeping_ends = settings_.solver.sleeping && !settings.solver.sleeping;
  settings_ = settings;
  // Without sleeping, nothing would wake the sleepers but a touch: they wake now.
  if (sleeping_ends) {
    for (std::uint32_t island = 0; island < sleeper_head_.size(); ++island)
      if (sleeper_head_[island] != kNoSlot) wake_island(island);
    drop_woken_contacts();
  }
  return Status::ok();
}

Result<BodyId> World::create_body(const BodyDef& def) {
  Result<std::vector<BodyId>> ids = create_bodies(std::span<const BodyDef>(&def, 1));
  if (!ids) {
    // A single definition needs no "bodies[0]." prefix.
    const std::string& message = ids.error();
    return Status::error(message.substr(message.find('.') + 1), ids.status().code());
  }
  return ids.value()[0];
}

Result<std::vector<BodyId>> World::create_bodies(std::span<const BodyDef> defs) {
  // Build every body first; the world changes only when all of them are valid.
  std::vector<Body> made;
  made.reserve(defs.size());
  for (std::size_t i = 0; i < defs.size(); ++i) {
    Result<Body> body = make_body(defs[i]);
    const Status status = body ? check_limits(body.value(), settings_.limits) : body.status();
    if (!status) return status.within("bodies[" + std::to_string(i) + "].");
    made.push_back(std::move(body).value());
  }
  ++query_version_;
  std::vector<BodyId> ids;
  ids.reserve(made.size());
  // The resting log's bound (resting_changed), so that steps never grow it.
  resting_log_.reserve(256 + (bodies_.size() + made.size()) / 4);
  for (Body& body : made) {
    filters_used_ = filters_used_ || body.filter != CollisionFilter{};
    std::uint32_t index;
    if (!free_slots_.empty()) {
      index = free_slots_.back();
      free_slots_.pop_back();
    } else {
      index = static_cast<std::uint32_t>(bodies_.size());
      bodies_.emplace_back();
      sleeper_head_.push_back(kNoSlot);
      sleeper_next_.push_back(kNoSlot);
    }
    Slot& slot = bodies_[index];
    slot.body = std::move(body);
    slot.alive = true;
    // A moving body joins the moving set, which every step visits anyway; only a resting one
    // changes what the broad phase keeps.
    if (slot.body.is_kinematic()) kinematic_.push_back(index);
    if (makes_many_manifolds(slot.body.shape.type())) ++many_manifold_bodies_;
    if (slot.body.is_moving())
      join_awake(index);
    else if (!slot.body.carries())  // a carrier's bounds are made every step, as a moving body's
      resting_changed(index);
    ids.push_back({index, slot.generation});
    ++live_count_;
    note_event(index, kBodyAdded);
  }
  return ids;
}

Status World::remove_body(BodyId id) {
  if (!contains(id)) return Status::not_found("body: no body with this id");
  ++query_version_;
  remove_joints_of(id.index);
  Slot& slot = bodies_[id.index];
  wake_around(slot.body);                                     // whatever rested on it must fall
  if (slot.body.asleep) wake_island(slot.body.sleep_island);  // it leaves its island's set
  if (slot.body.is_moving())
    leave_awake(id.index);
  else
    resting_changed(id.index);
  if (slot.body.is_kinematic()) std::erase(kinematic_, id.index);
  if (makes_many_manifolds(slot.body.shape.type())) --many_manifold_bodies_;
  // The step's per-slot data forget it (bounds kept for moving bodies are not visited again).
  if (id.index < bounds_.size()) {
    bounds_[id.index] = Aabb();
    movable_[id.index] = 0;
    speculative_[id.index] = 0;
    fast_[id.index] = 0;
    motion_[id.index] = 0;
  }
  note_event(id.index, kBodyRemoved);
  slot.alive = false;
  ++slot.generation;
  slot.body = Body();
  free_slots_.push_back(id.index);
  --live_count_;
  drop_woken_contacts();
  return Status::ok();
}

void World::wake_around(const Body& body) {
  const Aabb near = transform_aabb(body.shape.local_bounds(), body.pose())
                        .expanded(settings_.solver.speculative_distance + 0.05);
  auto wake_if_near = [&](std::uint32_t i) {
    const Body& other = bodies_[i].body;
    if (bodies_[i].alive && other.asleep &&
        transform_aabb(other.shape.local_bounds(), other.pose()).overlaps(near))
      wake_island(other.sleep_island);
  };
  if (!sleepers_indexed_) {
    for (std::uint32_t i = 0; i < bodies_.size(); ++i)
      wake_if_near(i);
    return;
  }
  // The sleepers the grid listed near the body, and those fallen asleep since; each is checked
  // as it is now (it may have woken, or its slot gone to another body).
  near_scratch_.clear();
  scratch_->grid.resting_near(near, &near_scratch_);
  near_scratch_.insert(near_scratch_.end(), recent_sleepers_.begin(), recent_sleepers_.end());
  for (std::uint32_t i : near_scratch_)
    wake_if_near(i);
}

Status World::check_motion(BodyId id, const BodyMotion& motion) const {
  if (!contains(id)) return Status::not_found("body: no body with this id");
  const Body& body = bodies_[id.index].body;
  if (motion.position && !is_finite(*motion.position))
    return Status::error("position: must be finite");
  if (motion.position) {
    Body moved;
    moved.type = BodyType::kStatic;  // only the position is checked here
    moved.shape = body.shape;
    moved.position = *motion.position;
    if (Status s = check_limits(moved, settings_.limits); !s) return s;
  }
  if (motion.orientation) {
    const double norm = motion.orientation->norm();
    if (!std::isfinite(norm) || std::abs(norm - 1) > 1e-3)
      return Status::error("orientation: must be a unit quaternion");
  }
  const bool is_static = body.is_static();
  if (body.is_kinematic()) {
    if (Status s = check_kinematic_motion(
            motion.force.value_or(Vec3::Zero()), motion.torque.value_or(Vec3::Zero()),
            motion.gravity_scale.value_or(1), motion.linear_damping.value_or(0),
            motion.angular_damping.value_or(0));
        !s)
      return s;
  }
  for (const auto& [velocity, name] : {std::pair{&motion.linear_velocity, "linear_velocity"},
                                       {&motion.angular_velocity, "angular_velocity"}}) {
    if (!*velocity) continue;
    if (!is_finite(**velocity)) return Status::error(std::string(name) + ": must be finite");
    if (is_static && !(*velocity)->isZero(0))
      return Status::error(std::string(name) + ": a static body does not move");
  }
  if (motion.force_point && !motion.force)
    return Status::error("force_point: needs a force to act there");
  if (Status s = check_vector(motion.force_point, "force_point"); !s) return s;
  if (Status s = check_vector(motion.force, "force"); !s) return s;
  if (Status s = check_vector(motion.torque, "torque"); !s) return s;
  if (Status s = check_own_forces(motion.gravity_scale.value_or(body.gravity_scale),
                                  motion.linear_damping.value_or(body.linear_damping),
                                  motion.angular_damping.value_or(body.angular_damping));
      !s)
    return s;
  if (body.is_kinematic())
    return check_speeds(motion.linear_velocity.value_or(body.linear_velocity),
                        motion.angular_velocity.value_or(body.angular_velocity), settings_.limits);
  if (is_static) {
    for (const auto& [v, name] :
         {std::pair{&motion.force, "force"}, std::pair{&motion.torque, "torque"}})
      if (*v && !(*v)->isZero(0))
        return Status::error(std::string(name) + ": a static body does not move");
    return Status::ok();
  }
  const auto [force, torque] = held_forces(body, motion);
  if (Status s = check_held_forces(force, torque, body.inverse_mass, body.inverse_inertia_world,
                                   settings_.limits);
      !s)
    return s;
  return check_speeds(motion.linear_velocity.value_or(body.linear_velocity),
                      motion.angular_velocity.value_or(body.angular_velocity), settings_.limits);
}

Status World::set_motion(BodyId id, const BodyMotion& motion) {
  if (Status s = check_motion(id, motion); !s) return s;
  ++query_version_;
  Body& body = bodies_[id.index].body;
  const bool immovable = !body.is_dynamic();  // moved here only by the user
  const bool carried_before = body.carries();
  if (immovable) wake_around(body);  // what rested on it where it was
  if (motion.position) body.position = *motion.position;
  if (motion.orientation) body.orientation = motion.orientation->normalized();
  if (!body.is_static()) {
    if (motion.linear_velocity) body.linear_velocity = *motion.linear_velocity;
    if (motion.angular_velocity) body.angular_velocity = *motion.angular_velocity;
  }
  if (body.is_dynamic()) std::tie(body.force, body.torque) = held_forces(body, motion);
  if (motion.gravity_scale) body.gravity_scale = *motion.gravity_scale;
  if (motion.linear_damping) body.linear_damping = *motion.linear_damping;
  if (motion.angular_damping) body.angular_damping = *motion.angular_damping;
  body.refresh_own_forces();
  // Bodies resting on it may no longer meet it (or may now): they wake, as does the body.
  if (motion.filter && *motion.filter != body.filter) {
    body.filter = *motion.filter;
    filters_used_ = filters_used_ || body.filter != CollisionFilter{};
    wake_around(body);
  }
  body.update_world_inertia();
  // A resting body's bounds and cells change; a kinematic one that starts or stops moving joins
  // or leaves the broad phase's moving bodies. (A sleeper wakes below, which counts too.)
  if (immovable && (!body.carries() || !carried_before)) resting_changed(id.index);
  if (immovable) {
    wake_around(body);         // and what it now touches
    wake_joined_to(id.index);  // and what its joints hold, however far
  } else if (body.asleep)
    wake_island(body.sleep_island);
  body.sleep_timer = 0;
  note_event(id.index, kBodyMoved);
  drop_woken_contacts();
  return Status::ok();
}

Status World::check_impulse(BodyId id, const Vec3& impulse, const Vec3* point) const {
  if (!contains(id)) return Status::not_found("body: no body with this id");
  if (bodies_[id.index].body.is_static()) return Status::error("body: a static body does not move");
  if (bodies_[id.index].body.is_kinematic())
    return Status::error("body: a kinematic body moves only by the velocity given it");
  if (!is_finite(impulse)) return Status::error("impulse: must be finite");
  if (point != nullptr && !is_finite(*point)) return Status::error("point: must be finite");
  const Body& body = bodies_[id.index].body;
  const auto [v, w] = velocities_after_impulse(body, impulse, point);
  if (Status s = check_speeds(v, w, settings_.limits); !s)
    return Status::error("impulse: it would give " + s.message());
  return Status::ok();
}

Status World::apply_impulse(BodyId id, const Vec3& impulse, const Vec3* point) {
  if (Status s = check_impulse(id, impulse, point); !s) return s;
  Body& body = bodies_[id.index].body;
  if (body.asleep) wake_island(body.sleep_island);
  body.sleep_timer = 0;
  std::tie(body.linear_velocity, body.angular_velocity) =
      velocities_after_impulse(body, impulse, point);
  note_event(id.index, kBodyMoved);
  drop_woken_contacts();
  return Status::ok();
}

Status World::apply_impulses(std::span<const ImpulseAt> impulses) {
  // The velocities each touched body would have after the entries so far, in the order the
  // bodies first appear (so that waking them is in a fixed order), and where each is by slot.
  std::vector<std::pair<std::uint32_t, std::pair<Vec3, Vec3>>> after;
  std::unordered_map<std::uint32_t, std::size_t> where;
  for (std::size_t i = 0; i < impulses.size(); ++i) {
    const ImpulseAt& entry = impulses[i];
    // The entry's path, made only for a refusal.
    const auto at = [i] { return std::string(1, '[').append(std::to_string(i)).append("]."); };
    if (!contains(entry.body)) return Status::not_found(at() + "body: no body with this id");
    const Body& body = bodies_[entry.body.index].body;
    if (body.is_static()) return Status::error(at() + "body: a static body does not move");
    if (body.is_kinematic())
      return Status::error(at() + "body: a kinematic body moves only by the velocity given it");
    if (!is_finite(entry.impulse)) return Status::error(at() + "impulse: must be finite");
    if (entry.point && !is_finite(*entry.point))
      return Status::error(at() + "point: must be finite");
    const auto [found, is_new] = where.try_emplace(entry.body.index, after.size());
    if (is_new) after.push_back({entry.body.index, {body.linear_velocity, body.angular_velocity}});
    auto& [v, w] = after[found->second].second;
    v += body.inverse_mass * entry.impulse;
    if (entry.point)
      w += body.inverse_inertia_world * (*entry.point - body.position).cross(entry.impulse);
    if (Status s = check_speeds(v, w, settings_.limits); !s)
      return Status::error(at() + "impulse: with the impulses before it on the same body, it " +
                           "would give " + s.message());
  }
  for (const auto& [slot, velocities] : after) {
    Body& body = bodies_[slot].body;
    if (body.asleep) wake_island(body.sleep_island);
    body.sleep_timer = 0;
    std::tie(body.linear_velocity, body.angular_velocity) = velocities;
    note_event(slot, kBodyMoved);
  }
  drop_woken_contacts();
  return Status::ok();
}

std::uint32_t World::wake_island(std::uint32_t island) {
  std::uint32_t woken = 0;
  std::uint32_t next = sleeper_head_[island];
  sleeper_head_[island] = kNoSlot;
  while (next != kNoSlot) {
    Body& body = bodies_[next].body;
    TUMBLE_ASSERT(bodies_[next].alive && body.asleep && body.sleep_island == island);
    body.asleep = false;
    body.sleep_timer = 0;
    ++woken;
    --sleeping_count_;
    join_awake(next);
    resting_changed(next);
    note_event(next, kBodyWoke);
    const std::uint32_t slot = next;
    next = sleeper_next_[slot];
    sleeper_next_[slot] = kNoSlot;
  }
  resting_woken_ = resting_woken_ || woken > 0;
  return woken;
}

void World::keep_resting_contacts(std::uint32_t island, std::uint32_t island_index, double dt) {
  const StepScratch& s = *scratch_;
  for (std::uint32_t k = s.islands.link_begin[island_index];
       k < s.islands.link_begin[island_index + 1]; ++k) {
    const std::uint32_t m = s.islands.links[k];
    ++resting_contacts_version_;
    resting_contacts_.push_back(contacts_[m]);
    resting_island_.push_back(island);
    for (std::uint32_t r = s.row_begin[m]; r < s.row_begin[m + 1]; ++r)
      resting_forces_.push_back(impulses_[r] / dt);
  }
}

void World::drop_woken_contacts() {
  if (!resting_woken_) return;
  resting_woken_ = false;
  ++resting_contacts_version_;
  std::size_t kept = 0, kept_points = 0, point = 0;
  for (std::size_t m = 0; m < resting_contacts_.size(); ++m) {
    const int count = resting_contacts_[m].manifold.count;
    if (sleeper_head_[resting_island_[m]] != kNoSlot) {  // still asleep
      resting_contacts_[kept] = resting_contacts_[m];
      resting_island_[kept++] = resting_island_[m];
      for (int i = 0; i < count; ++i)
        resting_forces_[kept_points++] = resting_forces_[point + i];
    }
    point += static_cast<std::size_t>(count);
  }
  resting_contacts_.resize(kept);
  resting_island_.resize(kept);
  resting_forces_.resize(kept_points);
}

void World::resting_changed(std::uint32_t slot) {
  ++resting_version_;
  if (resting_log_dropped_) return;
  // Bounded by the capacity reserved as bodies are made (256 and a quarter of the slots): past it,
  // redoing every resting body costs about as much.
  if (resting_log_.size() >= resting_log_.capacity()) {
    resting_all_changed();
    return;
  }
  resting_log_.push_back(slot);
}

void World::resting_all_changed() {
  ++resting_version_;
  resting_log_dropped_ = true;
  resting_log_.clear();
}

void World::join_awake(std::uint32_t slot) {
  awake_sorted_ = awake_sorted_ && (awake_.empty() || awake_.back() < slot);
  awake_.push_back(slot);
}

void World::leave_awake(std::uint32_t slot) {
  // Left in place: the next awake_slots() drops every slot that stopped moving in one pass, so a
  // batch of removals costs one pass over the set instead of a search each.
  TUMBLE_ASSERT(std::find(awake_.begin(), awake_.end(), slot) != awake_.end());
  awake_stale_ = true;
}

std::span<const std::uint32_t> World::awake_slots() {
  if (awake_stale_)
    std::erase_if(awake_, [&](std::uint32_t slot) {
      return !bodies_[slot].alive || !bodies_[slot].body.is_moving();
    });
  if (!awake_sorted_) {
    std::sort(awake_.begin(), awake_.end());
    awake_sorted_ = true;
  }
  // A slot freed and given to a new moving body before this pass is listed twice.
  if (awake_stale_) awake_.erase(std::unique(awake_.begin(), awake_.end()), awake_.end());
  awake_stale_ = false;
  return awake_;
}

void World::link_sleeper(std::uint32_t slot, std::uint32_t island) {
  sleeper_next_[slot] = sleeper_head_[island];
  sleeper_head_[island] = slot;
  ++sleeping_count_;
}

Status World::wake(BodyId id) {
  if (!contains(id)) return Status::not_found("body: no body with this id");
  const Body& body = bodies_[id.index].body;
  if (body.asleep) wake_island(body.sleep_island);
  drop_woken_contacts();
  return Status::ok();
}

bool World::contains(BodyId id) const {
  return id.index < bodies_.size() && bodies_[id.index].alive &&
         bodies_[id.index].generation == id.generation;
}

void World::note_event(std::uint32_t slot, std::uint8_t flag) {
  if (!events_complete_) return;
  if (event_of_slot_.size() < bodies_.size()) event_of_slot_.resize(bodies_.size(), kNoSlot);
  const BodyId id{slot, bodies_[slot].generation};
  std::uint32_t& entry = event_of_slot_[slot];
  if (entry != kNoSlot && events_[entry].body == id) {
    events_[entry].flags |= flag;
    return;
  }
  if (events_.size() >= 2 * bodies_.size() + 4096) {  // the bound body_events() promises
    events_.clear();
    event_of_slot_.assign(event_of_slot_.size(), kNoSlot);
    events_complete_ = false;
    return;
  }
  entry = static_cast<std::uint32_t>(events_.size());
  events_.push_back({id, flag});
}

void World::clear_body_events() {
  if (events_complete_) {
    for (const BodyEvent& event : events_)
      if (event.body.index < event_of_slot_.size()) event_of_slot_[event.body.index] = kNoSlot;
  } else {
    event_of_slot_.assign(event_of_slot_.size(), kNoSlot);
  }
  events_.clear();
  events_complete_ = true;
}

std::uint32_t World::slot_count() const {
  return static_cast<std::uint32_t>(bodies_.size());
}

BodyView World::body(BodyId id) const {
  return contains(id) ? BodyView(&bodies_[id.index].body) : BodyView();
}

BodyId World::id_at(std::uint32_t index) const {
  if (index >= bodies_.size() || !bodies_[index].alive) return {};
  return {index, bodies_[index].generation};
}

// With dt > 0 each body's bounds grow by how far it can move in the step, so pairs about to
// touch are found before they do. Its speculative distance is that motion, or for a fast body
// (continuous collision) the part of it the sweep does not cover.
void World::compute_bounds(double dt) {
  const double base_margin =
      settings_.collision.margin + (dt > 0 ? settings_.solver.speculative_distance : 0.0);
  if (base_margin != bounds_margin_) {
    bounds_margin_ = base_margin;
    resting_all_changed();
  }
  // Bodies that do not move keep last time's bounds while none of them changed, and all but the
  // logged ones when the log holds every change since these bounds. Slots made since hold moving
  // bodies (a resting one is logged), which are visited below, or none.
  const bool changed = bounds_version_ != resting_version_;
  const bool logged = !resting_log_dropped_ && bounds_version_ >= resting_logged_from_;
  const bool all = changed && !logged;
  bounds_version_ = resting_version_;
  bounds_.resize(bodies_.size());
  movable_.resize(bodies_.size());
  speculative_.resize(bodies_.size());
  fast_.resize(bodies_.size());
  motion_.resize(bodies_.size());
  // Zero for every body that does not move; a moving body's are set below.
  if (all) {
    speculative_.assign(bodies_.size(), 0.0);
    fast_.assign(bodies_.size(), 0);
    motion_.assign(bodies_.size(), 0.0);
  }
  const double gravity = settings_.gravity.norm();
  const SolverSettings& solver = settings_.solver;
  auto bound = [&](std::uint32_t i) {
    const Slot& slot = bodies_[i];
    if (!slot.alive) {
      bounds_[i] = Aabb();
      movable_[i] = 0;
      return;
    }
    const Body& body = slot.body;
    speculative_[i] = 0;
    fast_[i] = 0;
    motion_[i] = 0;
    const Aabb box = transform_aabb(body.shape.local_bounds(), body.pose());
    const double margin =
        settings_.collision.margin + (dt > 0 ? rest_margin(body.shape, solver) : 0.0);
    if (dt > 0 && body.carries()) {
      // Moved by its velocity alone: swept along it, grown by its turn; never swept by
      // continuous collision (what it meets is pushed, not stopped).
      const Vec3 travel = body.linear_velocity * dt;
      const double motion =
          travel.norm() + body.angular_velocity.norm() * body.shape.outer_radius() * dt;
      speculative_[i] = motion;
      motion_[i] = motion;
      Aabb swept = box;
      swept.min += travel.cwiseMin(Vec3::Zero());
      swept.max += travel.cwiseMax(Vec3::Zero());
      bounds_[i] = swept.expanded(margin + motion - travel.norm());
    } else if (dt > 0 && body.is_moving()) {
      // The box is swept along the velocity rather than grown by the speed on every side: boxes
      // falling side by side in a pile are not neighbours (a pile of 16,000 halved its pairs).
      // What the velocity cannot say, the pull of gravity over the step and the turn, grows it on
      // every side.
      const double unsure =
          (body.pull(gravity) * dt + body.angular_velocity.norm() * body.shape.outer_radius()) *
          dt;
      const Vec3 travel = body.linear_velocity * dt;
      const double motion = travel.norm() + unsure;
      const double swept_beyond = solver.continuous_fraction * body.shape.inner_radius();
      // A jointed body is not swept: stopping it at its first impact after the solve would tear
      // its joints. Its speculative contacts reach its whole motion instead.
      const bool jointed = i < joints_of_body_.size() && joints_of_body_[i] > 0;
      if (solver.continuous && motion > swept_beyond && !jointed) {
        fast_[i] = 1;
      }
      speculative_[i] = fast_[i] ? swept_beyond : motion;
      motion_[i] = motion;
      Aabb swept = box;
      swept.min += travel.cwiseMin(Vec3::Zero());
      swept.max += travel.cwiseMax(Vec3::Zero());
      bounds_[i] = swept.expanded(margin + unsure);
    } else {
      bounds_[i] = box.expanded(margin);
    }
    // Sleepers pair only with moving bodies, as statics do.
    movable_[i] = body.is_moving() || body.carries() ? 1 : 0;
  };
  const int threads = thread_count(settings_.threads);
  const std::span<const std::uint32_t> awake = awake_slots();
  if (all) {
    const std::int64_t n = static_cast<std::int64_t>(bodies_.size());
    for_indices(threads, worth_a_team(n, 40), n,
                [&](std::int64_t i) { bound(static_cast<std::uint32_t>(i)); });
  } else {
    if (changed)
      for (std::uint32_t slot : resting_log_)
        bound(slot);
    const std::int64_t n = static_cast<std::int64_t>(awake.size());
    for_indices(threads, worth_a_team(n, 40), n, [&](std::int64_t k) { bound(awake[k]); });
    for (std::uint32_t slot : kinematic_)
      if (bodies_[slot].body.carries()) bound(slot);
  }
  fast_count_ = 0;
  for (std::uint32_t slot : awake)
    fast_count_ += fast_[slot];
}

std::span<const std::uint32_t> World::broad_phase_moving() {
  const std::span<const std::uint32_t> awake = awake_slots();
  if (kinematic_.empty()) return awake;
  moving_scratch_.assign(awake.begin(), awake.end());
  const std::size_t dynamic = moving_scratch_.size();
  for (std::uint32_t slot : kinematic_)
    if (bodies_[slot].body.carries()) moving_scratch_.push_back(slot);
  if (moving_scratch_.size() == dynamic) return awake;
  std::sort(moving_scratch_.begin() + static_cast<std::ptrdiff_t>(dynamic), moving_scratch_.end());
  std::inplace_merge(moving_scratch_.begin(),
                     moving_scratch_.begin() + static_cast<std::ptrdiff_t>(dynamic),
                     moving_scratch_.end());
  return moving_scratch_;
}

std::span<const BodyPair> World::find_pairs() {
  compute_bounds(0);
  run_broad_phase();
  return pairs_;
}

std::size_t World::max_pairs() const {
  return kPairsPerBody * live_count_ + kMinPairBound;
}

void World::run_broad_phase() {
  BroadPhaseInput input{bounds_, movable_, thread_count(settings_.threads)};
  input.moving = broad_phase_moving();
  input.moving_listed = true;
  input.resting_version = resting_version_;
  if (!resting_log_dropped_) {
    input.resting_changes = resting_log_;
    input.changes_since = resting_logged_from_;
  }
  BroadPhaseMethod method = settings_.broad_phase;
  if (method == BroadPhaseMethod::kAuto)
    method = live_count_ < kSweepAndPruneBelow ? BroadPhaseMethod::kSweepAndPrune
                                               : BroadPhaseMethod::kHashGrid;
  // The grid lists every body that does not move, sleepers included; sweep and prune keeps none.
  sleepers_indexed_ = method == BroadPhaseMethod::kHashGrid;
  recent_sleepers_.clear();
  input.max_pairs = max_pairs();
  const bool cut = method == BroadPhaseMethod::kSweepAndPrune
                       ? scratch_->sweep.find_pairs(input, &pairs_)
                       : scratch_->grid.find_pairs(input, &pairs_);
  if (cut) ++stats_.pair_limit_hits;
  // The bounds (compute_bounds comes first) and the grid have seen every change so far.
  resting_log_.clear();
  resting_logged_from_ = resting_version_;
  resting_log_dropped_ = false;
}

std::span<const Contact> World::find_contacts() {
  find_pairs();
  find_contacts(0);
  return contacts_;
}

void World::find_contacts(double dt) {
  StepScratch& s = *scratch_;
  const std::int64_t n = static_cast<std::int64_t>(pairs_.size());
  // Every pair writes its own slot, then the touching ones are packed in pair order: the same
  // result for any thread count.
  if (s.found_contacts.size() < pairs_.size()) {
    resize_for_overwrite(s.found_contacts, pairs_.size());
    resize_for_overwrite(s.found_records, pairs_.size());
  }
  resize_reusing(s.found_previous, pairs_.size());
  resize_reusing(s.found_flags, pairs_.size());
  resize_reusing(s.kept_index, pairs_.size());
  const double reuse = dt > 0 ? settings_.solver.manifold_reuse : 0.0;
  const double gravity = settings_.gravity.norm();
  const int threads = thread_count(settings_.threads);
  match_pair_records(pairs_, s.pairs, s.found_previous);
  if (!unjoined_pairs_.empty()) {
    resize_reusing(s.unjoined, pairs_.size());
    mark_unjoined(pairs_, s.unjoined);
  }
  // Pairs with terrain or a compound get room for several manifolds, numbered in pair order.
  if (many_manifold_bodies_ > 0) {
    resize_reusing(s.many_slot, pairs_.size());
    // Doubled when they grow: a pile still landing on terrain adds a few such pairs most steps.
    const auto grow = [](auto& buffer, std::size_t size) {
      if (size > buffer.capacity()) buffer.reserve(std::max(size, 2 * buffer.capacity()));
      buffer.resize(size);
    };
    s.many_found.clear();  // keeps its room; push_back doubles it like grow
    std::uint32_t room = 0;
    for (std::size_t i = 0; i < pairs_.size(); ++i) {
      const Shape& a = bodies_[pairs_[i].a].body.shape;
      const Shape& b = bodies_[pairs_[i].b].body.shape;
      if (!is_many_manifold_pair(a, b)) {
        s.many_slot[i] = StepScratch::kNotMany;
        continue;
      }
      const auto most = static_cast<std::uint32_t>(most_manifolds(a, b));
      s.many_slot[i] = static_cast<std::uint32_t>(s.many_found.size());
      s.many_found.push_back({room, most, 0});
      room += most;
    }
    grow(s.many_manifolds, room);
    grow(s.many_records, room);
    grow(s.many_previous, room);
    grow(s.many_features, room);
  }
  const std::uint32_t flags =
      or_over_indices(threads, n > 64, n, 32, [&](std::int64_t i) -> std::uint32_t {
        const Body& a = bodies_[pairs_[i].a].body;
        const Body& b = bodies_[pairs_[i].b].body;
        Contact& contact = s.found_contacts[i];
        contact.a = {pairs_[i].a, bodies_[pairs_[i].a].generation};
        contact.b = {pairs_[i].b, bodies_[pairs_[i].b].generation};
        std::uint32_t previous = s.found_previous[i];
        if (previous != kNoRecord &&
            (s.pairs[previous].a != contact.a || s.pairs[previous].b != contact.b))
          previous = kNoRecord;  // the slot now holds another body
        s.found_previous[i] = previous;
        s.found_flags[i] = 0;
        // Bodies a joint holds together do not collide unless it says so, nor bodies their
        // collision filters keep apart.
        if (!unjoined_pairs_.empty() && s.unjoined[i] != 0) return 0u;
        if (filters_used_ && !a.filter.collides_with(b.filter)) return 0u;
        // A kinematic body meets the dynamic ones only: nothing moves it.
        if (!kinematic_.empty() && a.inverse_mass == 0 && b.inverse_mass == 0) return 0u;
        const Pose pose_a = a.pose(), pose_b = b.pose();
        CollisionSettings settings = settings_.collision;
        const bool fast = fast_[pairs_[i].a] || fast_[pairs_[i].b];
        const double rest = std::min(rest_margin(a.shape, settings_.solver),
                                     rest_margin(b.shape, settings_.solver));
        if (dt > 0) {
          const double reach_a = speculative_[pairs_[i].a], reach_b = speculative_[pairs_[i].b];
          settings.margin +=
              rest + (fast ? reach_a + reach_b : pair_reach(a, b, reach_a, reach_b, gravity, dt));
          // A stepping world wants the same manifold from step to step (see CollisionSettings).
          settings.feature_slack = std::max(settings.feature_slack, settings_.solver.slop);
          settings.feature_slack_relative = std::max(settings.feature_slack_relative, 0.05);
          settings.face_angle = std::max(settings.face_angle, 0.02);
        }
        if (many_manifold_bodies_ > 0 && s.many_slot[i] != StepScratch::kNotMany) {
          StepScratch::ManyFound& found = s.many_found[s.many_slot[i]];
          const std::span<ContactManifold> room(s.many_manifolds.data() + found.first, found.room);
          const std::span<PartFeature> features(s.many_features.data() + found.first, found.room);
          // The pair's records of the last step follow one another, manifold by manifold.
          std::size_t run = 0;
          if (previous != kNoRecord)
            while (previous + run < s.pairs.size() && s.pairs[previous + run].a == contact.a &&
                   s.pairs[previous + run].b == contact.b)
              ++run;
          const std::span<const ContactPairRecord> last_step =
              std::span<const ContactPairRecord>(s.pairs).subspan(
                  previous == kNoRecord ? 0 : previous, run);
          // A compound's part pairs keep their features as a single pair does (below).
          const PartHistory history{last_step, reuse, a.shape.outer_radius(),
                                    b.shape.outer_radius()};
          const bool keep_features = reuse > 0 && !fast && run > 0;
          std::size_t count = 0;
          std::uint32_t pair_flags =
              collide_many(a.shape, pose_a, b.shape, pose_b, settings, room, &count,
                           keep_features ? &history : nullptr, features);
          if (dt > 0 && count > 0 && fast) {  // as for any pair, below
            settings.margin =
                settings_.collision.margin + rest + motion_[pairs_[i].a] + motion_[pairs_[i].b];
            pair_flags |= collide_many(a.shape, pose_a, b.shape, pose_b, settings, room, &count,
                                       nullptr, features);
          }
          found.count = static_cast<std::uint32_t>(count);
          if (count == 0) return pair_flags;
          s.found_flags[i] = StepScratch::kPairTouches;
          const std::span<ContactPairRecord> records(s.many_records.data() + found.first, count);
          const std::span<std::uint32_t> matched(s.many_previous.data() + found.first, count);
          match_manifold_records(room.first(count), last_step, is_compound_pair(a.shape, b.shape),
                                 matched);
          for (std::size_t c = 0; c < count; ++c) {
            record_manifold(room[c], features[c].feature, contact.a, pose_a, contact.b, pose_b,
                            &records[c]);
            // The motion allowed is counted from where the feature was searched for.
            if (features[c].kept_from != UINT32_MAX) {
              const ContactPairRecord& kept = last_step[features[c].kept_from];
              records[c].relative_position = kept.relative_position;
              records[c].relative_orientation = kept.relative_orientation;
            }
            if (matched[c] != kNoRecord) matched[c] += previous;
          }
          if (features[0].kept_from != UINT32_MAX)
            s.found_flags[i] |= StepScratch::kPairKeptFeature;
          contact.manifold = room[0];
          s.found_records[i] = records[0];
          s.found_previous[i] = matched[0];
          return pair_flags;
        }
        // A pair of polytopes that has barely moved since its feature was searched for clips
        // that feature again (ContactPairRecord).
        PolytopeFeature known;
        const bool take_known = [&] {
          if (reuse <= 0 || fast || previous == kNoRecord) return false;
          const ContactPairRecord& record = s.pairs[previous];
          if (record.feature_kind == PolytopeFeature::kNone) return false;
          const double motion = relative_motion(record, pose_a, pose_b, a.shape.outer_radius(),
                                                b.shape.outer_radius());
          if (motion > reuse * std::min(a.shape.size(), b.shape.size())) return false;
          known = recorded_feature(record);
          return true;
        }();
        PolytopeFeature chosen;
        std::uint32_t pair_flags =
            collide(a.shape, pose_a, b.shape, pose_b, settings, take_known ? &known : nullptr,
                    &chosen, &contact.manifold);
        // A fast body already touching something is not swept against it (there is no first
        // impact to find), so the solver must see every feature that can reach it in the step: the
        // far edge of a plate falling flat, for one. Its speculative contacts cover the whole
        // motion.
        if (dt > 0 && contact.manifold.count > 0 && fast) {
          settings.margin =
              settings_.collision.margin + rest + motion_[pairs_[i].a] + motion_[pairs_[i].b];
          pair_flags |= collide(a.shape, pose_a, b.shape, pose_b, settings, nullptr, &chosen,
                                &contact.manifold);
        }
        if (contact.manifold.count > 0) {
          s.found_flags[i] = StepScratch::kPairTouches;
          ContactPairRecord& record = s.found_records[i];
          record_manifold(contact.manifold, chosen, contact.a, pose_a, contact.b, pose_b, &record);
          // The motion allowed is counted from where the feature was searched for.
          if (!chosen.searched) {
            s.found_flags[i] |= StepScratch::kPairKeptFeature;
            record.relative_position = s.pairs[previous].relative_position;
            record.relative_orientation = s.pairs[previous].relative_orientation;
          }
        }
        return pair_flags;
      });
  // The touching pairs, in pair order: where each goes (a count, on one thread, over a byte per
  // pair), then the copies spread over the team.
  std::uint32_t kept = 0;
  for (std::size_t i = 0; i < pairs_.size(); ++i) {
    s.kept_index[i] = kept;
    if ((s.found_flags[i] & StepScratch::kPairTouches) == 0) continue;
    const bool many = many_manifold_bodies_ > 0 && s.many_slot[i] != StepScratch::kNotMany;
    kept += many ? s.many_found[s.many_slot[i]].count : 1;
  }
  resize_reusing(contacts_, kept);
  resize_for_overwrite(s.next_pairs, kept);
  resize_reusing(s.previous_pair, kept);
  resize_reusing(s.reused, kept);
  for_indices(threads, worth_a_team(n, 20), n, [&](std::int64_t i) {
    if ((s.found_flags[i] & StepScratch::kPairTouches) == 0) return;
    const std::uint32_t k = s.kept_index[i];
    contacts_[k] = s.found_contacts[i];
    s.next_pairs[k] = s.found_records[i];
    s.previous_pair[k] = s.found_previous[i];
    s.reused[k] = (s.found_flags[i] & StepScratch::kPairKeptFeature) != 0;
    if (many_manifold_bodies_ == 0 || s.many_slot[i] == StepScratch::kNotMany) return;
    const StepScratch::ManyFound& found = s.many_found[s.many_slot[i]];
    for (std::uint32_t c = 1; c < found.count; ++c) {
      contacts_[k + c] = {contacts_[k].a, contacts_[k].b, s.many_manifolds[found.first + c]};
      s.next_pairs[k + c] = s.many_records[found.first + c];
      s.previous_pair[k + c] = s.many_previous[found.first + c];
      s.reused[k + c] = s.many_features[found.first + c].kept_from != UINT32_MAX;
    }
  });
  collision_flags_ = flags;
}

}  // namespace tumble
