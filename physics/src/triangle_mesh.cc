#include "physics/triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "four_wide_tree.h"

namespace tumble {
namespace {

float round_down(double x) {
  const float f = static_cast<float>(x);
  return f > x ? std::nextafter(f, -HUGE_VALF) : f;
}
float round_up(double x) {
  const float f = static_cast<float>(x);
  return f < x ? std::nextafter(f, HUGE_VALF) : f;
}

constexpr std::uint32_t kLeafTriangles = 4;

}  // namespace

Result<TriangleMesh> TriangleMesh::create(const TriangleMeshDef& def) {
  if (def.vertices.size() > kMaxMeshVertices)
    return Status::error("vertices: " + std::to_string(def.vertices.size()) + ", more than the " +
                         std::to_string(kMaxMeshVertices) + " a mesh may have");
  if (def.triangles.empty()) return Status::error("triangles: a mesh needs at least one");
  if (def.triangles.size() > kMaxMeshTriangles)
    return Status::error("triangles: " + std::to_string(def.triangles.size()) + ", more than the " +
                         std::to_string(kMaxMeshTriangles) + " a mesh may have");
  for (std::size_t k = 0; k < def.vertices.size(); ++k)
    if (!def.vertices[k].allFinite() ||
        !(def.vertices[k].cwiseAbs().maxCoeff() <= kMaxMeshCoordinate))
      return Status::error("vertices[" + std::to_string(k) + "]: must be finite, within 1e6 m");
  TriangleMesh mesh;
  double longest_edge = 0;
  for (std::size_t t = 0; t < def.triangles.size(); ++t) {
    for (std::uint32_t index : def.triangles[t])
      if (index >= def.vertices.size())
        return Status::error("triangles[" + std::to_string(t) + "]: vertex " +
                             std::to_string(index) + " of " + std::to_string(def.vertices.size()));
    const auto& [a, b, c] = def.triangles[t];
    const Vec3 &p = def.vertices[a], &q = def.vertices[b], &r = def.vertices[c];
    const double longest =
        std::max({(q - p).squaredNorm(), (r - q).squaredNorm(), (p - r).squaredNorm()});
    if (!((q - p).cross(r - p).norm() > 1e-12 * longest))
      return Status::error("triangles[" + std::to_string(t) +
                           "]: degenerate (its corners are repeated or in a line)");
    longest_edge = std::max(longest_edge, std::sqrt(longest));
  }
  mesh.def_ = def;
  mesh.feature_size_ = longest_edge;
  mesh.normals_.resize(def.triangles.size());
  for (std::size_t t = 0; t < def.triangles.size(); ++t) {
    const std::array<Vec3, 3> v = mesh.triangle(t);
    mesh.normals_[t] = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
  }
  for (const auto& triangle : def.triangles)
    for (std::uint32_t index : triangle)
      mesh.bounds_.grow(def.vertices[index]);
  mesh.build_adjacency();
  mesh.build_tree();
  return mesh;
}

void TriangleMesh::build_adjacency() {
  // Every edge keyed by its lower and higher vertex; equal keys sort together.
  struct EdgeUse {
    std::uint64_t key;
    std::uint32_t triangle;
    std::uint8_t edge;
  };
  const std::size_t count = triangle_count();
  std::vector<EdgeUse> uses;
  uses.reserve(3 * count);
  for (std::size_t t = 0; t < count; ++t) {
    for (int e = 0; e < 3; ++e) {
      const std::uint64_t a = def_.triangles[t][e], b = def_.triangles[t][(e + 1) % 3];
      uses.push_back({std::min(a, b) << 32 | std::max(a, b), static_cast<std::uint32_t>(t),
                      static_cast<std::uint8_t>(e)});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.triangle < y.triangle;
  });
  neighbours_.assign(3 * count, -1);
  for (std::size_t k = 0; k < uses.size();) {
    std::size_t end = k + 1;
    while (end < uses.size() && uses[end].key == uses[k].key)
      ++end;
    // Two triangles winding the edge in opposite directions: their fronts agree, and the edge
    // joins them. Anything else (three sheets on one edge, a flipped neighbour) is a boundary.
    if (end - k == 2) {
      const EdgeUse& x = uses[k];
      const EdgeUse& y = uses[k + 1];
      if (def_.triangles[x.triangle][x.edge] == def_.triangles[y.triangle][(y.edge + 1) % 3]) {
        neighbours_[3 * x.triangle + x.edge] = static_cast<std::int32_t>(y.triangle);
        neighbours_[3 * y.triangle + y.edge] = static_cast<std::int32_t>(x.triangle);
      }
    }
    k = end;
  }
  // Convex edges are active, as on a heightfield (height_field.cc): the neighbour's far corner
  // clearly behind this triangle's plane and the two turning by more than kSmoothEdgeAngle; the
  // convex ones that turn less are gentle (round bodies meet them in their wedge alone).
  const double smooth = std::cos(kSmoothEdgeAngle);
  edge_bits_.assign(count, 0);
  for (std::size_t t = 0; t < count; ++t) {
    const std::array<Vec3, 3> v = triangle(t);
    const Vec3 n = normal(t);
    const double flat =
        1e-9 * std::sqrt(std::max({(v[1] - v[0]).squaredNorm(), (v[2] - v[1]).squaredNorm(),
                                   (v[0] - v[2]).squaredNorm()}));
    std::uint8_t bits = 0;
    for (int e = 0; e < 3; ++e) {
      const std::int64_t other = neighbour(t, e);
      if (other < 0) {
        bits |= 1u << e;
        continue;
      }
      const std::array<Vec3, 3> w = triangle(static_cast<std::size_t>(other));
      double behind = 0;
      for (const Vec3& q : w)
        behind = std::min(behind, (q - v[0]).dot(n));
      if (behind < -flat)
        bits |= normal(static_cast<std::size_t>(other)).dot(n) < smooth ? 1u << e : 8u << e;
    }
    edge_bits_[t] = bits;
  }
}

void TriangleMesh::build_tree() {
  const std::size_t count = triangle_count();
  std::vector<std::uint32_t> order(count);
  std::vector<Vec3> centres(count);
  for (std::size_t t = 0; t < count; ++t) {
    order[t] = static_cast<std::uint32_t>(t);
    const std::array<Vec3, 3> v = triangle(t);
    centres[t] = (v[0] + v[1] + v[2]) / 3;
  }
  // First a binary tree: each node's bounds and either two children (count 0: at first and
  // first + 1) or `count` triangles of `order` from first.
  struct BinaryNode {
    std::array<float, 3> min, max;
    std::uint32_t first = 0, count = 0;
  };
  std::vector<BinaryNode> binary;
  binary.reserve(2 * (count / kLeafTriangles + 1));
  binary.push_back({});
  // Each entry: a node to fill from `order`[first, first + count). Splitting at the median keeps
  // the tree balanced, so its depth is bounded by the logarithm of the triangle count.
  struct Task {
    std::uint32_t node, first, count;
  };
  std::vector<Task> tasks{{0, 0, static_cast<std::uint32_t>(count)}};
  while (!tasks.empty()) {
    const Task task = tasks.back();
    tasks.pop_back();
    Aabb box, centre_box;
    for (std::uint32_t k = task.first; k < task.first + task.count; ++k) {
      const auto& triangle = def_.triangles[order[k]];
      for (std::uint32_t index : triangle)
        box.grow(def_.vertices[index]);
      centre_box.grow(centres[order[k]]);
    }
    BinaryNode& node = binary[task.node];
    for (int k = 0; k < 3; ++k) {
      node.min[k] = round_down(box.min[k]);
      node.max[k] = round_up(box.max[k]);
    }
    if (task.count <= kLeafTriangles) {
      node.first = task.first;
      node.count = task.count;
      continue;
    }
    int axis = 0;
    centre_box.extent().maxCoeff(&axis);
    const std::uint32_t half = task.count / 2;
    std::nth_element(
        order.begin() + task.first, order.begin() + task.first + half,
        order.begin() + task.first + task.count, [&](std::uint32_t x, std::uint32_t y) {
          return centres[x][axis] != centres[y][axis] ? centres[x][axis] < centres[y][axis] : x < y;
        });
    const auto left = static_cast<std::uint32_t>(binary.size());
    node.first = left;
    node.count = 0;
    binary.push_back({});
    binary.push_back({});
    tasks.push_back({left, task.first, half});
    tasks.push_back({left + 1, task.first + half, task.count - half});
  }
  // Then read as four children a node (four_wide_tree.h).
  nodes_.clear();
  nodes_.reserve(binary.size() / 3 + 1);
  std::vector<std::array<std::uint32_t, 2>> pending;
  collapse_to_four_wide([&](std::uint32_t b) { return binary[b].count != 0; },
                        [&](std::uint32_t b) {
                          return std::array<std::uint32_t, 2>{binary[b].first, binary[b].first + 1};
                        },
                        [&] {
                          nodes_.push_back({});
                          return static_cast<std::uint32_t>(nodes_.size() - 1);
                        },
                        [&](std::uint32_t at, int k, std::uint32_t b, std::uint32_t wide) {
                          Node& node = nodes_[at];
                          if (b == kNoBinaryNode) {
                            // Empty bounds (min above max) meet no box and no ray.
                            for (int axis = 0; axis < 3; ++axis) {
                              node.min[axis][k] = HUGE_VALF;
                              node.max[axis][k] = -HUGE_VALF;
                            }
                            node.first[k] = 0;
                            node.count[k] = kNoChild;
                            return;
                          }
                          const BinaryNode& child = binary[b];
                          for (int axis = 0; axis < 3; ++axis) {
                            node.min[axis][k] = child.min[axis];
                            node.max[axis][k] = child.max[axis];
                          }
                          node.count[k] = static_cast<std::uint8_t>(child.count);
                          node.first[k] = child.count == 0 ? wide : child.first;
                        },
                        &pending);
  leaf_triangles_.resize(count);
  for (std::size_t k = 0; k < count; ++k)
    leaf_triangles_[k] = {order[k], def_.triangles[order[k]]};
}

TriangleMeshDef mesh_of_height_field(const HeightField& field) {
  TriangleMeshDef mesh;
  const HeightFieldDef& def = field.def();
  mesh.vertices.reserve(std::size_t{def.samples_x} * def.samples_y);
  for (std::uint32_t j = 0; j < def.samples_y; ++j)
    for (std::uint32_t i = 0; i < def.samples_x; ++i)
      mesh.vertices.push_back(field.sample(i, j));
  mesh.triangles.reserve(field.triangle_count());
  const auto at = [&](std::uint32_t i, std::uint32_t j) { return j * def.samples_x + i; };
  for (std::uint32_t j = 0; j < field.cells_y(); ++j) {
    for (std::uint32_t i = 0; i < field.cells_x(); ++i) {
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return mesh;
}

bool TriangleMesh::triangles_meeting(const Aabb& box, std::vector<LeafTriangle>* out,
                                     std::size_t limit) const {
  out->clear();
  // The box rounded outwards to floats: a node's float bound meets the double one exactly where
  // it meets the rounded one, so the four children are tested in one float vector an axis.
  using Float4 = float __attribute__((vector_size(16)));
  std::array<Float4, 3> low, high;
  for (int axis = 0; axis < 3; ++axis) {
    const float lo = round_up(box.min[axis]), hi = round_down(box.max[axis]);
    low[axis] = Float4{lo, lo, lo, lo};
    high[axis] = Float4{hi, hi, hi, hi};
  }
  const auto lanes = [](const std::array<float, 4>& bounds) {
    Float4 v;
    std::memcpy(&v, bounds.data(), sizeof v);
    return v;
  };
  // Children (nodes and leaves) pushed in order and popped last first: the order in which the
  // binary tree of old was walked (it popped a node's second child first), so the contacts meet
  // the triangles in the same order as before.
  struct Pending {
    std::uint32_t first, count;
  };
  std::array<Pending, 4 * kMaxDepth> stack;
  int size = 0;
  stack[size++] = {0, 0};
  while (size > 0) {
    const Pending pending = stack[--size];
    if (pending.count != 0) {
      for (std::uint32_t k = pending.first; k < pending.first + pending.count; ++k) {
        if (out->size() == limit) return false;
        out->push_back(leaf_triangles_[k]);
      }
      continue;
    }
    // Every child written and the stack moved on only past those the box meets: which of four
    // children a box meets is a pattern the branch predictor does not learn.
    const Node& node = nodes_[pending.first];
    const auto meets = (lanes(node.min[0]) <= high[0]) & (low[0] <= lanes(node.max[0])) &
                       (lanes(node.min[1]) <= high[1]) & (low[1] <= lanes(node.max[1])) &
                       (lanes(node.min[2]) <= high[2]) & (low[2] <= lanes(node.max[2]));
    for (int k = 0; k < 4; ++k) {
      stack[size] = {node.first[k], node.count[k]};
      size += (meets[k] != 0) & (node.count[k] != kNoChild);
    }
  }
  return true;
}

}  // namespace tumble
