#include "run.h"

#include <chrono>
#include <cmath>

namespace tumble::report {

RunOutcome run_scene(const Engine& engine, const SceneDef& scene, const bench::PeerOptions& options,
                     const Observer& observe, double time_limit) {
  RunOutcome out;
  std::unique_ptr<bench::Simulation> simulation = engine.make(scene, options, &out.why_not);
  if (!simulation) {
    out.why_not = "not supported: " + out.why_not;
    return out;
  }
  out.ran = true;
  out.settings = simulation->settings();
  const long steps = std::lround(scene.duration / scene.dt);
  for (long s = 1; s <= steps; ++s) {
    const auto start = std::chrono::steady_clock::now();
    const bool ok = simulation->step();
    out.step_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    out.steps = s;
    if (!ok) {
      out.why_not = "engine stopped: it reported it cannot go on (buffers full or unstable)";
      out.stopped_early = true;
      return out;
    }
    if (!observe(*simulation, s * scene.dt, s == steps)) {
      out.stopped_early = s < steps;
      return out;
    }
    if (out.step_seconds > time_limit) {
      out.why_not = "too slow: over " + std::to_string(static_cast<int>(time_limit)) +
                    " s of wall time at t = " + std::to_string(s * scene.dt) + " s";
      out.stopped_early = true;
      return out;
    }
  }
  return out;
}

BodyDef ground() {
  BodyDef def;
  def.shape = HalfSpaceDef{};
  def.type = BodyType::kStatic;
  return def;
}

double kinetic_energy(const bench::BodyState& s, double mass, const Vec3& inertia) {
  const Vec3 w_body = s.orientation.conjugate() * s.angular_velocity;
  return 0.5 * mass * s.linear_velocity.squaredNorm() +
         0.5 * w_body.dot(inertia.cwiseProduct(w_body));
}

Vec3 angular_momentum(const bench::BodyState& s, const Vec3& inertia) {
  const Vec3 w_body = s.orientation.conjugate() * s.angular_velocity;
  return s.orientation * inertia.cwiseProduct(w_body);
}

bool non_finite(const bench::BodyState& s) {
  return !s.position.allFinite() || !s.orientation.coeffs().allFinite() ||
         !s.linear_velocity.allFinite() || !s.angular_velocity.allFinite();
}

}  // namespace tumble::report
