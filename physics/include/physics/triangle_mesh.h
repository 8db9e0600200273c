// A triangle mesh: static geometry (a room, a floor, a terrain from a modelling tool) given as
// vertices and triangles. Static only.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "physics/height_field.h"  // kSmoothEdgeAngle
#include "physics/math.h"
#include "physics/status.h"

namespace tumble {

// vertices: m, finite, each coordinate within kMaxMeshCoordinate; triangles: indices into
// vertices, counter-clockwise seen from the side bodies are pushed out to (the triangle's
// front). A triangle whose corners are repeated or in a line (its area below 1e-12 of its longest
// edge squared) is refused: it has no normal. Open meshes (a floor, a ramp) are fine; an edge that
// is not shared by exactly two triangles winding it in opposite directions is a boundary edge.
// At most kMaxMeshVertices and kMaxMeshTriangles (each step's contact search and every query walk
// the mesh's tree, and a snapshot carries every vertex).
inline constexpr std::size_t kMaxMeshVertices = std::size_t{1} << 21;   // 2,097,152
inline constexpr std::size_t kMaxMeshTriangles = std::size_t{1} << 21;  // 2,097,152
inline constexpr double kMaxMeshCoordinate = 1e6;
struct TriangleMeshDef {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

// The built mesh, immutable and shared by the shapes made of it: the triangles' adjacency, which
// edges are convex, and a bounding-volume tree over the triangles.
class TriangleMesh {
 public:
  // The message names the bad field ("triangles[17]: degenerate ...").
  static Result<TriangleMesh> create(const TriangleMeshDef& def);

  const TriangleMeshDef& def() const { return def_; }
  std::size_t triangle_count() const { return def_.triangles.size(); }
  std::array<Vec3, 3> triangle(std::size_t t) const {
    const auto& [a, b, c] = def_.triangles[t];
    return {def_.vertices[a], def_.vertices[b], def_.vertices[c]};
  }
  // Unit, out of the front; worked out once when the mesh is made (24 bytes a triangle), as the
  // contacts of every body on the mesh ask for it several times a step.
  const Vec3& normal(std::size_t t) const { return normals_[t]; }
  // Bit e set: the edge from vertex e to vertex e+1 is convex (the neighbour across it turns
  // away behind the triangle's plane by more than kSmoothEdgeAngle) or a boundary edge. Only such
  // edges may give a contact a normal other than a face's (docs/COLLISION.md, "Triangle meshes").
  std::uint8_t active_edges(std::size_t t) const { return edge_bits_[t] & 7u; }
  // Bit e set: that edge is convex but turns by no more than kSmoothEdgeAngle (not active): a
  // sphere's or capsule's core can lie beyond both its triangles' feet, where only the edge holds
  // it (docs/COLLISION.md).
  std::uint8_t gentle_edges(std::size_t t) const { return edge_bits_[t] >> 3; }
  // The triangle across edge e of t, or -1 on a boundary edge.
  std::int64_t neighbour(std::size_t t, int e) const { return neighbours_[3 * t + e]; }
  Aabb bounds() const { return bounds_; }
  // The longest edge of any triangle, m: the size of the mesh's features.
  double feature_size() const { return feature_size_; }

  // The tree: four children a node, each child's bounds in the node (single precision, rounded
  // outwards), by axis and then child, so that a ray or a box meets all four at once and walks
  // half the levels of a binary tree (Wald, Benthin and Boulos 2008, "Getting rid of packets";
  // Embree's BVH4). A child is a node (count 0: `first` indexes nodes()), a leaf of `count`
  // triangles of leaf_triangle() from `first`, or none (kNoChild: its bounds are empty).
  static constexpr std::uint8_t kNoChild = 255;
  struct alignas(64) Node {
    std::array<std::array<float, 4>, 3> min, max;
    std::array<std::uint32_t, 4> first;
    std::array<std::uint8_t, 4> count;
  };
  const std::vector<Node>& nodes() const { return nodes_; }
  // The triangles in the leaves' order, each with its corners' indices beside it: a ray's walk
  // reads a leaf's triangles from one place rather than through two lookups (12 bytes a
  // triangle; 1.1x the rays a second on the terrain of docs/PERFORMANCE.md).
  struct LeafTriangle {
    std::uint32_t triangle;
    std::array<std::uint32_t, 3> corners;
  };
  const LeafTriangle& leaf_triangle(std::size_t k) const { return leaf_triangles_[k]; }
  // The triangles whose bounds meet `box`, appended to `out` (cleared first), at most `limit` of
  // them; false when more were there. Each comes with its corners as the leaves hold them: the
  // contacts' loop over a body's triangles reads them from these records rather than fetching
  // each triangle's indices again from wherever its number puts them.
  bool triangles_meeting(const Aabb& box, std::vector<LeafTriangle>* out, std::size_t limit) const;
  // Deep enough for any tree create() builds (it splits at the median: the binary tree it is
  // made of is at most log2 of the triangle count + 1 deep, and this one half as deep).
  static constexpr int kMaxDepth = 48;

 private:
  TriangleMeshDef def_;
  std::vector<Vec3> normals_;
  std::vector<std::int32_t> neighbours_;
  std::vector<std::uint8_t> edge_bits_;  // active edges in bits 0-2, gentle ones in bits 3-5
  std::vector<Node> nodes_;
  std::vector<LeafTriangle> leaf_triangles_;
  Aabb bounds_;
  double feature_size_ = 0;
  void build_adjacency();
  void build_tree();
};

// The heightfield's surface as a mesh of the same triangles (the same vertex order and split), for
// terrain authored as a grid but wanted as a mesh, and for comparing the two.
TriangleMeshDef mesh_of_height_field(const HeightField& field);

}  // namespace tumble
