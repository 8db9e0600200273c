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
#include "wide.h"

namespace tumble {
namespace {

// A child's bounds, four lanes, as doubles (exactly: every float is a double).
TUMBLE_INLINE Wide lanes_of(const std::array<float, 4>& bound) {
  return Wide{bound[0], bound[1], bound[2], bound[3]};
}

}  // namespace

// The four children's slabs are met at once, each lane the scalar slab test's arithmetic in
// double (the same entry distances, so the same walk and hit on any machine).
TUMBLE_PER_CPU
bool ray_mesh(const TriangleMesh& mesh, const Vec3& origin, const Vec3& direction, double max_t,
              ShapeRayHit* hit) {
  const Vec3 inverse = direction.cwiseInverse();
  const Wide from[3] = {wide(origin.x()), wide(origin.y()), wide(origin.z())};
  const Wide scale[3] = {wide(inverse.x()), wide(inverse.y()), wide(inverse.z())};
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
    // Where the ray enters each child's box within [0, best]; a direction of 0 gives (±inf,
    // ±inf) outside the slab and NaN on its plane, which compares false, keeping the ray.
    Wide enter = wide(0), leave = wide(best);
    for (int axis = 0; axis < 3; ++axis) {
      const Wide low = (lanes_of(node.min[axis]) - from[axis]) * scale[axis];
      const Wide high = (lanes_of(node.max[axis]) - from[axis]) * scale[axis];
      const WideMask swapped = low > high;
      const Wide near = select(swapped, high, low), far = select(swapped, low, high);
      enter = select(near > enter, near, enter);
      leave = select(far < leave, far, leave);
    }
    const WideMask met = enter <= leave;
    // The children met, farthest first onto the stack (an insertion sort of at most four).
    std::array<int, 4> lanes;
    std::array<double, 4> enters;
    int met_count = 0;
    for (int k = 0; k < 4; ++k) {
      if (!met[k] || node.count[k] == TriangleMesh::kNoChild) continue;
      int slot = met_count++;
      for (; slot > 0 && enters[slot - 1] < enter[k]; --slot) {
        enters[slot] = enters[slot - 1];
        lanes[slot] = lanes[slot - 1];
      }
      enters[slot] = enter[k];
      lanes[slot] = k;
    }
    for (int slot = 0; slot < met_count; ++slot)
      stack[size++] = {node.first[lanes[slot]], node.count[lanes[slot]]};
  }
  if (best_triangle < 0) return false;
  hit->t = best;
  hit->normal = mesh.normal(static_cast<std::size_t>(best_triangle));
  return true;
}

}  // namespace tumble
