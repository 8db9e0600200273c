// Shape casts (physics/query.h): the shape's bounds swept along its path pick candidate bodies
// from the query tree (query_index.h, visit_sweep); they are met in the order in which the sweeping box can
// first reach them, each by conservative advancement (continuous.h, with no rotation: the gap is
// then a convex function of the fraction and each step is its tangent, so advancement never
// steps over the first contact), until no candidate left can come before the best hit.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "continuous.h"
#include "parallel.h"
#include "physics/collision.h"
#include "physics/world.h"
#include "query_index.h"
#include "step_stages.h"
#include "world_slot.h"

namespace tumble {

Status validate(const ShapeCast& cast) {
  if (std::holds_alternative<HalfSpaceDef>(cast.shape))
    return Status::error("shape: a half-space holds half the world and cannot be swept");
  if (std::holds_alternative<HeightFieldDef>(cast.shape))
    return Status::error("shape: a heightfield is terrain and cannot be swept");
  if (std::holds_alternative<TriangleMeshDef>(cast.shape))
    return Status::error("shape: a mesh is terrain and cannot be swept");
  if (Status s = validate_placement(cast.pose); !s) return s;
  if (!is_finite(cast.translation)) return Status::error("translation: must be finite");
  if (!(cast.translation.norm() <= kMaxRayLength))
    return Status::error("translation: longer than 1e10 m");
  return Status::ok();
}

namespace {

struct Candidate {
  double entry;
  std::uint32_t slot;
};

}  // namespace

Result<ShapeHit> World::cast_shape(const ShapeCast& cast) const {
  ShapeHit hit;
  if (Status s = cast_shapes(std::span(&cast, 1), std::span(&hit, 1)); !s) {
    const std::string& message = s.message();
    return Status::error(message.substr(message.find('.') + 1));  // no "casts[0]." for one
  }
  return hit;
}

Status World::cast_shapes(std::span<const ShapeCast> casts, std::span<ShapeHit> hits,
                          std::size_t max_candidates) const {
  if (hits.size() != casts.size()) return Status::error("hits: must have one entry per cast");
  std::vector<Shape> shapes;
  shapes.reserve(casts.size());
  for (std::size_t i = 0; i < casts.size(); ++i) {
    const std::string at = "casts[" + std::to_string(i) + "].";
    if (Status s = validate(casts[i]); !s) return s.within(at);
    Result<Shape> shape = Shape::create(casts[i].shape);
    if (!shape) return shape.status().within(at + "shape.");
    shapes.push_back(std::move(shape).value());
  }
  // Every cast's candidates first, from the tree alone (over the threads), so that a batch whose
  // sweeps reach more bodies than it may test is refused before any is tested.
  const QueryIndex& index = query_index();
  std::vector<std::vector<Candidate>> candidates(casts.size());
  const int threads = team_size(settings_.threads);
  const std::int64_t n = static_cast<std::int64_t>(casts.size());
  for_indices(threads, n >= 8, n, [&](std::int64_t i) {
    const ShapeCast& cast = casts[i];
    const Aabb start = transform_aabb(shapes[i].local_bounds(),
                                      {cast.pose.position, cast.pose.orientation.normalized()});
    index.visit_sweep(start, cast.translation, [&](std::uint32_t slot, double entry) {
      if ((bodies_[slot].body.filter.layers & cast.mask) != 0)
        candidates[i].push_back({entry, slot});
    });
  });
  std::size_t total = 0;
  for (std::size_t i = 0; i < casts.size(); ++i) {
    total += candidates[i].size();
    if (total > max_candidates)
      return Status::error("casts: the sweeps reach more than the " +
                               std::to_string(max_candidates) +
                               " bodies a batch may test (from casts[" + std::to_string(i) +
                               "]); cast shorter or fewer",
                           StatusCode::kResourceExhausted);
  }
  for_indices(threads, n >= 8, n, [&](std::int64_t i) {
    const ShapeCast& cast = casts[i];
    const Shape& shape = shapes[i];
    const SweptMotion motion{{cast.pose.position, cast.pose.orientation.normalized()},
                             cast.translation};
    std::vector<Candidate>& ordered = candidates[i];
    std::sort(ordered.begin(), ordered.end(), [](const Candidate& a, const Candidate& b) {
      return a.entry < b.entry || (a.entry == b.entry && a.slot < b.slot);
    });
    ImpactResult best;
    std::uint32_t best_slot = 0;
    bool found = false;
    for (const Candidate& candidate : ordered) {
      if (found && candidate.entry > best.t) break;  // the rest come later
      const Body& body = bodies_[candidate.slot].body;
      const ImpactResult impact =
          time_of_impact(shape, motion, body.shape, SweptMotion{body.pose()}, 0.0,
                         kShapeCastTolerance, kShapeCastIterations);
      if (impact.status == ImpactStatus::kMiss) continue;
      if (found && (impact.t > best.t || (impact.t == best.t && candidate.slot > best_slot)))
        continue;
      best = impact;
      best_slot = candidate.slot;
      found = true;
    }
    ShapeHit& out = hits[i];
    out = ShapeHit{};
    if (!found) return;
    const Body& body = bodies_[best_slot].body;
    out.body = BodyId{best_slot, bodies_[best_slot].generation};
    out.fraction = best.t;
    out.converged = best.status != ImpactStatus::kIterationLimit;
    // Where they touch there: the narrow phase's contact (normal from the cast shape to the body)
    // within the advancement's tolerance, its deepest point on the body.
    CollisionSettings reach;
    reach.margin = 2 * kShapeCastTolerance;
    reach.feature_slack = 0;
    ContactManifold manifold;
    (void)collide(shape, pose_at(motion, best.t), body.shape, body.pose(), reach, &manifold);
    if (manifold.count == 0) {  // (not expected: the advancement stopped within the reach)
      out.normal = -best.normal;
      out.point = pose_at(motion, best.t).position;
      return;
    }
    int deepest = 0;
    for (int k = 1; k < manifold.count; ++k)
      if (manifold.points[k].depth > manifold.points[deepest].depth) deepest = k;
    out.point = manifold.points[deepest].point_b;
    out.normal = -manifold.normal;
  });
  return Status::ok();
}

}  // namespace tumble
