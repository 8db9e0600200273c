// Between the API's messages and the engine's types. Every refusal names the field at fault,
// relative to the message given ("shape.box.size.x: must be > 0").
#pragma once

#include <optional>
#include "frame.h"
#include "world_host.h"

#include "physics/world.h"
#include "tumble/v1/world.pb.h"

namespace tumble::server {

Result<BodyDef> body_from_proto(const v1::BodySpec& spec);

Vec3 vec_from_proto(const v1::Vec3& v);
void vec_to_proto(const Vec3& v, v1::Vec3* out);
// The fields an update sets (SetBodyState); its own checks are World::check_motion's. A filter
// field not given keeps the body's (`current_filter`).
BodyMotion motion_from_proto(const v1::BodyStateUpdate& update,
                             const CollisionFilter& current_filter);

// A shape as the engine defines it, or why the message is not one ("shape: required ...").
Result<ShapeDef> shape_def_from_proto(const v1::Shape& shape);
// An engine refusal of a shape's field in the API's terms: the engine names a hull's points
// `shape.points` and a compound part `shape.parts[i]`, the API nests each kind in its own message
// (`shape.hull.points`, `shape.compound.parts[i].shape.hull.points`; a sphere's and a capsule's
// radius and half height likewise). A box's `shape.half_extents` (the message has its full size)
// and other messages are left as they are.
std::string in_api_terms(const std::string& message, const v1::Shape& shape);
Status in_api_terms(const Status& status, const v1::Shape& shape);

// What a viewer needs to draw the body with wire id `id`.
v1::BodyType proto_body_type(BodyType type);
void describe(std::uint64_t id, const BodyLook& look, v1::BodyDescription* out);
// What acts on it beyond gravity and contacts, and its collision filter (GetBodies).
void describe_forces(const BodyView& body, v1::BodyDescription* out);

struct FrameOptions {
  bool velocities = false, contacts = false, stats = false, joints = false;
  std::vector<std::uint64_t> ids;  // sorted; empty: every body
  bool changes_only = false;       // StreamFramesRequest.changes_only
  double full_frame_interval = 0;  // s; 0: full frames only when needed
};

// The frame's bodies (and, when asked, velocities, contacts and statistics) into `out`; with
// `changed_after` > 0, only the bodies changed after that tick of the change clock
// (FrameData::changed_at), and the frame is marked changes_only.
void frame_to_proto(const FrameData& frame, const FrameOptions& options, v1::Frame* out,
                    std::uint64_t changed_after = 0);

void stats_to_proto(const StepStats& stats, v1::StepStats* out);

// A joint's definition as a JointSpec, its bodies' wire ids given (b: 0 for the world).
void joint_spec_to_proto(const JointDef& def, std::uint64_t a, std::uint64_t b, v1::JointSpec* out);

// What a Control request changes, checked field by field ("dt: must be finite and > 0").
struct RunChange {
  std::optional<double> dt, real_time_factor;
  std::optional<Vec3> gravity;
  std::optional<int> substeps, iterations, joint_position_passes;
  std::optional<SolverKind> solver;
  std::optional<bool> sleeping;
  // `settings` with this change's world settings applied.
  WorldSettings applied_to(WorldSettings settings) const;
  // Whether the world would take `now` with this change applied; a refusal names the request's
  // field (RunSettings.substeps, where the world says solver.substeps).
  Status check_against(const WorldSettings& now) const;
};
Result<RunChange> run_change_from_proto(const v1::RunSettings& settings, double max_time_step);
// The settings in force: the host's pace and the world's solver and gravity.
void run_settings_to_proto(double dt, double real_time_factor, const WorldSettings& world,
                           v1::RunSettings* out);

}  // namespace tumble::server
