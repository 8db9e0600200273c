#include "convert.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <string>
#include <string_view>

#include "physics/compound.h"

namespace tumble::server {
namespace {

Status finite(const v1::Vec3& v, const std::string& field) {
  if (!std::isfinite(v.x())) return Status::error(field + ".x: must be finite");
  if (!std::isfinite(v.y())) return Status::error(field + ".y: must be finite");
  if (!std::isfinite(v.z())) return Status::error(field + ".z: must be finite");
  return Status::ok();
}

Status positive(double value, const std::string& field) {
  if (!std::isfinite(value) || !(value > 0))
    return Status::error(field + ": must be finite and > 0");
  return Status::ok();
}

Vec3 vec(const v1::Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

void set(const Vec3& v, v1::Vec3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}

Result<Quat> unit_quat(const v1::Quat& q, const std::string& field) {
  const double norm = std::sqrt(q.w() * q.w() + q.x() * q.x() + q.y() * q.y() + q.z() * q.z());
  if (!std::isfinite(norm) || std::abs(norm - 1) > 1e-3)
    return Status::error(field + ": must be a unit quaternion (|q| = " + std::to_string(norm) +
                         ")");
  return Quat(q.w() / norm, q.x() / norm, q.y() / norm, q.z() / norm);
}

Result<ShapeDef> shape_from_proto(const v1::Shape& shape);

Result<ShapeDef> compound_from_proto(const v1::Shape& shape) {
  const v1::Compound& compound = shape.compound();
  // Counted before anything is built: each part costs a shape.
  if (compound.parts().empty())
    return Status::error("shape.compound.parts: a compound needs at least one part");
  if (static_cast<std::size_t>(compound.parts().size()) > kMaxCompoundParts)
    return Status::error("shape.compound.parts: " + std::to_string(compound.parts().size()) +
                         " parts, more than the " + std::to_string(kMaxCompoundParts) +
                         " a compound may have");
  CompoundDef def;
  def.parts.reserve(compound.parts().size());
  for (int i = 0; i < compound.parts().size(); ++i) {
    const v1::CompoundPart& given = compound.parts(i);
    const std::string field = "shape.compound.parts[" + std::to_string(i) + "]";
    // Refused before it is read: a compound inside a compound would recurse.
    switch (given.shape().kind_case()) {
      case v1::Shape::kBox:
      case v1::Shape::kSphere:
      case v1::Shape::kCapsule:
      case v1::Shape::kHull:
        break;
      default:
        return Status::error(field +
                             ".shape: a compound's parts must be a box, sphere, capsule "
                             "or hull");
    }
    Result<ShapeDef> shape = shape_from_proto(given.shape());
    if (!shape) return Status::error(field + "." + shape.status().message());
    CompoundPart part{std::move(shape).value(), Pose{}};
    if (Status s = finite(given.position(), field + ".position"); !s) return s;
    part.pose.position = vec(given.position());
    if (given.has_orientation()) {
      Result<Quat> q = unit_quat(given.orientation(), field + ".orientation");
      if (!q) return q.status();
      part.pose.orientation = q.value();
    }
    def.parts.push_back(std::move(part));
  }
  // The engine checks the rest (offsets, sizes, a flat hull) and names the part in its terms.
  if (Result<Shape> built = Shape::create(def); !built)
    return in_api_terms(built.status().within("shape."), shape);
  return ShapeDef{std::move(def)};
}

Result<ShapeDef> shape_from_proto(const v1::Shape& shape) {
  switch (shape.kind_case()) {
    case v1::Shape::kCompound:
      return compound_from_proto(shape);
    case v1::Shape::kBox: {
      const v1::Vec3& size = shape.box().size();
      for (auto [value, axis] : {std::pair{size.x(), "x"}, {size.y(), "y"}, {size.z(), "z"}})
        if (Status s = positive(value, std::string("shape.box.size.") + axis); !s) return s;
      return ShapeDef{BoxDef::of_size(vec(size))};
    }
    case v1::Shape::kSphere:
      if (Status s = positive(shape.sphere().radius(), "shape.sphere.radius"); !s) return s;
      return ShapeDef{SphereDef{shape.sphere().radius()}};
    case v1::Shape::kCapsule:
      if (Status s = positive(shape.capsule().radius(), "shape.capsule.radius"); !s) return s;
      if (Status s = positive(shape.capsule().half_height(), "shape.capsule.half_height"); !s)
        return s;
      return ShapeDef{CapsuleDef{shape.capsule().radius(), shape.capsule().half_height()}};
    case v1::Shape::kHull: {
      const auto& points = shape.hull().points();
      if (points.size() % 3 != 0)
        return Status::error("shape.hull.points: must hold x, y, z triples");
      HullDef hull;
      for (int i = 0; i < points.size(); i += 3) {
        if (!std::isfinite(points[i]) || !std::isfinite(points[i + 1]) ||
            !std::isfinite(points[i + 2]))
          return Status::error("shape.hull.points[" + std::to_string(i / 3) + "]: must be finite");
        hull.points.emplace_back(points[i], points[i + 1], points[i + 2]);
      }
      return ShapeDef{std::move(hull)};
    }
    case v1::Shape::kPlane:
      return ShapeDef{HalfSpaceDef{}};
    case v1::Shape::kHeightfield: {
      const v1::HeightField& field = shape.heightfield();
      HeightFieldDef def;
      def.samples_x = field.samples_x();
      def.samples_y = field.samples_y();
      def.spacing_x = field.spacing_x();
      def.spacing_y = field.spacing_y();
      def.heights.assign(field.heights().begin(), field.heights().end());
      // The engine checks every field and names it; here only the prefix is the message's.
      if (Result<HeightField> built = HeightField::create(def); !built)
        return built.status().within("shape.heightfield.");
      return ShapeDef{std::move(def)};
    }
    case v1::Shape::kMesh: {
      const v1::Mesh& mesh = shape.mesh();
      if (mesh.vertices().size() % 3 != 0)
        return Status::error("shape.mesh.vertices: must hold x, y, z triples");
      if (mesh.triangles().size() % 3 != 0)
        return Status::error("shape.mesh.triangles: must hold triples of vertex indices");
      TriangleMeshDef def;
      def.vertices.reserve(mesh.vertices().size() / 3);
      for (int i = 0; i < mesh.vertices().size(); i += 3)
        def.vertices.emplace_back(mesh.vertices(i), mesh.vertices(i + 1), mesh.vertices(i + 2));
      def.triangles.reserve(mesh.triangles().size() / 3);
      for (int i = 0; i < mesh.triangles().size(); i += 3)
        def.triangles.push_back({mesh.triangles(i), mesh.triangles(i + 1), mesh.triangles(i + 2)});
      if (Result<TriangleMesh> built = TriangleMesh::create(def); !built)
        return built.status().within("shape.mesh.");
      return ShapeDef{std::move(def)};
    }
    case v1::Shape::KIND_NOT_SET:
      break;
  }
  return Status::error(
      "shape: required (box, sphere, capsule, hull, plane, heightfield, mesh or compound)");
}

}  // namespace

Result<ShapeDef> shape_def_from_proto(const v1::Shape& shape) {
  return shape_from_proto(shape);
}

std::string in_api_terms(const std::string& message, const v1::Shape& shape) {
  const std::string_view prefix = "shape.";
  if (message.rfind(prefix, 0) != 0) return message;
  const std::string rest = message.substr(prefix.size());
  // Where the engine's field has the message's name within its kind (a box's half extents are
  // not its size: left as the engine names them).
  switch (shape.kind_case()) {
    case v1::Shape::kHull:
      if (rest.rfind("points", 0) == 0) return "shape.hull." + rest;
      return message;
    case v1::Shape::kSphere:
      if (rest.rfind("radius", 0) == 0) return "shape.sphere." + rest;
      return message;
    case v1::Shape::kCapsule:
      if (rest.rfind("radius", 0) == 0 || rest.rfind("half_height", 0) == 0)
        return "shape.capsule." + rest;
      return message;
    default:
      break;
  }
  if (shape.kind_case() != v1::Shape::kCompound || rest.rfind("parts", 0) != 0) return message;
  // parts[i].shape.…: the part's own shape, in its kind's terms too.
  const std::size_t close = rest.find(']');
  int index = -1;
  if (rest.rfind("parts[", 0) == 0 && close != std::string::npos) {
    const char* first = rest.data() + 6;
    const char* last = rest.data() + close;
    if (std::from_chars(first, last, index).ptr != last) index = -1;
  }
  const std::string after = close == std::string::npos ? "" : rest.substr(close + 1);
  if (index < 0 || index >= shape.compound().parts_size() || after.rfind(".shape.", 0) != 0)
    return "shape.compound." + rest;
  return "shape.compound." + rest.substr(0, close + 1) + "." +
         in_api_terms(after.substr(1), shape.compound().parts(index).shape());
}

Status in_api_terms(const Status& status, const v1::Shape& shape) {
  return status ? status : Status::error(in_api_terms(status.message(), shape), status.code());
}

Result<BodyDef> body_from_proto(const v1::BodySpec& spec) {
  BodyDef def;
  Result<ShapeDef> shape = shape_from_proto(spec.shape());
  if (!shape) return shape.status();
  def.shape = std::move(shape).value();
  switch (spec.type()) {
    case v1::BODY_TYPE_DYNAMIC:
      def.type = BodyType::kDynamic;
      break;
    case v1::BODY_TYPE_STATIC:
      def.type = BodyType::kStatic;
      break;
    case v1::BODY_TYPE_KINEMATIC:
      def.type = BodyType::kKinematic;
      break;
    default:
      return Status::error("type: unknown body type " + std::to_string(spec.type()));
  }
  if (std::holds_alternative<HalfSpaceDef>(def.shape) && def.type != BodyType::kStatic)
    return Status::error("type: a plane must be static");
  if (std::holds_alternative<HeightFieldDef>(def.shape) && def.type != BodyType::kStatic)
    return Status::error("type: a heightfield must be static");
  if (std::holds_alternative<TriangleMeshDef>(def.shape) && def.type != BodyType::kStatic)
    return Status::error("type: a mesh must be static");
  if (Status s = finite(spec.position(), "position"); !s) return s;
  if (Status s = finite(spec.linear_velocity(), "linear_velocity"); !s) return s;
  if (Status s = finite(spec.angular_velocity(), "angular_velocity"); !s) return s;
  def.position = vec(spec.position());
  def.linear_velocity = vec(spec.linear_velocity());
  def.angular_velocity = vec(spec.angular_velocity());
  if (spec.has_orientation()) {
    Result<Quat> q = unit_quat(spec.orientation(), "orientation");
    if (!q) return q.status();
    def.orientation = q.value();
  }
  if (spec.has_mass()) {
    if (Status s = positive(spec.mass(), "mass"); !s) return s;
    def.mass = spec.mass();
  }
  if (spec.has_density()) {
    if (Status s = positive(spec.density(), "density"); !s) return s;
    def.density = spec.density();
  }
  if (spec.has_friction()) {
    if (!std::isfinite(spec.friction()) || spec.friction() < 0)
      return Status::error("friction: must be finite and >= 0");
    def.friction = spec.friction();
  }
  if (spec.has_restitution()) {
    if (!(spec.restitution() >= 0 && spec.restitution() <= 1))
      return Status::error("restitution: must be in [0, 1]");
    def.restitution = spec.restitution();
  }
  if (spec.has_gravity_scale()) def.gravity_scale = spec.gravity_scale();
  if (spec.has_linear_damping()) def.linear_damping = spec.linear_damping();
  if (spec.has_angular_damping()) def.angular_damping = spec.angular_damping();
  if (Status s = finite(spec.force(), "force"); !s) return s;
  if (Status s = finite(spec.torque(), "torque"); !s) return s;
  def.force = vec(spec.force());
  def.torque = vec(spec.torque());
  if (spec.has_collision_layers()) def.filter.layers = spec.collision_layers();
  if (spec.has_collision_mask()) def.filter.mask = spec.collision_mask();
  if (def.type != BodyType::kDynamic) def.mass = 0;
  // What only the engine can tell (a flat hull), named as the message names it.
  if (Status s = validate(def); !s) return in_api_terms(s, spec.shape());
  return def;
}

v1::BodyType proto_body_type(BodyType type) {
  switch (type) {
    case BodyType::kStatic:
      return v1::BODY_TYPE_STATIC;
    case BodyType::kKinematic:
      return v1::BODY_TYPE_KINEMATIC;
    case BodyType::kDynamic:
      break;
  }
  return v1::BODY_TYPE_DYNAMIC;
}

namespace {

void describe_shape(const Shape& s, v1::Shape* shape) {
  switch (s.type()) {
    case ShapeType::kBox:
      set(2 * s.half_extents(), shape->mutable_box()->mutable_size());
      break;
    case ShapeType::kSphere:
      shape->mutable_sphere()->set_radius(s.radius());
      break;
    case ShapeType::kCapsule:
      shape->mutable_capsule()->set_radius(s.radius());
      shape->mutable_capsule()->set_half_height(s.half_height());
      break;
    case ShapeType::kHull:
      for (const Vec3& v : s.polyhedron()->vertices)
        for (int k = 0; k < 3; ++k)
          shape->mutable_hull()->add_points(v[k]);
      break;
    case ShapeType::kHalfSpace:
      shape->mutable_plane();
      break;
    case ShapeType::kHeightField: {
      const HeightFieldDef& def = s.height_field()->def();
      v1::HeightField* field = shape->mutable_heightfield();
      field->set_samples_x(def.samples_x);
      field->set_samples_y(def.samples_y);
      field->set_spacing_x(def.spacing_x);
      field->set_spacing_y(def.spacing_y);
      field->mutable_heights()->Assign(def.heights.begin(), def.heights.end());
      break;
    }
    case ShapeType::kMesh: {
      const TriangleMeshDef& def = s.mesh()->def();
      v1::Mesh* mesh = shape->mutable_mesh();
      mesh->mutable_vertices()->Reserve(static_cast<int>(3 * def.vertices.size()));
      for (const Vec3& v : def.vertices)
        for (int k = 0; k < 3; ++k)
          mesh->add_vertices(v[k]);
      mesh->mutable_triangles()->Reserve(static_cast<int>(3 * def.triangles.size()));
      for (const auto& t : def.triangles)
        for (std::uint32_t index : t)
          mesh->add_triangles(index);
      break;
    }
    case ShapeType::kCompound:
      for (const Compound::Part& part : s.compound()->parts()) {
        v1::CompoundPart* out = shape->mutable_compound()->add_parts();
        describe_shape(part.shape, out->mutable_shape());
        set(part.pose.position, out->mutable_position());
        const Quat& q = part.pose.orientation;
        out->mutable_orientation()->set_w(q.w());
        out->mutable_orientation()->set_x(q.x());
        out->mutable_orientation()->set_y(q.y());
        out->mutable_orientation()->set_z(q.z());
      }
      break;
  }
}

}  // namespace

void describe(std::uint64_t id, const BodyLook& look, v1::BodyDescription* out) {
  out->set_id(id);
  out->set_type(proto_body_type(look.type));
  out->set_mass(look.mass);
  out->set_color(look.colour);
  describe_shape(look.shape, out->mutable_shape());
}

void describe_forces(const BodyView& body, v1::BodyDescription* out) {
  out->set_gravity_scale(body.gravity_scale());
  out->set_linear_damping(body.linear_damping());
  out->set_angular_damping(body.angular_damping());
  vec_to_proto(body.force(), out->mutable_force());
  vec_to_proto(body.torque(), out->mutable_torque());
  out->set_collision_layers(body.filter().layers);
  out->set_collision_mask(body.filter().mask);
}

void stats_to_proto(const StepStats& s, v1::StepStats* out) {
  out->set_step(s.step);
  out->set_pairs(s.pairs);
  out->set_manifolds(s.manifolds);
  out->set_contact_points(s.contact_points);
  out->set_islands(s.islands);
  out->set_sleeping_bodies(s.sleeping_bodies);
  out->set_velocity_iterations(s.velocity_iterations);
  out->set_lemke_pivots(s.lemke_pivots);
  out->set_residual(s.residual);
  out->set_max_penetration(s.max_penetration);
  out->set_swept_bodies(s.swept_bodies);
  out->set_non_finite_bodies(s.non_finite_bodies);
  out->set_slowed_bodies(s.slowed_bodies);
  out->set_bodies_at_edge(s.bodies_at_edge);
  out->set_solver_bodies(s.solver_bodies);
  out->set_woken_bodies(s.woken_bodies);
  out->set_exact_islands(s.exact_islands);
  out->set_iterative_islands(s.iterative_islands);
  out->set_exact_fallbacks(s.exact_fallbacks);
  out->set_exact_oversized(s.exact_oversized);
  out->set_coloured_islands(s.coloured_islands);
  out->set_colours(s.colours);
  out->set_overflow_manifolds(s.overflow_manifolds);
  out->set_coloured_islands_alone(s.coloured_islands_alone);
  out->set_packed_manifolds(s.packed_manifolds);
  out->set_reused_manifolds(s.reused_manifolds);
  out->set_stiffened_islands(s.stiffened_islands);
  out->set_stiffness_capped(s.stiffness_capped);
  out->set_continuous_impacts(s.continuous_impacts);
  out->set_continuous_limit_hits(s.continuous_limit_hits);
  out->set_gyroscopic_limit_hits(s.gyroscopic_limit_hits);
  out->set_pair_limit_hits(s.pair_limit_hits);
  out->set_impact_limit_hits(s.impact_limit_hits);
  out->set_resting_contact_points(s.resting_contact_points);
  out->set_solved_joints(s.solved_joints);
  out->set_joint_error(s.joint_error);
  out->set_broad_phase_seconds(s.time.broad_phase);
  out->set_narrow_phase_seconds(s.time.narrow_phase);
  out->set_prepare_seconds(s.time.prepare);
  out->set_solve_seconds(s.time.solve);
  out->set_correct_positions_seconds(s.time.correct_positions);
  out->set_continuous_seconds(s.time.continuous);
  out->set_total_seconds(s.time.total);
}

WorldSettings RunChange::applied_to(WorldSettings settings) const {
  if (gravity) settings.gravity = *gravity;
  if (substeps) settings.solver.substeps = *substeps;
  if (iterations) settings.solver.iterations = *iterations;
  if (joint_position_passes) settings.solver.joint_position_passes = *joint_position_passes;
  if (solver) settings.solver.kind = *solver;
  if (sleeping) settings.solver.sleeping = *sleeping;
  return settings;
}

Status RunChange::check_against(const WorldSettings& now) const {
  const Status checked = validate(applied_to(now));
  if (checked) return checked;
  // The world's solver fields that RunSettings carries at its top level.
  for (const std::string_view field : {"substeps", "iterations", "joint_position_passes"}) {
    const std::string world_name = "solver." + std::string(field) + ":";
    if (checked.message().starts_with(world_name))
      return Status::error(checked.message().substr(std::string_view("solver.").size()),
                           checked.code());
  }
  return checked;
}

Result<RunChange> run_change_from_proto(const v1::RunSettings& settings, double max_time_step) {
  RunChange change;
  if (settings.has_dt()) {
    WorldLimits limits;
    limits.max_time_step = max_time_step;
    if (Status s = check_time_step(settings.dt(), limits); !s) return s;
    change.dt = settings.dt();
  }
  if (settings.has_real_time_factor()) {
    if (Status s = check_real_time_factor(settings.real_time_factor()); !s) return s;
    change.real_time_factor = settings.real_time_factor();
  }
  if (settings.has_gravity()) {
    if (Status s = finite(settings.gravity(), "gravity"); !s) return s;
    change.gravity = vec(settings.gravity());
  }
  if (settings.has_substeps()) change.substeps = settings.substeps();
  if (settings.has_iterations()) change.iterations = settings.iterations();
  if (settings.has_joint_position_passes())
    change.joint_position_passes = settings.joint_position_passes();
  if (settings.has_sleeping()) change.sleeping = settings.sleeping();
  switch (settings.solver()) {
    case v1::SOLVER_KIND_UNSPECIFIED:
      break;
    case v1::SOLVER_KIND_EXACT:
      change.solver = SolverKind::kExact;
      break;
    case v1::SOLVER_KIND_PGS:
      change.solver = SolverKind::kPgs;
      break;
    case v1::SOLVER_KIND_SOFT:
      change.solver = SolverKind::kSoft;
      break;
    case v1::SOLVER_KIND_AUTO:
      change.solver = SolverKind::kAuto;
      break;
    default:
      return Status::error("solver: unknown solver " + std::to_string(settings.solver()));
  }
  return change;
}

void run_settings_to_proto(double dt, double real_time_factor, const WorldSettings& world,
                           v1::RunSettings* out) {
  out->set_dt(dt);
  out->set_real_time_factor(real_time_factor);
  out->set_substeps(world.solver.substeps);
  out->set_iterations(world.solver.iterations);
  out->set_joint_position_passes(world.solver.joint_position_passes);
  out->set_sleeping(world.solver.sleeping);
  out->set_solver(static_cast<v1::SolverKind>(static_cast<int>(world.solver.kind) + 1));
  set(world.gravity, out->mutable_gravity());
}

void frame_to_proto(const FrameData& frame, const FrameOptions& options, v1::Frame* out,
                    std::uint64_t changed_after) {
  out->set_step(frame.step);
  out->set_time(frame.time);
  out->set_stepped_at_unix_ns(frame.stepped_at_unix_ns);
  if (changed_after > 0) out->set_changes_only(true);
  const bool every_id = options.ids.empty();
  const bool all = every_id && changed_after == 0;
  if (all) {  // whole arrays at once: the common case, and the one worth being fast
    out->mutable_ids()->Add(frame.ids.begin(), frame.ids.end());
    out->mutable_positions()->Add(frame.positions.begin(), frame.positions.end());
    out->mutable_orientations()->Add(frame.orientations.begin(), frame.orientations.end());
    if (options.velocities) {
      out->mutable_linear_velocities()->Add(frame.linear_velocities.begin(),
                                            frame.linear_velocities.end());
      out->mutable_angular_velocities()->Add(frame.angular_velocities.begin(),
                                             frame.angular_velocities.end());
    }
  }
  for (std::size_t i = 0; !all && i < frame.ids.size(); ++i) {
    if (changed_after > 0 && frame.changed_at[i] <= changed_after) continue;
    if (!every_id && !std::binary_search(options.ids.begin(), options.ids.end(), frame.ids[i]))
      continue;
    out->add_ids(frame.ids[i]);
    for (int k = 0; k < 3; ++k)
      out->add_positions(frame.positions[3 * i + k]);
    for (int k = 0; k < 4; ++k)
      out->add_orientations(frame.orientations[4 * i + k]);
    if (options.velocities) {
      for (int k = 0; k < 3; ++k) {
        out->add_linear_velocities(frame.linear_velocities[3 * i + k]);
        out->add_angular_velocities(frame.angular_velocities[3 * i + k]);
      }
    }
  }
  if (options.contacts) {
    v1::Contacts* contacts = out->mutable_contacts();
    for (const ContactTable* table : frame.contact_tables()) {
      contacts->mutable_body_a()->Add(table->a.begin(), table->a.end());
      contacts->mutable_body_b()->Add(table->b.begin(), table->b.end());
      contacts->mutable_points()->Add(table->points.begin(), table->points.end());
      contacts->mutable_normals()->Add(table->normals.begin(), table->normals.end());
      contacts->mutable_depths()->Add(table->depths.begin(), table->depths.end());
      contacts->mutable_impulses()->Add(table->impulses.begin(), table->impulses.end());
    }
  }
  if (options.stats) stats_to_proto(frame.stats, out->mutable_stats());
  if (options.joints && frame.joints.size() > 0) {
    const JointTable& table = frame.joints;
    v1::JointStates* joints = out->mutable_joints();
    joints->mutable_ids()->Add(table.ids.begin(), table.ids.end());
    joints->mutable_positions()->Add(table.positions.begin(), table.positions.end());
    joints->mutable_speeds()->Add(table.speeds.begin(), table.speeds.end());
    joints->mutable_efforts()->Add(table.efforts.begin(), table.efforts.end());
    joints->mutable_forces()->Add(table.forces.begin(), table.forces.end());
    joints->mutable_torques()->Add(table.torques.begin(), table.torques.end());
    joints->mutable_anchors()->Add(table.anchors.begin(), table.anchors.end());
    joints->mutable_axes()->Add(table.axes.begin(), table.axes.end());
  }
}

void joint_spec_to_proto(const JointDef& def, std::uint64_t a, std::uint64_t b,
                         v1::JointSpec* out) {
  out->set_kind(static_cast<v1::JointKind>(static_cast<int>(def.kind)));
  out->set_a(a);
  out->set_b(b);
  vec_to_proto(def.anchor, out->mutable_anchor());
  if (def.kind == JointKind::kDistance) vec_to_proto(def.anchor_b, out->mutable_anchor_b());
  vec_to_proto(def.axis, out->mutable_axis());
  out->set_length(def.length);
  out->set_collide_connected(def.collide_connected);
  if (def.limit.enabled) {
    out->mutable_limit()->set_lower(def.limit.lower);
    out->mutable_limit()->set_upper(def.limit.upper);
  }
  if (def.motor.enabled) {
    out->mutable_motor()->set_speed(def.motor.speed);
    out->mutable_motor()->set_max_force(def.motor.max_force);
  }
  if (def.spring.enabled) {
    out->mutable_spring()->set_target(def.spring.target);
    out->mutable_spring()->set_stiffness(def.spring.stiffness);
    out->mutable_spring()->set_damping(def.spring.damping);
  }
  if (def.max_swing < std::numbers::pi) out->set_max_swing(def.max_swing);
  out->set_friction(def.friction);
}

Vec3 vec_from_proto(const v1::Vec3& v) {
  return vec(v);
}

void vec_to_proto(const Vec3& v, v1::Vec3* out) {
  set(v, out);
}

BodyMotion motion_from_proto(const v1::BodyStateUpdate& update,
                             const CollisionFilter& current_filter) {
  BodyMotion motion;
  if (update.has_position()) motion.position = vec(update.position());
  if (update.has_orientation()) {
    const v1::Quat& q = update.orientation();
    motion.orientation = Quat(q.w(), q.x(), q.y(), q.z());
  }
  if (update.has_linear_velocity()) motion.linear_velocity = vec(update.linear_velocity());
  if (update.has_angular_velocity()) motion.angular_velocity = vec(update.angular_velocity());
  if (update.has_force()) motion.force = vec(update.force());
  if (update.has_torque()) motion.torque = vec(update.torque());
  if (update.has_force_point()) motion.force_point = vec(update.force_point());
  if (update.has_gravity_scale()) motion.gravity_scale = update.gravity_scale();
  if (update.has_linear_damping()) motion.linear_damping = update.linear_damping();
  if (update.has_angular_damping()) motion.angular_damping = update.angular_damping();
  if (update.has_collision_layers() || update.has_collision_mask()) {
    CollisionFilter filter = current_filter;
    if (update.has_collision_layers()) filter.layers = update.collision_layers();
    if (update.has_collision_mask()) filter.mask = update.collision_mask();
    motion.filter = filter;
  }
  return motion;
}

}  // namespace tumble::server
