// A drawable mesh of a heightfield from its description (samples, spacing, heights): the surface's
// triangles as the engine splits its cells, with a normal per sample from its neighbours'
// heights (smooth shading of the same surface).
#pragma once

#include <cstdint>
#include <span>

#include "mesh.h"

namespace tumble::viewer {

// At most this many triangles: a larger field is drawn from every k-th sample.
inline constexpr std::size_t kMaxHeightFieldTriangles = std::size_t{1} << 21;

// Empty when the description does not make a grid (fewer than 2 x 2 samples, heights of another
// count, spacing not > 0).
Mesh height_field_mesh(std::uint32_t samples_x, std::uint32_t samples_y, double spacing_x,
                       double spacing_y, std::span<const double> heights);

}  // namespace tumble::viewer
