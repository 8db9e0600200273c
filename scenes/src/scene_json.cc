// The JSON scene format. Every field is checked with its path; unknown fields are errors, so a
// misspelt key never silently falls back to a default.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <sstream>
#include <utility>

#include "scenes/mesh_file.h"
#include "scenes/scene.h"

namespace tumble {
namespace {

using Json = nlohmann::json;

// A failure already carrying its field path; thrown inside the parser only, caught at its edge.
struct FieldError {
  std::string message;
};

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw FieldError{path + ": " + what};
}

// An object being read: remembers which keys were used so the rest can be reported.
class ObjectReader {
 public:
  ObjectReader(const Json& json, std::string path) : json_(json), path_(std::move(path)) {
    if (!json_.is_object()) fail(path_.empty() ? "scene" : path_, "must be an object");
  }

  const Json* find(const std::string& key) {
    used_.insert(key);
    const auto it = json_.find(key);
    return it == json_.end() ? nullptr : &*it;
  }
  std::string child(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }

  double number(const std::string& key, double fallback) {
    const Json* value = find(key);
    if (value == nullptr) return fallback;
    return read_number(*value, child(key));
  }
  int integer(const std::string& key, int fallback, int min, int max) {
    const Json* value = find(key);
    if (value == nullptr) return fallback;
    if (!value->is_number_integer()) fail(child(key), "must be an integer");
    const auto v = value->get<long long>();
    if (v < min || v > max)
      fail(child(key), "must be in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    return static_cast<int>(v);
  }
  std::string string(const std::string& key, const std::string& fallback) {
    const Json* value = find(key);
    if (value == nullptr) return fallback;
    if (!value->is_string()) fail(child(key), "must be a string");
    return value->get<std::string>();
  }
  std::uint32_t bits(const std::string& key, std::uint32_t fallback) {
    const Json* value = find(key);
    if (value == nullptr) return fallback;
    if (!value->is_number_unsigned() || value->get<unsigned long long>() > UINT32_MAX)
      fail(child(key), "must be an integer in [0, 4294967295] (32 bits)");
    return static_cast<std::uint32_t>(value->get<unsigned long long>());
  }
  bool boolean(const std::string& key, bool fallback) {
    const Json* value = find(key);
    if (value == nullptr) return fallback;
    if (!value->is_boolean()) fail(child(key), "must be true or false");
    return value->get<bool>();
  }
  Vec3 vector(const std::string& key, const Vec3& fallback) {
    const Json* value = find(key);
    if (value == nullptr) return fallback;
    return read_vector(*value, child(key));
  }
  void reject_unknown() const {
    for (const auto& [key, value] : json_.items())
      if (!used_.contains(key)) fail(child(key), "unknown field");
  }

  static double read_number(const Json& value, const std::string& path) {
    if (!value.is_number()) fail(path, "must be a number");
    const double v = value.get<double>();
    if (!std::isfinite(v)) fail(path, "must be finite");
    return v;
  }
  static Vec3 read_vector(const Json& value, const std::string& path) {
    if (!value.is_array() || value.size() != 3) fail(path, "must be an array of 3 numbers");
    Vec3 v;
    for (int k = 0; k < 3; ++k)
      v[k] = read_number(value[k], path + "[" + std::to_string(k) + "]");
    return v;
  }

 private:
  const Json& json_;
  std::string path_;
  std::set<std::string> used_;
};

double positive(ObjectReader& r, const std::string& key, double fallback) {
  const double v = r.number(key, fallback);
  if (!(v > 0)) fail(r.child(key), "must be > 0");
  return v;
}

// "samples": [nx, ny], "spacing": [sx, sy] (m), "heights": nx * ny numbers, x fastest.
HeightFieldDef read_height_field(ObjectReader& r) {
  HeightFieldDef def;
  const Json* samples = r.find("samples");
  if (samples == nullptr || !samples->is_array() || samples->size() != 2 ||
      !(*samples)[0].is_number_unsigned() || !(*samples)[1].is_number_unsigned())
    fail(r.child("samples"), "must be [samples along x, samples along y], whole numbers");
  const auto side = [&](int k) {
    const std::uint64_t n = (*samples)[k].get<std::uint64_t>();
    if (n < 2 || n > kMaxHeightFieldSide)
      fail(r.child("samples") + "[" + std::to_string(k) + "]",
           "must be 2 to " + std::to_string(kMaxHeightFieldSide));
    return static_cast<std::uint32_t>(n);
  };
  def.samples_x = side(0);
  def.samples_y = side(1);
  const Json* spacing = r.find("spacing");
  if (spacing == nullptr || !spacing->is_array() || spacing->size() != 2)
    fail(r.child("spacing"), "must be [spacing along x, spacing along y] in m");
  for (int k = 0; k < 2; ++k) {
    const std::string path = r.child("spacing") + "[" + std::to_string(k) + "]";
    const double value = ObjectReader::read_number((*spacing)[k], path);
    if (!(value > 0)) fail(path, "must be > 0");
    (k == 0 ? def.spacing_x : def.spacing_y) = value;
  }
  const Json* heights = r.find("heights");
  const std::size_t expected = std::size_t{def.samples_x} * def.samples_y;
  if (heights == nullptr || !heights->is_array() || heights->size() != expected)
    fail(r.child("heights"), "must be an array of samples[0] * samples[1] = " +
                                 std::to_string(expected) + " heights in m, x fastest");
  def.heights.reserve(expected);
  for (std::size_t i = 0; i < expected; ++i)
    def.heights.push_back(ObjectReader::read_number(
        (*heights)[i], r.child("heights") + "[" + std::to_string(i) + "]"));
  return def;
}

// The folder of the scene file being loaded, against which a mesh's "file" is found; empty while
// parsing text that came from elsewhere (the network), which may not name files on this machine.
thread_local const std::filesystem::path* mesh_folder = nullptr;

// Inline: "vertices": [[x, y, z], ...] (m), "triangles": [[a, b, c], ...] (indices, counter-
// clockwise seen from the front). Or, in a scene file on disk, "file": an OBJ, STL, PLY, ... path
// relative to the scene file, with an optional "scale".
TriangleMeshDef read_mesh(ObjectReader& r) {
  const Json* file = r.find("file");
  const Json* vertices = r.find("vertices");
  const Json* triangles = r.find("triangles");
  if (file != nullptr) {
    if (vertices != nullptr || triangles != nullptr)
      fail(r.child("file"), "a mesh comes from a file or from vertices and triangles, not both");
    if (!file->is_string() || file->get<std::string>().empty())
      fail(r.child("file"), "must be the path of a mesh file (OBJ, STL, PLY, ...)");
    if (mesh_folder == nullptr)
      fail(r.child("file"),
           "mesh files are read only from scene files on disk; send vertices and triangles");
    const double scale = positive(r, "scale", 1);
    Result<TriangleMeshDef> mesh =
        read_mesh_file((*mesh_folder / file->get<std::string>()).string(), scale);
    if (!mesh) fail(r.child("file"), mesh.status().message());
    return std::move(mesh).value();
  }
  TriangleMeshDef def;
  if (vertices == nullptr || !vertices->is_array() || vertices->empty())
    fail(r.child("vertices"), "must be an array of points [x, y, z] in m (or give a \"file\")");
  if (vertices->size() > kMaxMeshVertices)
    fail(r.child("vertices"), std::to_string(vertices->size()) + ", more than the " +
                                  std::to_string(kMaxMeshVertices) + " a mesh may have");
  def.vertices.reserve(vertices->size());
  for (std::size_t i = 0; i < vertices->size(); ++i)
    def.vertices.push_back(ObjectReader::read_vector(
        (*vertices)[i], r.child("vertices") + "[" + std::to_string(i) + "]"));
  if (triangles == nullptr || !triangles->is_array() || triangles->empty())
    fail(r.child("triangles"), "must be an array of [a, b, c], indices into vertices");
  if (triangles->size() > kMaxMeshTriangles)
    fail(r.child("triangles"), std::to_string(triangles->size()) + ", more than the " +
                                   std::to_string(kMaxMeshTriangles) + " a mesh may have");
  def.triangles.reserve(triangles->size());
  for (std::size_t i = 0; i < triangles->size(); ++i) {
    const Json& t = (*triangles)[i];
    const std::string path = r.child("triangles") + "[" + std::to_string(i) + "]";
    if (!t.is_array() || t.size() != 3) fail(path, "must be [a, b, c], indices into vertices");
    std::array<std::uint32_t, 3> triangle;
    for (int k = 0; k < 3; ++k) {
      if (!t[k].is_number_unsigned() || t[k].get<std::uint64_t>() >= vertices->size())
        fail(path + "[" + std::to_string(k) + "]",
             "must be an index into vertices, 0 to " + std::to_string(vertices->size() - 1));
      triangle[k] = static_cast<std::uint32_t>(t[k].get<std::uint64_t>());
    }
    def.triangles.push_back(triangle);
  }
  return def;
}

ShapeDef read_shape(ObjectReader& r);

// A quaternion [w, x, y, z].
Quat read_quat(const Json& q, const std::string& path) {
  if (!q.is_array() || q.size() != 4) fail(path, "must be a quaternion [w, x, y, z]");
  double c[4];
  for (int k = 0; k < 4; ++k)
    c[k] = ObjectReader::read_number(q[k], path + "[" + std::to_string(k) + "]");
  return Quat(c[0], c[1], c[2], c[3]);
}

// "parts": [{"shape": "box", "size": [...], "position": [x, y, z], "orientation": [w, x, y, z]},
// ...]: convex parts placed in the body's frame.
CompoundDef read_compound(ObjectReader& r) {
  const Json* parts = r.find("parts");
  const std::string path = r.child("parts");
  if (parts == nullptr || !parts->is_array() || parts->empty())
    fail(path, "must be an array of parts, each a convex shape with a position and orientation");
  if (parts->size() > kMaxCompoundParts)
    fail(path, std::to_string(parts->size()) + " parts, more than the " +
                   std::to_string(kMaxCompoundParts) + " a compound may have");
  CompoundDef def;
  for (std::size_t i = 0; i < parts->size(); ++i) {
    ObjectReader part((*parts)[i], path + "[" + std::to_string(i) + "]");
    // Refused before it is read: a compound inside a compound would recurse.
    const Json* kind = (*parts)[i].contains("shape") ? &(*parts)[i]["shape"] : nullptr;
    if (kind != nullptr && kind->is_string() && kind->get<std::string>() != "box" &&
        kind->get<std::string>() != "sphere" && kind->get<std::string>() != "capsule" &&
        kind->get<std::string>() != "hull")
      fail(part.child("shape"), "a compound's parts must be a box, sphere, capsule or hull");
    CompoundPart placed{read_shape(part), Pose{}};
    placed.pose.position = part.vector("position", Vec3::Zero());
    if (const Json* q = part.find("orientation"))
      placed.pose.orientation = read_quat(*q, part.child("orientation"));
    part.reject_unknown();
    def.parts.push_back(std::move(placed));
  }
  return def;
}

ShapeDef read_shape(ObjectReader& r) {
  const std::string type = r.string("shape", "");
  if (type.empty())
    fail(r.child("shape"),
         "missing (box, sphere, capsule, hull, plane, heightfield, mesh or compound)");
  if (type == "box") {
    const Json* size = r.find("size");
    if (size == nullptr) fail(r.child("size"), "missing (full extents x, y, z in m)");
    const Vec3 v = ObjectReader::read_vector(*size, r.child("size"));
    for (int k = 0; k < 3; ++k)
      if (!(v[k] > 0)) fail(r.child("size") + "[" + std::to_string(k) + "]", "must be > 0");
    return BoxDef::of_size(v);
  }
  if (type == "sphere") return SphereDef{positive(r, "radius", 0.5)};
  if (type == "capsule") {
    const double radius = positive(r, "radius", 0.25);
    // half_height, as in the API, the CLI and Python; `length` (twice it) is the older name.
    if (r.find("half_height") != nullptr && r.find("length") != nullptr)
      fail(r.child("length"), "half_height and length give the same size: give one");
    if (r.find("length") != nullptr) return CapsuleDef{radius, 0.5 * positive(r, "length", 1.0)};
    return CapsuleDef{radius, positive(r, "half_height", 0.5)};
  }
  if (type == "hull") {
    const Json* points = r.find("points");
    const std::string path = r.child("points");
    if (const Json* file = r.find("file")) {
      // As a mesh's file: read only from scene files on disk, relative to the scene's folder.
      if (points != nullptr)
        fail(r.child("file"), "a hull comes from a file or from points, not both");
      if (!file->is_string() || file->get<std::string>().empty())
        fail(r.child("file"), "must be the path of a mesh file (OBJ, STL, PLY, ...)");
      if (mesh_folder == nullptr)
        fail(r.child("file"), "mesh files are read only from scene files on disk; send points");
      const double scale = positive(r, "scale", 1);
      Result<HullDef> hull =
          read_hull_file((*mesh_folder / file->get<std::string>()).string(), scale);
      if (!hull) fail(r.child("file"), hull.status().message());
      return std::move(hull).value();
    }
    if (points == nullptr || !points->is_array() || points->size() < 4)
      fail(path, "must be an array of at least 4 points [x, y, z]");
    HullDef hull;
    for (std::size_t i = 0; i < points->size(); ++i)
      hull.points.push_back(
          ObjectReader::read_vector((*points)[i], path + "[" + std::to_string(i) + "]"));
    return hull;
  }
  if (type == "plane") return HalfSpaceDef{};
  if (type == "heightfield") return read_height_field(r);
  if (type == "mesh") return read_mesh(r);
  if (type == "compound") return read_compound(r);
  fail(r.child("shape"),
       "unknown shape '" + type +
           "' (box, sphere, capsule, hull, plane, heightfield, mesh or compound)");
}

void read_limits(const Json& json, WorldLimits* limits) {
  ObjectReader r(json, "limits");
  for (const LimitField& field : limit_fields())
    limits->*field.value = r.number(std::string(field.name), limits->*field.value);
  r.reject_unknown();
  if (Status s = validate(*limits); !s) throw FieldError{"limits." + s.message()};
}

Json limits_json(const WorldLimits& limits) {
  Json out = Json::object();
  for (const LimitField& field : limit_fields())
    out[std::string(field.name)] = limits.*field.value;
  return out;
}

BodyDef read_body(const Json& json, const std::string& path, const WorldLimits& limits) {
  ObjectReader r(json, path);
  BodyDef def;
  def.shape = read_shape(r);
  const bool ground = std::holds_alternative<HalfSpaceDef>(def.shape) ||
                      std::holds_alternative<HeightFieldDef>(def.shape) ||
                      std::holds_alternative<TriangleMeshDef>(def.shape);
  const bool is_static = r.boolean("static", ground);
  const bool kinematic = r.boolean("kinematic", false);
  if (is_static && kinematic) fail(r.child("kinematic"), "a body is static or kinematic, not both");
  def.type = is_static ? BodyType::kStatic
             : kinematic ? BodyType::kKinematic
                         : BodyType::kDynamic;
  def.mass = r.number("mass", 0);
  def.density = r.number("density", def.density);
  def.position = r.vector("position", def.position);
  if (const Json* q = r.find("orientation"))
    def.orientation = read_quat(*q, r.child("orientation"));
  def.linear_velocity = r.vector("linear_velocity", def.linear_velocity);
  def.angular_velocity = r.vector("angular_velocity", def.angular_velocity);
  def.friction = r.number("friction", def.friction);
  def.restitution = r.number("restitution", def.restitution);
  def.gravity_scale = r.number("gravity_scale", def.gravity_scale);
  def.linear_damping = r.number("linear_damping", def.linear_damping);
  def.angular_damping = r.number("angular_damping", def.angular_damping);
  def.force = r.vector("force", def.force);
  def.torque = r.vector("torque", def.torque);
  def.filter.layers = r.bits("collision_layers", def.filter.layers);
  def.filter.mask = r.bits("collision_mask", def.filter.mask);
  r.reject_unknown();
  // The engine's own checks (mass, friction, orientation, hull degeneracy...) with this path.
  if (Status s = check_definition(def, limits); !s) throw FieldError{path + "." + s.message()};
  return def;
}

constexpr std::pair<const char*, JointKind> kJointKinds[] = {{"ball", JointKind::kBall},
                                                             {"hinge", JointKind::kHinge},
                                                             {"fixed", JointKind::kFixed},
                                                             {"distance", JointKind::kDistance},
                                                             {"slider", JointKind::kSlider}};

const char* joint_kind_name(JointKind kind) {
  for (const auto& [name, value] : kJointKinds)
    if (value == kind) return name;
  return "ball";
}

// A body's place in the scene's list.
std::size_t body_index(const Json& value, const std::string& path, std::size_t bodies) {
  if (!value.is_number_unsigned()) fail(path, "must be a body's index in \"bodies\"");
  const auto index = value.get<unsigned long long>();
  if (index >= bodies)
    fail(path, "body " + std::to_string(index) + ", but the scene has " + std::to_string(bodies) +
                   " bodies");
  return static_cast<std::size_t>(index);
}

SceneJoint read_joint(const Json& json, const std::string& path, std::size_t bodies) {
  ObjectReader r(json, path);
  SceneJoint joint;
  const std::string kind = r.string("kind", "");
  bool known = false;
  for (const auto& [name, value] : kJointKinds)
    if (kind == name) {
      joint.def.kind = value;
      known = true;
    }
  if (!known) fail(r.child("kind"), "must be ball, hinge, fixed, distance or slider");
  const Json* a = r.find("a");
  if (a == nullptr) fail(r.child("a"), "must name a body");
  joint.a = body_index(*a, r.child("a"), bodies);
  if (const Json* b = r.find("b"); b != nullptr && !b->is_null())
    joint.b = body_index(*b, r.child("b"), bodies);
  joint.def.anchor = r.vector("anchor", joint.def.anchor);
  joint.def.anchor_b = r.vector("anchor_b", joint.def.anchor_b);
  joint.def.axis = r.vector("axis", joint.def.axis);
  joint.def.length = r.number("length", joint.def.length);
  joint.def.collide_connected = r.boolean("collide_connected", joint.def.collide_connected);
  if (const Json* limit = r.find("limit"); limit != nullptr) {
    if (!limit->is_array() || limit->size() != 2) fail(r.child("limit"), "must be [lower, upper]");
    joint.def.limit = {true, ObjectReader::read_number((*limit)[0], r.child("limit") + "[0]"),
                       ObjectReader::read_number((*limit)[1], r.child("limit") + "[1]")};
  }
  if (const Json* motor = r.find("motor"); motor != nullptr) {
    ObjectReader m(*motor, r.child("motor"));
    joint.def.motor = {true, m.number("speed", 0), m.number("max_force", 0)};
    m.reject_unknown();
  }
  if (const Json* spring = r.find("spring"); spring != nullptr) {
    ObjectReader m(*spring, r.child("spring"));
    joint.def.spring = {true, m.number("target", 0), m.number("stiffness", 0),
                        m.number("damping", 0)};
    m.reject_unknown();
  }
  joint.def.max_swing = r.number("max_swing", joint.def.max_swing);
  joint.def.friction = r.number("friction", joint.def.friction);
  r.reject_unknown();
  // The engine's checks of what needs no world, with this path (the ids are filled in later).
  JointDef check = joint.def;
  check.a = BodyId{0, 0};
  check.b = joint.b ? BodyId{1, 0} : BodyId{};
  if (joint.b && *joint.b == joint.a) fail(r.child("b"), "must differ from a");
  if (Status s = validate(check); !s) throw FieldError{path + "." + s.message()};
  return joint;
}

Json vector_json(const Vec3& v);

Json joint_json(const SceneJoint& joint) {
  Json out = Json::object();
  out["kind"] = joint_kind_name(joint.def.kind);
  out["a"] = joint.a;
  if (joint.b) out["b"] = *joint.b;
  out["anchor"] = vector_json(joint.def.anchor);
  if (joint.def.kind == JointKind::kDistance) {
    out["anchor_b"] = vector_json(joint.def.anchor_b);
    out["length"] = joint.def.length;
  }
  if (joint.def.kind == JointKind::kHinge || joint.def.kind == JointKind::kSlider ||
      (joint.def.kind == JointKind::kBall && joint.def.max_swing < std::numbers::pi))
    out["axis"] = vector_json(joint.def.axis);
  out["collide_connected"] = joint.def.collide_connected;
  if (joint.def.limit.enabled) out["limit"] = {joint.def.limit.lower, joint.def.limit.upper};
  if (joint.def.motor.enabled)
    out["motor"] = {{"speed", joint.def.motor.speed}, {"max_force", joint.def.motor.max_force}};
  if (joint.def.spring.enabled)
    out["spring"] = {{"target", joint.def.spring.target},
                     {"stiffness", joint.def.spring.stiffness},
                     {"damping", joint.def.spring.damping}};
  if (joint.def.max_swing < std::numbers::pi) out["max_swing"] = joint.def.max_swing;
  if (joint.def.friction > 0) out["friction"] = joint.def.friction;
  return out;
}

SceneDef read_scene(const Json& json) {
  ObjectReader r(json, "");
  SceneDef scene;
  scene.name = r.string("name", scene.name);
  r.string("description", "");
  scene.dt = positive(r, "dt", scene.dt);
  scene.duration = r.number("duration", scene.duration);
  if (scene.duration < 0) fail("duration", "must be >= 0");
  WorldSettings& world = scene.world;
  world.gravity = r.vector("gravity", world.gravity);
  world.threads = r.integer("threads", world.threads, 0, 1024);
  SolverSettings& solver = world.solver;
  const std::string kind = r.string("solver", std::string(solver_name(solver.kind)));
  const std::optional<SolverKind> parsed = solver_from_name(kind);
  if (!parsed) fail("solver", "unknown solver '" + kind + "' (exact, pgs, soft or auto)");
  solver.kind = *parsed;
  solver.iterations = r.integer("iterations", solver.iterations, 1, 1000);
  solver.soft_iterations = r.integer("soft_iterations", solver.soft_iterations, 1, 1000);
  solver.relax_iterations = r.integer("relax_iterations", solver.relax_iterations, 1, 1000);
  solver.substeps = r.integer("substeps", solver.substeps, 1, 1000);
  solver.position_iterations =
      r.integer("position_iterations", solver.position_iterations, 0, 1000);
  solver.joint_position_passes =
      r.integer("joint_position_passes", solver.joint_position_passes, 0, 1000);
  solver.exact_max_points = r.integer("exact_max_points", solver.exact_max_points, 0, 100000);
  solver.friction_directions = r.integer("friction_directions", solver.friction_directions, 4, 32);
  solver.exact_max_island_points =
      r.integer("exact_max_island_points", solver.exact_max_island_points, 1, 256);
  solver.exact_velocity_tolerance =
      r.number("exact_velocity_tolerance", solver.exact_velocity_tolerance);
  solver.velocity_tolerance = r.number("velocity_tolerance", solver.velocity_tolerance);
  solver.sleeping = r.boolean("sleeping", solver.sleeping);
  solver.sleep_linear_speed = r.number("sleep_linear_speed", solver.sleep_linear_speed);
  solver.sleep_angular_speed = r.number("sleep_angular_speed", solver.sleep_angular_speed);
  solver.sleep_delay = r.number("sleep_delay", solver.sleep_delay);
  solver.slop = r.number("slop", solver.slop);
  solver.speculative_distance = r.number("speculative_distance", solver.speculative_distance);
  solver.restitution_threshold = r.number("restitution_threshold", solver.restitution_threshold);
  solver.manifold_reuse = r.number("manifold_reuse", solver.manifold_reuse);
  solver.contact_hertz = r.number("contact_hertz", solver.contact_hertz);
  solver.continuous = r.boolean("continuous", solver.continuous);
  solver.continuous_fraction = r.number("continuous_fraction", solver.continuous_fraction);
  if (const Json* limits = r.find("limits")) read_limits(*limits, &world.limits);
  if (Status s = validate(world); !s) throw FieldError{s.message()};
  if (Status s = check_time_step(scene.dt, world.limits); !s) throw FieldError{s.message()};

  const Json* bodies = r.find("bodies");
  if (bodies != nullptr) {
    if (!bodies->is_array()) fail("bodies", "must be an array");
    for (std::size_t i = 0; i < bodies->size(); ++i)
      scene.bodies.push_back(
          read_body((*bodies)[i], "bodies[" + std::to_string(i) + "]", world.limits));
  }
  if (const Json* joints = r.find("joints")) {
    if (!joints->is_array()) fail("joints", "must be an array");
    if (joints->size() > World::kMaxJoints)
      fail("joints", "more than the " + std::to_string(World::kMaxJoints) + " a world holds");
    for (std::size_t i = 0; i < joints->size(); ++i)
      scene.joints.push_back(
          read_joint((*joints)[i], "joints[" + std::to_string(i) + "]", scene.bodies.size()));
  }
  r.reject_unknown();
  return scene;
}

Json vector_json(const Vec3& v) {
  return Json::array({v.x(), v.y(), v.z()});
}

void shape_json(const ShapeDef& def, Json& out) {
  std::visit(
      [&](const auto& shape) {
        using T = std::decay_t<decltype(shape)>;
        if constexpr (std::is_same_v<T, BoxDef>) {
          out["shape"] = "box";
          out["size"] = vector_json(2 * shape.half_extents);
        } else if constexpr (std::is_same_v<T, SphereDef>) {
          out["shape"] = "sphere";
          out["radius"] = shape.radius;
        } else if constexpr (std::is_same_v<T, CapsuleDef>) {
          out["shape"] = "capsule";
          out["radius"] = shape.radius;
          out["half_height"] = shape.half_height;
        } else if constexpr (std::is_same_v<T, HullDef>) {
          out["shape"] = "hull";
          out["points"] = Json::array();
          for (const Vec3& p : shape.points)
            out["points"].push_back(vector_json(p));
        } else if constexpr (std::is_same_v<T, HeightFieldDef>) {
          out["shape"] = "heightfield";
          out["samples"] = Json::array({shape.samples_x, shape.samples_y});
          out["spacing"] = Json::array({shape.spacing_x, shape.spacing_y});
          out["heights"] = shape.heights;
        } else if constexpr (std::is_same_v<T, TriangleMeshDef>) {
          out["shape"] = "mesh";
          out["vertices"] = Json::array();
          for (const Vec3& v : shape.vertices)
            out["vertices"].push_back(vector_json(v));
          out["triangles"] = Json::array();
          for (const auto& t : shape.triangles)
            out["triangles"].push_back(Json::array({t[0], t[1], t[2]}));
        } else if constexpr (std::is_same_v<T, CompoundDef>) {
          out["shape"] = "compound";
          out["parts"] = Json::array();
          for (const CompoundPart& part : shape.parts) {
            Json each = Json::object();
            shape_json(part.shape, each);
            each["position"] = vector_json(part.pose.position);
            const Quat& q = part.pose.orientation;
            each["orientation"] = Json::array({q.w(), q.x(), q.y(), q.z()});
            out["parts"].push_back(std::move(each));
          }
        } else {
          out["shape"] = "plane";
        }
      },
      def);
}

Json body_json(const BodyDef& def) {
  Json out = Json::object();
  shape_json(def.shape, out);
  out["static"] = def.type == BodyType::kStatic;
  if (def.type == BodyType::kKinematic) out["kinematic"] = true;
  if (def.mass > 0)
    out["mass"] = def.mass;
  else
    out["density"] = def.density;
  out["position"] = vector_json(def.position);
  const Quat& q = def.orientation;
  out["orientation"] = Json::array({q.w(), q.x(), q.y(), q.z()});
  out["linear_velocity"] = vector_json(def.linear_velocity);
  out["angular_velocity"] = vector_json(def.angular_velocity);
  out["friction"] = def.friction;
  out["restitution"] = def.restitution;
  // What most bodies leave at its default is written only where it is not.
  const BodyDef plain;
  if (def.gravity_scale != plain.gravity_scale) out["gravity_scale"] = def.gravity_scale;
  if (def.linear_damping != 0) out["linear_damping"] = def.linear_damping;
  if (def.angular_damping != 0) out["angular_damping"] = def.angular_damping;
  if (!def.force.isZero(0)) out["force"] = vector_json(def.force);
  if (!def.torque.isZero(0)) out["torque"] = vector_json(def.torque);
  if (def.filter.layers != plain.filter.layers) out["collision_layers"] = def.filter.layers;
  if (def.filter.mask != plain.filter.mask) out["collision_mask"] = def.filter.mask;
  return out;
}

// Counts what a scene's JSON holds without building it: the entries of the top-level "bodies"
// array and every value. The document a parse builds takes tens of bytes per value, so a scene
// is refused on these counts before it is built.
class SceneCounter final : public nlohmann::json_sax<Json> {
 public:
  std::size_t bodies = 0, values = 0;

  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override { return open(); }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override {
    const bool opens_bodies = depth_ == 1 && last_key_is_bodies_;
    if (!open()) return false;
    if (opens_bodies) bodies_depth_ = depth_;
    return true;
  }
  bool end_array() override {
    if (depth_ == bodies_depth_) bodies_depth_ = 0;
    return close();
  }
  bool key(string_t& key) override {
    if (depth_ == 1) last_key_is_bodies_ = key == "bodies";
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;  // the real parse says what is wrong
  }

 private:
  bool value() {
    ++values;
    if (bodies_depth_ != 0 && depth_ == bodies_depth_) ++bodies;
    return true;
  }
  bool open() {
    value();
    ++depth_;
    return true;
  }
  bool close() {
    --depth_;
    return true;
  }
  int depth_ = 0, bodies_depth_ = 0;
  bool last_key_is_bodies_ = false;
};

}  // namespace

Result<SceneDef> parse_scene(std::string_view json_text, std::size_t max_bodies) {
  if (max_bodies != kNoBodyLimit) {
    SceneCounter counter;
    Json::sax_parse(json_text, &counter);
    // A body with every field set, or a hull of a few hundred points, is a few hundred values.
    const std::size_t max_values = 64 * max_bodies + (1u << 20);
    if (counter.bodies > max_bodies)
      return Status::error("bodies: " + std::to_string(counter.bodies) + " bodies, more than the " +
                               std::to_string(max_bodies) + " allowed",
                           StatusCode::kResourceExhausted);
    if (counter.values > max_values)
      return Status::error("scene: " + std::to_string(counter.values) +
                               " JSON values, more than the " + std::to_string(max_values) +
                               " a scene of at most " + std::to_string(max_bodies) +
                               " bodies may hold",
                           StatusCode::kResourceExhausted);
  }
  Json json;
  try {
    json = Json::parse(json_text);
  } catch (const Json::parse_error& e) {
    return Status::error(std::string("scene: not valid JSON: ") + e.what());
  }
  SceneDef scene;
  try {
    scene = read_scene(json);
  } catch (const FieldError& e) {
    return Status::error(e.message);
  }
  // A world that may hold max_bodies bodies holds at most kJointsPerBody joints a body.
  if (max_bodies != kNoBodyLimit && scene.joints.size() > kJointsPerBody * max_bodies)
    return Status::error("joints: " + std::to_string(scene.joints.size()) +
                             " joints, more than the " + std::to_string(kJointsPerBody) +
                             " a body allowed (" + std::to_string(max_bodies) + " bodies)",
                         StatusCode::kResourceExhausted);
  return scene;
}

Result<SceneDef> load_scene_file(const std::string& path) {
  std::ifstream file(path);
  if (!file) return Status::error(path + ": cannot open");
  std::stringstream text;
  text << file.rdbuf();
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  mesh_folder = &folder;
  Result<SceneDef> scene = parse_scene(text.str());
  mesh_folder = nullptr;
  if (!scene) return scene.status().within(path + ": ");
  return scene;
}

std::string scene_to_json(const SceneDef& scene) {
  const SolverSettings& s = scene.world.solver;
  Json out = {{"name", scene.name},
              {"dt", scene.dt},
              {"duration", scene.duration},
              {"gravity", vector_json(scene.world.gravity)},
              {"threads", scene.world.threads},
              {"solver", std::string(solver_name(s.kind))},
              {"iterations", s.iterations},
              {"soft_iterations", s.soft_iterations},
              {"relax_iterations", s.relax_iterations},
              {"substeps", s.substeps},
              {"position_iterations", s.position_iterations},
              {"joint_position_passes", s.joint_position_passes},
              {"exact_max_points", s.exact_max_points},
              {"friction_directions", s.friction_directions},
              {"exact_max_island_points", s.exact_max_island_points},
              {"exact_velocity_tolerance", s.exact_velocity_tolerance},
              {"velocity_tolerance", s.velocity_tolerance},
              {"sleeping", s.sleeping},
              {"sleep_linear_speed", s.sleep_linear_speed},
              {"sleep_angular_speed", s.sleep_angular_speed},
              {"sleep_delay", s.sleep_delay},
              {"slop", s.slop},
              {"speculative_distance", s.speculative_distance},
              {"restitution_threshold", s.restitution_threshold},
              {"manifold_reuse", s.manifold_reuse},
              {"contact_hertz", s.contact_hertz},
              {"continuous", s.continuous},
              {"continuous_fraction", s.continuous_fraction},
              {"limits", limits_json(scene.world.limits)}};
  out["bodies"] = Json::array();
  for (const BodyDef& def : scene.bodies)
    out["bodies"].push_back(body_json(def));
  if (!scene.joints.empty()) {
    out["joints"] = Json::array();
    for (const SceneJoint& joint : scene.joints)
      out["joints"].push_back(joint_json(joint));
  }
  return out.dump(1);
}

Result<World> make_world(const SceneDef& scene) {
  if (Status s = validate(scene.world); !s) return s;
  World world(scene.world);
  Result<std::vector<BodyId>> ids = world.create_bodies(scene.bodies);
  if (!ids) return ids.status();
  for (std::size_t i = 0; i < scene.joints.size(); ++i) {
    const SceneJoint& joint = scene.joints[i];
    JointDef def = joint.def;
    if (joint.a >= ids.value().size() || (joint.b && *joint.b >= ids.value().size()))
      return Status::error("joints[" + std::to_string(i) + "]: names a body the scene lacks");
    def.a = ids.value()[joint.a];
    def.b = joint.b ? ids.value()[*joint.b] : BodyId{};
    if (Result<JointId> made = world.create_joint(def); !made)
      return made.status().within("joints[" + std::to_string(i) + "].");
  }
  return world;
}

}  // namespace tumble
