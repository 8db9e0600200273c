// A hull's points from a cloud of any size (a mesh file's vertices), within the at most
// kMaxHullPoints a hull may be given. Plain arrays, none of the engine: the CLI uses it too.
#pragma once

#include <cstddef>
#include <vector>

namespace tumble::mesh_files {

// The most points a hull may be given (the engine's kMaxHullPoints, physics/shape.h).
inline constexpr std::size_t kMaxHullInputPoints = 1024;

// Which of the points (x, y, z each in `xyz`) to give a hull, as sorted indices: every point when
// there are at most max_points; otherwise, for each of max_points directions spread evenly over
// the sphere (a Fibonacci lattice), the point farthest along it (the lowest index of equals),
// each once. Every point kept lies on the cloud's hull, and the hull of the kept points reaches
// as far as the cloud's towards every one of those directions: a polyhedral cloud keeps its
// corners (each is the farthest towards a cone of directions wider than the lattice's spacing),
// a finely tessellated round one loses its shallowest bulges (a sphere of radius r in 99,014
// vertices keeps 1024 and its faces lie within 0.0034 r of the sphere, tests/test_scenes.cc).
// Costs max_points passes over the points.
std::vector<std::size_t> hull_point_indices(const std::vector<double>& xyz,
                                            std::size_t max_points = kMaxHullInputPoints);

}  // namespace tumble::mesh_files
