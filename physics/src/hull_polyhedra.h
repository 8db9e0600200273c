// Hull bodies made from the same points share their polyhedra, as boxes of one size do
// (box_polyhedra.h): a field of 1000 copies of one rock runs Qhull once and holds one built hull
// and one copy moved to its centre of mass, where each body used to build and hold its own
// (measured in docs/PERFORMANCE.md, "Hull bodies of one rock").
#pragma once

#include <memory>
#include <span>

#include "physics/math.h"
#include "physics/polyhedron.h"
#include "physics/status.h"

namespace tumble {

// The last hulls built are kept alive (shared_hull_polyhedron) up to this many and this many bytes
// of vertices, faces and edges: enough for a scene's kinds of rock taken in turn, and at most
// about 1 MB however many different rocks a client makes.
inline constexpr std::size_t kRecentHulls = 64;
inline constexpr std::size_t kRecentHullBytes = std::size_t{1} << 20;

// build_convex_hull(points)'s polyhedron, shared with every other live hull made from exactly
// the same points (bit for bit, in the same order, so the shared hull is the one these points
// would build). A refusal is build_convex_hull's, and nothing is kept of it.
Result<std::shared_ptr<const ConvexPolyhedron>> shared_hull_polyhedron(
    std::span<const Vec3> points);

// `source` with every vertex, face plane and the centroid moved by -offset, shared with every
// other live copy of the same source moved by exactly the same offset.
std::shared_ptr<const ConvexPolyhedron> shared_moved_polyhedron(
    const std::shared_ptr<const ConvexPolyhedron>& source, const Vec3& offset);

}  // namespace tumble
