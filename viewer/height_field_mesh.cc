#include "height_field_mesh.h"

#include <algorithm>
#include <cmath>

namespace tumble::viewer {

Mesh height_field_mesh(std::uint32_t samples_x, std::uint32_t samples_y, double spacing_x,
                       double spacing_y, std::span<const double> heights) {
  Mesh mesh;
  if (samples_x < 2 || samples_y < 2 || !(spacing_x > 0) || !(spacing_y > 0) ||
      heights.size() != std::size_t{samples_x} * samples_y)
    return mesh;
  std::uint32_t stride = 1;
  while (2.0 * ((samples_x - 1) / stride) * ((samples_y - 1) / stride) >
         static_cast<double>(kMaxHeightFieldTriangles))
    ++stride;
  // The samples drawn along each side: every stride-th, and the last.
  const auto drawn = [&](std::uint32_t samples) {
    std::vector<std::uint32_t> out;
    for (std::uint32_t i = 0; i < samples; i += stride)
      out.push_back(i);
    if (out.back() != samples - 1) out.push_back(samples - 1);
    return out;
  };
  const std::vector<std::uint32_t> xs = drawn(samples_x), ys = drawn(samples_y);
  const auto height = [&](std::uint32_t i, std::uint32_t j) {
    return heights[std::size_t{j} * samples_x + i];
  };
  for (std::uint32_t j : ys)
    for (std::uint32_t i : xs) {
      // The slope by central differences (one-sided at the border).
      const std::uint32_t i0 = i > 0 ? i - 1 : i, i1 = std::min(i + 1, samples_x - 1);
      const std::uint32_t j0 = j > 0 ? j - 1 : j, j1 = std::min(j + 1, samples_y - 1);
      const double dx = (height(i1, j) - height(i0, j)) / ((i1 - i0) * spacing_x);
      const double dy = (height(i, j1) - height(i, j0)) / ((j1 - j0) * spacing_y);
      const double length = std::sqrt(dx * dx + dy * dy + 1);
      const double x = (i - 0.5 * (samples_x - 1)) * spacing_x;
      const double y = (j - 0.5 * (samples_y - 1)) * spacing_y;
      for (double value : {x, y, height(i, j), -dx / length, -dy / length, 1 / length})
        mesh.vertices.push_back(static_cast<float>(value));
    }
  const auto columns = static_cast<std::uint32_t>(xs.size());
  for (std::uint32_t b = 0; b + 1 < ys.size(); ++b)
    for (std::uint32_t a = 0; a + 1 < columns; ++a) {
      const std::uint32_t v00 = b * columns + a, v10 = v00 + 1, v01 = v00 + columns, v11 = v01 + 1;
      // Split along (i, j)-(i + 1, j + 1), as the engine's cells are.
      for (std::uint32_t v : {v00, v10, v11, v00, v11, v01})
        mesh.indices.push_back(v);
    }
  return mesh;
}

}  // namespace tumble::viewer
