#include "snapshot.h"

#include <cmath>
#include <unordered_set>

#include "tumble/v1/snapshot.pb.h"

namespace tumble::server {
namespace {

namespace pb = v1::snapshot;
using google::protobuf::RepeatedField;

template <class Vector>
void put(const Vector& v, RepeatedField<double>* out) {
  for (int k = 0; k < v.size(); ++k)
    out->Add(v.data()[k]);
}

// Reads exactly n doubles, or says which field had how many.
Status take(const RepeatedField<double>& in, int n, const char* field, double* out) {
  if (in.size() != n)
    return Status::error(std::string(field) + ": needs " + std::to_string(n) + " numbers, has " +
                         std::to_string(in.size()));
  for (int k = 0; k < n; ++k)
    out[k] = in[k];
  return Status::ok();
}

void put_settings(const WorldSettings& s, pb::WorldSettings* out) {
  put(s.gravity, out->mutable_gravity());
  out->set_broad_phase(static_cast<std::uint32_t>(s.broad_phase));
  pb::CollisionSettings* c = out->mutable_collision();
  c->set_margin(s.collision.margin);
  c->set_method(static_cast<std::uint32_t>(s.collision.method));
  c->set_feature_slack(s.collision.feature_slack);
  c->set_feature_slack_relative(s.collision.feature_slack_relative);
  c->set_face_angle(s.collision.face_angle);
  const SolverSettings& v = s.solver;
  pb::SolverSettings* o = out->mutable_solver();
  o->set_kind(static_cast<std::uint32_t>(v.kind));
  o->set_iterations(v.iterations);
  o->set_soft_iterations(v.soft_iterations);
  o->set_relax_iterations(v.relax_iterations);
  o->set_velocity_tolerance(v.velocity_tolerance);
  o->set_substeps(v.substeps);
  o->set_position_iterations(v.position_iterations);
  o->set_exact_max_points(v.exact_max_points);
  o->set_friction_directions(v.friction_directions);
  o->set_lemke_pivots_per_unknown(v.lemke_pivots_per_unknown);
  o->set_exact_max_island_points(v.exact_max_island_points);
  o->set_exact_velocity_tolerance(v.exact_velocity_tolerance);
  o->set_sleeping(v.sleeping);
  o->set_sleep_linear_speed(v.sleep_linear_speed);
  o->set_sleep_angular_speed(v.sleep_angular_speed);
  o->set_sleep_delay(v.sleep_delay);
  o->set_slop(v.slop);
  o->set_speculative_distance(v.speculative_distance);
  o->set_restitution_threshold(v.restitution_threshold);
  o->set_manifold_reuse(v.manifold_reuse);
  o->set_joint_position_passes(v.joint_position_passes);
  o->set_continuous(v.continuous);
  o->set_continuous_fraction(v.continuous_fraction);
  o->set_continuous_iterations(v.continuous_iterations);
  o->set_contact_hertz(v.contact_hertz);
  o->set_contact_damping_ratio(v.contact_damping_ratio);
  o->set_max_push_velocity(v.max_push_velocity);
  o->set_max_correction(v.max_correction);
  o->set_baumgarte(v.baumgarte);
  const WorldLimits& l = s.limits;
  pb::WorldLimits* lo = out->mutable_limits();
  lo->set_max_coordinate(l.max_coordinate);
  lo->set_min_size(l.min_size);
  lo->set_max_size(l.max_size);
  lo->set_min_mass(l.min_mass);
  lo->set_max_mass(l.max_mass);
  lo->set_max_linear_speed(l.max_linear_speed);
  lo->set_max_angular_speed(l.max_angular_speed);
  lo->set_max_time_step(l.max_time_step);
}

void take_limits(const pb::WorldLimits& in, WorldLimits* l) {
  for (const auto& [value, field] : {std::pair{in.max_coordinate(), &l->max_coordinate},
                                     {in.min_size(), &l->min_size},
                                     {in.max_size(), &l->max_size},
                                     {in.min_mass(), &l->min_mass},
                                     {in.max_mass(), &l->max_mass},
                                     {in.max_linear_speed(), &l->max_linear_speed},
                                     {in.max_angular_speed(), &l->max_angular_speed},
                                     {in.max_time_step(), &l->max_time_step}})
    if (value != 0) *field = value;
}

Result<WorldSettings> take_settings(const pb::WorldSettings& in) {
  WorldSettings s;
  if (Status t = take(in.gravity(), 3, "gravity", s.gravity.data()); !t) return t;
  if (in.broad_phase() > static_cast<std::uint32_t>(BroadPhaseMethod::kSweepAndPrune))
    return Status::error("broad_phase: unknown method");
  s.broad_phase = static_cast<BroadPhaseMethod>(in.broad_phase());
  const pb::CollisionSettings& c = in.collision();
  if (c.method() > static_cast<std::uint32_t>(NarrowPhaseMethod::kGjkEpa))
    return Status::error("collision.method: unknown method");
  s.collision.margin = c.margin();
  s.collision.method = static_cast<NarrowPhaseMethod>(c.method());
  s.collision.feature_slack = c.feature_slack();
  s.collision.feature_slack_relative = c.feature_slack_relative();
  s.collision.face_angle = c.face_angle();
  const pb::SolverSettings& o = in.solver();
  if (o.kind() > static_cast<std::uint32_t>(SolverKind::kAuto))
    return Status::error("solver.kind: unknown solver");
  SolverSettings& v = s.solver;
  v.kind = static_cast<SolverKind>(o.kind());
  v.iterations = o.iterations();
  v.soft_iterations = o.soft_iterations();
  v.relax_iterations = o.relax_iterations();
  v.velocity_tolerance = o.velocity_tolerance();
  v.substeps = o.substeps();
  v.position_iterations = o.position_iterations();
  v.exact_max_points = o.exact_max_points();
  v.friction_directions = o.friction_directions();
  v.lemke_pivots_per_unknown = o.lemke_pivots_per_unknown();
  if (o.exact_max_island_points() != 0) v.exact_max_island_points = o.exact_max_island_points();
  if (o.exact_velocity_tolerance() != 0) v.exact_velocity_tolerance = o.exact_velocity_tolerance();
  v.sleeping = o.sleeping();
  v.sleep_linear_speed = o.sleep_linear_speed();
  v.sleep_angular_speed = o.sleep_angular_speed();
  v.sleep_delay = o.sleep_delay();
  v.slop = o.slop();
  v.speculative_distance = o.speculative_distance();
  v.restitution_threshold = o.restitution_threshold();
  if (o.has_manifold_reuse()) v.manifold_reuse = o.manifold_reuse();
  if (o.has_joint_position_passes()) v.joint_position_passes = o.joint_position_passes();
  take_limits(in.limits(), &s.limits);
  v.continuous = o.continuous();
  v.continuous_fraction = o.continuous_fraction();
  v.continuous_iterations = o.continuous_iterations();
  v.contact_hertz = o.contact_hertz();
  v.contact_damping_ratio = o.contact_damping_ratio();
  v.max_push_velocity = o.max_push_velocity();
  v.max_correction = o.max_correction();
  v.baumgarte = o.baumgarte();
  return s;  // the engine validates the values (World::from_state)
}

}  // namespace

namespace {

// Ids by slot (0: none) below 2^53, none used twice, and the next id below 2^53 too.
Status check_ids(const std::vector<std::uint64_t>& ids, const std::string& field,
                 std::uint64_t next, const std::string& next_field) {
  std::unordered_set<std::uint64_t> seen;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] == 0) continue;
    const std::string at = field + "[" + std::to_string(i) + "]: ";
    if (ids[i] >= kMaxBodyId) return Status::error(at + "must be below 2^53");
    if (!seen.insert(ids[i]).second) return Status::error(at + "used by another slot too");
  }
  if (next >= kMaxBodyId) return Status::error(next_field + ": must be below 2^53");
  return Status::ok();
}

}  // namespace

std::string encode_snapshot(const SavedWorld& saved) {
  pb::WorldSnapshot out;
  out.set_version(pb::VERSION_2);
  put_settings(saved.settings, out.mutable_settings());
  out.set_dt(saved.dt);
  out.set_engine_state(saved.state);
  out.mutable_colors()->Add(saved.colours.begin(), saved.colours.end());
  out.mutable_ids()->Add(saved.ids.begin(), saved.ids.end());
  out.set_server_instance(saved.server_instance);
  out.set_next_id(saved.next_id);
  out.mutable_joint_ids()->mutable_ids()->Add(saved.joint_ids.begin(), saved.joint_ids.end());
  out.mutable_joint_ids()->set_next(saved.next_joint_id);
  return out.SerializeAsString();
}

Result<SavedWorld> decode_snapshot(std::string_view bytes) {
  pb::WorldSnapshot in;
  if (!in.ParseFromArray(bytes.data(), static_cast<int>(bytes.size())))
    return Status::error("state: not a snapshot (cannot be parsed)");
  if (in.version() == pb::VERSION_1)
    return Status::error(
        "version: 1, a snapshot written before the engine kept its own state format; this server "
        "reads version 2 only (restore it with the server that wrote it, or save the world again)");
  if (in.version() != pb::VERSION_2)
    return Status::error("version: " + std::to_string(in.version()) +
                         " is not a snapshot version this server reads (2)");
  SavedWorld saved;
  Result<WorldSettings> settings = take_settings(in.settings());
  if (!settings) return settings.status().within("settings.");
  saved.settings = settings.value();
  saved.dt = in.dt();
  if (Status s = check_time_step(saved.dt, saved.settings.limits); !s) return s;
  Result<StateSizes> sizes = World::state_sizes(in.engine_state());
  if (!sizes) return sizes.status().within("engine_state.");
  const std::uint32_t slots = sizes.value().slots;
  if (static_cast<std::size_t>(in.colors_size()) != slots ||
      static_cast<std::size_t>(in.ids_size()) != slots)
    return Status::error("colors, ids: " + std::to_string(in.colors_size()) + " and " +
                         std::to_string(in.ids_size()) + " entries; the engine state has " +
                         std::to_string(slots) + " slots");
  saved.colours.assign(in.colors().begin(), in.colors().end());
  saved.ids.assign(in.ids().begin(), in.ids().end());
  if (Status s = check_ids(saved.ids, "ids", in.next_id(), "next_id"); !s) return s;
  saved.next_id = in.next_id();
  // Joint ids: checked alike; matched to the engine's joint slots when restored (a joint slot
  // without a live joint, or beyond the engine's, takes no id; a joint without one gets a new one).
  saved.joint_ids.assign(in.joint_ids().ids().begin(), in.joint_ids().ids().end());
  if (Status s =
          check_ids(saved.joint_ids, "joint_ids.ids", in.joint_ids().next(), "joint_ids.next");
      !s)
    return s;
  saved.next_joint_id = in.joint_ids().next();
  saved.server_instance = in.server_instance();
  saved.state = std::move(*in.mutable_engine_state());
  return saved;
}

}  // namespace tumble::server
