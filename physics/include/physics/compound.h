// The parts of a compound shape (CompoundDef, physics/shape.h): convex shapes at poses in the
// body's frame, built and checked once and shared by every body of that shape.
#pragma once

#include <span>
#include <vector>

#include "physics/math.h"
#include "physics/shape.h"
#include "physics/status.h"

namespace tumble {

class Compound {
 public:
  struct Part {
    Shape shape;  // convex
    Pose pose;    // the part's frame in the compound's, orientation of unit length
    Aabb bounds;  // the part's bounds in the compound's frame
  };

  // Builds a compound shape; a message names the part and its field
  // ("parts[2].shape.radius: must be > 0").
  static Result<Shape> create(const CompoundDef& def);
  // A compound shape of parts already built (a snapshot's); each must be convex and each pose
  // finite with a unit orientation. The bounds are computed here.
  static Result<Shape> of_parts(std::vector<Part> parts);

  std::span<const Part> parts() const { return parts_; }
  // The parts' bounds together, in the compound's frame.
  const Aabb& bounds() const { return bounds_; }

  double volume() const;
  MassProperties mass_properties(double density) const;
  double smallest_size() const;
  double inner_radius() const;
  double outer_radius() const;
  Vec3 support(const Vec3& direction) const;
  // The same parts with `offset` (compound frame) as the new origin.
  Shape recentred(const Vec3& offset) const;

 private:
  std::vector<Part> parts_;
  Aabb bounds_;
  static Shape shape_of(std::vector<Part> parts);
};

// Whether a shape may be a compound's part.
inline bool is_convex_part(ShapeType type) {
  return type == ShapeType::kSphere || type == ShapeType::kCapsule || type == ShapeType::kBox ||
         type == ShapeType::kHull;
}

}  // namespace tumble
