#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "box_polyhedra.h"
#include "hull_polyhedra.h"
#include "mass_integrals.h"
#include "physics/compound.h"
#include "physics/shape.h"
#include "shape_state.h"

namespace tumble {
namespace {

Status check_length(double value, const char* field) {
  if (!is_finite(value)) return Status::error(std::string(field) + ": must be finite");
  if (!(value > 0)) return Status::error(std::string(field) + ": must be > 0");
  return Status::ok();
}

}  // namespace

const char* shape_type_name(ShapeType type) {
  switch (type) {
    case ShapeType::kSphere:
      return "sphere";
    case ShapeType::kCapsule:
      return "capsule";
    case ShapeType::kBox:
      return "box";
    case ShapeType::kHull:
      return "hull";
    case ShapeType::kHalfSpace:
      return "half_space";
    case ShapeType::kHeightField:
      return "heightfield";
    case ShapeType::kMesh:
      return "mesh";
    case ShapeType::kCompound:
      return "compound";
  }
  return "unknown";
}

Result<Shape> Shape::create(const ShapeDef& def) {
  Shape shape;
  if (const auto* sphere = std::get_if<SphereDef>(&def)) {
    if (Status s = check_length(sphere->radius, "radius"); !s) return s;
    shape.type_ = ShapeType::kSphere;
    shape.radius_ = sphere->radius;
  } else if (const auto* capsule = std::get_if<CapsuleDef>(&def)) {
    if (Status s = check_length(capsule->radius, "radius"); !s) return s;
    if (Status s = check_length(capsule->half_height, "half_height"); !s) return s;
    shape.type_ = ShapeType::kCapsule;
    shape.radius_ = capsule->radius;
    shape.half_height_ = capsule->half_height;
  } else if (const auto* box = std::get_if<BoxDef>(&def)) {
    for (int k = 0; k < 3; ++k) {
      const std::string field = "half_extents[" + std::to_string(k) + "]";
      if (Status s = check_length(box->half_extents[k], field.c_str()); !s) return s;
    }
    shape.type_ = ShapeType::kBox;
    shape.half_extents_ = box->half_extents;
    shape.polyhedron_ = shared_box_polyhedron(box->half_extents);
  } else if (const auto* hull = std::get_if<HullDef>(&def)) {
    if (hull->points.size() > kMaxHullPoints)
      return Status::error("points: " + std::to_string(hull->points.size()) +
                           " points, more than the " + std::to_string(kMaxHullPoints) +
                           " a hull may have");
    Result<std::shared_ptr<const ConvexPolyhedron>> built = shared_hull_polyhedron(hull->points);
    if (!built) return built.status();
    shape.type_ = ShapeType::kHull;
    shape.polyhedron_ = std::move(built).value();
    const Aabb bounds = shape.local_bounds();
    shape.half_extents_ = 0.5 * bounds.extent();
  } else if (const auto* field = std::get_if<HeightFieldDef>(&def)) {
    Result<HeightField> built = HeightField::create(*field);
    if (!built) return built.status();
    shape.type_ = ShapeType::kHeightField;
    shape.height_field_ = std::make_shared<HeightField>(std::move(built).value());
  } else if (const auto* mesh = std::get_if<TriangleMeshDef>(&def)) {
    Result<TriangleMesh> built = TriangleMesh::create(*mesh);
    if (!built) return built.status();
    shape.type_ = ShapeType::kMesh;
    shape.mesh_ = std::make_shared<TriangleMesh>(std::move(built).value());
  } else if (const auto* compound = std::get_if<CompoundDef>(&def)) {
    return Compound::create(*compound);
  } else {
    shape.type_ = ShapeType::kHalfSpace;
  }
  shape.update_radii();
  return shape;
}

Aabb Shape::local_bounds() const {
  switch (type_) {
    case ShapeType::kSphere:
      return {Vec3::Constant(-radius_), Vec3::Constant(radius_)};
    case ShapeType::kCapsule: {
      const Vec3 half(radius_, radius_, radius_ + half_height_);
      return {-half, half};
    }
    case ShapeType::kBox:
      return {-half_extents_, half_extents_};
    case ShapeType::kHull: {
      Aabb bounds;
      for (const Vec3& v : polyhedron_->vertices)
        bounds.grow(v);
      return bounds;
    }
    case ShapeType::kHalfSpace:
      return Aabb::infinite();
    case ShapeType::kHeightField:
      return height_field_->bounds();
    case ShapeType::kMesh:
      return mesh_->bounds();
    case ShapeType::kCompound:
      return compound_->bounds();
  }
  return Aabb::infinite();
}

double Shape::volume() const {
  constexpr double pi = std::numbers::pi;
  switch (type_) {
    case ShapeType::kSphere:
      return 4.0 / 3.0 * pi * radius_ * radius_ * radius_;
    case ShapeType::kCapsule:
      return pi * radius_ * radius_ * (2 * half_height_ + 4.0 / 3.0 * radius_);
    case ShapeType::kBox:
      return 8 * half_extents_.prod();
    case ShapeType::kHull:
      return polyhedron_->volume;
    case ShapeType::kCompound:
      return compound_->volume();
    case ShapeType::kHalfSpace:
    case ShapeType::kHeightField:
    case ShapeType::kMesh:
      return std::numeric_limits<double>::infinity();
  }
  return 0;
}

MassProperties Shape::mass_properties(double density) const {
  constexpr double pi = std::numbers::pi;
  MassProperties props;
  props.mass = density * volume();
  const double m = props.mass;
  switch (type_) {
    case ShapeType::kSphere:
      props.inertia = Mat3::Identity() * (0.4 * m * radius_ * radius_);
      break;
    case ShapeType::kCapsule: {
      // Cylinder plus two hemispheres; each hemisphere's centroid sits 3r/8 beyond its flat face,
      // and about that centroid a hemisphere has 83/320 m r^2 across its axis.
      const double r = radius_, length = 2 * half_height_;
      const double m_cylinder = density * pi * r * r * length;
      const double m_hemisphere = density * 2.0 / 3.0 * pi * r * r * r;
      const double along = 0.5 * m_cylinder * r * r + 2 * (0.4 * m_hemisphere * r * r);
      const double lever = half_height_ + 3.0 * r / 8.0;
      const double across = m_cylinder * (3 * r * r + length * length) / 12.0 +
                            2 * m_hemisphere * (83.0 / 320.0 * r * r + lever * lever);
      props.inertia = Vec3(across, across, along).asDiagonal();
      break;
    }
    case ShapeType::kBox: {
      const Vec3 e2 = (2 * half_extents_).cwiseProduct(2 * half_extents_);
      props.inertia = Vec3(e2.y() + e2.z(), e2.x() + e2.z(), e2.x() + e2.y()).asDiagonal();
      props.inertia *= m / 12.0;
      break;
    }
    case ShapeType::kHull: {
      const PolyhedronIntegrals integrals = integrate_polyhedron(*polyhedron_);
      props.center_of_mass = integrals.centroid;
      props.inertia = inertia_from_second_moment(integrals.second_moment, density);
      break;
    }
    case ShapeType::kHalfSpace:
    case ShapeType::kHeightField:
    case ShapeType::kMesh:
      props.mass = std::numeric_limits<double>::infinity();
      break;
    case ShapeType::kCompound:
      return compound_->mass_properties(density);
  }
  return props;
}

double Shape::size() const {
  switch (type_) {
    case ShapeType::kSphere:
      return radius_;
    case ShapeType::kCapsule:
      return radius_ + half_height_;
    case ShapeType::kBox:
    case ShapeType::kHull:
      return half_extents_.maxCoeff();
    case ShapeType::kHalfSpace:
      return 1.0;
    case ShapeType::kHeightField:
      return std::max(height_field_->def().spacing_x, height_field_->def().spacing_y);
    case ShapeType::kMesh:
      return mesh_->feature_size();
    case ShapeType::kCompound:
      return compound_->smallest_size();
  }
  return 1.0;
}

namespace {

double compute_inner_radius(ShapeType type, double radius, const Vec3& half_extents,
                            const ConvexPolyhedron* polyhedron) {
  switch (type) {
    case ShapeType::kHeightField:
    case ShapeType::kMesh:
    case ShapeType::kCompound:  // Compound::inner_radius
      return 0;
    case ShapeType::kSphere:
    case ShapeType::kCapsule:
      return radius;
    case ShapeType::kBox:
      return half_extents.minCoeff();
    case ShapeType::kHull: {
      double nearest = std::numeric_limits<double>::infinity();
      for (const ConvexPolyhedron::Face& face : polyhedron->faces)
        nearest = std::min(nearest, face.offset);
      return std::max(nearest, 0.0);
    }
    case ShapeType::kHalfSpace:
      return std::numeric_limits<double>::infinity();
  }
  return 0;
}

double compute_outer_radius(ShapeType type, double radius, double half_height,
                            const Vec3& half_extents, const ConvexPolyhedron* polyhedron,
                            const Aabb& terrain_bounds) {
  switch (type) {
    case ShapeType::kHeightField:
    case ShapeType::kMesh:
      return terrain_bounds.min.cwiseAbs().cwiseMax(terrain_bounds.max.cwiseAbs()).norm();
    case ShapeType::kSphere:
      return radius;
    case ShapeType::kCapsule:
      return radius + half_height;
    case ShapeType::kBox:
      return half_extents.norm();
    case ShapeType::kHull: {
      double farthest = 0;
      for (const Vec3& v : polyhedron->vertices)
        farthest = std::max(farthest, v.norm());
      return farthest;
    }
    case ShapeType::kHalfSpace:
      return std::numeric_limits<double>::infinity();
    case ShapeType::kCompound:  // Compound::outer_radius
      return 0;
  }
  return 0;
}

}  // namespace

void Shape::update_radii() {
  if (type_ == ShapeType::kCompound) {
    inner_radius_ = compound_->inner_radius();
    outer_radius_ = compound_->outer_radius();
    return;
  }
  inner_radius_ = compute_inner_radius(type_, radius_, half_extents_, polyhedron_.get());
  outer_radius_ =
      compute_outer_radius(type_, radius_, half_height_, half_extents_, polyhedron_.get(),
                           is_terrain(type_) ? local_bounds() : Aabb{});
}

Vec3 Shape::support(const Vec3& d) const {
  switch (type_) {
    case ShapeType::kSphere: {
      const double n = d.norm();
      return n > 0 ? Vec3(d * (radius_ / n)) : Vec3(radius_, 0, 0);
    }
    case ShapeType::kCapsule: {
      const double n = d.norm();
      const Vec3 tip(0, 0, d.z() >= 0 ? half_height_ : -half_height_);
      return n > 0 ? Vec3(tip + d * (radius_ / n)) : tip;
    }
    case ShapeType::kBox:
      return Vec3(d.x() >= 0 ? half_extents_.x() : -half_extents_.x(),
                  d.y() >= 0 ? half_extents_.y() : -half_extents_.y(),
                  d.z() >= 0 ? half_extents_.z() : -half_extents_.z());
    case ShapeType::kHull:
      return polyhedron_->support(d);
    case ShapeType::kCompound:
      return compound_->support(d);
    case ShapeType::kHalfSpace:
    case ShapeType::kHeightField:
    case ShapeType::kMesh:
      break;
  }
  TUMBLE_ASSERT(false && "a half-space or terrain has no support point");
  return Vec3::Zero();
}

Shape Shape::recentred(const Vec3& offset) const {
  if (type_ == ShapeType::kCompound && !offset.isZero(0)) return compound_->recentred(offset);
  if (type_ != ShapeType::kHull || offset.isZero(0)) return *this;
  Shape shape = *this;
  shape.polyhedron_ = shared_moved_polyhedron(polyhedron_, offset);
  shape.update_radii();
  return shape;
}

ShapeState Shape::state() const {
  ShapeState state{type_, radius_, half_height_, half_extents_, nullptr, nullptr, nullptr, nullptr};
  if (type_ == ShapeType::kCompound) state.compound = compound_;
  if (type_ == ShapeType::kHull) state.polyhedron = polyhedron_;
  if (type_ == ShapeType::kHeightField)  // the definition, owned with the field
    state.height_field =
        std::shared_ptr<const HeightFieldDef>(height_field_, &height_field_->def());
  if (type_ == ShapeType::kMesh)
    state.mesh = std::shared_ptr<const TriangleMeshDef>(mesh_, &mesh_->def());
  return state;
}

namespace {

// A stored polyhedron (from a snapshot) must be the hull its vertices make, as a built one is:
// every vertex of a face's loop on the face's plane, every vertex on or behind every face, every
// vertex on some face, and the stored volume, centroid and extents its own. The references are
// in range (check_polyhedron checked them first). O(vertices x faces): at most 1024 x 2044.
Status check_polyhedron_geometry(const ConvexPolyhedron& p) {
  double scale = 0;
  for (const Vec3& v : p.vertices)
    scale = std::max(scale, v.cwiseAbs().maxCoeff());
  // Qhull merges nearly coplanar facets; their vertices sit within rounding of the plane.
  const double tolerance = 1e-6 * scale;
  std::vector<std::uint8_t> on_a_face(p.vertices.size(), 0);
  for (std::size_t i = 0; i < p.faces.size(); ++i) {
    const ConvexPolyhedron::Face& face = p.faces[i];
    for (std::uint32_t k = 0; k < face.count; ++k) {
      const std::uint32_t v = p.face_vertices[face.first + k];
      on_a_face[v] = 1;
      if (std::abs(face.normal.dot(p.vertices[v]) - face.offset) > tolerance)
        return Status::error("polyhedron.faces[" + std::to_string(i) +
                             "]: a vertex of its loop is off its plane");
    }
    for (std::size_t v = 0; v < p.vertices.size(); ++v)
      if (face.normal.dot(p.vertices[v]) - face.offset > tolerance)
        return Status::error("polyhedron.vertices[" + std::to_string(v) + "]: outside faces[" +
                             std::to_string(i) + "] (the polyhedron is not convex)");
  }
  for (std::size_t v = 0; v < p.vertices.size(); ++v)
    if (on_a_face[v] == 0)
      return Status::error("polyhedron.vertices[" + std::to_string(v) + "]: on no face");
  const PolyhedronIntegrals integrals = integrate_polyhedron(p);
  if (!(std::abs(integrals.volume - p.volume) <= 1e-9 * std::abs(integrals.volume)))
    return Status::error("polyhedron.volume: not the volume its faces enclose");
  if (!((integrals.centroid - p.centroid).cwiseAbs().maxCoeff() <= 1e-9 * scale))
    return Status::error("polyhedron.centroid: not the centroid of its faces");
  return Status::ok();
}

Status check_polyhedron(const ConvexPolyhedron& p) {
  const std::size_t vertex_count = p.vertices.size(), face_count = p.faces.size();
  if (vertex_count < 4 || face_count < 4 || p.edges.size() < 6)
    return Status::error("polyhedron: needs at least 4 vertices, 4 faces and 6 edges");
  // As many vertices as a built hull may have, and no more faces and edges than a polyhedron of
  // that many vertices has (Euler: F <= 2V - 4, E <= 3V - 6), each edge in two face loops.
  if (vertex_count > kMaxHullPoints)
    return Status::error("polyhedron.vertices: " + std::to_string(vertex_count) +
                         ", more than the " + std::to_string(kMaxHullPoints) + " a hull may have");
  if (face_count > 2 * vertex_count - 4 || p.edges.size() > 3 * vertex_count - 6)
    return Status::error("polyhedron: more faces or edges than its vertices can make");
  if (p.face_vertices.size() != 2 * p.edges.size())
    return Status::error("polyhedron.face_vertices: must hold every edge twice");
  for (std::size_t i = 0; i < vertex_count; ++i)
    if (!is_finite(p.vertices[i]))
      return Status::error("polyhedron.vertices[" + std::to_string(i) + "]: must be finite");
  for (std::size_t i = 0; i < face_count; ++i) {
    const ConvexPolyhedron::Face& face = p.faces[i];
    const std::string field = "polyhedron.faces[" + std::to_string(i) + "]";
    if (!is_finite(face.normal) || std::abs(face.normal.norm() - 1) > 1e-9 ||
        !std::isfinite(face.offset))
      return Status::error(field + ": needs a finite unit normal and offset");
    if (face.count < 3 || face.first > p.face_vertices.size() ||
        face.count > p.face_vertices.size() - face.first)
      return Status::error(field + ": vertex loop out of range");
  }
  for (std::size_t i = 0; i < p.face_vertices.size(); ++i)
    if (p.face_vertices[i] >= vertex_count)
      return Status::error("polyhedron.face_vertices[" + std::to_string(i) + "]: out of range");
  for (std::size_t i = 0; i < p.edges.size(); ++i) {
    const ConvexPolyhedron::Edge& edge = p.edges[i];
    if (edge.tail >= vertex_count || edge.head >= vertex_count || edge.left >= face_count ||
        edge.right >= face_count)
      return Status::error("polyhedron.edges[" + std::to_string(i) + "]: out of range");
  }
  if (!is_finite(p.centroid)) return Status::error("polyhedron.centroid: must be finite");
  if (!(p.volume > 0) || !std::isfinite(p.volume))
    return Status::error("polyhedron.volume: must be finite and > 0");
  return check_polyhedron_geometry(p);
}

}  // namespace

Result<Shape> Shape::from_state(const ShapeState& state) {
  ShapeDef def;
  switch (state.type) {
    case ShapeType::kSphere:
      def = SphereDef{state.radius};
      break;
    case ShapeType::kCapsule:
      def = CapsuleDef{state.radius, state.half_height};
      break;
    case ShapeType::kBox:
      def = BoxDef{state.half_extents};
      break;
    case ShapeType::kHalfSpace:
      def = HalfSpaceDef{};
      break;
    case ShapeType::kHeightField: {
      if (state.height_field == nullptr)
        return Status::error("height_field: required for a heightfield");
      // Built again from its definition: the checks and the derived edges are create()'s.
      return create(*state.height_field);
    }
    case ShapeType::kMesh: {
      if (state.mesh == nullptr) return Status::error("mesh: required for a mesh");
      return create(*state.mesh);
    }
    case ShapeType::kCompound: {
      if (state.compound == nullptr) return Status::error("parts: required for a compound");
      return Compound::of_parts(std::vector<Compound::Part>(state.compound->parts().begin(),
                                                            state.compound->parts().end()));
    }
    case ShapeType::kHull: {
      if (state.polyhedron == nullptr) return Status::error("polyhedron: required for a hull");
      if (Status s = check_polyhedron(*state.polyhedron); !s) return s;
      for (int k = 0; k < 3; ++k)
        if (Status s = check_length(state.half_extents[k], "half_extents"); !s) return s;
      Shape shape;
      shape.type_ = ShapeType::kHull;
      shape.polyhedron_ = state.polyhedron;
      // The broad phase bounds a hull by its vertices; the stored extents must say the same.
      const Vec3 extents = 0.5 * shape.local_bounds().extent();
      if (!((extents - state.half_extents).cwiseAbs().maxCoeff() <= 1e-9 * extents.maxCoeff()))
        return Status::error("half_extents: not half the extent of the hull's vertices");
      shape.half_extents_ = state.half_extents;
      shape.update_radii();
      return shape;
    }
    default:
      return Status::error("type: unknown shape type");
  }
  return create(def);
}

}  // namespace tumble
