// Pairs of boxes drawn from the hard cases of box-box contact: generic overlaps, exact
// face-to-face touching, parallel edges, near-degenerate orientations, tiny depths, size ratios up
// to 1:1000, and positions 1e5 m from the origin (test_box_collision, test_box_sat).
#pragma once

#include <cmath>

#include "physics/math.h"
#include "test_support.h"

namespace tumble::testing {

struct BoxPair {
  Vec3 ha, hb;
  Pose pa, pb;
  const char* kind;
};

inline Quat small_rotation(Random& rng) {
  const double angle = std::pow(10.0, rng.uniform(-12, -3));
  return Quat(Eigen::AngleAxisd(angle, rng.direction()));
}

// The index picks the case (index % 7): generic, face-touch, parallel-edges, near-degenerate,
// tiny-depth, size-ratio, far; every fifth pair, and every far one, lies 1e5 m from the origin.
inline BoxPair make_box_pair(Random& rng, int index) {
  BoxPair p;
  p.ha = rng.vector(0.1, 2.0);
  p.hb = rng.vector(0.1, 2.0);
  p.pa.orientation = rng.rotation();
  p.pb.orientation = rng.rotation();
  const double reach = (p.ha.norm() + p.hb.norm());
  switch (index % 7) {
    case 0:  // generic: anywhere from deep overlap to clearly apart
      p.kind = "generic";
      p.pb.position = rng.direction() * rng.uniform(0, 1.1 * reach);
      break;
    case 1: {  // B's face flush on A's top face, turned about the shared normal
      p.kind = "face-touch";
      p.pa.orientation = Quat::Identity();
      p.pb.orientation = Quat(Eigen::AngleAxisd(rng.uniform(0, M_PI), Vec3::UnitZ()));
      p.pb.position = Vec3(rng.uniform(-p.ha.x(), p.ha.x()), rng.uniform(-p.ha.y(), p.ha.y()),
                           p.ha.z() + p.hb.z());
      break;
    }
    case 2: {  // edges parallel: both turned about x by 45 degrees plus a multiple of 90
      p.kind = "parallel-edges";
      const Quat q(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX()));
      p.pa.orientation = Quat::Identity();
      p.pb.orientation = q * Quat(Eigen::AngleAxisd(M_PI / 2 * rng.integer(0, 3), Vec3::UnitX()));
      p.pb.position =
          Vec3(rng.uniform(-0.5, 0.5), 0, 0) +
          Vec3(0, 0, 1) * (p.ha.z() + std::sqrt(0.5) * (p.hb.y() + p.hb.z()) - rng.uniform(0, 0.2));
      break;
    }
    case 3: {  // nearly aligned: identity perturbed by 1e-12 .. 1e-3 rad
      p.kind = "near-degenerate";
      p.pa.orientation = small_rotation(rng);
      p.pb.orientation = small_rotation(rng);
      p.pb.position =
          Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), p.ha.z() + p.hb.z() - rng.uniform(0, 0.3));
      break;
    }
    case 4: {  // tiny penetration, 1e-12 .. 1e-6 m, on a random face
      p.kind = "tiny-depth";
      p.pa.orientation = Quat::Identity();
      p.pb.orientation = Quat(Eigen::AngleAxisd(rng.uniform(0, M_PI), Vec3::UnitZ()));
      p.pb.position = Vec3(rng.uniform(-0.3, 0.3) * p.ha.x(), rng.uniform(-0.3, 0.3) * p.ha.y(),
                           p.ha.z() + p.hb.z() - std::pow(10.0, rng.uniform(-12, -6)));
      break;
    }
    case 5: {  // size ratio up to 1:1000, the small box anywhere near the big one's surface
      p.kind = "size-ratio";
      p.ha = rng.vector(0.5, 1.0);
      p.hb = rng.vector(0.0005, 0.005);
      p.pb.position = p.pa.orientation * rng.vector(-1.0, 1.0).cwiseProduct(p.ha);
      p.pb.position += p.pa.orientation * Vec3(0, 0, p.ha.z() * rng.uniform(0.99, 1.01));
      break;
    }
    default: {  // far from the origin
      p.kind = "far";
      p.pb.position = rng.direction() * rng.uniform(0, 1.1 * reach);
      break;
    }
  }
  if (index % 7 == 6 || index % 5 == 0) {
    const Vec3 far = Vec3(1e5, -1e5, 1e5);
    p.pa.position += far;
    p.pb.position += far;
  }
  return p;
}

}  // namespace tumble::testing
