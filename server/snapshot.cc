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

void put_matrix(const Mat3& m, RepeatedField<double>* out) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      out->Add(m(r, c));
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

Status take_matrix(const RepeatedField<double>& in, const char* field, Mat3* m) {
  double values[9] = {};
  if (Status s = take(in, 9, field, values); !s) return s;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      (*m)(r, c) = values[3 * r + c];
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

void put_shape(const Shape& shape, pb::Shape* out) {
  const ShapeState s = shape.state();
  out->set_type(static_cast<std::uint32_t>(s.type));
  out->set_radius(s.radius);
  out->set_half_height(s.half_height);
  put(s.half_extents, out->mutable_half_extents());
  if (s.polyhedron == nullptr) return;
  const ConvexPolyhedron& p = *s.polyhedron;
  pb::Polyhedron* o = out->mutable_polyhedron();
  for (const Vec3& v : p.vertices)
    put(v, o->mutable_vertices());
  for (const ConvexPolyhedron::Face& f : p.faces) {
    put(f.normal, o->mutable_face_normals());
    o->add_face_offsets(f.offset);
    o->add_face_first(f.first);
    o->add_face_count(f.count);
  }
  o->mutable_face_vertices()->Add(p.face_vertices.begin(), p.face_vertices.end());
  for (const ConvexPolyhedron::Edge& e : p.edges)
    for (std::uint32_t index : {e.tail, e.head, e.left, e.right})
      o->add_edges(index);
  put(p.centroid, o->mutable_centroid());
  o->set_volume(p.volume);
}

Result<Shape> take_shape(const pb::Shape& in) {
  if (in.type() > static_cast<std::uint32_t>(ShapeType::kHalfSpace))
    return Status::error("type: unknown shape type");
  ShapeState s;
  s.type = static_cast<ShapeType>(in.type());
  s.radius = in.radius();
  s.half_height = in.half_height();
  if (Status t = take(in.half_extents(), 3, "half_extents", s.half_extents.data()); !t) return t;
  if (s.type == ShapeType::kHull) {
    const pb::Polyhedron& p = in.polyhedron();
    auto poly = std::make_shared<ConvexPolyhedron>();
    const int faces = p.face_offsets_size();
    if (p.vertices_size() % 3 != 0 || p.face_normals_size() != 3 * faces ||
        p.face_first_size() != faces || p.face_count_size() != faces || p.edges_size() % 4 != 0)
      return Status::error("polyhedron: array lengths do not match");
    for (int i = 0; i < p.vertices_size(); i += 3)
      poly->vertices.emplace_back(p.vertices(i), p.vertices(i + 1), p.vertices(i + 2));
    for (int i = 0; i < faces; ++i)
      poly->faces.push_back(
          {Vec3(p.face_normals(3 * i), p.face_normals(3 * i + 1), p.face_normals(3 * i + 2)),
           p.face_offsets(i), p.face_first(i), p.face_count(i)});
    poly->face_vertices.assign(p.face_vertices().begin(), p.face_vertices().end());
    for (int i = 0; i < p.edges_size(); i += 4)
      poly->edges.push_back({p.edges(i), p.edges(i + 1), p.edges(i + 2), p.edges(i + 3)});
    if (Status t = take(p.centroid(), 3, "polyhedron.centroid", poly->centroid.data()); !t)
      return t;
    poly->volume = p.volume();
    s.polyhedron = std::move(poly);
  }
  return Shape::from_state(s);
}

void put_body(const BodySlotState& slot, std::uint32_t colour, pb::Body* out) {
  out->set_generation(slot.generation);
  out->set_alive(slot.alive);
  if (!slot.alive) return;
  const Body& b = slot.body;
  put_shape(b.shape, out->mutable_shape());
  out->set_is_static(b.is_static());
  out->set_mass(b.mass);
  out->set_inverse_mass(b.inverse_mass);
  put_matrix(b.inertia_body, out->mutable_inertia_body());
  put_matrix(b.inverse_inertia_body, out->mutable_inverse_inertia_body());
  put_matrix(b.inverse_inertia_world, out->mutable_inverse_inertia_world());
  put(b.position, out->mutable_position());
  for (double q : {b.orientation.w(), b.orientation.x(), b.orientation.y(), b.orientation.z()})
    out->add_orientation(q);
  put(b.linear_velocity, out->mutable_linear_velocity());
  put(b.angular_velocity, out->mutable_angular_velocity());
  out->set_friction(b.friction);
  out->set_restitution(b.restitution);
  out->set_spherical_inertia(b.spherical_inertia);
  out->set_sleep_timer(b.sleep_timer);
  out->set_asleep(b.asleep);
  out->set_sleep_island(b.sleep_island);
  out->set_color(colour);
}

Status take_body(const pb::Body& in, BodySlotState* slot) {
  slot->generation = in.generation();
  slot->alive = in.alive();
  if (!slot->alive) return Status::ok();
  Body& b = slot->body;
  Result<Shape> shape = take_shape(in.shape());
  if (!shape) return shape.status().within("shape.");
  b.shape = std::move(shape).value();
  b.type = in.is_static() ? BodyType::kStatic : BodyType::kDynamic;
  b.mass = in.mass();
  b.inverse_mass = in.inverse_mass();
  for (auto [field, name, m] :
       {std::tuple{&in.inertia_body(), "inertia_body", &b.inertia_body},
        {&in.inverse_inertia_body(), "inverse_inertia_body", &b.inverse_inertia_body},
        {&in.inverse_inertia_world(), "inverse_inertia_world", &b.inverse_inertia_world}})
    if (Status t = take_matrix(*field, name, m); !t) return t;
  double q[4];
  if (Status t = take(in.position(), 3, "position", b.position.data()); !t) return t;
  if (Status t = take(in.orientation(), 4, "orientation", q); !t) return t;
  b.orientation = Quat(q[0], q[1], q[2], q[3]);
  if (Status t = take(in.linear_velocity(), 3, "linear_velocity", b.linear_velocity.data()); !t)
    return t;
  if (Status t = take(in.angular_velocity(), 3, "angular_velocity", b.angular_velocity.data()); !t)
    return t;
  b.friction = in.friction();
  b.restitution = in.restitution();
  b.spherical_inertia = in.spherical_inertia();
  b.sleep_timer = in.sleep_timer();
  b.asleep = in.asleep();
  b.sleep_island = in.sleep_island();
  return Status::ok();  // World::from_state checks the values
}

void put_contact_pairs(const std::vector<ContactPairRecord>& pairs, pb::ContactPairs* out) {
  for (const ContactPairRecord& r : pairs) {
    out->add_body_a(r.a.index);
    out->add_body_b(r.b.index);
    out->add_generation_a(r.a.generation);
    out->add_generation_b(r.b.generation);
    put(r.relative_position, out->mutable_relative_position());
    const Quat& q = r.relative_orientation;
    for (double value : {q.w(), q.x(), q.y(), q.z()})
      out->add_relative_orientation(value);
    out->add_feature_kind(r.feature_kind);
    out->add_feature_first(r.feature_first);
    out->add_feature_second(r.feature_second);
    out->add_count(static_cast<std::uint32_t>(r.count));
    out->add_colour(r.colour);
    for (int i = 0; i < r.count; ++i) {
      const ContactPointRecord& p = r.points[i];
      out->add_feature(p.feature);
      put(p.local_a, out->mutable_local_a());
      out->add_normal_impulse(p.normal_impulse);
      put(p.friction_impulse, out->mutable_friction_impulse());
    }
  }
}

Vec3 vec3_at(const RepeatedField<double>& values, int i) {
  return Vec3(values[3 * i], values[3 * i + 1], values[3 * i + 2]);
}

// The engine checks the values (World::from_state); here only the arrays' shapes.
Result<std::vector<ContactPairRecord>> take_contact_pairs(const pb::ContactPairs& in) {
  const int n = in.body_a_size();
  if (in.body_b_size() != n || in.generation_a_size() != n || in.generation_b_size() != n ||
      in.relative_position_size() != 3 * n || in.relative_orientation_size() != 4 * n ||
      in.feature_kind_size() != n || in.feature_first_size() != n ||
      in.feature_second_size() != n || in.count_size() != n)
    return Status::error("array lengths do not match");
  if (in.colour_size() != 0 && in.colour_size() != n)
    return Status::error("colour: must be empty or one per pair");
  std::int64_t points = 0;
  for (int k = 0; k < n; ++k) {
    if (in.count(k) < 1 || in.count(k) > 4)
      return Status::error("count[" + std::to_string(k) + "]: must be 1 to 4");
    if (in.feature_kind(k) > 3)
      return Status::error("feature_kind[" + std::to_string(k) + "]: must be 0 to 3");
    if (in.colour_size() != 0 && in.colour(k) > kNoContactColour)
      return Status::error("colour[" + std::to_string(k) + "]: must be below 256");
    points += in.count(k);
  }
  if (in.feature_size() != points || in.local_a_size() != 3 * points ||
      in.normal_impulse_size() != points || in.friction_impulse_size() != 3 * points)
    return Status::error("point arrays: lengths do not match the counts");
  std::vector<ContactPairRecord> pairs(n);
  int point = 0;
  for (int k = 0; k < n; ++k) {
    ContactPairRecord& r = pairs[k];
    r.a = {in.body_a(k), in.generation_a(k)};
    r.b = {in.body_b(k), in.generation_b(k)};
    r.relative_position = vec3_at(in.relative_position(), k);
    r.relative_orientation =
        Quat(in.relative_orientation(4 * k), in.relative_orientation(4 * k + 1),
             in.relative_orientation(4 * k + 2), in.relative_orientation(4 * k + 3));
    r.feature_kind = static_cast<std::uint8_t>(in.feature_kind(k));
    r.feature_first = in.feature_first(k);
    r.feature_second = in.feature_second(k);
    r.count = static_cast<int>(in.count(k));
    if (in.colour_size() != 0) r.colour = static_cast<std::uint8_t>(in.colour(k));
    for (int i = 0; i < r.count; ++i, ++point)
      r.points[i] = {in.feature(point), vec3_at(in.local_a(), point), in.normal_impulse(point),
                     vec3_at(in.friction_impulse(), point)};
  }
  return pairs;
}

// An older snapshot's impulses, point by point: grouped into records by body pair (at most four
// points each, the rest dropped) without a feature, so the narrow phase searches again.
Result<std::vector<ContactPairRecord>> take_warm_start(const pb::WarmStart& w) {
  const int n = w.body_a_size();
  if (w.body_b_size() != n || w.generation_a_size() != n || w.generation_b_size() != n ||
      w.feature_size() != n || w.local_a_size() != 3 * n || w.normal_size() != n ||
      w.friction_size() != 3 * n)
    return Status::error("array lengths do not match");
  std::vector<ContactPairRecord> pairs;
  for (int i = 0; i < n; ++i) {
    const BodyId a{w.body_a(i), w.generation_a(i)}, b{w.body_b(i), w.generation_b(i)};
    if (pairs.empty() || pairs.back().a != a || pairs.back().b != b) {
      pairs.emplace_back();
      pairs.back().a = a;
      pairs.back().b = b;
    }
    ContactPairRecord& r = pairs.back();
    if (r.count == 4) continue;
    r.points[r.count++] = {w.feature(i), vec3_at(w.local_a(), i), w.normal(i),
                           vec3_at(w.friction(), i)};
  }
  return pairs;
}

}  // namespace

std::string encode_snapshot(const SavedWorld& saved) {
  pb::WorldSnapshot out;
  out.set_version(pb::VERSION_1);
  put_settings(saved.settings, out.mutable_settings());
  out.set_dt(saved.dt);
  const WorldStateData& state = saved.state;
  for (std::size_t i = 0; i < state.slots.size(); ++i) {
    pb::Body* body = out.add_slots();
    put_body(state.slots[i], i < saved.colours.size() ? saved.colours[i] : 0, body);
    if (state.slots[i].alive && i < saved.ids.size()) body->set_id(saved.ids[i]);
  }
  out.mutable_free_slots()->Add(state.free_slots.begin(), state.free_slots.end());
  out.set_time(state.time);
  out.set_step(state.step);
  out.set_server_instance(saved.server_instance);
  out.set_next_id(saved.next_id);
  put_contact_pairs(state.contact_pairs, out.mutable_contact_pairs());
  return out.SerializeAsString();
}

Result<SavedWorld> decode_snapshot(std::string_view bytes) {
  pb::WorldSnapshot in;
  if (!in.ParseFromArray(bytes.data(), static_cast<int>(bytes.size())))
    return Status::error("state: not a snapshot (cannot be parsed)");
  if (in.version() != pb::VERSION_1)
    return Status::error("version: " + std::to_string(in.version()) +
                         " is not a snapshot version this server reads (1)");
  SavedWorld saved;
  Result<WorldSettings> settings = take_settings(in.settings());
  if (!settings) return settings.status().within("settings.");
  saved.settings = settings.value();
  saved.dt = in.dt();
  if (Status s = check_time_step(saved.dt, saved.settings.limits); !s) return s;
  WorldStateData& state = saved.state;
  state.slots.resize(in.slots_size());
  saved.colours.resize(in.slots_size(), 0);
  saved.ids.resize(in.slots_size(), 0);
  std::unordered_set<std::uint64_t> ids;
  for (int i = 0; i < in.slots_size(); ++i) {
    const std::string slot = "slots[" + std::to_string(i) + "].";
    if (Status s = take_body(in.slots(i), &state.slots[i]); !s) return s.within(slot);
    saved.colours[i] = in.slots(i).color();
    const std::uint64_t id = in.slots(i).id();
    if (id == 0) continue;
    if (!state.slots[i].alive) return Status::error(slot + "id: a free slot has no id");
    if (id >= kMaxBodyId) return Status::error(slot + "id: must be below 2^53");
    if (!ids.insert(id).second) return Status::error(slot + "id: used by another slot too");
    saved.ids[i] = id;
  }
  if (in.next_id() >= kMaxBodyId) return Status::error("next_id: must be below 2^53");
  saved.next_id = in.next_id();
  saved.server_instance = in.server_instance();
  state.free_slots.assign(in.free_slots().begin(), in.free_slots().end());
  state.time = in.time();
  state.step = in.step();
  if (in.contact_pairs().body_a_size() > 0) {
    Result<std::vector<ContactPairRecord>> pairs = take_contact_pairs(in.contact_pairs());
    if (!pairs) return pairs.status().within("contact_pairs.");
    state.contact_pairs = std::move(pairs).value();
  } else {
    Result<std::vector<ContactPairRecord>> pairs = take_warm_start(in.warm_start());
    if (!pairs) return pairs.status().within("warm_start.");
    state.contact_pairs = std::move(pairs).value();
  }
  return saved;
}

}  // namespace tumble::server
