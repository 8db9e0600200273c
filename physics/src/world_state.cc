// Saving a world's state and restoring it.
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <string>

#include "contact_pairs.h"
#include "physics/world.h"
#include "state_format.h"
#include "step_scratch.h"
#include "world_slot.h"
#include "world_state_data.h"

namespace tumble {
namespace {

Status check_body(const Body& body, std::uint32_t slot_count) {
  if (!is_finite(body.position) || !is_finite(body.linear_velocity) ||
      !is_finite(body.angular_velocity))
    return Status::error("position and velocities: must be finite");
  const double norm = body.orientation.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1) > 1e-6)
    return Status::error("orientation: must be a unit quaternion");
  if (!body.inertia_body.allFinite() || !body.inverse_inertia_body.allFinite() ||
      !body.inverse_inertia_world.allFinite())
    return Status::error("inertia: must be finite");
  if (is_static_only(body.shape.type()) && !body.is_static())
    return Status::error(std::string("shape: a ") + shape_type_name(body.shape.type()) +
                         " must be static");
  if (!body.is_dynamic()) {
    if (body.inverse_mass != 0 || !body.inverse_inertia_body.isZero(0))
      return Status::error("inverse_mass: must be 0 for a static or kinematic body");
    if (body.asleep) return Status::error("asleep: only a dynamic body sleeps");
  } else {
    if (!(body.mass > 0) || !std::isfinite(body.mass) || !(body.inverse_mass > 0) ||
        !std::isfinite(body.inverse_mass))
      return Status::error("mass: must be finite and > 0 for a dynamic body");
    // The inverses are stored too (a restored world steps bit for bit), so a crafted state could
    // pair a mass with any inverse: they must agree, and the inertia must be positive definite.
    if (std::abs(body.mass * body.inverse_mass - 1) > 1e-9)
      return Status::error("inverse_mass: must be 1 / mass");
    if (!body.inverse_inertia_body.isApprox(body.inertia_body.inverse(), 1e-9))
      return Status::error("inverse_inertia_body: must be the inverse of inertia_body");
    if (!body.inertia_body.isApprox(body.inertia_body.transpose(), 1e-9) ||
        body.inertia_body.llt().info() != Eigen::Success)
      return Status::error("inertia_body: must be symmetric positive definite");
    const Mat3 r = body.orientation.toRotationMatrix();
    const Mat3 world_inverse = r * body.inverse_inertia_body * r.transpose();
    if (!body.inverse_inertia_world.isApprox(world_inverse, 1e-6))
      return Status::error("inverse_inertia_world: must be the body's inverse inertia, rotated");
  }
  if (!(body.friction >= 0) || !std::isfinite(body.friction))
    return Status::error("friction: must be finite and >= 0");
  if (!(body.restitution >= 0 && body.restitution <= 1))
    return Status::error("restitution: must be in [0, 1]");
  if (Status s = check_own_forces(body.gravity_scale, body.linear_damping, body.angular_damping);
      !s)
    return s;
  if (!is_finite(body.force) || !is_finite(body.torque))
    return Status::error("force, torque: must be finite");
  if (body.is_static() && !(body.force.isZero(0) && body.torque.isZero(0)))
    return Status::error("force, torque: must be 0 for a static body");
  if (body.is_static() && !(body.linear_velocity.isZero(0) && body.angular_velocity.isZero(0)))
    return Status::error("linear_velocity, angular_velocity: must be 0 for a static body");
  if (body.is_kinematic()) {
    if (Status s = check_kinematic_motion(body.force, body.torque, body.gravity_scale,
                                          body.linear_damping, body.angular_damping);
        !s)
      return s;
  }
  if (!(body.sleep_timer >= 0) || !std::isfinite(body.sleep_timer))
    return Status::error("sleep_timer: must be finite and >= 0");
  if (!is_finite(body.sleep_anchor_position))
    return Status::error("sleep_anchor_position: must be finite");
  const double anchor_norm = body.sleep_anchor_orientation.norm();
  if (!std::isfinite(anchor_norm) || std::abs(anchor_norm - 1) > 1e-6)
    return Status::error("sleep_anchor_orientation: must be a unit quaternion");
  if (body.sleep_island >= slot_count) return Status::error("sleep_island: out of range");
  return Status::ok();
}

// A record names the feature its pair is clipped on while it barely moves, so the feature must
// be one the two shapes have. A record of a body removed since is kept until the next step and
// never matched (the slot's generation moves on).
Status check_contact_pair(const ContactPairRecord& record, std::span<const BodySlotState> slots) {
  if (record.a.index >= slots.size() || record.b.index >= slots.size())
    return Status::error("a, b: body out of range");
  if (record.a.index >= record.b.index) return Status::error("a: must be below b");
  if (record.count < 1 || record.count > 4) return Status::error("count: must be 1 to 4");
  if (!is_finite(record.relative_position) ||
      !(std::abs(record.relative_orientation.norm() - 1) <= 1e-6))
    return Status::error("relative pose: must be finite, with a unit quaternion");
  if (record.feature_kind > PolytopeFeature::kEdges)
    return Status::error("feature_kind: must be 0 to 3");
  if (record.colour >= kContactColours && record.colour != kNoContactColour)
    return Status::error("colour: must be below " + std::to_string(kContactColours) + ", or " +
                         std::to_string(kNoContactColour) + " for none");
  const BodySlotState& a = slots[record.a.index];
  const BodySlotState& b = slots[record.b.index];
  const bool current = a.alive && b.alive && a.generation == record.a.generation &&
                       b.generation == record.b.generation;
  if (current && !feature_fits(a.body.shape, b.body.shape, recorded_feature(record)))
    return Status::error("feature: names a face or edge the bodies' shapes do not have");
  for (int i = 0; i < record.count; ++i) {
    const ContactPointRecord& point = record.points[i];
    if (!is_finite(point.local_a) || !std::isfinite(point.normal_impulse) ||
        !is_finite(point.friction_impulse))
      return Status::error("points[" + std::to_string(i) + "]: must be finite");
  }
  return Status::ok();
}

bool unit(const Vec3& v) {
  return is_finite(v) && std::abs(v.norm() - 1) <= 1e-6;
}

// A joint names live bodies (b may be the world), one of them dynamic, with finite anchors, unit
// axes and rotation, a length a distance joint can hold, and finite impulses.
Status check_joint(const Joint& joint, std::span<const BodySlotState> slots,
                   const WorldLimits& limits) {
  auto live = [&](std::uint32_t slot) { return slot < slots.size() && slots[slot].alive; };
  if (!live(joint.a)) return Status::error("a: not a live body");
  if (joint.b != kWorldAnchor && (!live(joint.b) || joint.b == joint.a))
    return Status::error("b: not a live body other than a, nor the world");
  const bool b_static = joint.b == kWorldAnchor || slots[joint.b].body.is_static();
  if (slots[joint.a].body.is_static() && b_static)
    return Status::error("a: a joint needs a dynamic body on one side");
  if (!slots[joint.a].body.is_dynamic() &&
      (joint.b == kWorldAnchor || !slots[joint.b].body.is_dynamic()))
    return Status::error("a: a joint needs a dynamic body on one side");
  const double reach = 2 * limits.max_coordinate;
  if (!is_finite(joint.local_a) || !is_finite(joint.local_b) ||
      joint.local_a.cwiseAbs().maxCoeff() > reach || joint.local_b.cwiseAbs().maxCoeff() > reach)
    return Status::error("local_a, local_b: must be finite, within twice max_coordinate");
  if (!unit(joint.axis_a) || !unit(joint.axis_b))
    return Status::error("axis_a, axis_b: must be unit vectors");
  if (!(std::abs(joint.relative.norm() - 1) <= 1e-6))
    return Status::error("relative: must be a unit quaternion");
  if (!std::isfinite(joint.length) || joint.length < 0 || joint.length > reach ||
      (joint.kind == JointKind::kDistance && !(joint.length > 0)))
    return Status::error("length: must be finite, and > 0 for a distance joint");
  if (!is_finite(joint.linear_impulse) || !is_finite(joint.angular_impulse) ||
      !std::isfinite(joint.axial_impulse) || !std::isfinite(joint.limit_impulse) ||
      !std::isfinite(joint.motor_impulse) || !std::isfinite(joint.spring_impulse) ||
      !std::isfinite(joint.swing_impulse) || !is_finite(joint.friction_impulse))
    return Status::error("impulses: must be finite");
  if (!(std::isfinite(joint.impulse_time) && joint.impulse_time >= 0))
    return Status::error("impulse_time: must be finite and >= 0");
  if (!unit(joint.reference_a) || !unit(joint.reference_b))
    return Status::error("reference_a, reference_b: must be unit vectors");
  if (!(joint.max_swing > 0 && joint.max_swing <= std::numbers::pi) ||
      (joint.kind != JointKind::kBall && joint.max_swing < std::numbers::pi))
    return Status::error("max_swing: must be in (0, pi], below pi for a ball joint alone");
  if (Status s = validate_friction(joint.kind, joint.friction); !s) return s;
  if (Status s = validate(joint.kind, joint.limit); !s) return s;
  if (Status s = validate(joint.kind, joint.motor); !s) return s;
  if (Status s = validate(joint.kind, joint.spring); !s) return s;
  const double speed =
      joint.kind == JointKind::kHinge ? limits.max_angular_speed : limits.max_linear_speed;
  if ((joint.limit.enabled &&
       (std::abs(joint.limit.lower) > reach || std::abs(joint.limit.upper) > reach)) ||
      (joint.motor.enabled && std::abs(joint.motor.speed) > speed) ||
      (joint.spring.enabled && std::abs(joint.spring.target) > reach))
    return Status::error("limit, motor, spring: beyond the world's limits");
  return Status::ok();
}

}  // namespace

WorldStateData WorldInternals::state_of(const World& world) {
  WorldStateData state;
  state.slots.reserve(world.bodies_.size());
  for (const World::Slot& slot : world.bodies_)
    state.slots.push_back({slot.generation, slot.alive, slot.alive ? slot.body : Body{}});
  state.free_slots = world.free_slots_;
  state.time = world.time_;
  state.step = world.stats_.step;
  state.contact_pairs.assign(world.scratch_->pairs.begin(), world.scratch_->pairs.end());
  if (world.joint_count_ > 0 || !world.free_joint_slots_.empty()) {
    state.joints = world.joints_;
    state.free_joints = world.free_joint_slots_;
  }
  return state;
}

Result<World> WorldInternals::world_from(const WorldSettings& settings, WorldStateData state) {
  if (Status s = validate(settings); !s) return s.within("settings.");
  if (!(state.time >= 0) || !std::isfinite(state.time))
    return Status::error("time: must be finite and >= 0");
  const auto slot_count = static_cast<std::uint32_t>(state.slots.size());
  if (state.slots.size() >= UINT32_MAX) return Status::error("slots: too many");
  std::size_t live = 0;
  for (std::uint32_t i = 0; i < slot_count; ++i) {
    const BodySlotState& slot = state.slots[i];
    if (!slot.alive) continue;
    ++live;
    if (Status s = check_body(slot.body, slot_count); !s)
      return s.within("slots[" + std::to_string(i) + "].");
    if (Status s = check_limits(slot.body, settings.limits); !s)
      return s.within("slots[" + std::to_string(i) + "].");
  }
  // Exactly the dead slots are free, each once: creation reuses them in this order.
  std::vector<std::uint8_t> listed(slot_count, 0);
  for (std::size_t k = 0; k < state.free_slots.size(); ++k) {
    const std::uint32_t i = state.free_slots[k];
    if (i >= slot_count || state.slots[i].alive || listed[i])
      return Status::error("free_slots[" + std::to_string(k) + "]: not a dead slot, or repeated");
    listed[i] = 1;
  }
  if (state.free_slots.size() != slot_count - live)
    return Status::error("free_slots: must list every dead slot");
  // A pair with terrain has a record for each of its manifolds, one after another.
  std::size_t repeats = 0;
  for (std::size_t k = 0; k < state.contact_pairs.size(); ++k) {
    if (Status s = check_contact_pair(state.contact_pairs[k], state.slots); !s)
      return s.within("contact_pairs[" + std::to_string(k) + "].");
    if (k == 0) continue;
    const ContactPairRecord& p = state.contact_pairs[k - 1];
    const ContactPairRecord& r = state.contact_pairs[k];
    const bool same = p.a.index == r.a.index && p.b.index == r.b.index;
    repeats = same ? repeats + 1 : 0;
    // (A record of a body removed since is never matched: nothing to check of it.)
    const BodySlotState& a = state.slots[r.a.index];
    const BodySlotState& b = state.slots[r.b.index];
    const bool current =
        a.alive && b.alive && a.generation == r.a.generation && b.generation == r.b.generation;
    const bool many = !current || is_many_manifold_pair(a.body.shape, b.body.shape);
    const bool repeat_allowed = same && many && repeats < kMaxPairManifolds;
    if (!repeat_allowed &&
        (p.a.index != r.a.index ? p.a.index > r.a.index : p.b.index >= r.b.index))
      return Status::error("contact_pairs[" + std::to_string(k) +
                           "]: not sorted by body pair, or repeated");
  }

  if (state.joints.size() > World::kMaxJoints)
    return Status::error("joints: more than " + std::to_string(World::kMaxJoints));
  std::size_t live_joints = 0;
  for (std::size_t i = 0; i < state.joints.size(); ++i) {
    if (!state.joints[i].alive) continue;
    ++live_joints;
    if (Status s = check_joint(state.joints[i].joint, state.slots, settings.limits); !s)
      return s.within("joints[" + std::to_string(i) + "].");
  }
  std::vector<std::uint8_t> joint_listed(state.joints.size(), 0);
  for (std::size_t k = 0; k < state.free_joints.size(); ++k) {
    const std::uint32_t i = state.free_joints[k];
    if (i >= state.joints.size() || state.joints[i].alive || joint_listed[i])
      return Status::error("free_joints[" + std::to_string(k) + "]: not a dead slot, or repeated");
    joint_listed[i] = 1;
  }
  if (state.free_joints.size() != state.joints.size() - live_joints)
    return Status::error("free_joints: must list every dead joint slot");

  World world(settings);
  world.bodies_.reserve(slot_count);
  for (BodySlotState& slot : state.slots)
    world.bodies_.push_back({std::move(slot.body), slot.generation, slot.alive});
  world.free_slots_ = std::move(state.free_slots);
  world.resting_log_.reserve(256 + slot_count / 4);  // as create_bodies reserves it
  world.sleeper_head_.assign(slot_count, World::kNoSlot);
  world.sleeper_next_.assign(slot_count, World::kNoSlot);
  for (std::uint32_t i = 0; i < slot_count; ++i) {
    if (!world.bodies_[i].alive) continue;
    if (world.bodies_[i].body.asleep) world.link_sleeper(i, world.bodies_[i].body.sleep_island);
    if (world.bodies_[i].body.is_moving()) world.awake_.push_back(i);
    if (world.bodies_[i].body.is_kinematic()) world.kinematic_.push_back(i);
    if (makes_many_manifolds(world.bodies_[i].body.shape.type())) ++world.many_manifold_bodies_;
    world.filters_used_ = world.filters_used_ || world.bodies_[i].body.filter != CollisionFilter{};
  }
  world.live_count_ = live;
  world.time_ = state.time;
  world.stats_.step = state.step;
  world.scratch_->pairs.assign(state.contact_pairs.begin(), state.contact_pairs.end());
  world.joints_ = std::move(state.joints);
  world.free_joint_slots_ = std::move(state.free_joints);
  world.restore_joint_indexes();
  world.events_complete_ = false;  // every body is new to whoever mirrors this world
  return world;
}

std::string World::save_state() const {
  return encode_state(WorldInternals::state_of(*this));
}

Result<StateSizes> World::state_sizes(std::string_view bytes) {
  return read_state_header(bytes);
}

Result<World> World::from_state(const WorldSettings& settings, std::string_view bytes) {
  Result<WorldStateData> state = decode_state(bytes);
  if (!state) return state.status();
  return WorldInternals::world_from(settings, std::move(state).value());
}

Status World::restore_state(std::string_view bytes) {
  Result<World> restored = from_state(settings_, bytes);
  if (!restored) return restored.status();
  *this = std::move(restored).value();
  return Status::ok();
}

}  // namespace tumble
