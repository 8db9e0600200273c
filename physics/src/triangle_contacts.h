// What heightfields and triangle meshes share in meeting a convex body: the face rule, convex
// edges met as segments within their wedge, and contacts gathered into one manifold per normal
// (docs/COLLISION.md, "Heightfields" and "Triangle meshes").
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "narrow_phase.h"
#include "physics/shape.h"

namespace tumble {

// The convex body, placed in the triangles' frame.
struct TriangleBody {
  TriangleBody(const Shape& shape, const Mat3& rotation, const Vec3& translation, double margin);
  const Shape& shape;
  Mat3 rotation, to_body;
  Vec3 translation;
  bool round;                     // a sphere or capsule: met by its core
  std::array<Vec3, 2> core_ends;  // its core segment's ends (both the centre for a sphere)
  int core_count;                 // 1 for a sphere, 2 for a capsule
  Aabb bounds;                    // in the triangles' frame, grown by the margin
  Aabb body_bounds;               // in its own frame, grown by the margin
  std::span<const Vec3> cores() const { return {core_ends.data(), std::size_t(core_count)}; }
};

// One thread's contacts of one body against triangles, kept from call to call so that a
// warmed-up step does not allocate.
class TriangleContacts {
 public:
  // This thread's, emptied, for a pair whose features are about `scale` m apart.
  static TriangleContacts& begin(double margin, double scale);

  // A point `on_body` touching `on_terrain`, pushed along `up` (out of the triangles). `shared`:
  // another triangle may give the same point (a vertex or edge both touch), kept once by `id`.
  void add_point(const Vec3& up, const Vec3& on_body, const Vec3& on_terrain, std::uint64_t id,
                 bool shared);
  // The face rule for a round body's core ends over triangle v (normal n).
  void round_face_points(const TriangleBody& body, const std::array<Vec3, 3>& v, const Vec3& n);
  // A body vertex x (index `index`) over triangle v, within the margin of its plane or below it.
  void vertex_face_point(const std::array<Vec3, 3>& v, const Vec3& n, const Vec3& x,
                         std::uint32_t index, bool shared);
  // Edge e of triangle v (normal n) met as a segment; `neighbour_normal` null on a boundary.
  // `edge_key` numbers the edge among the terrain's. Returns the collision flags.
  std::uint32_t edge(const TriangleBody& body, const std::array<Vec3, 3>& v, const Vec3& n, int e,
                     const Vec3* neighbour_normal, std::uint64_t edge_key,
                     const CollisionSettings& settings);
  // After every face: whether a round body's core needs the gentle edges (edges convex but too
  // gentle to be active): a core end that no face held (its foot inside no triangle within the
  // margin). Where a face holds each end, a capsule lying across a gentle ridge sinks into it by
  // up to half its length times the turn, as a box does (docs/COLLISION.md).
  bool wants_gentle_edges(const TriangleBody& body) const {
    return body.round && !(core_held_[0] && (body.core_count == 1 || core_held_[1]));
  }
  // Then each gentle edge e of triangle v (normal n): a point for a core end no face held, where
  // it lies in the wedge between the two triangles' normals, beyond both feet.
  void gentle_edge(const TriangleBody& body, const std::array<Vec3, 3>& v, const Vec3& n, int e,
                   const Vec3& neighbour_normal, std::uint64_t edge_key);
  // The manifolds, normals from the body into the triangles.
  void finish(TerrainContacts* out);

 private:
  struct Cluster {
    Vec3 up;
    std::vector<ContactPoint> points;
  };
  std::array<Cluster, kMaxTerrainManifolds> clusters_;
  int count_ = 0;
  std::array<bool, 2> core_held_{};  // whether a face held each core end
  double margin_ = 0;
  double scale_ = 1;
  Cluster& cluster_for(const Vec3& up);
};

// Whether the point's foot on the triangle's plane lies inside it (edges included).
bool inside_triangle(const std::array<Vec3, 3>& v, const Vec3& n, const Vec3& p);

inline Vec3 normal_of(const std::array<Vec3, 3>& v) {
  return (v[1] - v[0]).cross(v[2] - v[0]).normalized();
}

// A triangle's own points are told apart from another's by mixing in its index.
inline std::uint64_t terrain_feature(std::size_t triangle, std::uint64_t id) {
  return id ^ ((static_cast<std::uint64_t>(triangle) + 1) * 0x9E3779B97F4A7C15ull);
}

}  // namespace tumble
