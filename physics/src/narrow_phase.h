// The pair routines of the narrow phase. Each works in one local frame given by the caller and
// writes its manifold (normal from A to B) in that frame; collide() moves it to the world.
#pragma once

#include "physics/collision.h"

namespace tumble {

// B placed in A's frame by (rotation, translation). Result in A's frame.
std::uint32_t collide_polytopes(const ConvexPolyhedron& a, const ConvexPolyhedron& b,
                                const Mat3& rotation, const Vec3& translation, double scale,
                                const CollisionSettings& settings, ContactManifold* out);
// Sphere A (centre at the origin of A's frame) against sphere or capsule B placed in A's frame.
std::uint32_t collide_sphere_sphere(double radius_a, double radius_b, const Vec3& centre_b,
                                    double margin, ContactManifold* out);
std::uint32_t collide_sphere_capsule(double radius_a, const Shape& capsule_b, const Mat3& rotation,
                                     const Vec3& translation, double margin, ContactManifold* out);
std::uint32_t collide_capsules(const Shape& a, const Shape& b, const Mat3& rotation,
                               const Vec3& translation, double margin, ContactManifold* out);
// A sphere or capsule A, given by its core segment p..q (p == q for a sphere) and radius in B's
// frame, against polytope B. Result in B's frame.
std::uint32_t collide_round_polytope(const Vec3& p, const Vec3& q, double radius,
                                     const Shape& polytope_b, const CollisionSettings& settings,
                                     ContactManifold* out);
// Any shape A placed in the half-space's frame (solid z <= 0). Result in the half-space's frame.
std::uint32_t collide_half_space(const Shape& a, const Mat3& rotation, const Vec3& translation,
                                 double margin, ContactManifold* out);

}  // namespace tumble
