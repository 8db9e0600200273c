// Boxes of one size share one polyhedron: a pile of 16,000 equal boxes reads one polyhedron in its
// narrow phase instead of 16,000 copies of about 1.25 KB each, scattered over 20 MB.
#pragma once

#include <memory>

#include "physics/math.h"
#include "physics/polyhedron.h"

namespace tumble {

// The polyhedron of a box of these half extents (make_box_polyhedron's), shared with every other
// live box of exactly the same extents. Safe from any thread; a polyhedron no shape holds any
// more is freed, and its entry dropped as entries accumulate.
std::shared_ptr<const ConvexPolyhedron> shared_box_polyhedron(const Vec3& half_extents);

}  // namespace tumble
