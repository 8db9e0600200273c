// Volume integrals of a closed polyhedron, by summing signed tetrahedra from a reference point
// (the covariance method of Blow and Binstock, "How to find the inertia tensor (or other mass
// properties) of a 3D solid body represented by a triangle mesh", 2004).
#pragma once

#include "physics/polyhedron.h"

namespace tumble {

struct PolyhedronIntegrals {
  double volume = 0;  // m^3
  Vec3 centroid = Vec3::Zero();
  Mat3 second_moment = Mat3::Zero();  // integral of (x - centroid)(x - centroid)^T dV, m^5
};

PolyhedronIntegrals integrate_polyhedron(const ConvexPolyhedron& polyhedron);

// Inertia tensor (kg m^2) of a solid with `second_moment` (m^5) at `density` (kg/m^3).
Mat3 inertia_from_second_moment(const Mat3& second_moment, double density);

}  // namespace tumble
