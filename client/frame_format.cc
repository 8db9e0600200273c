#include "frame_format.h"

#include <cstdio>
#include <nlohmann/json.hpp>

namespace tumble::client {
namespace {

using Json = nlohmann::json;

template <class Field>
Json slice(const Field& values, int first, int count) {
  Json out = Json::array();
  for (int k = 0; k < count; ++k)
    out.push_back(values[first + k]);
  return out;
}

Json shape_json(const v1::Shape& shape) {
  switch (shape.kind_case()) {
    case v1::Shape::kBox:
      return {{"box", {shape.box().size().x(), shape.box().size().y(), shape.box().size().z()}}};
    case v1::Shape::kSphere:
      return {{"sphere", shape.sphere().radius()}};
    case v1::Shape::kCapsule:
      return {{"capsule", {shape.capsule().radius(), shape.capsule().half_height()}}};
    case v1::Shape::kHull:
      return {{"hull", slice(shape.hull().points(), 0, shape.hull().points_size())}};
    case v1::Shape::kHeightfield: {
      const v1::HeightField& f = shape.heightfield();
      return {{"heightfield",
               {{"samples", {f.samples_x(), f.samples_y()}},
                {"spacing", {f.spacing_x(), f.spacing_y()}},
                {"heights", slice(f.heights(), 0, f.heights_size())}}}};
    }
    case v1::Shape::kMesh: {
      const v1::Mesh& m = shape.mesh();
      return {{"mesh",
               {{"vertices", slice(m.vertices(), 0, m.vertices_size())},
                {"triangles",
                 Json(std::vector<std::uint32_t>(m.triangles().begin(), m.triangles().end()))}}}};
    }
    case v1::Shape::kCompound: {
      Json parts = Json::array();
      for (const v1::CompoundPart& part : shape.compound().parts()) {
        const v1::Quat& q = part.orientation();
        parts.push_back(
            {{"shape", shape_json(part.shape())},
             {"position", {part.position().x(), part.position().y(), part.position().z()}},
             {"orientation", part.has_orientation() ? Json{q.w(), q.x(), q.y(), q.z()}
                                                    : Json{1.0, 0.0, 0.0, 0.0}}});
      }
      return {{"compound", parts}};
    }
    default:
      return {{"plane", true}};
  }
}

// Every field of the step's statistics under its proto name: counters as integers, times and
// measures as numbers. Read through the message's descriptor, so a field added to StepStats is
// printed without a change here.
Json stats_json(const v1::StepStats& stats) {
  Json out = Json::object();
  const google::protobuf::Descriptor* descriptor = stats.GetDescriptor();
  const google::protobuf::Reflection* reflection = stats.GetReflection();
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const google::protobuf::FieldDescriptor* field = descriptor->field(i);
    switch (field->cpp_type()) {
      case google::protobuf::FieldDescriptor::CPPTYPE_UINT32:
        out[field->name()] = reflection->GetUInt32(stats, field);
        break;
      case google::protobuf::FieldDescriptor::CPPTYPE_UINT64:
        out[field->name()] = reflection->GetUInt64(stats, field);
        break;
      case google::protobuf::FieldDescriptor::CPPTYPE_DOUBLE:
        out[field->name()] = reflection->GetDouble(stats, field);
        break;
      default:
        break;  // StepStats holds numbers only
    }
  }
  return out;
}

// "positions: 3 values for 2 bodies (3 each)" when `values` is not `per` times `bodies`.
Status check_length(const char* field, int values, int per, int bodies, const char* of) {
  if (static_cast<long long>(values) == static_cast<long long>(per) * bodies) return Status::ok();
  return Status::error(std::string(field) + ": " + std::to_string(values) + " values for " +
                       std::to_string(bodies) + " " + of + " (" + std::to_string(per) + " each)");
}

}  // namespace

Status check_frame(const v1::Frame& frame) {
  const int bodies = frame.ids_size();
  if (Status s = check_length("positions", frame.positions_size(), 3, bodies, "bodies"); !s)
    return s;
  if (Status s = check_length("orientations", frame.orientations_size(), 4, bodies, "bodies"); !s)
    return s;
  if (frame.linear_velocities_size() != 0 || frame.angular_velocities_size() != 0) {
    if (Status s =
            check_length("linear_velocities", frame.linear_velocities_size(), 3, bodies, "bodies");
        !s)
      return s;
    if (Status s = check_length("angular_velocities", frame.angular_velocities_size(), 3, bodies,
                                "bodies");
        !s)
      return s;
  }
  if (frame.has_contacts()) {
    const v1::Contacts& c = frame.contacts();
    const int contacts = c.body_a_size();
    const std::pair<const char*, std::pair<int, int>> arrays[] = {
        {"contacts.body_b", {c.body_b_size(), 1}},
        {"contacts.points", {c.points_size(), 3}},
        {"contacts.normals", {c.normals_size(), 3}},
        {"contacts.depths", {c.depths_size(), 1}},
        {"contacts.impulses", {c.impulses_size(), 1}}};
    for (const auto& [field, size] : arrays)
      if (Status s = check_length(field, size.first, size.second, contacts, "contacts"); !s)
        return s;
  }
  for (int i = 0; i < frame.added_size(); ++i)
    if (frame.added(i).shape().kind_case() == v1::Shape::KIND_NOT_SET)
      return Status::error("added[" + std::to_string(i) + "].shape: required");
  return Status::ok();
}

std::string frame_to_json_line(const v1::Frame& frame) {
  Json line = {{"step", frame.step()}, {"time", frame.time()}, {"dropped", frame.dropped()}};
  if (frame.changes_only()) line["changes_only"] = true;  // bodies not listed did not change
  const bool velocities = frame.linear_velocities_size() == 3 * frame.ids_size();
  Json bodies = Json::array();
  for (int i = 0; i < frame.ids_size(); ++i) {
    Json body = {{"id", frame.ids(i)},
                 {"p", slice(frame.positions(), 3 * i, 3)},
                 {"q", slice(frame.orientations(), 4 * i, 4)}};
    if (velocities) {
      body["v"] = slice(frame.linear_velocities(), 3 * i, 3);
      body["w"] = slice(frame.angular_velocities(), 3 * i, 3);
    }
    bodies.push_back(std::move(body));
  }
  line["bodies"] = std::move(bodies);
  if (frame.has_contacts()) {
    const v1::Contacts& c = frame.contacts();
    Json contacts = Json::array();
    for (int i = 0; i < c.body_a_size(); ++i)
      contacts.push_back({{"a", c.body_a(i)},
                          {"b", c.body_b(i)},
                          {"p", slice(c.points(), 3 * i, 3)},
                          {"n", slice(c.normals(), 3 * i, 3)},
                          {"depth", c.depths(i)},
                          {"impulse", c.impulses(i)}});
    line["contacts"] = std::move(contacts);
  }
  if (frame.added_size() > 0) {
    Json added = Json::array();
    for (const v1::BodyDescription& d : frame.added()) {
      added.push_back({{"id", d.id()},
                       {"shape", shape_json(d.shape())},
                       {"static", d.type() == v1::BODY_TYPE_STATIC},
                       {"mass", d.mass()},
                       {"color", d.color()}});
      if (d.type() == v1::BODY_TYPE_KINEMATIC) added.back()["kinematic"] = true;
    }
    line["added"] = std::move(added);
  }
  if (frame.removed_size() > 0) line["removed"] = slice(frame.removed(), 0, frame.removed_size());
  if (frame.has_stats()) line["stats"] = stats_json(frame.stats());
  if (frame.has_joints()) {
    const v1::JointStates& j = frame.joints();
    Json joints = Json::array();
    const bool placed = j.anchors_size() == 3 * j.ids_size() && j.axes_size() == 3 * j.ids_size();
    for (int i = 0; i < j.ids_size() && j.forces_size() == 3 * j.ids_size(); ++i) {
      Json joint = {{"id", j.ids(i)},
                    {"position", j.positions(i)},
                    {"speed", j.speeds(i)},
                    {"effort", j.efforts(i)},
                    {"force", slice(j.forces(), 3 * i, 3)},
                    {"torque", slice(j.torques(), 3 * i, 3)}};
      if (placed) {
        joint["anchor"] = slice(j.anchors(), 3 * i, 3);
        joint["axis"] = slice(j.axes(), 3 * i, 3);
      }
      joints.push_back(std::move(joint));
    }
    line["joints"] = std::move(joints);
  }
  if (frame.joints_added_size() > 0) {
    Json added = Json::array();
    for (const v1::JointDescription& d : frame.joints_added())
      added.push_back({{"id", d.id()},
                       {"kind", v1::JointKind_Name(d.spec().kind())},
                       {"a", d.spec().a()},
                       {"b", d.spec().b()}});
    line["joints_added"] = std::move(added);
  }
  if (frame.joints_removed_size() > 0)
    line["joints_removed"] = slice(frame.joints_removed(), 0, frame.joints_removed_size());
  return line.dump();
}

std::string csv_header(bool velocities) {
  return velocities ? "step,time,id,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz"
                    : "step,time,id,x,y,z,qw,qx,qy,qz";
}

std::string frame_to_csv_rows(const v1::Frame& frame, bool velocities) {
  // Rows keep the header's columns: asked-for velocities that a frame lacks are empty cells.
  const bool has_velocities = frame.linear_velocities_size() == 3 * frame.ids_size();
  std::string rows;
  char cell[32];
  auto add = [&](double value) {
    std::snprintf(cell, sizeof cell, ",%.17g", value);
    rows += cell;
  };
  for (int i = 0; i < frame.ids_size(); ++i) {
    rows += std::to_string(frame.step());
    add(frame.time());
    rows += ',';
    rows += std::to_string(frame.ids(i));
    for (int k = 0; k < 3; ++k)
      add(frame.positions(3 * i + k));
    for (int k = 0; k < 4; ++k)
      add(frame.orientations(4 * i + k));
    if (velocities && has_velocities) {
      for (int k = 0; k < 3; ++k)
        add(frame.linear_velocities(3 * i + k));
      for (int k = 0; k < 3; ++k)
        add(frame.angular_velocities(3 * i + k));
    } else if (velocities) {
      rows += ",,,,,,";
    }
    rows += '\n';
  }
  return rows;
}

}  // namespace tumble::client
