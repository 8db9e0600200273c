#include "epa.h"

namespace tumble::epa_detail {

bool Polytope::build(const int (*triples)[3], int count, const Vec3& inside) {
  face_count = 0;
  for (int i = 0; i < count; ++i) {
    Face& f = faces[face_count++];
    f.v = {triples[i][0], triples[i][1], triples[i][2]};
    f.obsolete = false;
    if (!set_plane(f)) return false;
    if (f.normal.dot(inside) > f.distance) {  // facing inwards: flip
      std::swap(f.v[1], f.v[2]);
      set_plane(f);
    }
  }
  // Neighbours: edge (p, q) of one face is (q, p) in exactly one other.
  for (int i = 0; i < face_count; ++i) {
    for (int e = 0; e < 3; ++e) {
      const int p = faces[i].v[e], q = faces[i].v[(e + 1) % 3];
      faces[i].adjacent[e] = -1;
      for (int j = 0; j < face_count && faces[i].adjacent[e] < 0; ++j) {
        if (j == i) continue;
        for (int k = 0; k < 3; ++k)
          if (faces[j].v[k] == q && faces[j].v[(k + 1) % 3] == p) {
            faces[i].adjacent[e] = j;
            faces[i].adjacent_edge[e] = k;
          }
      }
      if (faces[i].adjacent[e] < 0) return false;
    }
  }
  return true;
}

bool Polytope::expand(int seed, int apex) {
  const Vec3& w = vertices[apex].w;
  struct HorizonEdge {
    int face, edge;
  };
  std::array<HorizonEdge, kMaxFaces> horizon;
  int horizon_count = 0;
  // Depth-first flood fill across visible faces; an explicit stack keeps the depth bounded.
  struct Visit {
    int face, edge;
  };
  std::array<Visit, kMaxFaces> stack;
  int top = 0;
  faces[seed].obsolete = true;
  for (int e = 2; e >= 0; --e)
    stack[top++] = {faces[seed].adjacent[e], faces[seed].adjacent_edge[e]};
  while (top > 0) {
    const Visit visit = stack[--top];
    Face& f = faces[visit.face];
    if (f.obsolete) continue;
    if (f.normal.dot(w) - f.distance > 0) {
      f.obsolete = true;
      // Pushed in reverse so that the horizon comes out in order around the hole.
      const int e2 = (visit.edge + 2) % 3, e1 = (visit.edge + 1) % 3;
      stack[top++] = {f.adjacent[e2], f.adjacent_edge[e2]};
      stack[top++] = {f.adjacent[e1], f.adjacent_edge[e1]};
      if (top + 2 >= kMaxFaces) return false;
    } else {
      horizon[horizon_count++] = {visit.face, visit.edge};
    }
  }
  if (horizon_count < 3 || face_count + horizon_count > kMaxFaces) return false;

  const int first_new = face_count;
  for (int h = 0; h < horizon_count; ++h) {
    Face& outside = faces[horizon[h].face];
    const int e = horizon[h].edge;
    Face& f = faces[face_count];
    f.v = {outside.v[(e + 1) % 3], outside.v[e], apex};
    f.obsolete = false;
    if (!set_plane(f)) return false;
    f.adjacent[0] = horizon[h].face;
    f.adjacent_edge[0] = e;
    outside.adjacent[e] = face_count;
    outside.adjacent_edge[e] = 0;
    ++face_count;
  }
  // The fan's own seams: face A's edge (v1 -> apex) meets face B's edge (apex -> v0) where
  // B.v0 == A.v1.
  for (int i = first_new; i < face_count; ++i) {
    int match = -1;
    for (int j = first_new; j < face_count && match < 0; ++j)
      if (faces[j].v[0] == faces[i].v[1]) match = j;
    if (match < 0) return false;
    faces[i].adjacent[1] = match;
    faces[i].adjacent_edge[1] = 2;
    faces[match].adjacent[2] = i;
    faces[match].adjacent_edge[2] = 1;
  }
  return true;
}

}  // namespace tumble::epa_detail
