// Convex hulls of point clouds through Qhull's re-entrant C library (Barber, Dobkin, Huhdanpaa,
// "The Quickhull algorithm for convex hulls", ACM TOMS 1996).
//
// Steps: (1) reject non-finite input; (2) run qhull with facet merging, so coplanar triangles come
// back as one polygonal facet and duplicate/interior points vanish; (3) order each facet's
// vertices counter-clockwise about its outward normal; (4) derive edges with their two faces;
// (5) refuse hulls with no real volume, since every later algorithm divides by it somewhere.
#include <algorithm>
#include <cstdio>
#include <limits>
#include <map>
#include <string>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include "mass_integrals.h"
#include "physics/polyhedron.h"

namespace tumble {
namespace {

// Qhull reports through a FILE*; keep its message for our error instead of printing it.
class CapturedStream {
 public:
  CapturedStream() { stream_ = open_memstream(&buffer_, &size_); }
  ~CapturedStream() {
    if (stream_) std::fclose(stream_);
    std::free(buffer_);
  }
  FILE* get() { return stream_; }
  std::string text() {
    std::fflush(stream_);
    return buffer_ ? std::string(buffer_, size_) : std::string();
  }

 private:
  FILE* stream_ = nullptr;
  char* buffer_ = nullptr;
  std::size_t size_ = 0;
};

std::string first_line(const std::string& text) {
  const auto end = text.find('\n', text.find_first_not_of(" \n"));
  std::string line = text.substr(0, end);
  line.erase(0, line.find_first_not_of(" \n"));
  return line;
}

}  // namespace

Result<ConvexPolyhedron> build_convex_hull(std::span<const Vec3> points) {
  if (points.size() < 4) return Status::error("points: a hull needs at least 4 points");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_finite(points[i]))
      return Status::error("points[" + std::to_string(i) + "]: must be finite");
  }

  // Work relative to the bounding-box centre: qhull's tolerances are relative to coordinates.
  Aabb box;
  for (const Vec3& p : points)
    box.grow(p);
  const Vec3 centre = 0.5 * (box.min + box.max);
  const double span = box.extent().maxCoeff();
  if (!(span > 0)) return Status::error("points: all points coincide (degenerate hull)");

  std::vector<coordT> coords(points.size() * 3);
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k < 3; ++k)
      coords[3 * i + k] = points[i][k] - centre[k];

  CapturedStream errors;
  qhT qh_storage;
  qhT* qh = &qh_storage;
  QHULL_LIB_CHECK
  qh_zero(qh, errors.get());
  // Qt off: facets stay merged polygons. "C-0" merges coplanar facets; Qx merges exactly.
  char options[] = "qhull C-0 Qx";
  const int code = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False,
                                options, nullptr, errors.get());
  Result<ConvexPolyhedron> result = Status::error("points: qhull failed");
  if (code != 0) {
    const std::string message = first_line(errors.text());
    const bool flat = message.find("6154") != std::string::npos ||
                      message.find("flat") != std::string::npos ||
                      message.find("6214") != std::string::npos;
    result = Status::error(flat ? "points: coplanar or collinear (degenerate hull)"
                                : "points: qhull failed: " + message);
  } else {
    ConvexPolyhedron hull;
    std::map<int, std::uint32_t> vertex_index;  // qhull vertex id -> ours
    vertexT* vertex;
    FORALLvertices {
      const int point = qh_pointid(qh, vertex->point);
      vertex_index[vertex->id] = static_cast<std::uint32_t>(hull.vertices.size());
      hull.vertices.push_back(points[static_cast<std::size_t>(point)]);
    }
    facetT* facet;
    FORALLfacets {
      ConvexPolyhedron::Face face;
      face.normal = Vec3(facet->normal[0], facet->normal[1], facet->normal[2]).normalized();
      face.first = static_cast<std::uint32_t>(hull.face_vertices.size());
      std::vector<std::uint32_t> loop;
      vertexT** vertexp;
      FOREACHvertex_(facet->vertices) loop.push_back(vertex_index.at(vertex->id));
      Vec3 mid = Vec3::Zero();
      for (auto v : loop)
        mid += hull.vertices[v];
      mid /= static_cast<double>(loop.size());
      // Counter-clockwise about the outward normal: sort by angle in the facet plane.
      const Vec3 u = (hull.vertices[loop[0]] - mid).normalized();
      const Vec3 w = face.normal.cross(u);
      std::sort(loop.begin(), loop.end(), [&](std::uint32_t x, std::uint32_t y) {
        const Vec3 dx = hull.vertices[x] - mid, dy = hull.vertices[y] - mid;
        return std::atan2(dx.dot(w), dx.dot(u)) < std::atan2(dy.dot(w), dy.dot(u));
      });
      face.count = static_cast<std::uint32_t>(loop.size());
      // The plane through the outermost vertex, in our coordinates, so that it supports the hull.
      face.offset = -std::numeric_limits<double>::infinity();
      for (auto v : loop)
        face.offset = std::max(face.offset, face.normal.dot(hull.vertices[v]));
      hull.face_vertices.insert(hull.face_vertices.end(), loop.begin(), loop.end());
      hull.faces.push_back(face);
    }
    result = std::move(hull);
  }
  int leftover_long = 0, leftover_short = 0;
  qh_freeqhull(qh, !qh_ALL);
  qh_memfreeshort(qh, &leftover_long, &leftover_short);
  if (!result.ok()) return result;

  ConvexPolyhedron hull = std::move(result).value();
  // Edges: each directed edge of a face loop, paired with its reverse in the neighbouring face.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> directed;
  for (std::uint32_t f = 0; f < hull.faces.size(); ++f) {
    const auto& face = hull.faces[f];
    for (std::uint32_t k = 0; k < face.count; ++k) {
      const std::uint32_t a = hull.face_vertices[face.first + k];
      const std::uint32_t b = hull.face_vertices[face.first + (k + 1) % face.count];
      directed[{a, b}] = f;
    }
  }
  for (const auto& [key, left] : directed) {
    const auto reverse = directed.find({key.second, key.first});
    if (reverse == directed.end())
      return Status::error("points: hull is not closed (qhull returned an open surface)");
    if (key.first < key.second)
      hull.edges.push_back({key.first, key.second, left, reverse->second});
  }

  const PolyhedronIntegrals integrals = integrate_polyhedron(hull);
  if (!(integrals.volume > 1e-9 * span * span * span))
    return Status::error("points: the hull has no volume (degenerate hull)");
  hull.volume = integrals.volume;
  hull.centroid = integrals.centroid;
  return hull;
}

ConvexPolyhedron make_box_polyhedron(const Vec3& h) {
  ConvexPolyhedron box;
  for (int i = 0; i < 8; ++i)
    box.vertices.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                              (i & 4) ? h.z() : -h.z());
  // Loops counter-clockwise seen from outside: -x, +x, -y, +y, -z, +z.
  const std::uint32_t loops[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (int f = 0; f < 6; ++f) {
    const int axis = f / 2;
    const double sign = (f % 2) ? 1.0 : -1.0;
    ConvexPolyhedron::Face face;
    face.normal = Vec3::Zero();
    face.normal[axis] = sign;
    face.offset = h[axis];
    face.first = static_cast<std::uint32_t>(box.face_vertices.size());
    face.count = 4;
    box.face_vertices.insert(box.face_vertices.end(), loops[f], loops[f] + 4);
    box.faces.push_back(face);
  }
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> directed;
  for (std::uint32_t f = 0; f < 6; ++f)
    for (std::uint32_t k = 0; k < 4; ++k)
      directed[{loops[f][k], loops[f][(k + 1) % 4]}] = f;
  for (const auto& [key, left] : directed)
    if (key.first < key.second)
      box.edges.push_back({key.first, key.second, left, directed.at({key.second, key.first})});
  box.volume = 8 * h.x() * h.y() * h.z();
  box.box = true;
  return box;
}

}  // namespace tumble
