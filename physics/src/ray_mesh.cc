// A ray against a triangle mesh: the mesh's tree walked nearer children first, pruned by the
// closest hit so far, each triangle met by Möller and Trumbore's test (1997). Triangles are
// one-sided, as the mesh's contacts are: a ray meets a triangle's front only (Jolt's default,
// EBackFaceMode::IgnoreBackFaces), so a camera inside a closed room sees its walls and a ray
// leaving a mesh's inside passes out.
#include <algorithm>
#include <cmath>
#include <limits>

#include "physics/triangle_mesh.h"
#include "ray_shape.h"
#include "wide_slabs.h"

namespace tumble {
namespace {

// A child's bounds, four lanes, as doubles (exactly: every float is a double).
TUMBLE_INLINE Wide lanes_of(const std::array<float, 4>& bound) {
  return Wide{bound[0], bound[1], bound[2], bound[3]};
}

}  // namespace

// The four children's slabs are met at once, in double (wide_slabs.h).
TUMBLE_PER_CPU
bool ray_mesh(const TriangleMesh& mesh, const Vec3& origin, const Vec3& direction, double max_t,
              ShapeRayHit* hit) {
  const Vec3 inverse = direction.cwiseInverse();
  const WideRay ray = wide_ray(origin, inverse);
  const auto& nodes = mesh.nodes();
  const std::vector<Vec3>& vertices = mesh.def().vertices;
  double best = max_t;
  std::int64_t best_triangle = -1;
  // A node (count 0) or a leaf's triangles, nearer children popped first.
  struct Pending {
    std::uint32_t first, count;
  };
  std::array<Pending, 4 * TriangleMesh::kMaxDepth> stack;
  int size = 0;
  stack[size++] = {0, 0};
  while (size > 0) {
    const Pending pending = stack[--size];
    if (pending.count != 0) {
      for (std::uint32_t k = pending.first; k < pending.first + pending.count; ++k) {
        const TriangleMesh::LeafTriangle& leaf = mesh.leaf_triangle(k);
        double at;
        if (ray_triangle_front(
                {vertices[leaf.corners[0]], vertices[leaf.corners[1]], vertices[leaf.corners[2]]},
                origin, direction, &at) &&
            at <= best && (at < best || best_triangle < 0 || leaf.triangle < best_triangle)) {
          best = at;
          best_triangle = leaf.triangle;
        }
      }
      continue;
    }
    const TriangleMesh::Node& node = nodes[pending.first];
    WideMask reached;
    const Wide enter = enter_boxes(
        ray, {lanes_of(node.min[0]), lanes_of(node.min[1]), lanes_of(node.min[2])},
        {lanes_of(node.max[0]), lanes_of(node.max[1]), lanes_of(node.max[2])}, best, &reached);
    farthest_first(
        reached, enter, [&](int k) { return node.count[k] != TriangleMesh::kNoChild; },
        [&](int k) {
          stack[size++] = {node.first[k], node.count[k]};
        });
  }
  if (best_triangle < 0) return false;
  hit->t = best;
  hit->normal = mesh.normal(static_cast<std::size_t>(best_triangle));
  return true;
}

}  // namespace tumble
