#include "physics/compound.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

namespace tumble {
namespace {

std::string part_field(std::size_t index) {
  return "parts[" + std::to_string(index) + "]";
}

// Part poses must keep bodies within the sizes a world accepts (WorldLimits bounds the whole
// shape's reach); this only keeps the arithmetic finite before that check.
constexpr double kMaxPartOffset = 1e6;

Status check_pose(const Pose& pose, const std::string& field) {
  if (!is_finite(pose.position) || !(pose.position.cwiseAbs().maxCoeff() <= kMaxPartOffset))
    return Status::error(field + ".pose.position: must be finite with |x| <= 1e6");
  if (!is_finite(pose.orientation) || !(pose.orientation.norm() > 1e-9))
    return Status::error(field + ".pose.orientation: must be a finite, non-zero quaternion");
  return Status::ok();
}

}  // namespace

Result<Shape> Compound::create(const CompoundDef& def) {
  if (def.parts.empty()) return Status::error("parts: a compound needs at least one part");
  if (def.parts.size() > kMaxCompoundParts)
    return Status::error("parts: " + std::to_string(def.parts.size()) + " parts, more than the " +
                         std::to_string(kMaxCompoundParts) + " a compound may have");
  std::vector<Part> parts;
  parts.reserve(def.parts.size());
  for (std::size_t i = 0; i < def.parts.size(); ++i) {
    const CompoundPart& given = def.parts[i];
    const std::string field = part_field(i);
    // Checked before it is built: a nested compound would recurse without bound.
    if (std::holds_alternative<CompoundDef>(given.shape) ||
        std::holds_alternative<HalfSpaceDef>(given.shape) ||
        std::holds_alternative<HeightFieldDef>(given.shape) ||
        std::holds_alternative<TriangleMeshDef>(given.shape))
      return Status::error(field +
                           ".shape: a compound's parts must be convex (sphere, capsule, box or "
                           "hull)");
    if (Status s = check_pose(given.pose, field); !s) return s;
    Result<Shape> shape = Shape::create(given.shape);
    if (!shape) return shape.status().within(field + ".shape.");
    parts.push_back({std::move(shape).value(),
                     Pose{given.pose.position, given.pose.orientation.normalized()}, Aabb{}});
  }
  return shape_of(std::move(parts));
}

Result<Shape> Compound::of_parts(std::vector<Part> parts) {
  if (parts.empty()) return Status::error("parts: a compound needs at least one part");
  if (parts.size() > kMaxCompoundParts)
    return Status::error("parts: more than the " + std::to_string(kMaxCompoundParts) +
                         " a compound may have");
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string field = part_field(i);
    if (!is_convex_part(parts[i].shape.type()))
      return Status::error(field + ".shape: a compound's parts must be convex");
    if (Status s = check_pose(parts[i].pose, field); !s) return s;
    if (!(std::abs(parts[i].pose.orientation.norm() - 1) <= 1e-12))
      return Status::error(field + ".pose.orientation: must be of unit length");
  }
  return shape_of(std::move(parts));
}

Shape Compound::shape_of(std::vector<Part> parts) {
  auto compound = std::make_shared<Compound>();
  for (Part& part : parts) {
    part.bounds = transform_aabb(part.shape.local_bounds(), part.pose);
    compound->bounds_.min = compound->bounds_.min.cwiseMin(part.bounds.min);
    compound->bounds_.max = compound->bounds_.max.cwiseMax(part.bounds.max);
  }
  compound->parts_ = std::move(parts);
  Shape shape;
  shape.type_ = ShapeType::kCompound;
  shape.compound_ = std::move(compound);
  shape.update_radii();
  return shape;
}

double Compound::volume() const {
  double total = 0;
  for (const Part& part : parts_)
    total += part.shape.volume();
  return total;
}

// Each part's inertia turned into the compound's axes and moved to the common centre of mass
// (the parallel-axis theorem).
MassProperties Compound::mass_properties(double density) const {
  MassProperties total;
  Vec3 moment = Vec3::Zero();
  std::vector<MassProperties> each;
  each.reserve(parts_.size());
  for (const Part& part : parts_) {
    MassProperties props = part.shape.mass_properties(density);
    props.center_of_mass = part.pose.transform(props.center_of_mass);
    const Mat3 rotation = part.pose.orientation.toRotationMatrix();
    props.inertia = rotation * props.inertia * rotation.transpose();
    total.mass += props.mass;
    moment += props.mass * props.center_of_mass;
    each.push_back(props);
  }
  if (!(total.mass > 0)) return total;
  total.center_of_mass = moment / total.mass;
  for (const MassProperties& props : each) {
    const Vec3 d = props.center_of_mass - total.center_of_mass;
    total.inertia +=
        props.inertia + props.mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
  }
  return total;
}

double Compound::smallest_size() const {
  double smallest = std::numeric_limits<double>::infinity();
  for (const Part& part : parts_)
    smallest = std::min(smallest, part.shape.size());
  return smallest;
}

double Compound::inner_radius() const {
  double thinnest = std::numeric_limits<double>::infinity();
  for (const Part& part : parts_)
    thinnest = std::min(thinnest, part.shape.inner_radius());
  return thinnest;
}

double Compound::outer_radius() const {
  double farthest = 0;
  for (const Part& part : parts_)
    farthest = std::max(farthest, part.pose.position.norm() + part.shape.outer_radius());
  return farthest;
}

Vec3 Compound::support(const Vec3& direction) const {
  Vec3 best = Vec3::Zero();
  double reach = -std::numeric_limits<double>::infinity();
  for (const Part& part : parts_) {
    const Vec3 local = part.shape.support(part.pose.orientation.conjugate() * direction);
    const Vec3 point = part.pose.transform(local);
    if (const double along = point.dot(direction); along > reach) {
      reach = along;
      best = point;
    }
  }
  return best;
}

Shape Compound::recentred(const Vec3& offset) const {
  std::vector<Part> moved = parts_;
  for (Part& part : moved)
    part.pose.position -= offset;
  return shape_of(std::move(moved));
}

}  // namespace tumble
