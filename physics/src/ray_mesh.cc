// A ray against a triangle mesh: the mesh's tree walked nearer child first, pruned by the closest
// hit so far, each triangle met by Möller and Trumbore's test (1997). Triangles are one-sided, as
// the mesh's contacts are: a ray meets a triangle's front only (Jolt's default,
// EBackFaceMode::IgnoreBackFaces), so a camera inside a closed room sees its walls and a ray
// leaving a mesh's inside passes out.
#include <algorithm>
#include <cmath>
#include <limits>

#include "physics/triangle_mesh.h"
#include "ray_shape.h"

namespace tumble {
namespace {

// Where the ray enters the node's box within [0, max_t], or infinity.
double enter_node(const TriangleMesh::Node& node, const Vec3& origin, const Vec3& inverse,
                  double max_t) {
  double enter = 0, leave = max_t;
  for (int k = 0; k < 3; ++k) {
    double near = (node.min[k] - origin[k]) * inverse[k];
    double far = (node.max[k] - origin[k]) * inverse[k];
    if (near > far) std::swap(near, far);
    // A direction of 0 gives (±inf, ±inf) outside the slab and NaN on its plane: NaN compares
    // false, keeping the ray.
    if (near > enter) enter = near;
    if (far < leave) leave = far;
  }
  return enter <= leave ? enter : std::numeric_limits<double>::infinity();
}

}  // namespace

bool ray_mesh(const TriangleMesh& mesh, const Vec3& origin, const Vec3& direction, double max_t,
              ShapeRayHit* hit) {
  const Vec3 inverse = direction.cwiseInverse();
  const auto& nodes = mesh.nodes();
  double best = max_t;
  std::int64_t best_triangle = -1;
  std::array<std::uint32_t, 2 * TriangleMesh::kMaxDepth> stack;
  int size = 0;
  if (enter_node(nodes[0], origin, inverse, best) <= best) stack[size++] = 0;
  while (size > 0) {
    const TriangleMesh::Node& node = nodes[stack[--size]];
    if (node.count == 0) {
      const double near = enter_node(nodes[node.first], origin, inverse, best);
      const double far = enter_node(nodes[node.first + 1], origin, inverse, best);
      // The nearer child is popped first.
      const bool left_first = near <= far;
      const std::uint32_t children[2] = {node.first, node.first + 1};
      const double enters[2] = {near, far};
      for (int k : {left_first ? 1 : 0, left_first ? 0 : 1})
        if (enters[k] <= best) stack[size++] = children[k];
      continue;
    }
    for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
      const std::uint32_t t = mesh.ordered_triangle(k);
      double at;
      if (ray_triangle_front(mesh.triangle(t), origin, direction, &at) && at <= best &&
          (at < best || best_triangle < 0 || t < best_triangle)) {
        best = at;
        best_triangle = t;
      }
    }
  }
  if (best_triangle < 0) return false;
  hit->t = best;
  hit->normal = mesh.normal(static_cast<std::size_t>(best_triangle));
  return true;
}

}  // namespace tumble
