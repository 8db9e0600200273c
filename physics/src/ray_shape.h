// A ray against one shape, in the shape's frame: the exact entry point of each shape kind
// (closed forms for spheres, capsules, boxes and half-spaces; Cyrus and Beck's clipping against a
// hull's face planes, 1978).
#pragma once

#include "physics/height_field.h"
#include "physics/math.h"
#include "physics/shape.h"
#include "physics/triangle_mesh.h"

namespace tumble {

struct ShapeRayHit {
  double t = 0;                // along the unit direction
  Vec3 normal = Vec3::Zero();  // unit, outward, shape frame
};

// Where the ray origin + t direction (direction of unit length) first enters the shape with t in
// [0, max_t]; false if it does not. A ray that starts inside the shape hits at t = 0 with the
// normal against the direction (as Jolt reports it: the query is already touching).
bool ray_shape(const Shape& shape, const Vec3& origin, const Vec3& direction, double max_t,
               ShapeRayHit* hit);

// Möller and Trumbore's test (1997): where the ray origin + t direction meets the front of
// triangle v (the side its corners run counter-clockwise from) with t >= 0; false from behind or
// along its plane.
bool ray_triangle_front(const std::array<Vec3, 3>& v, const Vec3& origin, const Vec3& direction,
                        double* t);

// The same against a heightfield's surface and the solid below it (ray_height_field.cc).
bool ray_height_field(const HeightField& field, const Vec3& origin, const Vec3& direction,
                      double max_t, ShapeRayHit* hit);

// The same against a mesh's triangles, met from their fronts only (ray_mesh.cc).
bool ray_mesh(const TriangleMesh& mesh, const Vec3& origin, const Vec3& direction, double max_t,
              ShapeRayHit* hit);

}  // namespace tumble
