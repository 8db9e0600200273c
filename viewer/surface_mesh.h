// A drawable mesh of a triangle-mesh shape from its description (packed vertices and triangle
// indices): each triangle flat-shaded with its own normal, as the engine's one-sided triangles
// are met (a room's corners and a ramp's edges stay sharp).
#pragma once

#include <cstdint>
#include <span>

#include "mesh.h"

namespace tumble::viewer {

// Empty when the description does not make triangles (coordinates not in triples, indices not in
// triples or out of range); triangles of no area are left out.
Mesh surface_mesh(std::span<const double> xyz, std::span<const std::uint32_t> indices);

}  // namespace tumble::viewer
