#include "hull_mesh.h"

#include <libqhull_r/qhull_ra.h>

#include <cstdio>
#include <vector>

namespace tumble::viewer {

Mesh hull_mesh(std::span<const double> xyz) {
  Mesh mesh;
  const int count = static_cast<int>(xyz.size() / 3);
  if (count < 4) return mesh;
  std::vector<coordT> coords(xyz.begin(), xyz.begin() + 3 * count);
  qhT storage;
  qhT* qh = &storage;
  FILE* quiet = std::fopen("/dev/null", "w");
  qh_zero(qh, quiet);
  char options[] = "qhull Qt";  // triangulated facets
  if (qh_new_qhull(qh, 3, count, coords.data(), False, options, nullptr, quiet) == 0) {
    facetT* facet;
    FORALLfacets {
      const float n[3] = {static_cast<float>(facet->normal[0]),
                          static_cast<float>(facet->normal[1]),
                          static_cast<float>(facet->normal[2])};
      std::vector<const coordT*> corners;
      vertexT* vertex;
      vertexT** vertexp;
      FOREACHvertex_(facet->vertices) corners.push_back(vertex->point);
      if (corners.size() != 3) continue;
      // Counter-clockwise about the outward normal.
      const coordT *a = corners[0], *b = corners[1], *c = corners[2];
      const double cross[3] = {(b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]),
                               (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]),
                               (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])};
      if (cross[0] * n[0] + cross[1] * n[1] + cross[2] * n[2] < 0) std::swap(b, c);
      const auto first = static_cast<std::uint32_t>(mesh.vertices.size() / 6);
      for (const coordT* p : {a, b, c})
        for (float value : {static_cast<float>(p[0]), static_cast<float>(p[1]),
                            static_cast<float>(p[2]), n[0], n[1], n[2]})
          mesh.vertices.push_back(value);
      for (std::uint32_t k = 0; k < 3; ++k)
        mesh.indices.push_back(first + k);
    }
  }
  int leftover_long = 0, leftover_short = 0;
  qh_freeqhull(qh, !qh_ALL);
  qh_memfreeshort(qh, &leftover_long, &leftover_short);
  if (quiet != nullptr) std::fclose(quiet);
  return mesh;
}

}  // namespace tumble::viewer
