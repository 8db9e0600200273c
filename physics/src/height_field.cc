#include "physics/height_field.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace tumble {
namespace {

Vec3 triangle_normal(const std::array<Vec3, 3>& v) {
  return (v[1] - v[0]).cross(v[2] - v[0]).normalized();
}

}  // namespace

Result<HeightField> HeightField::create(const HeightFieldDef& def) {
  for (const auto& [count, field] :
       {std::pair{def.samples_x, "samples_x"}, std::pair{def.samples_y, "samples_y"}}) {
    if (count < 2 || count > kMaxHeightFieldSide)
      return Status::error(std::string(field) + ": must be 2 to " +
                           std::to_string(kMaxHeightFieldSide) + ", is " + std::to_string(count));
  }
  const std::size_t samples = std::size_t{def.samples_x} * def.samples_y;
  if (samples > kMaxHeightFieldSamples)
    return Status::error("samples_x * samples_y: " + std::to_string(samples) +
                         " samples, more than the " + std::to_string(kMaxHeightFieldSamples) +
                         " a heightfield may have");
  for (const auto& [spacing, field] :
       {std::pair{def.spacing_x, "spacing_x"}, std::pair{def.spacing_y, "spacing_y"}}) {
    if (!(spacing > 0 && spacing <= kMaxHeightFieldSpacing))
      return Status::error(std::string(field) + ": must be in (0, 1e4] m");
  }
  if (def.heights.size() != samples)
    return Status::error("heights: " + std::to_string(def.heights.size()) +
                         " values, samples_x * samples_y is " + std::to_string(samples));
  for (std::size_t k = 0; k < samples; ++k)
    if (!(std::abs(def.heights[k]) <= kMaxHeightFieldHeight))
      return Status::error("heights[" + std::to_string(k) + "]: must be finite, within 1e6 m");
  HeightField field;
  field.def_ = def;
  const auto [lowest, highest] = std::minmax_element(def.heights.begin(), def.heights.end());
  field.min_height_ = *lowest;
  field.max_height_ = *highest;
  field.base_ = *lowest - std::max(def.spacing_x, def.spacing_y);
  // An edge is flat within rounding of the cell's size; only a clearly convex one is active, and
  // only where its triangles turn by more than kSmoothEdgeAngle (below that the faces on either
  // side hold what lies on it, as on a plane; see height_field.h); a convex one turning less is
  // gentle (round bodies meet it in its wedge alone).
  const double flat = 1e-9 * std::max(def.spacing_x, def.spacing_y);
  const double smooth = std::cos(kSmoothEdgeAngle);
  field.edge_bits_.assign(field.triangle_count(), 0);
  for (std::size_t t = 0; t < field.triangle_count(); ++t) {
    const std::array<Vec3, 3> v = field.triangle(t);
    const Vec3 n = triangle_normal(v);
    std::uint8_t bits = 0;
    for (int e = 0; e < 3; ++e) {
      const std::int64_t other = field.neighbour(t, e);
      if (other < 0) {
        bits |= 1u << e;
        continue;
      }
      // The neighbour's vertex that is not on the shared edge: the one across from it.
      const std::array<Vec3, 3> w = field.triangle(static_cast<std::size_t>(other));
      double below = 0;
      for (const Vec3& q : w)
        below = std::min(below, (q - v[0]).dot(n));
      if (below < -flat) bits |= triangle_normal(w).dot(n) < smooth ? 1u << e : 8u << e;
    }
    field.edge_bits_[t] = bits;
  }
  return field;
}

Aabb HeightField::bounds() const {
  const double half_x = 0.5 * (def_.samples_x - 1) * def_.spacing_x;
  const double half_y = 0.5 * (def_.samples_y - 1) * def_.spacing_y;
  return {Vec3(-half_x, -half_y, base_), Vec3(half_x, half_y, max_height_)};
}

std::array<Vec3, 3> HeightField::triangle(std::size_t t) const {
  const std::size_t cell = t / 2;
  const auto i = static_cast<std::uint32_t>(cell % cells_x());
  const auto j = static_cast<std::uint32_t>(cell / cells_x());
  if (t % 2 == 0) return {sample(i, j), sample(i + 1, j), sample(i + 1, j + 1)};
  return {sample(i, j), sample(i + 1, j + 1), sample(i, j + 1)};
}

std::int64_t HeightField::neighbour(std::size_t t, int e) const {
  const std::size_t cell = t / 2;
  const std::int64_t i = static_cast<std::int64_t>(cell % cells_x());
  const std::int64_t j = static_cast<std::int64_t>(cell / cells_x());
  const std::int64_t nx = cells_x(), ny = cells_y();
  auto at = [&](std::int64_t ci, std::int64_t cj, int k) -> std::int64_t {
    if (ci < 0 || cj < 0 || ci >= nx || cj >= ny) return -1;
    return 2 * (cj * nx + ci) + k;
  };
  if (e == 2 - 2 * static_cast<int>(t % 2)) return static_cast<std::int64_t>(t ^ 1);  // diagonal
  if (t % 2 == 0) return e == 0 ? at(i, j - 1, 1) : at(i + 1, j, 1);
  return e == 1 ? at(i, j + 1, 0) : at(i - 1, j, 0);
}

double HeightField::height_at(double x, double y) const {
  const double fx = x / def_.spacing_x + 0.5 * (def_.samples_x - 1);
  const double fy = y / def_.spacing_y + 0.5 * (def_.samples_y - 1);
  const double ci = std::clamp(std::floor(fx), 0.0, cells_x() - 1.0);
  const double cj = std::clamp(std::floor(fy), 0.0, cells_y() - 1.0);
  const double u = std::clamp(fx - ci, 0.0, 1.0), w = std::clamp(fy - cj, 0.0, 1.0);
  const auto i = static_cast<std::uint32_t>(ci), j = static_cast<std::uint32_t>(cj);
  const double h00 = height(i, j), h11 = height(i + 1, j + 1);
  if (u >= w) return h00 + u * (height(i + 1, j) - h00) + w * (h11 - height(i + 1, j));
  return h00 + w * (height(i, j + 1) - h00) + u * (h11 - height(i, j + 1));
}

bool HeightField::cells_under(const Aabb& box, std::uint32_t* i0, std::uint32_t* j0,
                              std::uint32_t* i1, std::uint32_t* j1) const {
  const double x0 = -0.5 * (def_.samples_x - 1) * def_.spacing_x;
  const double y0 = -0.5 * (def_.samples_y - 1) * def_.spacing_y;
  const double lo_x = std::floor((box.min.x() - x0) / def_.spacing_x);
  const double hi_x = std::floor((box.max.x() - x0) / def_.spacing_x);
  const double lo_y = std::floor((box.min.y() - y0) / def_.spacing_y);
  const double hi_y = std::floor((box.max.y() - y0) / def_.spacing_y);
  const double last_x = cells_x() - 1.0, last_y = cells_y() - 1.0;
  // Also false for NaN bounds.
  if (!(hi_x >= 0 && hi_y >= 0 && lo_x <= last_x && lo_y <= last_y)) return false;
  *i0 = static_cast<std::uint32_t>(std::max(lo_x, 0.0));
  *j0 = static_cast<std::uint32_t>(std::max(lo_y, 0.0));
  *i1 = static_cast<std::uint32_t>(std::min(hi_x, last_x));
  *j1 = static_cast<std::uint32_t>(std::min(hi_y, last_y));
  return true;
}

}  // namespace tumble
