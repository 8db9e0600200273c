// Boxes and hulls against each other: the exact separating-axis test by default, GJK and EPA on
// request; either way the contact normal becomes a manifold by face clipping.
#include <algorithm>
#include <cmath>
#include <limits>

#include "epa.h"
#include "manifold.h"
#include "narrow_phase.h"
#include "sat.h"
#include "segment.h"

namespace tumble {
namespace {

// A face is preferred over an edge pair, and A's face over B's, unless the other separates by
// more than this share of the shapes' size: stable manifolds without giving up exactness.
constexpr double kFeaturePreference = 2e-10;

// How much better another feature must separate the shapes to be chosen; `separation` is the
// pair's (negative when overlapping).
double feature_tolerance(const CollisionSettings& settings, double scale, double separation) {
  return kFeaturePreference * scale + settings.feature_slack +
         settings.feature_slack_relative * std::max(0.0, -separation);
}

// Clips the face of `reference` against the face of `incident` most opposed to it.
void face_contact(const PlacedPolyhedron& reference, std::uint32_t face,
                  const PlacedPolyhedron& incident, bool reference_is_a, double margin,
                  ContactManifold* out) {
  clip_face_contact(reference, face, incident,
                    most_opposed_face(incident, reference.face_normal(face)), reference_is_a,
                    margin, out);
}

void edge_contact(const PlacedPolyhedron& a, const PlacedPolyhedron& b, const EdgeQuery& query,
                  ContactManifold* out) {
  const auto& ea = a.polyhedron->edges[query.edge_a];
  const auto& eb = b.polyhedron->edges[query.edge_b];
  const SegmentClosest c = closest_between_segments(a.point(ea.tail), a.point(ea.head),
                                                    b.point(eb.tail), b.point(eb.head));
  out->normal = query.axis;
  out->depth = -query.separation;
  out->count = 1;
  ContactPoint& point = out->points[0];
  point.point_a = c.on_first;
  point.point_b = c.on_second;
  point.depth = -query.separation;
  point.feature_id = feature_id(kFeatureEdges, query.edge_a, query.edge_b, 0);
}

// A manifold for a known normal (A to B): clip when the normal is a face normal of either body,
// otherwise one point at the witness pair.
void manifold_from_normal(const PlacedPolyhedron& a, const PlacedPolyhedron& b, const Vec3& normal,
                          double depth, const Vec3& witness_a, const Vec3& witness_b,
                          const CollisionSettings& settings, double scale, ContactManifold* out) {
  const double margin = settings.margin;
  const std::uint32_t face_b = most_opposed_face(b, normal);
  const std::uint32_t face_a = most_opposed_face(a, -normal);
  const double align_a = a.face_normal(face_a).dot(normal);
  const double align_b = -b.face_normal(face_b).dot(normal);
  // By default only faces parallel to EPA's accuracy (about 1e-12 in the cosine); a solver asks
  // for more so that slightly tilted faces keep their full manifold.
  const double face_alignment = std::cos(settings.face_angle);
  const bool a_aligned = align_a >= face_alignment, b_aligned = align_b >= face_alignment;
  if (a_aligned || b_aligned) {
    // Two nearly parallel faces: decide by their separations, exactly as the SAT path does, so
    // that both paths give the same manifold.
    bool use_a = a_aligned;
    if (a_aligned && b_aligned) {
      const Vec3 na = a.face_normal(face_a), nb = b.face_normal(face_b);
      const double sep_a =
          na.dot(b.point(b.polyhedron->support_index(b.rotation.transpose() * -na))) -
          a.face_offset(face_a);
      const double sep_b =
          nb.dot(a.point(a.polyhedron->support_index(a.rotation.transpose() * -nb))) -
          b.face_offset(face_b);
      use_a = sep_a >= sep_b - feature_tolerance(settings, scale, std::max(sep_a, sep_b));
    }
    if (use_a)
      face_contact(a, face_a, b, true, margin, out);
    else
      face_contact(b, face_b, a, false, margin, out);
    if (out->count > 0) {
      out->depth = depth;  // EPA's (or GJK's) own answer, not re-measured on the chosen face
      return;
    }
  }
  out->normal = normal;
  out->depth = depth;
  out->count = 1;
  out->points[0].point_a = witness_a;
  out->points[0].point_b = witness_b;
  out->points[0].depth = depth;
  out->points[0].feature_id =
      feature_id(kFeatureVertex, a.polyhedron->support_index(a.rotation.transpose() * normal),
                 b.polyhedron->support_index(b.rotation.transpose() * -normal), 0);
}

// The manifold of a feature found before, measured again at the present poses: the contact is
// exact for that feature, and the pair's depth is that feature's. False for a pair of edges that
// has turned parallel: the full search decides.
bool take_known_feature(const PlacedPolyhedron& a, const PlacedPolyhedron& b,
                        const PolytopeFeature& known, double margin, ContactManifold* out) {
  double separation = 0;
  switch (known.kind) {
    case PolytopeFeature::kFaceA:
    case PolytopeFeature::kFaceB: {
      const bool on_a = known.kind == PolytopeFeature::kFaceA;
      const PlacedPolyhedron& reference = on_a ? a : b;
      const PlacedPolyhedron& incident = on_a ? b : a;
      TUMBLE_ASSERT(known.first < reference.polyhedron->faces.size());
      separation = query_face(reference, known.first, incident).separation;
      if (separation > margin) return true;  // a separating axis: no contact
      face_contact(reference, known.first, incident, on_a, margin, out);
      break;
    }
    case PolytopeFeature::kEdges: {
      TUMBLE_ASSERT(known.first < a.polyhedron->edges.size() &&
                    known.second < b.polyhedron->edges.size());
      const EdgeQuery edges = query_edge_pair(a, known.first, b, known.second);
      if (edges.separation == -std::numeric_limits<double>::infinity()) return false;
      separation = edges.separation;
      if (separation > margin) return true;
      edge_contact(a, b, edges, out);
      break;
    }
    case PolytopeFeature::kNone:
      return false;
  }
  if (out->count > 0) out->depth = -separation;
  return true;
}

}  // namespace

std::uint32_t collide_polytopes(const ConvexPolyhedron& a, const ConvexPolyhedron& b,
                                const Mat3& rotation, const Vec3& translation, double scale,
                                const CollisionSettings& settings, const PolytopeFeature* known,
                                PolytopeFeature* chosen, ContactManifold* out) {
  out->count = 0;
  const PlacedPolyhedron pa{&a, Mat3::Identity(), Vec3::Zero()};
  const PlacedPolyhedron pb{&b, rotation, translation};
  const double margin = settings.margin;

  // SAT tests every Minkowski-face edge pair, so its cost grows with |E_A| |E_B|; past this many
  // pairs GJK/EPA is faster at the same exactness (bench/narrow_phase.cc).
  constexpr std::size_t kSatEdgePairLimit = 400;
  const bool use_gjk = settings.method == NarrowPhaseMethod::kGjkEpa ||
                       (settings.method == NarrowPhaseMethod::kAuto &&
                        a.edges.size() * b.edges.size() > kSatEdgePairLimit);
  if (use_gjk) {
    const PolyhedronSupport support_a{&a};
    const PolyhedronSupport local_b{&b};
    const Transformed<PolyhedronSupport> support_b{local_b, rotation, translation};
    GjkSettings gjk_settings;
    gjk_settings.tolerance = 1e-12 * scale;
    const GjkResult gjk = gjk_distance(support_a, support_b, translation, gjk_settings);
    std::uint32_t flags =
        gjk.status == GjkStatus::kIterationLimit ? std::uint32_t{kGjkIterationLimit} : 0u;
    if (gjk.status != GjkStatus::kIntersecting && gjk.distance > gjk_settings.tolerance) {
      if (gjk.distance > margin) return flags;
      const Vec3 normal = (gjk.point_b - gjk.point_a) / gjk.distance;
      manifold_from_normal(pa, pb, normal, -gjk.distance, gjk.point_a, gjk.point_b, settings, scale,
                           out);
      return flags;
    }
    EpaSettings epa_settings;
    epa_settings.tolerance = 1e-12 * scale;
    const EpaResult epa = epa_penetration(support_a, support_b, gjk.simplex, epa_settings);
    if (epa.status == EpaStatus::kIterationLimit) flags |= kEpaIterationLimit;
    if (epa.status == EpaStatus::kDegenerate) flags |= kEpaDegenerate;
    manifold_from_normal(pa, pb, epa.normal, epa.depth, epa.point_a, epa.point_b, settings, scale,
                         out);
    return flags;
  }

  if (known != nullptr && known->kind != PolytopeFeature::kNone &&
      take_known_feature(pa, pb, *known, margin, out)) {
    if (chosen != nullptr) {
      *chosen = *known;
      chosen->searched = false;
    }
    return kCollisionOk;
  }

  const FaceQuery face_a = query_faces(pa, pb);
  if (face_a.separation > margin) return kCollisionOk;
  const FaceQuery face_b = query_faces(pb, pa);
  if (face_b.separation > margin) return kCollisionOk;
  const EdgeQuery edges = query_edges(pa, pb);
  if (edges.separation > margin) return kCollisionOk;

  const double deepest = std::max({face_a.separation, face_b.separation, edges.separation});
  const double tolerance = feature_tolerance(settings, scale, deepest);
  const bool use_a = face_a.separation >= face_b.separation - tolerance;
  const double chosen_face = use_a ? face_a.separation : face_b.separation;
  PolytopeFeature feature{PolytopeFeature::kFaceA, face_a.face, 0};
  if (edges.separation > chosen_face + tolerance) {
    edge_contact(pa, pb, edges, out);
    feature = {PolytopeFeature::kEdges, edges.edge_a, edges.edge_b};
  } else if (use_a) {
    face_contact(pa, face_a.face, pb, true, margin, out);
  } else {
    face_contact(pb, face_b.face, pa, false, margin, out);
    feature = {PolytopeFeature::kFaceB, face_b.face, 0};
  }
  if (out->count > 0) out->depth = -deepest;  // the exact pair penetration, whatever the feature
  if (chosen != nullptr) *chosen = feature;
  return kCollisionOk;
}

}  // namespace tumble
