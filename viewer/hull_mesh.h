// A drawable mesh of a convex hull from its points (the stream describes a hull by its vertices):
// Qhull's triangulated facets, flat-shaded.
#pragma once

#include <span>

#include "mesh.h"

namespace tumble::viewer {

// Empty when the points span no volume.
Mesh hull_mesh(std::span<const double> xyz);

}  // namespace tumble::viewer
