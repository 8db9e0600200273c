#include "scenes/hull_points.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace tumble::mesh_files {

std::vector<std::size_t> hull_point_indices(const std::vector<double>& xyz,
                                            std::size_t max_points) {
  const std::size_t count = xyz.size() / 3;
  std::vector<std::size_t> kept;
  if (count <= max_points) {
    for (std::size_t i = 0; i < count; ++i)
      kept.push_back(i);
    return kept;
  }
  // The Fibonacci lattice (González, "Measurement of areas on a sphere using Fibonacci and
  // latitude-longitude lattices", Math. Geosci. 2010): equal-area bands in z, longitudes a golden
  // angle apart. Half a step off longitude 0, so that no direction lies in a plane of the axes:
  // a box drawn along them would otherwise tie along a whole edge and keep a point of it.
  const double golden_angle = std::numbers::pi * (3 - std::sqrt(5.0));
  const double n = static_cast<double>(max_points);
  for (std::size_t k = 0; k < max_points; ++k) {
    const double z = 1 - (2 * static_cast<double>(k) + 1) / n;
    const double ring = std::sqrt(std::max(0.0, 1 - z * z));
    const double longitude = golden_angle * (static_cast<double>(k) + 0.5);
    const double dx = ring * std::cos(longitude), dy = ring * std::sin(longitude);
    std::size_t best = 0;
    double farthest = -INFINITY;
    for (std::size_t i = 0; i < count; ++i) {
      const double along = dx * xyz[3 * i] + dy * xyz[3 * i + 1] + z * xyz[3 * i + 2];
      if (along > farthest) {
        farthest = along;
        best = i;
      }
    }
    kept.push_back(best);
  }
  std::sort(kept.begin(), kept.end());
  kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
  return kept;
}

}  // namespace tumble::mesh_files
