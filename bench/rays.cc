// Ray casts beside Bullet's btCollisionWorld::rayTest on the same scene: 10,000 boxes of random
// size and orientation standing on a ground plane over 200 m x 200 m, and 100,000 rays from
// sensors above it looking down at random. Rays per second (the median of five runs) for Tumble on
// one and two threads and Bullet (float, its dynamic AABB tree, ClosestRayResultCallback) on one;
// and the disagreements of Tumble's nearest hits with a brute-force pass over every body (a
// sample of the rays), and of Bullet's with Tumble's. Then sphere casts (a ball of 0.3 m swept
// along each of the first casts' rays) beside Bullet's convexSweepTest: casts per second, and
// each of Tumble's answers checked on a sample against a reference of our own that needs no GJK
// (the distance from the swept centre to each box, exact, is convex along the path: its first
// fall below the radius by bisection).
// With --terrain 1 the ground is a heightfield of 100,352 triangles (225 x 225 samples over the
// same 200 m, rolling hills up to about 1.1 m) under the boxes, beside Bullet's
// btHeightfieldTerrainShape (its quads split along the same diagonal); the brute force then meets
// every triangle too, and the sphere casts are left out. With --terrain 2 the same triangles are a
// triangle mesh (ours, its bounding-volume tree) beside Bullet's btBvhTriangleMeshShape (its
// quantized tree), rays meeting the triangles' fronts only in both.
// Usage: bench_rays [--rays N] [--boxes N] [--casts N] [--terrain 0|1|2]
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "physics/world.h"
#include "ray_shape.h"

#ifdef TUMBLE_HAVE_BULLET
#include <BulletCollision/CollisionShapes/btHeightfieldTerrainShape.h>
#include <BulletCollision/NarrowPhaseCollision/btRaycastCallback.h>
#include <btBulletCollisionCommon.h>

#include "bullet_triangles.h"
#include "timing.h"
#endif

using namespace tumble;

namespace {

struct Scene {
  std::vector<Vec3> half;
  std::vector<Pose> pose;
};

// The hills of --terrain: 225 x 225 samples over 200 m x 200 m.
HeightFieldDef hills() {
  HeightFieldDef def;
  def.samples_x = def.samples_y = 225;
  def.spacing_x = def.spacing_y = 200.0 / 224;
  for (std::uint32_t j = 0; j < def.samples_y; ++j)
    for (std::uint32_t i = 0; i < def.samples_x; ++i) {
      const double x = (i - 112.0) * def.spacing_x, y = (j - 112.0) * def.spacing_y;
      def.heights.push_back(0.8 * std::sin(0.07 * x) * std::cos(0.05 * y) +
                            0.3 * std::sin(0.31 * x + 0.23 * y));
    }
  return def;
}

Scene make_scene(int boxes, std::mt19937_64* rng, const HeightField* ground) {
  std::uniform_real_distribution<double> u(0, 1);
  Scene scene;
  for (int i = 0; i < boxes; ++i) {
    scene.half.push_back(Vec3(0.1 + 0.4 * u(*rng), 0.1 + 0.4 * u(*rng), 0.1 + 0.9 * u(*rng)));
    const Quat q(Eigen::AngleAxisd(2 * M_PI * u(*rng), Vec3::UnitZ()) *
                 Eigen::AngleAxisd(0.3 * (u(*rng) - 0.5), Vec3::UnitX()));
    const double x = 200 * u(*rng) - 100, y = 200 * u(*rng) - 100;
    const double base = ground != nullptr ? ground->height_at(x, y) : 0.0;
    scene.pose.push_back({Vec3(x, y, base + scene.half.back().z()), q});
  }
  return scene;
}

std::vector<RayCast> make_rays(int count, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<RayCast> rays(count);
  for (RayCast& ray : rays) {
    ray.origin = Vec3(200 * u(*rng) - 100, 200 * u(*rng) - 100, 3 + 10 * u(*rng));
    ray.direction = Vec3(u(*rng) - 0.5, u(*rng) - 0.5, -0.2 - u(*rng)).normalized();
    ray.max_distance = 60;
  }
  return rays;
}

using tumble::bench::median;

template <class Run>
double rays_per_second(std::size_t rays, Run&& run) {
  std::vector<double> rates;
  for (int k = 0; k < 5; ++k) {
    const auto start = std::chrono::steady_clock::now();
    run();
    rates.push_back(
        rays / std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return median(rates);
}

}  // namespace

int main(int argc, char** argv) {
  int ray_count = 100000, box_count = 10000, cast_count = 10000;
  int terrain_kind = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--rays")) ray_count = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--boxes")) box_count = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--casts")) cast_count = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--terrain")) terrain_kind = std::atoi(argv[i + 1]);
  }
  if (terrain_kind < 0 || terrain_kind > 2) {
    std::fprintf(stderr,
                 "bench_rays: --terrain must be 0 (a plane), 1 (a heightfield) or 2 (a mesh)\n");
    return 2;
  }
  const bool terrain = terrain_kind != 0, mesh = terrain_kind == 2;
  const HeightFieldDef hills_def = hills();
  const HeightField hills_field = HeightField::create(hills_def).value();
  const HeightField* field = terrain ? &hills_field : nullptr;
  if (terrain) cast_count = 0;
  std::mt19937_64 rng(2026);
  const Scene scene = make_scene(box_count, &rng, field);
  const std::vector<RayCast> rays = make_rays(ray_count, &rng);

  World world;
  BodyDef ground;
  ground.shape = HalfSpaceDef{};
  if (terrain) ground.shape = hills_def;
  if (mesh) ground.shape = mesh_of_height_field(hills_field);
  ground.type = BodyType::kStatic;
  world.create_body(ground).value();
  for (std::size_t i = 0; i < scene.half.size(); ++i) {
    BodyDef def;
    def.shape = BoxDef{scene.half[i]};
    def.type = BodyType::kStatic;
    def.position = scene.pose[i].position;
    def.orientation = scene.pose[i].orientation;
    world.create_body(def).value();
  }
  std::vector<RayHit> hits(rays.size());
  std::printf("%d boxes on %s, %d rays\n", box_count,
              mesh      ? "hills of 100,352 triangles as a mesh"
              : terrain ? "hills of 100,352 triangles as a heightfield"
                        : "a plane",
              ray_count);
  {
    // The query tree is built by the first query after a change: one ray times it.
    std::vector<double> builds;
    for (int k = 0; k < 5; ++k) {
      BodyMotion nudge;  // a change of bodies makes the tree stale
      nudge.position = world.body(world.id_at(1))->position();
      (void)world.set_motion(world.id_at(1), nudge);
      const auto start = std::chrono::steady_clock::now();
      (void)world.cast_ray(rays[0]);
      builds.push_back(
          1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::printf("  the query tree of %d bodies: built in %.2f ms (median of five)\n", box_count + 1,
                median(builds));
  }
  for (int threads : {1, 2}) {
    WorldSettings settings = world.settings();
    settings.threads = threads;
    (void)world.set_settings(settings);
    (void)world.cast_rays(rays, hits);  // the query tree is built once, before timing
    const double rate = rays_per_second(rays.size(), [&] { (void)world.cast_rays(rays, hits); });
    std::printf("  Tumble, %d thread%s   %12.0f rays/s\n", threads, threads > 1 ? "s" : " ", rate);
  }
  int hit_count = 0;
  for (const RayHit& hit : hits)
    hit_count += hit.hit();
  std::printf("  %d of %d rays hit something\n", hit_count, ray_count);

  // Brute force on a sample: every box and the plane, each by its own closed form.
  const int sample = std::min(ray_count, 2000);
  std::vector<Shape> boxes;
  for (const Vec3& half : scene.half)
    boxes.push_back(Shape::create(BoxDef{half}).value());
  auto brute_force = [&](const RayCast& ray) {
    const Vec3 d = ray.direction.normalized();
    double best = ray.origin.z() > 0 && d.z() < 0 ? -ray.origin.z() / d.z() : INFINITY;
    if (terrain) {
      // Every triangle's upper side, by its plane and the three edges' sides.
      best = INFINITY;
      for (std::size_t t = 0; t < field->triangle_count(); ++t) {
        const std::array<Vec3, 3> v = field->triangle(t);
        const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]);
        const double along = n.dot(d);
        if (along >= 0) continue;
        const double s = n.dot(v[0] - ray.origin) / along;
        if (s < 0 || s >= best) continue;
        const Vec3 p = ray.origin + s * d;
        bool inside = true;
        for (int e = 0; e < 3 && inside; ++e)
          inside = (v[(e + 1) % 3] - v[e]).cross(p - v[e]).dot(n) >= -1e-12 * n.squaredNorm();
        if (inside) best = s;
      }
    }
    if (best > ray.max_distance) best = INFINITY;
    for (std::size_t b = 0; b < scene.half.size(); ++b) {
      const Quat inverse = scene.pose[b].orientation.conjugate();
      ShapeRayHit local;
      if (ray_shape(boxes[b], inverse * (ray.origin - scene.pose[b].position), inverse * d,
                    ray.max_distance, &local))
        best = std::min(best, local.t);
    }
    return best;
  };
  int disagreements = 0;
  double worst = 0;
  for (int i = 0; i < sample; ++i) {
    const double best = brute_force(rays[i]);
    const double tumble = hits[i].hit() ? hits[i].distance : INFINITY;
    const double gap = std::isinf(best) && std::isinf(tumble) ? 0 : std::abs(best - tumble);
    worst = std::max(worst, gap);
    disagreements += gap > 1e-9 ? 1 : 0;
  }
  std::printf(
      "  brute force, %d rays: %d disagreements (closest hit within 1e-9 m), worst %.3g m\n",
      sample, disagreements, worst);

  // Sphere casts: a ball of 0.3 m along the rays (their full length); none over terrain.
  constexpr double kBall = 0.3;
  cast_count = std::min(cast_count, ray_count);
  std::vector<ShapeCast> casts(cast_count);
  std::vector<ShapeHit> cast_hits(cast_count);
  for (int i = 0; i < cast_count; ++i) {
    casts[i].shape = SphereDef{kBall};
    casts[i].pose.position = rays[i].origin;
    casts[i].translation = rays[i].max_distance * rays[i].direction.normalized();
  }
  if (!terrain)
    std::printf("%d sphere casts (a ball of %.1f m along the first rays)\n", cast_count, kBall);
  for (int threads : {1, 2}) {
    if (terrain) break;
    WorldSettings settings = world.settings();
    settings.threads = threads;
    (void)world.set_settings(settings);
    const double rate =
        rays_per_second(casts.size(), [&] { (void)world.cast_shapes(casts, cast_hits); });
    std::printf("  Tumble, %d thread%s   %12.0f casts/s\n", threads, threads > 1 ? "s" : " ", rate);
  }
  int cast_hit_count = 0, unconverged = 0;
  for (const ShapeHit& hit : cast_hits) {
    cast_hit_count += hit.hit();
    unconverged += hit.hit() && !hit.converged;
  }
  if (!terrain)
    std::printf("  %d of %d casts hit something, %d stopped at the iteration bound\n",
                cast_hit_count, cast_count, unconverged);
  // The reference: the exact distance from a point to a turned box, and for each box the swept
  // centre's first fall within the ball's radius (the distance is convex along the path: its
  // minimum by golden-section search, then the first crossing by bisection, to 1e-12 of the path).
  auto box_distance = [&](std::size_t b, const Vec3& point) {
    const Vec3 local = scene.pose[b].orientation.conjugate() * (point - scene.pose[b].position);
    return (local.cwiseAbs() - scene.half[b]).cwiseMax(0.0).norm();
  };
  auto first_within = [&](std::size_t b, const ShapeCast& cast, double radius) {
    auto gap = [&](double t) {
      return box_distance(b, cast.pose.position + t * cast.translation) - radius;
    };
    if (gap(0) <= 0) return 0.0;
    double lo = 0, hi = 1;
    for (int k = 0; k < 100; ++k) {  // the minimum of a convex function, by thirds
      const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
      if (gap(m1) < gap(m2))
        hi = m2;
      else
        lo = m1;
    }
    if (gap(lo) > 0) return std::numeric_limits<double>::infinity();
    double a = 0, b2 = lo;
    for (int k = 0; k < 100; ++k) {
      const double m = 0.5 * (a + b2);
      (gap(m) > 0 ? a : b2) = m;
    }
    return b2;
  };
  auto reference_cast = [&](const ShapeCast& cast) {
    double best = INFINITY;
    const double dz = cast.translation.z();
    if (dz < 0) best = std::max(0.0, (cast.pose.position.z() - kBall) / -dz);
    if (best > 1) best = INFINITY;
    const Vec3 end = cast.pose.position + cast.translation;
    const Vec3 low = cast.pose.position.cwiseMin(end) - Vec3::Constant(kBall);
    const Vec3 high = cast.pose.position.cwiseMax(end) + Vec3::Constant(kBall);
    for (std::size_t b = 0; b < scene.half.size(); ++b) {
      const double reach = scene.half[b].norm();
      const Vec3& c = scene.pose[b].position;
      if ((c.array() + reach < low.array()).any() || (c.array() - reach > high.array()).any())
        continue;
      best = std::min(best, first_within(b, cast, kBall));
    }
    return best;
  };
  const int cast_sample = std::min(cast_count, 500);
  int cast_wrong = 0;
  double worst_gap = 0, worst_early = 0;
  for (int i = 0; i < cast_sample; ++i) {
    const double reference = reference_cast(casts[i]);
    const ShapeHit& hit = cast_hits[i];
    if (!hit.hit()) {
      cast_wrong += std::isfinite(reference) ? 1 : 0;
      continue;
    }
    // Nothing is met before Tumble's fraction, and there the ball is within the tolerance of a
    // body: the gap from the centre to the nearest surface, less the radius.
    const Vec3 centre = casts[i].pose.position + hit.fraction * casts[i].translation;
    double gap = std::max(0.0, centre.z() - kBall);
    for (std::size_t b = 0; b < scene.half.size(); ++b)
      gap = std::min(gap, box_distance(b, centre) - kBall);
    const double length = casts[i].translation.norm();
    worst_gap = std::max(worst_gap, gap);
    worst_early = std::max(worst_early, (reference - hit.fraction) * length);
    if (gap > kShapeCastTolerance + 1e-12 || gap < -1e-9 || hit.fraction > reference + 1e-12 ||
        !hit.converged)
      ++cast_wrong;
  }
  if (!terrain)
    std::printf(
        "  reference, %d casts: %d wrong (a miss that hits, a hit beyond the first contact "
        "or not within %.0e m of a body); the gap at the answers at most %.2g m, the answers "
        "at most %.2g m before the first contact along the path\n",
        cast_sample, cast_wrong, kShapeCastTolerance, worst_gap, worst_early);
  disagreements += cast_wrong;

#ifdef TUMBLE_HAVE_BULLET
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btCollisionWorld bullet(&dispatcher, &broadphase, &configuration);
  std::vector<std::unique_ptr<btBoxShape>> shapes;
  std::vector<std::unique_ptr<btCollisionObject>> objects;
  btStaticPlaneShape plane(btVector3(0, 0, 1), 0);
  auto add = [&](btCollisionShape* shape, const Pose& pose) {
    auto object = std::make_unique<btCollisionObject>();
    const Quat& q = pose.orientation;
    object->setWorldTransform(
        btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()),
                    btVector3(pose.position.x(), pose.position.y(), pose.position.z())));
    object->setCollisionShape(shape);
    bullet.addCollisionObject(object.get());
    objects.push_back(std::move(object));
  };
  // Bullet's heightfield is centred on its bounds, the up axis included; its quads split along
  // (x, y)-(x + 1, y + 1), as ours, with flipQuadEdges.
  btHeightfieldTerrainShape bullet_hills(
      static_cast<int>(hills_def.samples_x), static_cast<int>(hills_def.samples_y),
      hills_def.heights.data(), hills_field.min_height(), hills_field.max_height(), 2, true);
  bullet_hills.setLocalScaling(btVector3(hills_def.spacing_x, hills_def.spacing_y, 1));
  // The mesh: the same vertices and triangles (Bullet's mesh interface in single precision).
  const BulletTriangles mesh_arrays(mesh_of_height_field(hills_field));
  std::unique_ptr<btBvhTriangleMeshShape> bullet_mesh;
  if (mesh) {
    bullet_mesh = std::make_unique<btBvhTriangleMeshShape>(mesh_arrays.arrays.get(), true);
    add(bullet_mesh.get(), Pose{});
  } else if (terrain)
    add(&bullet_hills, Pose{Vec3(0, 0, 0.5 * (hills_field.min_height() + hills_field.max_height())),
                            Quat::Identity()});
  else
    add(&plane, Pose{});
  for (std::size_t b = 0; b < scene.half.size(); ++b) {
    const Vec3& h = scene.half[b];
    shapes.push_back(std::make_unique<btBoxShape>(btVector3(h.x(), h.y(), h.z())));
    shapes.back()->setMargin(0);
    add(shapes.back().get(), scene.pose[b]);
  }
  bullet.updateAabbs();
  std::vector<double> bullet_distance(rays.size());
  const double bullet_rate = rays_per_second(rays.size(), [&] {
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Vec3 from = rays[i].origin;
      const Vec3 to = from + rays[i].max_distance * rays[i].direction.normalized();
      const btVector3 a(from.x(), from.y(), from.z()), b(to.x(), to.y(), to.z());
      btCollisionWorld::ClosestRayResultCallback closest(a, b);
      // Triangles hold rays on their fronts only, as a mesh's and a heightfield's do in ours. Not
      // for the plane: Bullet meets a btStaticPlaneShape through two triangles wound downwards,
      // which the filter drops (every ray that missed the boxes then missed the ground, 80%).
      if (terrain) closest.m_flags |= btTriangleRaycastCallback::kF_FilterBackfaces;
      bullet.rayTest(a, b, closest);
      bullet_distance[i] =
          closest.hasHit() ? closest.m_closestHitFraction * rays[i].max_distance : INFINITY;
    }
  });
  std::printf("  Bullet float, 1 thread %12.0f rays/s\n", bullet_rate);
  int differ = 0, missed = 0, tumble_wrong = 0;
  std::vector<double> gaps;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const double tumble = hits[i].hit() ? hits[i].distance : INFINITY;
    if (std::isinf(tumble) != std::isinf(bullet_distance[i])) {
      ++missed;
      continue;
    }
    if (std::isinf(tumble)) continue;
    gaps.push_back(std::abs(tumble - bullet_distance[i]));
    if (gaps.back() > 1e-3 && ++differ <= 200 && std::abs(brute_force(rays[i]) - tumble) > 1e-9)
      ++tumble_wrong;
  }
  std::sort(gaps.begin(), gaps.end());
  std::printf(
      "  Bullet's nearest hits beside Tumble's: %d rays hit in one and not the other, %d "
      "differ by over 1 mm; the distances' differences: median %.2g m, 99th percentile "
      "%.2g m, largest %.2g m\n",
      missed, differ, gaps.empty() ? 0.0 : gaps[gaps.size() / 2],
      gaps.empty() ? 0.0 : gaps[gaps.size() * 99 / 100], gaps.empty() ? 0.0 : gaps.back());
  std::printf("  of the first %d rays where they differ, the brute force sides with Bullet on %d\n",
              std::min(differ, 200), tumble_wrong);
  if (terrain) return disagreements == 0 ? 0 : 1;
  btSphereShape ball(kBall);
  std::vector<double> bullet_fraction(casts.size());
  const double bullet_cast_rate = rays_per_second(casts.size(), [&] {
    for (std::size_t i = 0; i < casts.size(); ++i) {
      const Vec3 from = casts[i].pose.position, to = from + casts[i].translation;
      const btTransform a(btQuaternion::getIdentity(), btVector3(from.x(), from.y(), from.z()));
      const btTransform b(btQuaternion::getIdentity(), btVector3(to.x(), to.y(), to.z()));
      btCollisionWorld::ClosestConvexResultCallback closest(a.getOrigin(), b.getOrigin());
      bullet.convexSweepTest(&ball, a, b, closest);
      bullet_fraction[i] = closest.hasHit() ? closest.m_closestHitFraction : INFINITY;
    }
  });
  std::printf("  Bullet float, 1 thread %12.0f casts/s (convexSweepTest)\n", bullet_cast_rate);
  int cast_missed = 0, cast_differ = 0, reference_with_bullet = 0;
  std::vector<double> cast_gaps;
  for (std::size_t i = 0; i < casts.size(); ++i) {
    const double tumble = cast_hits[i].hit() ? cast_hits[i].fraction : INFINITY;
    if (std::isinf(tumble) != std::isinf(bullet_fraction[i])) {
      ++cast_missed;
      continue;
    }
    if (std::isinf(tumble)) continue;
    const double length = casts[i].translation.norm();
    cast_gaps.push_back(std::abs(tumble - bullet_fraction[i]) * length);
    // Where they differ by over 1 mm, which one the reference sides with (the first 200).
    if (cast_gaps.back() > 1e-3 && ++cast_differ <= 200) {
      const double reference = reference_cast(casts[i]);
      if (std::abs(reference - bullet_fraction[i]) < std::abs(reference - tumble))
        ++reference_with_bullet;
    }
  }
  std::sort(cast_gaps.begin(), cast_gaps.end());
  std::printf(
      "  Bullet's sphere casts beside Tumble's: %d hit in one and not the other; the "
      "distances' differences: median %.2g m, 99th percentile %.2g m, largest %.2g m\n",
      cast_missed, cast_gaps.empty() ? 0.0 : cast_gaps[cast_gaps.size() / 2],
      cast_gaps.empty() ? 0.0 : cast_gaps[cast_gaps.size() * 99 / 100],
      cast_gaps.empty() ? 0.0 : cast_gaps.back());
  std::printf(
      "  %d casts differ by over 1 mm; of the first %d, the reference sides with Bullet on "
      "%d\n",
      cast_differ, std::min(cast_differ, 200), reference_with_bullet);
#else
  std::printf("  (no Bullet: built without the peers)\n");
#endif
  return disagreements == 0 ? 0 : 1;
}
