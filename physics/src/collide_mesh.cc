// Convex bodies against a triangle mesh: the triangles the mesh's tree finds under the body's
// bounds, met by the rules of triangle_contacts.cc. Unlike a heightfield's, a mesh's triangles
// are surfaces with a front, not the top of a solid, so a triangle holds only a body whose centre
// is in front of it (one-sided, as Jolt's and Bullet's meshes are by default), and a body vertex
// counts for a triangle only where the line from the centre to it crosses the triangle: a box
// hanging over a mesh cube's top edge then meets the top, not the side its lower corners lie
// behind. And where that line crosses several triangles that do not make a concave corner (both
// slopes of a ridge, two faces of gently curved terrain), the vertex counts for the one it
// crosses first only: as on a heightfield, where a vertex is over one triangle, a body resting
// across an edge gets one manifold and not two of almost the same normal.
#include <algorithm>
#include <bit>
#include <cmath>
#include <span>
#include <vector>

#include "manifold.h"
#include "narrow_phase.h"
#include "physics/triangle_mesh.h"
#include "triangle_contacts.h"

namespace tumble {
namespace {

// A triangle whose face may hold the body's vertices.
struct FrontFace {
  std::array<Vec3, 3> v;
  Vec3 n;
  double centre_height;  // of the body's centre over the plane, > 0
  // n x (v[e+1] - v[e]): pointing into the triangle from edge e, and the tolerance of
  // inside_triangle (triangle_contacts.h): worked out once for the several vertices tested.
  std::array<Vec3, 3> inwards;
  double tolerance;

  FrontFace(const std::array<Vec3, 3>& v, const Vec3& n, double centre_height)
      : v(v), n(n), centre_height(centre_height) {
    for (int e = 0; e < 3; ++e)
      inwards[e] = n.cross(v[(e + 1) % 3] - v[e]);
    tolerance = -1e-12 * (v[1] - v[0]).cross(v[2] - v[0]).dot(n);
  }
  // inside_triangle's test, the triple products taken in another order. All three are taken
  // (no early return): which side of which edge a vertex falls is a coin the branch predictor
  // loses about one time in three.
  bool holds(const Vec3& p) const {
    bool inside = true;
    for (int e = 0; e < 3; ++e)
      inside &= !((p - v[e]).dot(inwards[e]) < tolerance);
    return inside;
  }
};

// A face a vertex counts for, and where the line from the body's centre to the vertex crosses
// the face's plane: a fraction of the way (past 1 for a vertex in front of the plane).
struct Crossing {
  const FrontFace* face;
  double at;
};

struct MeshScratch {
  std::vector<TriangleMesh::LeafTriangle> triangles;
  std::vector<Vec3> vertices;  // the body's, in the mesh's frame
  std::vector<FrontFace> faces;
  std::vector<Crossing> crossings;
  // A vertex's faces within the margin (or below), in the faces' order, and its heights over them.
  std::vector<std::uint32_t> near_faces;
  std::vector<double> near_heights;
};

// a where `first`, else b: both already worked out, chosen bit for bit without a branch (which
// of the two a vertex takes is as unpredictable as whether it is below the face).
Vec3 select(bool first, const Vec3& a, const Vec3& b) {
  const std::uint64_t mask = 0 - static_cast<std::uint64_t>(first);
  Vec3 out;
  for (int k = 0; k < 3; ++k) {
    const std::uint64_t chosen =
        (std::bit_cast<std::uint64_t>(a[k]) & mask) | (std::bit_cast<std::uint64_t>(b[k]) & ~mask);
    out[k] = std::bit_cast<double>(chosen);
  }
  return out;
}

// Whether triangles a and b make a concave corner: some corner of b clearly in front of a's plane.
bool concave(const FrontFace& a, const FrontFace& b) {
  const double flat = 1e-9 * (a.v[1] - a.v[0]).norm();
  for (const Vec3& q : b.v)
    if ((q - a.v[0]).dot(a.n) > flat) return true;
  return false;
}

MeshScratch& mesh_scratch() {
  thread_local MeshScratch scratch;
  return scratch;
}

}  // namespace

std::uint32_t collide_mesh(const Shape& a, const Mat3& rotation, const Vec3& translation,
                           const TriangleMesh& mesh, const CollisionSettings& settings,
                           TerrainContacts* out) {
  out->count = 0;
  const double margin = settings.margin;
  const TriangleBody body(a, rotation, translation, margin);
  MeshScratch& s = mesh_scratch();
  std::uint32_t flags = kCollisionOk;
  if (!mesh.triangles_meeting(body.bounds, &s.triangles, kMaxTerrainTriangles))
    flags |= kTerrainCellLimit;
  if (s.triangles.empty()) return flags;
  TriangleContacts& contacts =
      TriangleContacts::begin(margin, std::max(a.size(), mesh.feature_size()));
  if (!body.round) {
    const auto& vertices = a.polyhedron()->vertices;
    s.vertices.resize(vertices.size());
    for (std::size_t k = 0; k < vertices.size(); ++k)
      s.vertices[k] = rotation * vertices[k] + translation;
  }
  s.faces.clear();
  const Vec3 centre = 0.5 * (body.bounds.min + body.bounds.max);
  const Vec3 half = 0.5 * body.bounds.extent();
  const auto in_front = [&](const std::array<Vec3, 3>& v, const Vec3& n) {
    return (translation - v[0]).dot(n) > 0;
  };

  const std::vector<Vec3>& corners = mesh.def().vertices;
  for (const TriangleMesh::LeafTriangle& leaf : s.triangles) {
    const std::uint32_t t = leaf.triangle;
    const std::array<Vec3, 3> v{corners[leaf.corners[0]], corners[leaf.corners[1]],
                                corners[leaf.corners[2]]};
    const Vec3 n = mesh.normal(t);
    // Wholly more than the margin in front of the plane (its bounds, grown by the margin, are),
    // the body touches neither the face nor its edges; wholly behind, neither either.
    const double middle = (centre - v[0]).dot(n), reach = half.dot(n.cwiseAbs());
    if (middle - reach > 0 || middle + reach < 0) continue;
    const bool front = in_front(v, n);
    if (front && body.round) {
      contacts.round_face_points(body, v, n);
    } else if (front) {
      s.faces.emplace_back(v, n, (translation - v[0]).dot(n));
    }
    const std::uint8_t active = mesh.active_edges(t);
    for (int e = 0; e < 3; ++e) {
      const std::int64_t other = mesh.neighbour(t, e);
      if ((active & (1u << e)) == 0 || (other >= 0 && static_cast<std::uint32_t>(other) < t))
        continue;
      Vec3 other_normal;
      if (other >= 0) {
        const auto o = static_cast<std::size_t>(other);
        other_normal = mesh.normal(o);
        // A body behind both sides is inside the solid the two make: the edge does not hold it.
        if (!front && !in_front(mesh.triangle(o), other_normal)) continue;
      }
      flags |= contacts.edge(body, v, n, e, other >= 0 ? &other_normal : nullptr,
                             3 * std::uint64_t{t} + e, settings);
    }
  }
  // Vertex by vertex, as on a plane and a heightfield, so that a body on a flat floor gets its
  // points in the order the plane gives them. Whether a vertex is within the margin of a face
  // (about a third of the faces gathered are) and whether its point falls inside (a quarter of
  // those) follow no pattern a branch predictor learns: each list here (the faces a vertex is
  // near, the faces it crosses) is written at every candidate and moved on only past those that
  // pass, without a branch.
  s.near_faces.resize(s.faces.size() + 1);
  s.near_heights.resize(s.faces.size() + 1);
  s.crossings.resize(s.faces.size() + 1);
  for (std::uint32_t index = 0; index < s.vertices.size(); ++index) {
    const Vec3& x = s.vertices[index];
    std::size_t near = 0;
    for (std::uint32_t f = 0; f < s.faces.size(); ++f) {
      const double height = (x - s.faces[f].v[0]).dot(s.faces[f].n);
      s.near_faces[near] = f;
      s.near_heights[near] = height;
      near += !(height > margin);
    }
    std::size_t crossed = 0;
    bool within_margin = false;
    for (std::size_t k = 0; k < near; ++k) {
      const FrontFace& face = s.faces[s.near_faces[k]];
      const double height = s.near_heights[k];
      within_margin |= height >= 0;
      // Below the plane: where the line from the centre crosses it; within the margin above it,
      // the foot.
      const double at = face.centre_height / (face.centre_height - height);
      const Vec3 point =
          select(height < 0, Vec3(translation + (x - translation) * at), Vec3(x - height * face.n));
      s.crossings[crossed] = {&face, at};
      crossed += face.holds(point);
    }
    if (crossed == 0 && within_margin) {
      // The feet of a surface's triangles leave gaps: over a convex edge too gentle to be active
      // a vertex above both planes can lie beyond both feet (in the wedge between the normals, as
      // wide as its height times their turn). A box falling at 11 m/s onto the hills met neither
      // triangle and sank 10 cm into the mesh where the heightfield, one triangle under each
      // vertex, held it. Such a vertex counts where the line from the centre through it, carried
      // on, crosses a plane: along that line the triangles leave no gap. (Only then: beyond the
      // vertex the line can leave the triangles the body's bounds gathered, and where a foot
      // falls inside, the points stay as they were.)
      for (std::size_t k = 0; k < near; ++k) {
        const FrontFace& face = s.faces[s.near_faces[k]];
        const double height = s.near_heights[k];
        if (height < 0 || !(face.centre_height > height)) continue;
        const double at = face.centre_height / (face.centre_height - height);
        if (face.holds(translation + (x - translation) * at)) s.crossings[crossed++] = {&face, at};
      }
    }
    const std::span<const Crossing> crossings(s.crossings.data(), crossed);
    for (const Crossing& c : crossings) {
      const bool entered_elsewhere =
          std::any_of(crossings.begin(), crossings.end(), [&](const Crossing& d) {
            return (d.at < c.at || (d.at == c.at && d.face < c.face)) && !concave(*c.face, *d.face);
          });
      if (!entered_elsewhere) contacts.vertex_face_point(c.face->v, c.face->n, x, index, true);
    }
  }
  if (contacts.wants_gentle_edges(body)) {
    // A round core over a gentle ridge can lie beyond both triangles' feet (triangle_contacts.h).
    for (const TriangleMesh::LeafTriangle& leaf : s.triangles) {
      const std::uint32_t t = leaf.triangle;
      const std::uint8_t gentle = mesh.gentle_edges(t);
      if (gentle == 0) continue;
      const std::array<Vec3, 3> v = mesh.triangle(t);
      const Vec3 n = mesh.normal(t);
      for (int e = 0; e < 3; ++e) {
        const auto other = static_cast<std::size_t>(mesh.neighbour(t, e));
        if ((gentle & (1u << e)) == 0 || other < t) continue;
        if (!in_front(v, n) && !in_front(mesh.triangle(other), mesh.normal(other))) continue;
        contacts.gentle_edge(body, v, n, e, mesh.normal(other), 3 * std::uint64_t{t} + e);
      }
    }
  }
  contacts.finish(out);
  return flags;
}

std::uint32_t collide_terrain(const Shape& a, const Pose& pose_a, const Shape& b,
                              const Pose& pose_b, const CollisionSettings& settings,
                              TerrainContacts* out) {
  out->count = 0;
  if (is_static_only(a.type()) && is_static_only(b.type())) return kCollisionOk;
  const bool b_is_terrain = is_terrain(b.type());
  const Shape& body = b_is_terrain ? a : b;
  const Shape& terrain = b_is_terrain ? b : a;
  const Pose& body_pose = b_is_terrain ? pose_a : pose_b;
  const Pose& terrain_pose = b_is_terrain ? pose_b : pose_a;
  const Mat3 terrain_rotation = terrain_pose.orientation.toRotationMatrix();
  const Mat3 rotation = terrain_rotation.transpose() * body_pose.orientation.toRotationMatrix();
  const Vec3 translation =
      terrain_rotation.transpose() * (body_pose.position - terrain_pose.position);
  const std::uint32_t flags =
      terrain.type() == ShapeType::kMesh
          ? collide_mesh(body, rotation, translation, *terrain.mesh(), settings, out)
          : collide_height_field(body, rotation, translation, *terrain.height_field(), settings,
                                 out);
  for (int c = 0; c < out->count; ++c) {
    ContactManifold& m = out->manifolds[c];
    manifold_to_world(terrain_rotation, terrain_pose.position, &m);
    if (b_is_terrain) continue;
    m.normal = -m.normal;
    for (int i = 0; i < m.count; ++i)
      std::swap(m.points[i].point_a, m.points[i].point_b);
  }
  return flags;
}

}  // namespace tumble
