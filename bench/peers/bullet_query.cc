// Bullet's GJK/EPA (btGjkEpaSolver2::Penetration) on exact shapes (collision margin 0). Built
// twice: against Debian's single-precision Bullet and, with BT_USE_DOUBLE_PRECISION, its float64
// build.
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>

#include <chrono>
#include <memory>

#include "peer_query.h"

namespace tumble::bench {

namespace {

btTransform to_bullet(const Pose& p) {
  const Quat& q = p.orientation;
  return btTransform(
      btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())),
      btVector3(btScalar(p.position.x()), btScalar(p.position.y()), btScalar(p.position.z())));
}

std::unique_ptr<btConvexShape> make_shape(bool hull, const Vec3& half,
                                          const std::vector<Vec3>* points) {
  std::unique_ptr<btConvexShape> shape;
  if (hull) {
    auto h = std::make_unique<btConvexHullShape>();
    for (const Vec3& p : *points)
      h->addPoint(btVector3(btScalar(p.x()), btScalar(p.y()), btScalar(p.z())), false);
    h->recalcLocalAabb();
    shape = std::move(h);
  } else {
    shape = std::make_unique<btBoxShape>(
        btVector3(btScalar(half.x()), btScalar(half.y()), btScalar(half.z())));
  }
  shape->setMargin(0);
  return shape;
}

}  // namespace

#ifdef BT_USE_DOUBLE_PRECISION
static PeerRun run_bullet(const std::vector<PairSpec>& pairs) {
#else
PeerRun run_bullet_float(const std::vector<PairSpec>& pairs) {
#endif
  std::vector<std::unique_ptr<btConvexShape>> a, b;
  std::vector<btTransform> ta, tb;
  for (const PairSpec& p : pairs) {
    a.push_back(make_shape(p.hulls, p.half_a, p.points_a));
    b.push_back(make_shape(p.hulls, p.half_b, p.points_b));
    ta.push_back(to_bullet(p.pose_a));
    tb.push_back(to_bullet(p.pose_b));
  }
  PeerRun run;
  run.answers.resize(pairs.size());
  std::vector<btGjkEpaSolver2::sResults> results(pairs.size());
  std::vector<char> hit(pairs.size());
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const btVector3 guess = tb[i].getOrigin() - ta[i].getOrigin();
    hit[i] = btGjkEpaSolver2::Penetration(a[i].get(), ta[i], b[i].get(), tb[i], guess, results[i],
                                          false);
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const auto& r = results[i];
    run.answers[i].hit = hit[i] && r.status == btGjkEpaSolver2::sResults::Penetrating;
    run.answers[i].depth = -double(r.distance);
    // results.normal is not in world axes when shape 0 is rotated; the witnesses are, and for a
    // penetration their difference is depth times the normal.
    const btVector3 d = r.witnesses[0] - r.witnesses[1];
    run.answers[i].normal = Vec3(double(d.x()), double(d.y()), double(d.z()));
  }
  return run;
}

}  // namespace tumble::bench

#ifdef BT_USE_DOUBLE_PRECISION
// The float64 build exports the same symbol names as the float one, so this adapter is a module
// loaded with RTLD_DEEPBIND (see narrow_phase.cc) and entered through one C symbol.
extern "C" __attribute__((visibility("default"))) void tumble_run_bullet_double(
    const std::vector<tumble::bench::PairSpec>* pairs, tumble::bench::PeerRun* out) {
  *out = tumble::bench::run_bullet(*pairs);
}
#endif
