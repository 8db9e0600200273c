// Convex bodies against a heightfield: the triangles of the cells under the body, met by the
// rules of triangle_contacts.cc; each body vertex is over one triangle, found from its x and y.
#include <algorithm>
#include <cmath>

#include "narrow_phase.h"
#include "physics/height_field.h"
#include "triangle_contacts.h"

namespace tumble {

std::uint32_t collide_height_field(const Shape& a, const Mat3& rotation, const Vec3& translation,
                                   const HeightField& field, const CollisionSettings& settings,
                                   TerrainContacts* out) {
  out->count = 0;
  const double margin = settings.margin;
  const TriangleBody body(a, rotation, translation, margin);
  const Aabb& box = body.bounds;
  if (box.min.z() > field.max_height()) return kCollisionOk;
  std::uint32_t i0, j0, i1, j1;
  if (!field.cells_under(box, &i0, &j0, &i1, &j1)) return kCollisionOk;
  std::uint32_t flags = kCollisionOk;
  const std::size_t width = i1 - i0 + 1;
  if (width * (j1 - j0 + 1) > kMaxTerrainCells) {
    flags |= kTerrainCellLimit;
    i1 = i0 + static_cast<std::uint32_t>(std::min(width, kMaxTerrainCells)) - 1;
    j1 = j0 + static_cast<std::uint32_t>(kMaxTerrainCells / (i1 - i0 + 1)) - 1;
  }
  TriangleContacts& contacts = TriangleContacts::begin(
      margin, std::max(a.size(), field.def().spacing_x + field.def().spacing_y));

  for (std::uint32_t j = j0; j <= j1; ++j) {
    for (std::uint32_t i = i0; i <= i1; ++i) {
      for (std::uint32_t k = 0; k < 2; ++k) {
        const std::size_t t = 2 * (std::size_t{j} * field.cells_x() + i) + k;
        const std::uint8_t active = field.active_edges(t);
        // A polytope meets a triangle's face through its vertices (below) and its edges only
        // where they are active: on gently rolling ground most are not, and the triangle costs
        // nothing more.
        if (!body.round && active == 0) continue;
        const std::array<Vec3, 3> v = field.triangle(t);
        if (std::max({v[0].z(), v[1].z(), v[2].z()}) < box.min.z()) continue;
        const Vec3 n = normal_of(v);
        if (body.round) contacts.round_face_points(body, v, n);
        for (int e = 0; e < 3; ++e) {
          // Each edge once: from the lower of its two triangles.
          const std::int64_t other = field.neighbour(t, e);
          if ((active & (1u << e)) == 0 || (other >= 0 && static_cast<std::size_t>(other) < t))
            continue;
          if (std::max(v[e].z(), v[(e + 1) % 3].z()) < box.min.z()) continue;
          Vec3 other_normal;
          if (other >= 0) other_normal = normal_of(field.triangle(static_cast<std::size_t>(other)));
          flags |= contacts.edge(body, v, n, e, other >= 0 ? &other_normal : nullptr, 3 * t + e,
                                 settings);
        }
      }
    }
  }

  if (!body.round) {
    // Each vertex is over one triangle (the cell its x, y fall in, then the side of the diagonal).
    const HeightFieldDef& def = field.def();
    const double x0 = -0.5 * (def.samples_x - 1) * def.spacing_x;
    const double y0 = -0.5 * (def.samples_y - 1) * def.spacing_y;
    const auto& vertices = a.polyhedron()->vertices;
    for (std::uint32_t index = 0; index < vertices.size(); ++index) {
      const Vec3 x = rotation * vertices[index] + translation;
      const double fx = (x.x() - x0) / def.spacing_x, fy = (x.y() - y0) / def.spacing_y;
      const double ci = std::floor(fx), cj = std::floor(fy);
      if (!(ci >= i0 && ci <= i1 && cj >= j0 && cj <= j1)) continue;
      const auto i = static_cast<std::uint32_t>(ci), j = static_cast<std::uint32_t>(cj);
      const std::uint32_t k = fx - ci >= fy - cj ? 0 : 1;
      const std::array<Vec3, 3> v = field.triangle(2 * (std::size_t{j} * field.cells_x() + i) + k);
      contacts.vertex_face_point(v, normal_of(v), x, index, false);
    }
  }
  if (contacts.wants_gentle_edges(body)) {
    // A round core over a gentle ridge can lie beyond both triangles' feet (triangle_contacts.h).
    for (std::uint32_t j = j0; j <= j1; ++j)
      for (std::uint32_t i = i0; i <= i1; ++i)
        for (std::uint32_t k = 0; k < 2; ++k) {
          const std::size_t t = 2 * (std::size_t{j} * field.cells_x() + i) + k;
          const std::uint8_t gentle = field.gentle_edges(t);
          if (gentle == 0) continue;
          const std::array<Vec3, 3> v = field.triangle(t);
          const Vec3 n = normal_of(v);
          for (int e = 0; e < 3; ++e) {
            const std::int64_t other = field.neighbour(t, e);
            if ((gentle & (1u << e)) == 0 || static_cast<std::size_t>(other) < t) continue;
            contacts.gentle_edge(body, v, n, e,
                                 normal_of(field.triangle(static_cast<std::size_t>(other))),
                                 3 * t + e);
          }
        }
  }
  contacts.finish(out);
  return flags;
}

}  // namespace tumble
