// Narrow-phase table: box-box and hull-hull penetration queries, ours beside libccd and Bullet on
// identical pairs; and capsule-box, the closed form beside our GJK on the same box as a hull.
// Reference: boxes, a brute-force 15-axis SAT (tests/test_support.h); hulls, our SAT forced with
// kSat (checked against GJK/EPA and brute force in tests). Prints microseconds per query (median of
// 3 timed passes), failures (no hit reported where the reference overlaps by > 1e-6 of the size),
// depth error relative to the smaller shape, and normal error where the normal is unique.
#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>

#include "epa.h"
#include "peers/peer_query.h"
#include "physics/collision.h"
#include "test_support.h"

using namespace tumble;
using namespace tumble::bench;
using tumble::testing::Random;

namespace {

struct Reference {
  double depth;
  Vec3 normal;
  bool unique_normal;
  double size;  // the smaller shape's largest half extent
};

struct Method {
  std::string name;
  std::function<PeerRun(const std::vector<PairSpec>&)> run;
};

Shape shape_of(const PairSpec& p, bool first) {
  if (p.hulls) return Shape::create(HullDef{first ? *p.points_a : *p.points_b}).value();
  return Shape::create(BoxDef{first ? p.half_a : p.half_b}).value();
}

PeerRun run_ours(const std::vector<PairSpec>& pairs, NarrowPhaseMethod method) {
  std::vector<Shape> a, b;
  for (const auto& p : pairs) {
    a.push_back(shape_of(p, true));
    b.push_back(shape_of(p, false));
  }
  CollisionSettings settings;
  settings.method = method;
  std::vector<ContactManifold> out(pairs.size());
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < pairs.size(); ++i)
    collide(a[i], pairs[i].pose_a, b[i], pairs[i].pose_b, settings, &out[i]);
  PeerRun run;
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const auto& m : out)
    run.answers.push_back({m.count > 0, m.depth, m.normal});
  return run;
}

// GJK + EPA alone (no manifold), the work the peers' queries do.
PeerRun run_ours_depth_only(const std::vector<PairSpec>& pairs) {
  std::vector<Shape> a, b;
  for (const auto& p : pairs) {
    a.push_back(shape_of(p, true));
    b.push_back(shape_of(p, false));
  }
  PeerRun run;
  run.answers.resize(pairs.size());
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const Mat3 ra = pairs[i].pose_a.orientation.toRotationMatrix();
    const Mat3 rb = pairs[i].pose_b.orientation.toRotationMatrix();
    const Mat3 r = ra.transpose() * rb;
    const Vec3 t = ra.transpose() * (pairs[i].pose_b.position - pairs[i].pose_a.position);
    const PolyhedronSupport sa{a[i].polyhedron()}, sb{b[i].polyhedron()};
    const Transformed<PolyhedronSupport> placed{sb, r, t};
    GjkSettings gs;
    gs.tolerance = 1e-12 * std::max(a[i].size(), b[i].size());
    const GjkResult g = gjk_distance(sa, placed, t, gs);
    if (g.status != GjkStatus::kIntersecting && g.distance > gs.tolerance) continue;
    EpaSettings es;
    es.tolerance = gs.tolerance;
    const EpaResult e = epa_penetration(sa, placed, g.simplex, es);
    run.answers[i] = {true, e.depth, ra * e.normal};
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

#ifdef TUMBLE_HAVE_PEERS
PeerRun run_bullet_double_module(const std::vector<PairSpec>& pairs) {
  using Entry = void (*)(const std::vector<PairSpec>*, PeerRun*);
  static Entry entry = [] {
    void* module = dlopen(TUMBLE_BULLET_DOUBLE_MODULE, RTLD_NOW | RTLD_LOCAL | RTLD_DEEPBIND);
    if (!module) {
      std::fprintf(stderr, "cannot load %s: %s\n", TUMBLE_BULLET_DOUBLE_MODULE, dlerror());
      std::exit(1);
    }
    return reinterpret_cast<Entry>(dlsym(module, "tumble_run_bullet_double"));
  }();
  PeerRun run;
  entry(&pairs, &run);
  return run;
}
#endif

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * (v.size() - 1))];
}

void report(const char* title, const std::vector<PairSpec>& pairs,
            const std::vector<Reference>& ref, const std::vector<Method>& methods) {
  std::printf("\n%s: %zu overlapping pairs, one thread\n", title, pairs.size());
  std::printf(
      "| method | us/query | failures | depth error p99 / max | normal error p99 / max (deg) |\n");
  std::printf("|---|---|---|---|---|\n");
  // Calibration: B straight above A, overlapping 0.1: the normal must point up (+z).
  std::vector<Vec3> cube;
  for (int i = 0; i < 8; ++i)
    cube.emplace_back((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5);
  PairSpec calibration;
  calibration.hulls = pairs[0].hulls;
  calibration.half_a = calibration.half_b = Vec3::Constant(0.5);
  calibration.points_a = calibration.points_b = &cube;
  calibration.pose_b.position = Vec3(0.05, 0.02, 0.9);
  for (const Method& m : methods) {
    const double sign = m.run({calibration}).answers[0].normal.z() < 0 ? -1.0 : 1.0;
    std::vector<double> times;
    PeerRun run;
    for (int pass = 0; pass < 3; ++pass) {
      run = m.run(pairs);
      times.push_back(run.seconds);
    }
    std::sort(times.begin(), times.end());
    int failures = 0;
    std::vector<double> depth_error, normal_error;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const PeerAnswer& a = run.answers[i];
      if (!a.hit) {
        if (ref[i].depth > 1e-6 * ref[i].size) ++failures;
        continue;
      }
      depth_error.push_back(std::abs(a.depth - ref[i].depth) / ref[i].size);
      if (ref[i].unique_normal) {
        const Vec3 n = sign * a.normal.normalized();
        normal_error.push_back(std::acos(std::clamp(n.dot(ref[i].normal), -1.0, 1.0)) * 180 / M_PI);
      }
    }
    std::printf("| %s | %.2f | %d | %.1e / %.1e | %.1e / %.1e |\n", m.name.c_str(),
                times[1] / pairs.size() * 1e6, failures, percentile(depth_error, 0.99),
                percentile(depth_error, 1.0), percentile(normal_error, 0.99),
                percentile(normal_error, 1.0));
  }
}

// Capsule-box pairs, the closed forms (segment.h) against GJK and EPA on the same box as a hull.
// Where the capsule's core stays outside the box (a capsule resting on or against a box), the
// reference is the core's squared distance from the box, convex along the core, so that a ternary
// search over the core's parameter finds it to rounding (test_support.h). Where the core has
// entered the box (a terrain's edge pressed into a box resting on it is one), the error is how far
// from touching the capsule is once moved back by the depth along the normal, by the same search.
void report_capsule_box(int count, bool core_inside, Random& rng) {
  struct CapsulePair {
    double radius, half_height;
    Vec3 half;
    Pose capsule, box;
    double depth;
  };
  std::vector<CapsulePair> pairs;
  while (static_cast<int>(pairs.size()) < count) {
    CapsulePair p;
    p.radius = rng.uniform(0.03, 0.3);
    p.half_height = rng.uniform(0.05, 0.6);
    p.half = rng.vector(0.1, 1.0);
    const double reach = core_inside ? p.half.minCoeff() : p.half.norm() + p.half_height + p.radius;
    p.capsule = {rng.direction() * rng.uniform(0, reach), rng.rotation()};
    p.box = {Vec3::Zero(), rng.rotation()};
    const Mat3 to_box = p.box.orientation.toRotationMatrix().transpose();
    const Vec3 axis = p.capsule.orientation * Vec3(0, 0, p.half_height);
    const Vec3 core_p = to_box * (p.capsule.position - axis),
               core_q = to_box * (p.capsule.position + axis);
    const double distance =
        std::sqrt(testing::segment_box_squared_distance_by_search(core_p, core_q, p.half));
    // (Touching with the core outside, or the core inside.)
    if (core_inside ? distance > 0 : distance < 1e-3 || distance >= p.radius) continue;
    p.depth = p.radius - distance;
    pairs.push_back(p);
  }
  std::vector<Shape> capsules, boxes, hulls;
  for (const CapsulePair& p : pairs) {
    capsules.push_back(Shape::create(CapsuleDef{p.radius, p.half_height}).value());
    boxes.push_back(Shape::create(BoxDef{p.half}).value());
    hulls.push_back(Shape::create(HullDef{testing::box_corners(p.half)}).value());
  }
  std::printf("\nCapsule-box (core %s the box): %zu touching pairs, one thread\n",
              core_inside ? "inside" : "outside", pairs.size());
  std::printf("| method | us/query | failures | %s p99 / max |\n|---|---|---|---|\n",
              core_inside ? "gap once moved back (of the radius)" : "depth error");
  for (const auto& [name, others] :
       {std::pair{"Tumble capsule-box, closed form + manifold", &boxes},
        std::pair{core_inside ? "Tumble capsule-hull (the box as a hull: GJK, EPA) + manifold"
                              : "Tumble capsule-hull (the box as a hull: GJK) + manifold",
                  &hulls}}) {
    std::vector<ContactManifold> out(pairs.size());
    std::vector<double> times;
    for (int pass = 0; pass < 3; ++pass) {
      const auto start = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < pairs.size(); ++i)
        collide(capsules[i], pairs[i].capsule, (*others)[i], pairs[i].box, {}, &out[i]);
      times.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::sort(times.begin(), times.end());
    int failures = 0;
    std::vector<double> depth_error;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      if (out[i].count == 0) {
        ++failures;
        continue;
      }
      if (!core_inside) {
        depth_error.push_back(std::abs(out[i].depth - pairs[i].depth) / pairs[i].radius);
        continue;
      }
      const CapsulePair& p = pairs[i];
      const Vec3 moved = p.capsule.position - out[i].depth * out[i].normal;
      const Mat3 to_box = p.box.orientation.toRotationMatrix().transpose();
      const Vec3 axis = p.capsule.orientation * Vec3(0, 0, p.half_height);
      const double distance = std::sqrt(testing::segment_box_squared_distance_by_search(
          to_box * (moved - axis), to_box * (moved + axis), p.half));
      depth_error.push_back(std::abs(distance - p.radius) / p.radius);
    }
    std::printf("| %s | %.3f | %d | %.1e / %.1e |\n", name, times[1] / pairs.size() * 1e6, failures,
                percentile(depth_error, 0.99), percentile(depth_error, 1.0));
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int box_count = argc > 1 ? std::atoi(argv[1]) : 100000;
  const int hull_count = box_count / 5;
  Random rng(2026);

  std::vector<PairSpec> boxes;
  std::vector<Reference> box_ref;
  while (static_cast<int>(boxes.size()) < box_count) {
    PairSpec p;
    p.half_a = rng.vector(0.1, 2.0);
    p.half_b = rng.vector(0.1, 2.0);
    p.pose_a.orientation = rng.rotation();
    p.pose_b.orientation = rng.rotation();
    p.pose_b.position = rng.direction() * rng.uniform(0, p.half_a.norm() + p.half_b.norm());
    const auto r = testing::reference_box_sat(p.half_a, p.pose_a, p.half_b, p.pose_b);
    if (r.separation >= 0) continue;
    const double size = std::min(p.half_a.maxCoeff(), p.half_b.maxCoeff());
    boxes.push_back(p);
    box_ref.push_back({-r.separation, r.axis, r.runner_up < r.separation - 1e-6 * size, size});
  }

  // Hull clouds live in one arena so that PairSpec pointers stay valid.
  std::vector<std::vector<Vec3>> clouds;
  clouds.reserve(2 * hull_count + 8);
  std::vector<PairSpec> hulls;
  std::vector<Reference> hull_ref;
  while (static_cast<int>(hulls.size()) < hull_count) {
    auto cloud = [&]() {
      std::vector<Vec3> points;
      const Vec3 scale = rng.vector(0.2, 1.5);
      const int n = rng.integer(8, 64);
      for (int i = 0; i < n; ++i)
        points.push_back(rng.vector(-1, 1).cwiseProduct(scale));
      return points;
    };
    auto a = Shape::create(HullDef{cloud()});
    auto b = Shape::create(HullDef{cloud()});
    if (!a || !b) continue;
    PairSpec p;
    p.hulls = true;
    p.pose_a.orientation = rng.rotation();
    p.pose_b.orientation = rng.rotation();
    p.pose_b.position = rng.direction() * rng.uniform(0, 2.0);
    ContactManifold m;
    CollisionSettings exact;
    exact.method = NarrowPhaseMethod::kSat;
    collide(a.value(), p.pose_a, b.value(), p.pose_b, exact, &m);
    if (m.count == 0 || m.depth <= 0) continue;
    clouds.push_back(a.value().polyhedron()->vertices);
    p.points_a = &clouds.back();
    clouds.push_back(b.value().polyhedron()->vertices);
    p.points_b = &clouds.back();
    hulls.push_back(p);
    hull_ref.push_back({m.depth, m.normal, true, std::min(a.value().size(), b.value().size())});
  }

  std::vector<Method> methods = {
      {"Tumble auto + manifold (default)",
       [](const auto& p) { return run_ours(p, NarrowPhaseMethod::kAuto); }},
      {"Tumble SAT + manifold", [](const auto& p) { return run_ours(p, NarrowPhaseMethod::kSat); }},
      {"Tumble GJK/EPA + manifold",
       [](const auto& p) { return run_ours(p, NarrowPhaseMethod::kGjkEpa); }},
      {"Tumble GJK+EPA, depth only", run_ours_depth_only},
#ifdef TUMBLE_HAVE_PEERS
      {"libccd GJK+EPA, default tolerance", [](const auto& p) { return run_ccd(p, 1e-4, false); }},
      {"libccd GJK+EPA, tolerance 1e-10", [](const auto& p) { return run_ccd(p, 1e-10, false); }},
      {"libccd MPR", [](const auto& p) { return run_ccd(p, 1e-10, true); }},
      {"Bullet GJK/EPA float, margin 0", run_bullet_float},
      {"Bullet GJK/EPA double, margin 0", run_bullet_double_module},
#endif
  };
  std::printf("Narrow phase, seed 2026 (bench/narrow_phase.cc)\n");
#ifndef TUMBLE_HAVE_PEERS
  std::printf("(peers not built: configure with -DTUMBLE_BENCH_PEERS=ON, as `make bench` does)\n");
#endif
  report("Box-box", boxes, box_ref, methods);
  report("Hull-hull (8-64 points)", hulls, hull_ref, methods);
  report_capsule_box(box_count, false, rng);
  report_capsule_box(box_count / 10, true, rng);
  return 0;
}
