// Ray casts (physics/query.h): each ray walks the query tree of the bodies' bounds
// (query_index.h) and meets each body it reaches in that body's frame (ray_shape.h).
#include <algorithm>
#include <cmath>
#include <string>

#include "parallel.h"
#include "physics/collision.h"
#include "physics/world.h"
#include "query_index.h"
#include "ray_shape.h"
#include "step_stages.h"
#include "world_slot.h"

namespace tumble {

Status validate(const RayCast& ray) {
  if (!is_finite(ray.origin)) return Status::error("origin: must be finite");
  if (!is_finite(ray.direction)) return Status::error("direction: must be finite");
  if (!(ray.direction.norm() > 0)) return Status::error("direction: must not be zero");
  if (!(ray.max_distance > 0 && ray.max_distance <= kMaxRayLength))
    return Status::error("max_distance: must be in (0, 1e10] m");
  return Status::ok();
}

Status validate_placement(const Pose& pose) {
  if (!is_finite(pose.position)) return Status::error("position: must be finite");
  const double norm = pose.orientation.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1) > 1e-3)
    return Status::error("orientation: must be a unit quaternion");
  return Status::ok();
}

namespace {

// The ray met with one body, in the body's frame; false if it misses it within max_t.
bool hit_body(const Body& body, const Vec3& origin, const Vec3& direction, double max_t,
              ShapeRayHit* hit) {
  const Quat inverse = body.orientation.conjugate();
  return ray_shape(body.shape, inverse * (origin - body.position), inverse * direction, max_t,
                   hit);
}

RayHit world_hit(const Body& body, BodyId id, const RayCast& ray, const Vec3& direction,
                 const ShapeRayHit& hit) {
  RayHit out;
  out.body = id;
  out.distance = hit.t;
  out.fraction = std::min(1.0, hit.t / ray.max_distance);
  out.point = ray.origin + hit.t * direction;
  out.normal = (body.orientation * hit.normal).normalized();
  return out;
}

}  // namespace

const QueryIndex& World::query_index() const {
  QueryIndex& index = *query_index_;
  std::lock_guard lock(index.building);
  if (index.version != query_version_) {
    std::vector<QueryIndex::Entry> entries;
    entries.reserve(live_count_);
    for (std::uint32_t slot = 0; slot < bodies_.size(); ++slot) {
      if (!bodies_[slot].alive) continue;
      const Body& body = bodies_[slot].body;
      entries.push_back({slot, transform_aabb(body.shape.local_bounds(), body.pose())});
    }
    index.build(entries);
    index.version = query_version_;
  }
  return index;
}

Result<RayHit> World::cast_ray(const RayCast& ray) const {
  RayHit hit;
  if (Status s = cast_rays(std::span(&ray, 1), std::span(&hit, 1)); !s) {
    const std::string& message = s.message();
    return Status::error(message.substr(message.find('.') + 1));  // no "rays[0]." for one ray
  }
  return hit;
}

Status World::cast_rays(std::span<const RayCast> rays, std::span<RayHit> hits) const {
  if (hits.size() != rays.size()) return Status::error("hits: must have one entry per ray");
  for (std::size_t i = 0; i < rays.size(); ++i)
    if (Status s = validate(rays[i]); !s) return s.within("rays[" + std::to_string(i) + "].");
  const QueryIndex& index = query_index();
  const int threads = team_size(settings_.threads);
  const std::int64_t n = static_cast<std::int64_t>(rays.size());
  for_indices(threads, n >= 64, n, [&](std::int64_t i) {
    const RayCast& ray = rays[i];
    const Vec3 direction = ray.direction.normalized();
    RayHit best;
    ShapeRayHit best_local;
    std::uint32_t best_slot = 0;
    index.visit_ray(ray.origin, direction, ray.max_distance, [&](std::uint32_t slot, double t_max) {
      const Body& body = bodies_[slot].body;
      if ((body.filter.layers & ray.mask) == 0) return t_max;
      ShapeRayHit hit;
      if (!hit_body(body, ray.origin, direction, t_max, &hit)) return t_max;
      // Equal distances go to the lower slot: the same answer whatever order the tree gives.
      if (best.hit() && (hit.t > best.distance || (hit.t == best.distance && slot > best_slot)))
        return t_max;
      best.body = BodyId{slot, bodies_[slot].generation};
      best.distance = hit.t;
      best_local = hit;
      best_slot = slot;
      return hit.t;
    });
    hits[i] = best.hit() ? world_hit(bodies_[best_slot].body, best.body, ray, direction, best_local)
                         : RayHit{};
  });
  return Status::ok();
}

Result<bool> World::cast_ray_all(const RayCast& ray, std::size_t max_hits,
                                 std::vector<RayHit>* hits) const {
  if (Status s = validate(ray); !s) return s;
  hits->clear();
  const QueryIndex& index = query_index();
  const Vec3 direction = ray.direction.normalized();
  std::vector<std::pair<ShapeRayHit, std::uint32_t>> found;
  index.visit_ray(ray.origin, direction, ray.max_distance, [&](std::uint32_t slot, double t_max) {
    const Body& body = bodies_[slot].body;
    ShapeRayHit hit;
    if ((body.filter.layers & ray.mask) != 0 && hit_body(body, ray.origin, direction, t_max, &hit))
      found.push_back({hit, slot});
    return t_max;  // every body, not only the nearest
  });
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    return a.first.t < b.first.t || (a.first.t == b.first.t && a.second < b.second);
  });
  const bool left_out = found.size() > max_hits;
  if (left_out) found.resize(max_hits);
  for (const auto& [hit, slot] : found)
    hits->push_back(
        world_hit(bodies_[slot].body, BodyId{slot, bodies_[slot].generation}, ray, direction, hit));
  return left_out;
}

Result<ClosestPoint> World::closest_point(BodyId id, const Vec3& point,
                                          double max_distance) const {
  if (!contains(id)) return Status::not_found("body: no body with this id");
  if (!is_finite(point)) return Status::error("point: must be finite");
  if (!(max_distance > 0 && max_distance <= kMaxRayLength))
    return Status::error("max_distance: must be in (0, 1e10] m");
  // A sphere of a nanometre about the point, met with the narrow phase's speculative reach of
  // max_distance: its contact's point on the body is the nearest, and its depth is the probe's
  // radius less the distance (the closed forms for round shapes against every shape kind).
  constexpr double kProbe = 1e-9;
  static const Shape probe = Shape::create(SphereDef{kProbe}).value();
  const Body& body = bodies_[id.index].body;
  CollisionSettings reach;
  reach.margin = max_distance;
  ContactManifold manifold;
  (void)collide(probe, Pose{point, Quat::Identity()}, body.shape, body.pose(), reach, &manifold);
  ClosestPoint out;
  if (manifold.count == 0) return out;
  const ContactPoint& contact = manifold.points[0];
  out.found = true;
  out.point = contact.point_b;
  out.normal = -manifold.normal;  // the manifold's runs from the probe to the body
  out.distance = kProbe - contact.depth;
  if (out.distance > max_distance) out.found = false;
  return out;
}

Result<bool> World::overlap(const OverlapQuery& query, std::size_t max_bodies,
                            std::vector<BodyId>* bodies) const {
  bodies->clear();
  if (std::holds_alternative<HalfSpaceDef>(query.shape))
    return Status::error("shape: a half-space holds half the world; ask a large box");
  if (std::holds_alternative<HeightFieldDef>(query.shape))
    return Status::error("shape: a heightfield is terrain, not a query's shape; ask a box");
  if (std::holds_alternative<TriangleMeshDef>(query.shape))
    return Status::error("shape: a mesh is terrain, not a query's shape; ask a box");
  Result<Shape> shape = Shape::create(query.shape);
  if (!shape) return shape.status().within("shape.");
  if (Status s = validate_placement(query.pose); !s) return s;
  const Pose pose{query.pose.position, query.pose.orientation.normalized()};
  const Aabb box = transform_aabb(shape.value().local_bounds(), pose);
  std::vector<std::uint32_t> found;
  const QueryIndex& index = query_index();
  CollisionSettings touching;  // margin 0: overlapping or touching
  index.visit_box(box, [&](std::uint32_t slot) {
    const Body& body = bodies_[slot].body;
    if ((body.filter.layers & query.mask) == 0) return;
    ContactManifold manifold;
    // An iteration bound hit keeps GJK's and EPA's best answer, as the step does.
    (void)collide(shape.value(), pose, body.shape, body.pose(), touching, &manifold);
    if (manifold.count > 0) found.push_back(slot);
  });
  std::sort(found.begin(), found.end());
  const bool left_out = found.size() > max_bodies;
  if (left_out) found.resize(max_bodies);
  for (std::uint32_t slot : found)
    bodies->push_back({slot, bodies_[slot].generation});
  return left_out;
}

}  // namespace tumble
