#include "state_format.h"

#include "joint_geometry.h"
#include "shape_state.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <memory>
#include <utility>

#include "physics/world.h"

namespace tumble {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the state format is little-endian; a big-endian host would need byte swaps here");

class Writer {
 public:
  explicit Writer(std::string* out) : out_(out) {}
  template <class T>
  void put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out_->append(bytes, sizeof(T));
  }
  void put(const Vec3& v) {
    for (int k = 0; k < 3; ++k)
      put(v[k]);
  }
  void put(const Quat& q) {
    for (double c : {q.w(), q.x(), q.y(), q.z()})
      put(c);
  }
  void put(const Mat3& m) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        put(m(r, c));
  }

 private:
  std::string* out_;
};

// Reads what a Writer wrote; the first shortfall names the field and stops every later read.
class Reader {
 public:
  explicit Reader(std::string_view bytes) : bytes_(bytes) {}

  std::size_t left() const { return bytes_.size() - at_; }
  const Status& status() const { return status_; }
  bool ok() const { return status_.is_ok(); }

  template <class T>
  T take(const char* field) {
    T value{};
    if (!ok()) return value;
    if (left() < sizeof(T)) {
      fail(std::string(field) + ": the bytes end early (at byte " + std::to_string(at_) + ")");
      return value;
    }
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  Vec3 vec3(const char* field) {
    Vec3 v;
    for (int k = 0; k < 3; ++k)
      v[k] = take<double>(field);
    return v;
  }
  Quat quat(const char* field) {
    double c[4];
    for (double& x : c)
      x = take<double>(field);
    return Quat(c[0], c[1], c[2], c[3]);
  }
  Mat3 mat3(const char* field) {
    Mat3 m;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        m(r, c) = take<double>(field);
    return m;
  }
  // A count of items of at least `item_bytes` each, refused when the bytes left cannot hold them,
  // so that nothing is allocated for items that are not there.
  std::uint32_t count(const char* field, std::size_t item_bytes) {
    const auto n = take<std::uint32_t>(field);
    if (ok() && n > left() / item_bytes)
      fail(std::string(field) + ": " + std::to_string(n) + " entries of at least " +
           std::to_string(item_bytes) + " bytes, but " + std::to_string(left()) + " bytes left");
    return ok() ? n : 0;
  }
  void fail(std::string message) {
    if (ok()) status_ = Status::error(std::move(message));
  }

 private:
  std::string_view bytes_;
  std::size_t at_ = 0;
  Status status_ = Status::ok();
};

void put_shape(Writer& w, const Shape& shape) {
  const ShapeState s = shape.state();
  w.put(static_cast<std::uint8_t>(s.type));
  w.put(s.radius);
  w.put(s.half_height);
  w.put(s.half_extents);
  if (s.type == ShapeType::kHeightField) {
    const HeightFieldDef& def = *s.height_field;
    w.put(def.samples_x);
    w.put(def.samples_y);
    w.put(def.spacing_x);
    w.put(def.spacing_y);
    w.put(static_cast<std::uint32_t>(def.heights.size()));
    for (double h : def.heights)
      w.put(h);
    return;
  }
  if (s.type == ShapeType::kMesh) {
    const TriangleMeshDef& def = *s.mesh;
    w.put(static_cast<std::uint32_t>(def.vertices.size()));
    for (const Vec3& v : def.vertices)
      w.put(v);
    w.put(static_cast<std::uint32_t>(def.triangles.size()));
    for (const auto& triangle : def.triangles)
      for (std::uint32_t index : triangle)
        w.put(index);
    return;
  }
  if (s.type == ShapeType::kCompound) {
    w.put(static_cast<std::uint32_t>(s.compound->parts().size()));
    for (const Compound::Part& part : s.compound->parts()) {
      w.put(part.pose.position);
      w.put(part.pose.orientation);
      put_shape(w, part.shape);
    }
    return;
  }
  if (s.type != ShapeType::kHull) return;
  const ConvexPolyhedron& p = *s.polyhedron;
  w.put(static_cast<std::uint32_t>(p.vertices.size()));
  for (const Vec3& v : p.vertices)
    w.put(v);
  w.put(static_cast<std::uint32_t>(p.faces.size()));
  for (const ConvexPolyhedron::Face& f : p.faces) {
    w.put(f.normal);
    w.put(f.offset);
    w.put(f.first);
    w.put(f.count);
  }
  w.put(static_cast<std::uint32_t>(p.face_vertices.size()));
  for (std::uint32_t index : p.face_vertices)
    w.put(index);
  w.put(static_cast<std::uint32_t>(p.edges.size()));
  for (const ConvexPolyhedron::Edge& e : p.edges)
    for (std::uint32_t index : {e.tail, e.head, e.left, e.right})
      w.put(index);
  w.put(p.centroid);
  w.put(p.volume);
}

// `in_compound`: a part's shape, which may not itself be a compound (nor recurse further).
Result<Shape> take_shape(Reader& r, bool in_compound = false) {
  ShapeState s;
  const auto type = r.take<std::uint8_t>("type");
  s.radius = r.take<double>("radius");
  s.half_height = r.take<double>("half_height");
  s.half_extents = r.vec3("half_extents");
  if (!r.ok()) return r.status();
  if (type > static_cast<std::uint8_t>(ShapeType::kCompound))
    return Status::error("type: unknown shape type " + std::to_string(type));
  s.type = static_cast<ShapeType>(type);
  if (in_compound && !is_convex_part(s.type))
    return Status::error("type: a compound's parts must be convex");
  if (s.type == ShapeType::kCompound) {
    // The smallest part: a pose and a sphere's fixed fields.
    const std::uint32_t count = r.count("parts", 7 * 8 + 1 + 6 * 8);
    if (count > kMaxCompoundParts)
      return Status::error("parts: " + std::to_string(count) + ", more than the " +
                           std::to_string(kMaxCompoundParts) + " a compound may have");
    std::vector<Compound::Part> parts(count);
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const std::string field = "parts[" + std::to_string(i) + "].";
      parts[i].pose.position = r.vec3((field + "pose.position").c_str());
      parts[i].pose.orientation = r.quat((field + "pose.orientation").c_str());
      if (!r.ok()) return r.status();
      Result<Shape> part = take_shape(r, true);
      if (!part) return part.status().within(field + "shape.");
      parts[i].shape = std::move(part).value();
    }
    if (!r.ok()) return r.status();
    return Compound::of_parts(std::move(parts));
  }
  if (s.type == ShapeType::kHull) {
    auto p = std::make_shared<ConvexPolyhedron>();
    p->vertices.resize(r.count("polyhedron.vertices", 24));
    for (Vec3& v : p->vertices)
      v = r.vec3("polyhedron.vertices");
    p->faces.resize(r.count("polyhedron.faces", 40));
    for (ConvexPolyhedron::Face& f : p->faces) {
      f.normal = r.vec3("polyhedron.faces");
      f.offset = r.take<double>("polyhedron.faces");
      f.first = r.take<std::uint32_t>("polyhedron.faces");
      f.count = r.take<std::uint32_t>("polyhedron.faces");
    }
    p->face_vertices.resize(r.count("polyhedron.face_vertices", 4));
    for (std::uint32_t& index : p->face_vertices)
      index = r.take<std::uint32_t>("polyhedron.face_vertices");
    p->edges.resize(r.count("polyhedron.edges", 16));
    for (ConvexPolyhedron::Edge& e : p->edges)
      for (std::uint32_t* index : {&e.tail, &e.head, &e.left, &e.right})
        *index = r.take<std::uint32_t>("polyhedron.edges");
    p->centroid = r.vec3("polyhedron.centroid");
    p->volume = r.take<double>("polyhedron.volume");
    if (!r.ok()) return r.status();
    s.polyhedron = std::move(p);
  }
  if (s.type == ShapeType::kHeightField) {
    HeightFieldDef def;
    def.samples_x = r.take<std::uint32_t>("height_field.samples_x");
    def.samples_y = r.take<std::uint32_t>("height_field.samples_y");
    def.spacing_x = r.take<double>("height_field.spacing_x");
    def.spacing_y = r.take<double>("height_field.spacing_y");
    def.heights.resize(r.count("height_field.heights", 8));
    for (double& h : def.heights)
      h = r.take<double>("height_field.heights");
    if (!r.ok()) return r.status();
    s.height_field = std::make_shared<const HeightFieldDef>(std::move(def));
  }
  if (s.type == ShapeType::kMesh) {
    TriangleMeshDef def;
    def.vertices.resize(r.count("mesh.vertices", 24));
    for (Vec3& v : def.vertices)
      v = r.vec3("mesh.vertices");
    def.triangles.resize(r.count("mesh.triangles", 12));
    for (auto& triangle : def.triangles)
      for (std::uint32_t& index : triangle)
        index = r.take<std::uint32_t>("mesh.triangles");
    if (!r.ok()) return r.status();
    s.mesh = std::make_shared<const TriangleMeshDef>(std::move(def));
  }
  return Shape::from_state(s);  // checks every number and index
}

void put_body(Writer& w, const Body& b) {
  put_shape(w, b.shape);
  w.put(static_cast<std::uint8_t>(b.type));
  w.put(b.mass);
  w.put(b.inverse_mass);
  w.put(b.inertia_body);
  w.put(b.inverse_inertia_body);
  w.put(b.inverse_inertia_world);
  w.put(b.position);
  w.put(b.orientation);
  w.put(b.linear_velocity);
  w.put(b.angular_velocity);
  w.put(b.friction);
  w.put(b.restitution);
  w.put(static_cast<std::uint8_t>(b.spherical_inertia));
  w.put(b.sleep_timer);
  w.put(b.sleep_anchor_position);
  w.put(b.sleep_anchor_orientation);
  w.put(static_cast<std::uint8_t>(b.asleep));
  w.put(b.sleep_island);
}

// What a body holds beyond contacts and gravity (flag kStateBodyForces).
void put_body_forces(Writer& w, const Body& b) {
  w.put(b.gravity_scale);
  w.put(b.linear_damping);
  w.put(b.angular_damping);
  w.put(b.force);
  w.put(b.torque);
  w.put(b.filter.layers);
  w.put(b.filter.mask);
}

void take_body_forces(Reader& r, Body* b) {
  b->gravity_scale = r.take<double>("gravity_scale");
  b->linear_damping = r.take<double>("linear_damping");
  b->angular_damping = r.take<double>("angular_damping");
  b->force = r.vec3("force");
  b->torque = r.vec3("torque");
  b->filter.layers = r.take<std::uint32_t>("filter.layers");
  b->filter.mask = r.take<std::uint32_t>("filter.mask");
  b->refresh_own_forces();
}

// A byte that must be 0 or 1.
bool take_flag(Reader& r, const char* field) {
  const auto value = r.take<std::uint8_t>(field);
  if (value > 1) r.fail(std::string(field) + ": must be 0 or 1, is " + std::to_string(value));
  return value == 1;
}

Status take_body(Reader& r, Body* b) {
  Result<Shape> shape = take_shape(r);
  if (!shape) return shape.status().within("shape.");
  b->shape = std::move(shape).value();
  const auto type = r.take<std::uint8_t>("type");
  if (r.ok() && type > static_cast<std::uint8_t>(BodyType::kKinematic))
    return Status::error("type: unknown body type " + std::to_string(type));
  b->type = static_cast<BodyType>(type);
  b->mass = r.take<double>("mass");
  b->inverse_mass = r.take<double>("inverse_mass");
  b->inertia_body = r.mat3("inertia_body");
  b->inverse_inertia_body = r.mat3("inverse_inertia_body");
  b->inverse_inertia_world = r.mat3("inverse_inertia_world");
  b->position = r.vec3("position");
  b->orientation = r.quat("orientation");
  b->linear_velocity = r.vec3("linear_velocity");
  b->angular_velocity = r.vec3("angular_velocity");
  b->friction = r.take<double>("friction");
  b->restitution = r.take<double>("restitution");
  b->spherical_inertia = take_flag(r, "spherical_inertia");
  b->refresh_symmetric_top();  // from the inertia; a wrong one is refused with the whole state
  b->sleep_timer = r.take<double>("sleep_timer");
  b->sleep_anchor_position = r.vec3("sleep_anchor_position");
  b->sleep_anchor_orientation = r.quat("sleep_anchor_orientation");
  b->asleep = take_flag(r, "asleep");
  b->sleep_island = r.take<std::uint32_t>("sleep_island");
  return r.status();  // the values are checked with the whole state (world_from)
}

void put_pair(Writer& w, const ContactPairRecord& p) {
  w.put(p.a.index);
  w.put(p.a.generation);
  w.put(p.b.index);
  w.put(p.b.generation);
  w.put(p.relative_position);
  w.put(p.relative_orientation);
  w.put(p.feature_kind);
  w.put(p.feature_first);
  w.put(p.feature_second);
  w.put(p.colour);
  w.put(static_cast<std::uint8_t>(p.count));
  for (int i = 0; i < p.count; ++i) {
    const ContactPointRecord& point = p.points[i];
    w.put(point.feature);
    w.put(point.local_a);
    w.put(point.normal_impulse);
    w.put(point.friction_impulse);
  }
}

Status take_pair(Reader& r, ContactPairRecord* p) {
  p->a.index = r.take<std::uint32_t>("a");
  p->a.generation = r.take<std::uint32_t>("a");
  p->b.index = r.take<std::uint32_t>("b");
  p->b.generation = r.take<std::uint32_t>("b");
  p->relative_position = r.vec3("relative_position");
  p->relative_orientation = r.quat("relative_orientation");
  p->feature_kind = r.take<std::uint8_t>("feature_kind");
  p->feature_first = r.take<std::uint32_t>("feature_first");
  p->feature_second = r.take<std::uint32_t>("feature_second");
  p->colour = r.take<std::uint8_t>("colour");
  p->count = r.take<std::uint8_t>("count");
  if (r.ok() && (p->count < 1 || p->count > 4))
    return Status::error("count: must be 1 to 4, is " + std::to_string(p->count));
  for (int i = 0; i < p->count; ++i) {
    ContactPointRecord& point = p->points[i];
    point.feature = r.take<std::uint64_t>("points");
    point.local_a = r.vec3("points");
    point.normal_impulse = r.take<double>("points");
    point.friction_impulse = r.vec3("points");
  }
  return r.status();
}

void put_joint(Writer& w, const Joint& j) {
  w.put(static_cast<std::uint8_t>(j.kind));
  w.put(j.a);
  w.put(j.b);
  w.put(j.local_a);
  w.put(j.local_b);
  w.put(j.axis_a);
  w.put(j.axis_b);
  w.put(j.relative);
  w.put(j.length);
  w.put(static_cast<std::uint8_t>(j.collide_connected));
  w.put(j.linear_impulse);
  w.put(j.angular_impulse);
  w.put(j.axial_impulse);
}

// The drives section of a joint (flag kStateJointDrives): what joints carry beyond rigid rows.
void put_joint_drives(Writer& w, const Joint& j) {
  w.put(j.reference_a);
  w.put(j.reference_b);
  w.put(static_cast<std::uint8_t>(j.limit.enabled));
  w.put(j.limit.lower);
  w.put(j.limit.upper);
  w.put(static_cast<std::uint8_t>(j.motor.enabled));
  w.put(j.motor.speed);
  w.put(j.motor.max_force);
  w.put(static_cast<std::uint8_t>(j.spring.enabled));
  w.put(j.spring.target);
  w.put(j.spring.stiffness);
  w.put(j.spring.damping);
  w.put(j.max_swing);
  w.put(j.limit_impulse);
  w.put(j.motor_impulse);
  w.put(j.spring_impulse);
  w.put(j.swing_impulse);
  w.put(j.impulse_time);
}

Status take_joint_drives(Reader& r, Joint* j) {
  j->reference_a = r.vec3("reference_a");
  j->reference_b = r.vec3("reference_b");
  j->limit.enabled = take_flag(r, "limit.enabled");
  j->limit.lower = r.take<double>("limit.lower");
  j->limit.upper = r.take<double>("limit.upper");
  j->motor.enabled = take_flag(r, "motor.enabled");
  j->motor.speed = r.take<double>("motor.speed");
  j->motor.max_force = r.take<double>("motor.max_force");
  j->spring.enabled = take_flag(r, "spring.enabled");
  j->spring.target = r.take<double>("spring.target");
  j->spring.stiffness = r.take<double>("spring.stiffness");
  j->spring.damping = r.take<double>("spring.damping");
  j->max_swing = r.take<double>("max_swing");
  j->limit_impulse = r.take<double>("limit_impulse");
  j->motor_impulse = r.take<double>("motor_impulse");
  j->spring_impulse = r.take<double>("spring_impulse");
  j->swing_impulse = r.take<double>("swing_impulse");
  j->impulse_time = r.take<double>("impulse_time");
  return r.status();
}

Status take_joint(Reader& r, Joint* j) {
  const auto kind = r.take<std::uint8_t>("kind");
  if (r.ok() && kind > static_cast<std::uint8_t>(JointKind::kSlider))
    return Status::error("kind: unknown joint kind " + std::to_string(kind));
  j->kind = static_cast<JointKind>(kind);
  j->a = r.take<std::uint32_t>("a");
  j->b = r.take<std::uint32_t>("b");
  j->local_a = r.vec3("local_a");
  j->local_b = r.vec3("local_b");
  j->axis_a = r.vec3("axis_a");
  j->axis_b = r.vec3("axis_b");
  j->relative = r.quat("relative");
  j->length = r.take<double>("length");
  j->collide_connected = take_flag(r, "collide_connected");
  j->linear_impulse = r.vec3("linear_impulse");
  j->angular_impulse = r.vec3("angular_impulse");
  j->axial_impulse = r.take<double>("axial_impulse");
  return r.status();  // the values are checked with the whole state (world_from)
}

// Header flags: a joints section follows the contact pairs; each joint carries its drives
// (limits, motor, spring, their impulses). States written before drives existed have flag 1
// alone: their joints read with none. Each joint carries its friction (the bound and its impulse)
// only where some joint has any (flag 4): the bytes of a world without are as they were.
constexpr std::uint32_t kStateHasJoints = 1;
constexpr std::uint32_t kStateJointDrives = 2;
constexpr std::uint32_t kStateJointFriction = 4;
// Each live body carries its gravity scale, dampings, held force and torque and collision filter,
// written only where some body differs from the defaults (a world without writes the bytes it
// did before they existed).
constexpr std::uint32_t kStateBodyForces = 8;
constexpr std::uint32_t kStateFlags =
    kStateHasJoints | kStateJointDrives | kStateJointFriction | kStateBodyForces;
constexpr std::size_t kFlagsOffset = 36;  // magic 8, version 4, header 4, length 8, counts 12

// The least bytes of one entry, so that counts are checked against what is left.
constexpr std::size_t kLeastSlotBytes = 5;       // generation, alive
constexpr std::size_t kLeastPairBytes = 83;      // ids, pose, feature, colour, count
constexpr std::size_t kLeastJointSlotBytes = 5;  // generation, alive

}  // namespace

std::string encode_state(const WorldStateData& state) {
  std::string out;
  out.reserve(kStateHeaderBytes + 16 + state.slots.size() * 400 + state.contact_pairs.size() * 200);
  Writer w(&out);
  out.append(kStateMagic, sizeof kStateMagic);
  w.put(World::kStateFormatVersion);
  w.put(static_cast<std::uint32_t>(kStateHeaderBytes));
  const std::size_t length_at = out.size();
  w.put(std::uint64_t{0});  // the whole length, filled in below
  w.put(static_cast<std::uint32_t>(state.slots.size()));
  w.put(static_cast<std::uint32_t>(state.free_slots.size()));
  w.put(static_cast<std::uint32_t>(state.contact_pairs.size()));
  const bool friction =
      std::any_of(state.joints.begin(), state.joints.end(), [](const JointSlot& s) {
        return s.alive && (s.joint.friction != 0 || !s.joint.friction_impulse.isZero());
      });
  const bool body_forces =
      std::any_of(state.slots.begin(), state.slots.end(), [](const BodySlotState& s) {
        return s.alive && (s.body.has_own_forces() || s.body.filter != CollisionFilter{});
      });
  w.put((state.joints.empty() ? std::uint32_t{0}
                              : kStateHasJoints | kStateJointDrives |
                                    (friction ? kStateJointFriction : std::uint32_t{0})) |
        (body_forces ? kStateBodyForces : std::uint32_t{0}));
  w.put(state.time);
  w.put(state.step);
  for (const BodySlotState& slot : state.slots) {
    w.put(slot.generation);
    w.put(static_cast<std::uint8_t>(slot.alive));
    if (slot.alive) put_body(w, slot.body);
    if (slot.alive && body_forces) put_body_forces(w, slot.body);
  }
  for (std::uint32_t slot : state.free_slots)
    w.put(slot);
  for (const ContactPairRecord& pair : state.contact_pairs)
    put_pair(w, pair);
  if (!state.joints.empty()) {
    w.put(static_cast<std::uint32_t>(state.joints.size()));
    w.put(static_cast<std::uint32_t>(state.free_joints.size()));
    for (const JointSlot& slot : state.joints) {
      w.put(slot.generation);
      w.put(static_cast<std::uint8_t>(slot.alive));
      if (!slot.alive) continue;
      put_joint(w, slot.joint);
      put_joint_drives(w, slot.joint);
      if (friction) {
        w.put(slot.joint.friction);
        w.put(slot.joint.friction_impulse);
      }
    }
    for (std::uint32_t slot : state.free_joints)
      w.put(slot);
  }
  const std::uint64_t length = out.size();
  std::memcpy(out.data() + length_at, &length, sizeof length);
  return out;
}

Result<StateSizes> read_state_header(std::string_view bytes) {
  if (bytes.size() < kStateHeaderBytes || std::memcmp(bytes.data(), kStateMagic, 8) != 0)
    return Status::error("magic: not a Tumble world state (no TUMBLEWS header)");
  Reader r(bytes.substr(8, kStateHeaderBytes - 8));
  const auto version = r.take<std::uint32_t>("version");
  if (version != World::kStateFormatVersion)
    return Status::error("version: format version " + std::to_string(version) +
                         "; this engine reads version " +
                         std::to_string(World::kStateFormatVersion) + " only");
  const auto header_bytes = r.take<std::uint32_t>("header");
  StateSizes sizes;
  sizes.bytes = r.take<std::uint64_t>("length");
  sizes.slots = r.take<std::uint32_t>("slots");
  sizes.free_slots = r.take<std::uint32_t>("free_slots");
  sizes.contact_pairs = r.take<std::uint32_t>("contact_pairs");
  const auto flags = r.take<std::uint32_t>("flags");
  if (header_bytes != kStateHeaderBytes)
    return Status::error("header: " + std::to_string(header_bytes) + " bytes, expected " +
                         std::to_string(kStateHeaderBytes));
  if (sizes.bytes != bytes.size())
    return Status::error("length: the header says " + std::to_string(sizes.bytes) +
                         " bytes, there are " + std::to_string(bytes.size()));
  // Drives without joints, or friction without drives, is no state this engine writes.
  if ((flags & ~kStateFlags) != 0 ||
      (flags & (kStateHasJoints | kStateJointDrives)) == kStateJointDrives ||
      ((flags & kStateJointFriction) != 0 && (flags & kStateJointDrives) == 0))
    return Status::error("flags: unknown flags " + std::to_string(flags));
  // Every entry takes bytes: counts the length cannot hold are refused before anything is made.
  const std::size_t body = bytes.size() - kStateHeaderBytes;
  if (sizes.slots > body / kLeastSlotBytes || sizes.free_slots > body / 4 ||
      sizes.contact_pairs > body / kLeastPairBytes ||
      std::uint64_t{sizes.slots} * kLeastSlotBytes + std::uint64_t{sizes.free_slots} * 4 +
              std::uint64_t{sizes.contact_pairs} * kLeastPairBytes >
          body)
    return Status::error(
        "counts: the header's counts (" + std::to_string(sizes.slots) + " slots, " +
        std::to_string(sizes.free_slots) + " free, " + std::to_string(sizes.contact_pairs) +
        " contact pairs) do not fit in its " + std::to_string(bytes.size()) + " bytes");
  return sizes;
}

Result<WorldStateData> decode_state(std::string_view bytes) {
  Result<StateSizes> sizes = read_state_header(bytes);
  if (!sizes) return sizes.status();
  Reader r(bytes.substr(kStateHeaderBytes));
  WorldStateData state;
  std::uint32_t flags = 0;
  std::memcpy(&flags, bytes.data() + kFlagsOffset, sizeof flags);
  state.time = r.take<double>("time");
  state.step = r.take<std::uint64_t>("step");
  state.slots.resize(sizes.value().slots);
  for (std::size_t i = 0; i < state.slots.size() && r.ok(); ++i) {
    BodySlotState& slot = state.slots[i];
    slot.generation = r.take<std::uint32_t>("generation");
    slot.alive = take_flag(r, "alive");
    Status s = slot.alive ? take_body(r, &slot.body) : r.status();
    if (s && slot.alive && (flags & kStateBodyForces) != 0) {
      take_body_forces(r, &slot.body);
      s = r.status();
    }
    if (!s) return s.within("slots[" + std::to_string(i) + "].");
  }
  state.free_slots.resize(sizes.value().free_slots);
  for (std::uint32_t& slot : state.free_slots)
    slot = r.take<std::uint32_t>("free_slots");
  state.contact_pairs.resize(sizes.value().contact_pairs);
  for (std::size_t i = 0; i < state.contact_pairs.size() && r.ok(); ++i)
    if (Status s = take_pair(r, &state.contact_pairs[i]); !s)
      return s.within("contact_pairs[" + std::to_string(i) + "].");
  if ((flags & kStateHasJoints) != 0) {
    state.joints.resize(r.count("joints", kLeastJointSlotBytes));
    const std::uint32_t free_count = r.count("free_joints", 4);
    for (std::size_t i = 0; i < state.joints.size() && r.ok(); ++i) {
      JointSlot& slot = state.joints[i];
      slot.generation = r.take<std::uint32_t>("generation");
      slot.alive = take_flag(r, "alive");
      Status s = slot.alive ? take_joint(r, &slot.joint) : r.status();
      if (s && slot.alive && (flags & kStateJointDrives) != 0) {
        s = take_joint_drives(r, &slot.joint);
        if (s && (flags & kStateJointFriction) != 0) {
          slot.joint.friction = r.take<double>("friction");
          slot.joint.friction_impulse = r.vec3("friction_impulse");
          s = r.status();
        }
      } else if (s && slot.alive) {
        // No drives: the angles count from how the joint was made, as they would have.
        Joint& joint = slot.joint;
        joint.reference_a = joint_detail::perpendicular(joint.axis_a.normalized());
        joint.reference_b = joint.relative.conjugate() * joint.reference_a;
      }
      if (!s) return s.within("joints[" + std::to_string(i) + "].");
    }
    state.free_joints.resize(free_count);  // bounded by the bytes there were (count)
    for (std::uint32_t& slot : state.free_joints)
      slot = r.take<std::uint32_t>("free_joints");
  }
  if (!r.ok()) return r.status();
  if (r.left() != 0)
    return Status::error("length: " + std::to_string(r.left()) + " bytes after the last pair");
  return state;
}

}  // namespace tumble
