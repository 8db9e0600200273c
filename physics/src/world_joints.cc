// The world's joints: made, removed, checked, and handed to the step (joint_solver.h solves them
// with the contacts of their islands).
#include <algorithm>
#include <cmath>

#include "joint_geometry.h"
#include "joint_solver.h"
#include "joint_state.h"
#include "physics/world.h"
#include "step_scratch.h"
#include "world_slot.h"

namespace tumble {
namespace {

std::uint64_t pair_key(std::uint32_t x, std::uint32_t y) {
  return (static_cast<std::uint64_t>(std::min(x, y)) << 32) | std::max(x, y);
}

// A motor's speed within the world's speed limits, a spring's target within its reach.
Status check_motor(JointKind kind, const JointMotor& motor, const WorldLimits& limits) {
  const double most =
      kind == JointKind::kHinge ? limits.max_angular_speed : limits.max_linear_speed;
  if (motor.enabled && std::abs(motor.speed) > most)
    return Status::error("motor.speed: beyond the world's speed limit " + std::to_string(most));
  return Status::ok();
}

Status check_spring(const JointSpring& spring, const WorldLimits& limits) {
  if (spring.enabled && std::abs(spring.target) > 2 * limits.max_coordinate)
    return Status::error("spring.target: beyond twice the world's max_coordinate");
  return Status::ok();
}

}  // namespace

Status World::check_joint(const JointDef& def) const {
  if (Status valid = validate(def); !valid) return valid;
  if (!contains(def.a)) return Status::not_found("a: no body with this id");
  const bool world_b = !def.b.is_valid();
  if (!world_b && !contains(def.b)) return Status::not_found("b: no body with this id");
  const Body& a = bodies_[def.a.index].body;
  if (!a.is_dynamic() && (world_b || !bodies_[def.b.index].body.is_dynamic()))
    return Status::error("a: a joint needs a dynamic body on one side");
  const WorldLimits& limits = settings_.limits;
  auto within = [&](const Vec3& p) { return p.cwiseAbs().maxCoeff() <= limits.max_coordinate; };
  if (!within(def.anchor)) return Status::error("anchor: beyond the world's max_coordinate");
  if (!within(def.anchor_b)) return Status::error("anchor_b: beyond the world's max_coordinate");
  const double reach = 2 * limits.max_coordinate;
  if (def.length > reach) return Status::error("length: beyond twice the world's max_coordinate");
  if (def.limit.enabled && (std::abs(def.limit.lower) > reach || std::abs(def.limit.upper) > reach))
    return Status::error("limit: beyond twice the world's max_coordinate");
  if (Status s = check_motor(def.kind, def.motor, limits); !s) return s;
  if (Status s = check_spring(def.spring, limits); !s) return s;
  if (def.kind == JointKind::kDistance && def.limit.enabled && def.limit.lower == def.limit.upper &&
      !(def.limit.lower > 0))
    return Status::error("limit: a distance joint's length must be > 0");
  if (joint_count_ >= kMaxJoints)
    return Status::error(
        "joints: the world holds " + std::to_string(kMaxJoints) + " joints, the most it takes",
        StatusCode::kResourceExhausted);
  return Status::ok();
}

Result<JointId> World::create_joint(const JointDef& def) {
  if (Status checked = check_joint(def); !checked) return checked;
  const bool world_b = !def.b.is_valid();
  const Body& a = bodies_[def.a.index].body;
  const Body* b = world_b ? nullptr : &bodies_[def.b.index].body;

  Joint joint;
  joint.kind = def.kind;
  joint.a = def.a.index;
  joint.b = world_b ? kWorldAnchor : def.b.index;
  joint.collide_connected = def.collide_connected;
  const Vec3 end_b = def.kind == JointKind::kDistance ? def.anchor_b : def.anchor;
  const bool has_axis = def.kind == JointKind::kHinge || def.kind == JointKind::kSlider ||
                        def.kind == JointKind::kBall;
  const Vec3 axis = has_axis ? def.axis.stableNormalized() : Vec3::UnitZ();
  const Vec3 reference = joint_detail::perpendicular(axis);
  const Quat qa_inverse = a.orientation.conjugate();
  joint.local_a = qa_inverse * (def.anchor - a.position);
  joint.axis_a = qa_inverse * axis;
  joint.reference_a = qa_inverse * reference;
  if (world_b) {
    joint.local_b = end_b;
    joint.axis_b = axis;
    joint.reference_b = reference;
    joint.relative = qa_inverse;
  } else {
    const Quat qb_inverse = b->orientation.conjugate();
    joint.local_b = qb_inverse * (end_b - b->position);
    joint.axis_b = qb_inverse * axis;
    joint.reference_b = qb_inverse * reference;
    joint.relative = qa_inverse * b->orientation;
  }
  joint.length = def.length > 0 ? def.length : (def.anchor_b - def.anchor).norm();
  joint.limit = def.limit;
  joint.motor = def.motor;
  joint.spring = def.spring;
  joint.max_swing = def.max_swing;
  joint.friction = def.friction;
  if (def.kind == JointKind::kDistance && def.limit.enabled && def.limit.lower == def.limit.upper) {
    // A range of one length is a rod of that length.
    joint.length = def.limit.lower;
    joint.limit = JointLimit{};
  }

  std::uint32_t index;
  if (!free_joint_slots_.empty()) {
    index = free_joint_slots_.back();
    free_joint_slots_.pop_back();
  } else {
    index = static_cast<std::uint32_t>(joints_.size());
    joints_.emplace_back();
  }
  JointSlot& slot = joints_[index];
  slot.joint = joint;
  slot.alive = true;
  ++joint_count_;
  if (joints_of_body_.size() < bodies_.size()) joints_of_body_.resize(bodies_.size(), 0);
  ++joints_of_body_[joint.a];
  if (!world_b) ++joints_of_body_[joint.b];
  if (!world_b && !joint.collide_connected) {
    const std::uint64_t key = pair_key(joint.a, joint.b);
    unjoined_pairs_.insert(std::upper_bound(unjoined_pairs_.begin(), unjoined_pairs_.end(), key),
                           key);
  }
  wake_joint(joint);
  return JointId{index, slot.generation};
}

bool World::contains(JointId id) const {
  return id.index < joints_.size() && joints_[id.index].alive &&
         joints_[id.index].generation == id.generation;
}

Status World::remove_joint(JointId id) {
  if (!contains(id)) return Status::not_found("joint: no joint with this id");
  JointSlot& slot = joints_[id.index];
  const Joint& joint = slot.joint;
  for (std::uint32_t body : {joint.a, joint.b}) {
    if (body == kWorldAnchor) continue;
    --joints_of_body_[body];
    if (bodies_[body].body.asleep) wake_island(bodies_[body].body.sleep_island);
  }
  if (joint.b != kWorldAnchor && !joint.collide_connected) {
    const auto at = std::lower_bound(unjoined_pairs_.begin(), unjoined_pairs_.end(),
                                     pair_key(joint.a, joint.b));
    TUMBLE_ASSERT(at != unjoined_pairs_.end() && *at == pair_key(joint.a, joint.b));
    unjoined_pairs_.erase(at);
  }
  slot.alive = false;
  ++slot.generation;
  slot.joint = Joint();
  free_joint_slots_.push_back(id.index);
  --joint_count_;
  return Status::ok();
}

Result<double> World::joint_error(JointId id) const {
  if (!contains(id)) return Status::not_found("joint: no joint with this id");
  const Joint& joint = joints_[id.index].joint;
  const Pose pose_b = joint.b == kWorldAnchor ? Pose{} : bodies_[joint.b].body.pose();
  return tumble::joint_error(joint, bodies_[joint.a].body.pose(), pose_b);
}

Status World::set_joint_motor(JointId id, const JointMotor& motor) {
  if (!contains(id)) return Status::not_found("joint: no joint with this id");
  Joint& joint = joints_[id.index].joint;
  if (Status s = validate(joint.kind, motor); !s) return s;
  if (Status s = check_motor(joint.kind, motor, settings_.limits); !s) return s;
  joint.motor = motor;
  if (!motor.enabled) joint.motor_impulse = 0;
  wake_joint(joint);
  return Status::ok();
}

Status World::set_joint_spring(JointId id, const JointSpring& spring) {
  if (!contains(id)) return Status::not_found("joint: no joint with this id");
  Joint& joint = joints_[id.index].joint;
  if (Status s = validate(joint.kind, spring); !s) return s;
  if (Status s = check_spring(spring, settings_.limits); !s) return s;
  joint.spring = spring;
  if (!spring.enabled) joint.spring_impulse = 0;
  wake_joint(joint);
  return Status::ok();
}

void World::wake_joint(const Joint& joint) {
  for (std::uint32_t body : {joint.a, joint.b})
    if (body != kWorldAnchor && bodies_[body].body.asleep)
      wake_island(bodies_[body].body.sleep_island);
}

Result<JointReading> World::joint_reading(JointId id) const {
  if (!contains(id)) return Status::not_found("joint: no joint with this id");
  const Joint& joint = joints_[id.index].joint;
  auto motion = [](const Body& body) {
    SolverBody s;
    s.v = body.linear_velocity;
    s.w = body.angular_velocity;
    return s;
  };
  const Body& a = bodies_[joint.a].body;
  if (joint.b == kWorldAnchor) return read_joint(joint, a.pose(), Pose{}, motion(a), SolverBody{});
  const Body& b = bodies_[joint.b].body;
  return read_joint(joint, a.pose(), b.pose(), motion(a), motion(b));
}

Result<JointDef> World::joint_def(JointId id) const {
  if (!contains(id)) return Status::not_found("joint: no joint with this id");
  const Joint& joint = joints_[id.index].joint;
  const Body& a = bodies_[joint.a].body;
  JointDef def;
  def.kind = joint.kind;
  def.a = id_at(joint.a);
  def.anchor = a.pose().transform(joint.local_a);
  def.axis = a.orientation * joint.axis_a;
  if (joint.b == kWorldAnchor) {
    def.anchor_b = joint.local_b;
  } else {
    def.b = id_at(joint.b);
    def.anchor_b = bodies_[joint.b].body.pose().transform(joint.local_b);
  }
  if (joint.kind != JointKind::kDistance) def.anchor_b = Vec3::Zero();
  def.length = joint.kind == JointKind::kDistance ? joint.length : 0;
  def.collide_connected = joint.collide_connected;
  def.limit = joint.limit;
  def.motor = joint.motor;
  def.spring = joint.spring;
  def.max_swing = joint.max_swing;
  def.friction = joint.friction;
  return def;
}

std::uint32_t World::joint_slot_count() const {
  return static_cast<std::uint32_t>(joints_.size());
}

JointId World::joint_at(std::uint32_t slot) const {
  if (slot >= joints_.size() || !joints_[slot].alive) return {};
  return {slot, joints_[slot].generation};
}

void World::remove_joints_of(std::uint32_t body_slot) {
  if (body_slot >= joints_of_body_.size() || joints_of_body_[body_slot] == 0) return;
  for (std::uint32_t index = 0; index < joints_.size(); ++index) {
    const JointSlot& slot = joints_[index];
    if (slot.alive && (slot.joint.a == body_slot || slot.joint.b == body_slot))
      remove_joint({index, slot.generation});
  }
}

void World::restore_joint_indexes() {
  joint_count_ = 0;
  joints_of_body_.assign(bodies_.size(), 0);
  unjoined_pairs_.clear();
  for (const JointSlot& slot : joints_) {
    if (!slot.alive) continue;
    ++joint_count_;
    ++joints_of_body_[slot.joint.a];
    if (slot.joint.b == kWorldAnchor) continue;
    ++joints_of_body_[slot.joint.b];
    if (!slot.joint.collide_connected)
      unjoined_pairs_.push_back(pair_key(slot.joint.a, slot.joint.b));
  }
  std::sort(unjoined_pairs_.begin(), unjoined_pairs_.end());
}

void World::mark_unjoined(std::span<const BodyPair> pairs, std::span<std::uint8_t> out) const {
  // One walk of both sorted lists: pair_key orders pairs as the broad phase does (a < b, by a
  // then b). A binary search a pair cost the ragdolls' step 1% of its instructions, and its
  // branches were mispredicted a third of the time.
  std::size_t u = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const std::uint64_t key = pair_key(pairs[i].a, pairs[i].b);
    // The walk misses joined pairs if the list is out of order.
    TUMBLE_ASSERT(i == 0 || pair_key(pairs[i - 1].a, pairs[i - 1].b) < key);
    while (u < unjoined_pairs_.size() && unjoined_pairs_[u] < key)
      ++u;
    out[i] = u < unjoined_pairs_.size() && unjoined_pairs_[u] == key ? 1 : 0;
  }
}

std::uint32_t World::wake_jointed() {
  if (joint_count_ == 0 || sleeping_count_ == 0) return 0;
  std::uint32_t woken = 0;
  for (const JointSlot& slot : joints_) {
    if (!slot.alive || slot.joint.b == kWorldAnchor) continue;
    const Body& a = bodies_[slot.joint.a].body;
    const Body& b = bodies_[slot.joint.b].body;
    if ((a.is_moving() || a.carries()) && b.asleep) woken += wake_island(b.sleep_island);
    if ((b.is_moving() || b.carries()) && a.asleep) woken += wake_island(a.sleep_island);
  }
  return woken;
}

void World::wake_joined_to(std::uint32_t body_slot) {
  if (body_slot >= joints_of_body_.size() || joints_of_body_[body_slot] == 0) return;
  for (const JointSlot& slot : joints_) {
    if (!slot.alive || (slot.joint.a != body_slot && slot.joint.b != body_slot)) continue;
    const std::uint32_t other = slot.joint.a == body_slot ? slot.joint.b : slot.joint.a;
    if (other != kWorldAnchor && bodies_[other].body.asleep)
      wake_island(bodies_[other].body.sleep_island);
  }
}

void World::prepare_joint_rows() {
  StepScratch& s = *scratch_;
  s.joint_rows.clear();
  s.joint_links.clear();
  if (joint_count_ == 0) return;
  // A kinematic body with a velocity gets a solver body of its own in each joint that holds it:
  // the island's position passes move it to where it is at the island's time (SerialIsland),
  // and islands that share it run at different times on different threads.
  const auto kinematic_of_its_own = [&s](std::uint32_t k) {
    if (!s.bodies[k].kinematic) return k;
    const std::uint32_t copy = static_cast<std::uint32_t>(s.bodies.size());
    const SolverBody body = s.bodies[k];
    const Pose pose = s.poses[k];
    const Body* const of = s.body_of[k];
    const std::uint32_t slot = s.solver_slot[k];
    s.bodies.push_back(body);
    s.poses.push_back(pose);
    s.dynamic.push_back(0);
    s.body_of.push_back(of);
    s.solver_slot.push_back(slot);
    return copy;
  };
  for (std::uint32_t index = 0; index < joints_.size(); ++index) {
    const JointSlot& slot = joints_[index];
    if (!slot.alive) continue;
    const bool world_b = slot.joint.b == kWorldAnchor;
    const std::uint32_t a = s.solver_of_slot[slot.joint.a];
    const std::uint32_t b = world_b ? kWorldAnchor : s.solver_of_slot[slot.joint.b];
    const bool moves_a = a != kNoSolverBody && a < s.moving;
    const bool moves_b = !world_b && b != kNoSolverBody && b < s.moving;
    if (!moves_a && !moves_b) continue;  // asleep, or both static
    // number_solver_bodies numbered both bodies of a joint with a moving body.
    TUMBLE_ASSERT(a != kNoSolverBody && (world_b || b != kNoSolverBody));
    s.joint_rows.push_back({slot.joint, kinematic_of_its_own(a), world_b ? b : kinematic_of_its_own(b),
                            index});
    s.joint_links.push_back({a, b == kWorldAnchor ? a : b});
  }
  s.joint_terms.resize(s.joint_rows.size());
}

void World::store_joint_impulses() {
  const StepScratch& s = *scratch_;
  stats_.solved_joints = static_cast<std::uint32_t>(s.joint_rows.size());
  for (const JointRow& row : s.joint_rows) {
    const Pose pose_b = row.b == kWorldAnchor ? Pose{} : s.poses[row.b];
    stats_.joint_error =
        std::max(stats_.joint_error, tumble::joint_error(row.joint, s.poses[row.a], pose_b));
    Joint& joint = joints_[row.slot].joint;
    joint.linear_impulse = row.joint.linear_impulse;
    joint.angular_impulse = row.joint.angular_impulse;
    joint.axial_impulse = row.joint.axial_impulse;
    joint.limit_impulse = row.joint.limit_impulse;
    joint.motor_impulse = row.joint.motor_impulse;
    joint.spring_impulse = row.joint.spring_impulse;
    joint.swing_impulse = row.joint.swing_impulse;
    joint.friction_impulse = row.joint.friction_impulse;
    joint.impulse_time = row.joint.impulse_time;
  }
}

}  // namespace tumble
