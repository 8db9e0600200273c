#include "joint_commands.h"

#include <cmath>
#include <numbers>
#include <unordered_set>

#include "convert.h"
#include "world_commands.h"

namespace tumble::server {
namespace {

std::string entry(const char* list, int i) {
  return std::string(list) + "[" + std::to_string(i) + "]";
}

JointMotor motor_from_proto(const v1::JointMotor& m) {
  return {true, m.speed(), m.max_force()};
}
JointSpring spring_from_proto(const v1::JointSpring& s) {
  return {true, s.target(), s.stiffness(), s.damping()};
}

// The joints named by `wire_ids`, refusing the first unknown one, and ids listed twice.
Status find_joints(const HostedWorld& hosted, const char* list,
                   const google::protobuf::RepeatedField<std::uint64_t>& wire_ids,
                   std::vector<JointId>* ids) {
  std::unordered_set<std::uint64_t> seen;
  for (int i = 0; i < wire_ids.size(); ++i) {
    if (!seen.insert(wire_ids[i]).second) return Status::error(entry(list, i) + ": listed twice");
    const JointId id = hosted.joint_ids.find(wire_ids[i]);
    if (!hosted.world.contains(id))
      return Status::not_found(entry(list, i) + ": no joint " + std::to_string(wire_ids[i]));
    ids->push_back(id);
  }
  return Status::ok();
}

}  // namespace

Result<JointDef> joint_from_proto(const v1::JointSpec& spec) {
  JointDef def;
  switch (spec.kind()) {
    case v1::JOINT_KIND_BALL:
      def.kind = JointKind::kBall;
      break;
    case v1::JOINT_KIND_HINGE:
      def.kind = JointKind::kHinge;
      break;
    case v1::JOINT_KIND_FIXED:
      def.kind = JointKind::kFixed;
      break;
    case v1::JOINT_KIND_DISTANCE:
      def.kind = JointKind::kDistance;
      break;
    case v1::JOINT_KIND_SLIDER:
      def.kind = JointKind::kSlider;
      break;
    default:
      return Status::error("kind: unknown joint kind " + std::to_string(spec.kind()));
  }
  def.anchor = vec_from_proto(spec.anchor());
  def.anchor_b = vec_from_proto(spec.anchor_b());
  if (spec.has_axis()) def.axis = vec_from_proto(spec.axis());
  def.length = spec.length();
  def.collide_connected = spec.collide_connected();
  if (spec.has_limit()) def.limit = {true, spec.limit().lower(), spec.limit().upper()};
  if (spec.has_motor()) def.motor = motor_from_proto(spec.motor());
  if (spec.has_spring()) def.spring = spring_from_proto(spec.spring());
  if (spec.has_max_swing()) def.max_swing = spec.max_swing();
  def.friction = spec.friction();
  // The checks that need no world, with placeholder bodies (the world checks the real ones).
  JointDef check = def;
  check.a = BodyId{0, 0};
  check.b = BodyId{1, 0};
  if (Status s = validate(check); !s) return s;
  return def;
}

void joint_to_proto(const JointDef& def, const HostedWorld& hosted, v1::JointSpec* out) {
  joint_spec_to_proto(def, hosted.ids.wire(def.a), def.b.is_valid() ? hosted.ids.wire(def.b) : 0,
                      out);
}

Status create_joints(HostedWorld& hosted, const v1::CreateJointsRequest& request,
                     std::size_t max_joints, std::vector<std::uint64_t>* ids) {
  World& world = hosted.world;
  const std::size_t count = static_cast<std::size_t>(request.joints_size());
  if (world.joint_count() + count > max_joints)
    return Status::error("joints: " + std::to_string(count) + " more would exceed the " +
                             std::to_string(max_joints) + " joints allowed",
                         StatusCode::kResourceExhausted);
  // Every joint is checked against the world before any is made: all or nothing.
  std::vector<JointDef> defs;
  defs.reserve(count);
  for (int i = 0; i < request.joints_size(); ++i) {
    const v1::JointSpec& spec = request.joints(i);
    const std::string at = entry("joints", i) + ".";
    Result<JointDef> def = joint_from_proto(spec);
    if (!def) return def.status().within(at);
    def.value().a = hosted.ids.find(spec.a());
    if (!world.contains(def.value().a))
      return Status::not_found(at + "a: no body " + std::to_string(spec.a()));
    if (spec.b() != 0) {
      def.value().b = hosted.ids.find(spec.b());
      if (!world.contains(def.value().b))
        return Status::not_found(at + "b: no body " + std::to_string(spec.b()));
    }
    if (Status s = world.check_joint(def.value()); !s) return s.within(at);
    defs.push_back(std::move(def).value());
  }
  std::vector<JointId> made;
  made.reserve(count);
  for (const JointDef& def : defs) {
    Result<JointId> id = world.create_joint(def);
    if (!id)  // checked above, and nothing between changed the world
      return Status::error("joints: refused after its check: " + id.error(), StatusCode::kInternal);
    made.push_back(id.value());
  }
  hosted.joint_ids.sync(world);
  for (JointId id : made)
    ids->push_back(hosted.joint_ids.wire(id));
  return Status::ok();
}

Status remove_joints(HostedWorld& hosted, const v1::RemoveJointsRequest& request) {
  hosted.joint_ids.sync(hosted.world);  // joints removed with their bodies lose their ids
  std::vector<JointId> ids;
  if (Status found = find_joints(hosted, "ids", request.ids(), &ids); !found) return found;
  for (JointId id : ids)
    hosted.world.remove_joint(id);
  hosted.joint_ids.sync(hosted.world);
  return Status::ok();
}

Status set_joint_drives(HostedWorld& hosted, const v1::SetJointDrivesRequest& request) {
  World& world = hosted.world;
  hosted.joint_ids.sync(world);
  struct Change {
    JointId id;
    JointMotor motor;
    JointSpring spring;
    bool motor_set, spring_set;
  };
  std::vector<Change> changes;
  std::unordered_set<std::uint64_t> seen;
  for (int i = 0; i < request.updates_size(); ++i) {
    const v1::JointDriveUpdate& update = request.updates(i);
    const std::string at = entry("updates", i);
    if (!seen.insert(update.id()).second) return Status::error(at + ".id: listed twice");
    const JointId id = hosted.joint_ids.find(update.id());
    if (!world.contains(id))
      return Status::not_found(at + ".id: no joint " + std::to_string(update.id()));
    const JointDef def = world.joint_def(id).value();
    Change change{id, def.motor, def.spring, false, false};
    if (update.has_motor() || update.motor_off()) {
      if (update.has_motor() && update.motor_off())
        return Status::error(at + ".motor_off: a motor and motor_off both given");
      change.motor = update.motor_off() ? JointMotor{} : motor_from_proto(update.motor());
      change.motor_set = true;
      if (Status s = validate(def.kind, change.motor); !s) return s.within(at + ".");
    }
    if (update.has_spring() || update.spring_off()) {
      if (update.has_spring() && update.spring_off())
        return Status::error(at + ".spring_off: a spring and spring_off both given");
      change.spring = update.spring_off() ? JointSpring{} : spring_from_proto(update.spring());
      change.spring_set = true;
      if (Status s = validate(def.kind, change.spring); !s) return s.within(at + ".");
    }
    changes.push_back(change);
  }
  // Checked above: these cannot be refused.
  for (const Change& change : changes) {
    if (change.motor_set) world.set_joint_motor(change.id, change.motor);
    if (change.spring_set) world.set_joint_spring(change.id, change.spring);
  }
  return Status::ok();
}

Status get_joints(const HostedWorld& hosted, const v1::GetJointsRequest& request,
                  v1::GetJointsResponse* response) {
  // No sync needed: a joint gone with its body is not listed, and its stale id names nothing.
  const World& world = hosted.world;
  std::vector<JointId> ids;
  if (request.ids_size() == 0) {
    for (std::uint32_t slot = 0; slot < world.joint_slot_count(); ++slot)
      if (world.joint_at(slot).is_valid()) ids.push_back(world.joint_at(slot));
  } else if (Status found = find_joints(hosted, "ids", request.ids(), &ids); !found) {
    return found;
  }
  response->set_step(world.step_count());
  for (JointId id : ids) {
    response->add_ids(hosted.joint_ids.wire(id));
    joint_to_proto(world.joint_def(id).value(), hosted, response->add_specs());
    const JointReading reading = world.joint_reading(id).value();
    v1::JointState* state = response->add_states();
    state->set_id(hosted.joint_ids.wire(id));
    state->set_position(reading.position);
    state->set_speed(reading.speed);
    state->set_effort(reading.effort);
    vec_to_proto(reading.force, state->mutable_force());
    vec_to_proto(reading.torque, state->mutable_torque());
    state->set_error(world.joint_error(id).value());
  }
  return Status::ok();
}

}  // namespace tumble::server
