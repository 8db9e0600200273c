// A ray against a heightfield: the cells under the ray walked in order (Amanatides and Woo, "A
// fast voxel traversal algorithm for ray tracing", Eurographics 1987), each cell's two triangles
// met by Möller and Trumbore's test (1997). A ray visits at most one cell per row and column it
// crosses, so its cost is bounded by the field's sides, whatever its length.
#include <algorithm>
#include <cmath>
#include <limits>

#include "physics/height_field.h"
#include "ray_shape.h"

namespace tumble {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

bool ray_triangle_front(const std::array<Vec3, 3>& v, const Vec3& origin, const Vec3& direction,
                        double* t) {
  const Vec3 e1 = v[1] - v[0], e2 = v[2] - v[0];
  const Vec3 p = direction.cross(e2);
  const double det = e1.dot(p);
  // det = -direction . (e1 x e2): positive for a ray coming onto the front (a heightfield's upper
  // side); from behind (a heightfield's solid) or along the plane it does not enter here.
  if (det <= 0) return false;
  const double inverse = 1 / det;
  const Vec3 s = origin - v[0];
  const double u = s.dot(p) * inverse;
  const double tolerance = 1e-12;
  if (u < -tolerance || u > 1 + tolerance) return false;
  const Vec3 q = s.cross(e1);
  const double w = direction.dot(q) * inverse;
  if (w < -tolerance || u + w > 1 + tolerance) return false;
  *t = e2.dot(q) * inverse;
  return *t >= 0;
}

bool ray_height_field(const HeightField& field, const Vec3& origin, const Vec3& direction,
                      double max_t, ShapeRayHit* hit) {
  const Aabb box = field.bounds();
  double enter = 0, leave = max_t;
  int enter_axis = -1;
  for (int k = 0; k < 3; ++k) {
    if (direction[k] == 0) {
      if (origin[k] < box.min[k] || origin[k] > box.max[k]) return false;
      continue;
    }
    double near = (box.min[k] - origin[k]) / direction[k];
    double far = (box.max[k] - origin[k]) / direction[k];
    if (near > far) std::swap(near, far);
    if (near > enter) {
      enter = near;
      enter_axis = k;
    }
    leave = std::min(leave, far);
  }
  if (enter > leave) return false;
  const Vec3 entry = origin + enter * direction;
  // Entering below the surface: through the solid's side or bottom (or starting inside it).
  if (entry.z() <= field.height_at(entry.x(), entry.y())) {
    hit->t = enter;
    hit->normal = -direction;
    if (enter_axis >= 0) {
      hit->normal = Vec3::Zero();
      hit->normal[enter_axis] = direction[enter_axis] > 0 ? -1 : 1;
    }
    return true;
  }
  const HeightFieldDef& def = field.def();
  const double spacing[2] = {def.spacing_x, def.spacing_y};
  const double first[2] = {-0.5 * (def.samples_x - 1) * def.spacing_x,
                           -0.5 * (def.samples_y - 1) * def.spacing_y};
  const double last_cell[2] = {field.cells_x() - 1.0, field.cells_y() - 1.0};
  double cell[2], next[2], step_t[2];
  int step[2];
  for (int k = 0; k < 2; ++k) {
    cell[k] = std::clamp(std::floor((entry[k] - first[k]) / spacing[k]), 0.0, last_cell[k]);
    step[k] = direction[k] > 0 ? 1 : -1;
    if (direction[k] == 0) {
      next[k] = step_t[k] = kInfinity;
    } else {
      const double boundary = first[k] + (cell[k] + (step[k] > 0 ? 1 : 0)) * spacing[k];
      next[k] = (boundary - origin[k]) / direction[k];
      step_t[k] = spacing[k] / std::abs(direction[k]);
    }
  }
  for (;;) {
    const auto i = static_cast<std::uint32_t>(cell[0]), j = static_cast<std::uint32_t>(cell[1]);
    double best = kInfinity;
    Vec3 best_normal = Vec3::UnitZ();
    for (std::uint32_t k = 0; k < 2; ++k) {
      const std::array<Vec3, 3> v = field.triangle(2 * (std::size_t{j} * field.cells_x() + i) + k);
      double t;
      if (ray_triangle_front(v, origin, direction, &t) && t < best) {
        best = t;
        best_normal = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
      }
    }
    if (best <= leave) {
      hit->t = std::max(best, enter);
      hit->normal = best_normal;
      return true;
    }
    const int axis = next[0] < next[1] ? 0 : 1;
    if (next[axis] > leave) return false;
    cell[axis] += step[axis];
    if (cell[axis] < 0 || cell[axis] > last_cell[axis]) return false;
    next[axis] += step_t[axis];
  }
}

}  // namespace tumble
