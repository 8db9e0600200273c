// libccd's GJK+EPA (ccdGJKPenetration) and MPR (ccdMPRPenetration), double precision.
#include <ccd/ccd.h>
#include <ccd/quat.h>

#include <chrono>

#include "peer_query.h"

namespace tumble::bench {
namespace {

struct CcdObject {
  const PairSpec* pair;
  bool first;
  Mat3 rotation;
  Vec3 position;
};

void support(const void* object, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* o = static_cast<const CcdObject*>(object);
  const Vec3 local = o->rotation.transpose() * Vec3(dir->v[0], dir->v[1], dir->v[2]);
  Vec3 s = Vec3::Zero();
  if (o->pair->hulls) {
    const auto& points = o->first ? *o->pair->points_a : *o->pair->points_b;
    double best = -1e300;
    for (const Vec3& p : points)
      if (p.dot(local) > best) {
        best = p.dot(local);
        s = p;
      }
  } else {
    const Vec3& h = o->first ? o->pair->half_a : o->pair->half_b;
    s = Vec3(local.x() >= 0 ? h.x() : -h.x(), local.y() >= 0 ? h.y() : -h.y(),
             local.z() >= 0 ? h.z() : -h.z());
  }
  const Vec3 w = o->rotation * s + o->position;
  ccdVec3Set(out, w.x(), w.y(), w.z());
}

void centre(const void* object, ccd_vec3_t* out) {
  const auto* o = static_cast<const CcdObject*>(object);
  ccdVec3Set(out, o->position.x(), o->position.y(), o->position.z());
}

}  // namespace

PeerRun run_ccd(const std::vector<PairSpec>& pairs, double tolerance, bool mpr) {
  std::vector<CcdObject> a, b;
  for (const PairSpec& p : pairs) {
    a.push_back({&p, true, p.pose_a.orientation.toRotationMatrix(), p.pose_a.position});
    b.push_back({&p, false, p.pose_b.orientation.toRotationMatrix(), p.pose_b.position});
  }
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = support;
  ccd.support2 = support;
  ccd.center1 = centre;
  ccd.center2 = centre;
  ccd.max_iterations = 500;
  ccd.epa_tolerance = tolerance;
  ccd.mpr_tolerance = tolerance;
  PeerRun run;
  run.answers.resize(pairs.size());
  std::vector<ccd_real_t> depth(pairs.size());
  std::vector<ccd_vec3_t> dir(pairs.size()), pos(pairs.size());
  std::vector<int> code(pairs.size());
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < pairs.size(); ++i)
    code[i] = mpr ? ccdMPRPenetration(&a[i], &b[i], &ccd, &depth[i], &dir[i], &pos[i])
                  : ccdGJKPenetration(&a[i], &b[i], &ccd, &depth[i], &dir[i], &pos[i]);
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    run.answers[i].hit = code[i] == 0;
    run.answers[i].depth = depth[i];
    run.answers[i].normal = Vec3(dir[i].v[0], dir[i].v[1], dir[i].v[2]);
  }
  return run;
}

}  // namespace tumble::bench
