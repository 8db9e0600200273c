// The joints' stability scenarios: a chain's end made heavier, a chain made longer, a motor
// driven faster, a heavy slider driven into its stop faster, and Newton's cradle with more balls;
// each until an engine fails.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include "joint_gaps.h"
#include "run.h"
#include "scenario.h"
#include "scenes/standard.h"
#include "timing.h"

namespace tumble::report {
namespace {

constexpr double kG = 9.81;

// Fails where any joint comes more than `limit` apart at any step.
Checker holds_together(const SceneDef& scene, double limit) {
  auto gaps = std::make_shared<JointGaps>(scene);
  std::vector<Vec3> start = start_positions(scene);
  return [=](const bench::Simulation& sim, double, bool) -> std::string {
    if (std::string f = common_failure(sim, start); !f.empty()) return f;
    const double gap = gaps->largest(sim);
    return gap > limit ? format("a joint came %.3g m apart", gap) : "";
  };
}

// One body joined to the world (a = the body, b = the world), 2 s, sleeping off; the caller sets
// the joint's drives and limits.
SceneDef one_joint_scene(std::string name, const BodyDef& body, JointKind kind, const Vec3& anchor,
                         const Vec3& axis) {
  SceneDef scene;
  scene.name = std::move(name);
  scene.duration = 2;
  scene.world.solver.sleeping = false;
  scene.bodies = {body};
  SceneJoint joint;
  joint.def.kind = kind;
  joint.def.anchor = anchor;
  joint.def.axis = axis;
  joint.a = 0;
  scene.joints = {joint};
  return scene;
}

Scenario chain_mass_ratio() {
  Scenario s;
  s.info = {"chain end mass ratio",
            "mass ratio of the end link",
            "a chain of 20 ball-jointed links (0.2 m, 0.5 kg) hanging from a fixed point, its end "
            "link R times heavier and pushed sideways at 1 m/s, 10 s: no joint ever 1 cm apart",
            {1, 10, 100, 1e3, 1e4, 1e5, 1e6},
            true};
  s.build = [](double ratio) {
    SceneDef scene = hanging_chain_scene(20, ratio);
    scene.duration = 10;
    return scene;
  };
  s.checker = [](double, const SceneDef& scene) { return holds_together(scene, 0.01); };
  return s;
}

Scenario chain_length() {
  Scenario s;
  s.info = {"chain length",
            "links",
            "the standard chain:N (0.2 m, 0.5 kg ball-jointed links) released level from a fixed "
            "point, 5 s: no joint ever 1 cm apart",
            {10, 30, 100, 300, 1000},
            true};
  s.build = [](double links) {
    SceneDef scene = chain_scene(static_cast<int>(links));
    scene.duration = 5;
    scene.world.solver.sleeping = false;
    return scene;
  };
  s.checker = [](double, const SceneDef& scene) { return holds_together(scene, 0.01); };
  return s;
}

// A 0.2 m, 1 kg cube on a hinge about z through its centre, its motor (100 N m at most) driving
// it from rest toward `speed`.
Scenario motor_speed() {
  Scenario s;
  s.info = {"motor speed",
            "target speed, rad/s",
            "a 0.2 m cube of 1 kg on a hinge about z through its centre, driven from rest by a "
            "motor of at most 100 N m, 2 s: it ends within 1% of the target speed, turning the "
            "right way about the hinge's axis alone (other rates under 1% of it), the hinge "
            "under 1 mm apart",
            {1, 10, 100, 1e3, 1e4},
            true};
  s.build = [](double speed) {
    BodyDef wheel;
    wheel.shape = BoxDef{Vec3::Constant(0.1)};
    wheel.mass = 1;
    wheel.position = Vec3(0, 0, 1);
    SceneDef scene =
        one_joint_scene("motor", wheel, JointKind::kHinge, wheel.position, Vec3::UnitZ());
    // The free coordinate is b's (the world's) turn against the wheel's: minus the wheel's.
    scene.joints[0].def.motor = {true, -speed, 100};
    return scene;
  };
  s.checker = [](double speed, const SceneDef& scene) {
    Checker together = holds_together(scene, 1e-3);
    return [=](const bench::Simulation& sim, double t, bool last) -> std::string {
      if (std::string f = together(sim, t, last); !f.empty()) return f;
      if (!last) return "";
      const Vec3 w = sim.body(0).angular_velocity;
      if (w.head<2>().norm() > 0.01 * speed)
        return format("turned off its axis (%.3g rad/s across it)", w.head<2>().norm());
      if (std::abs(w.z() - speed) > 0.01 * speed)
        return format("ended at %.6g rad/s about the axis", w.z());
      return "";
    };
  };
  return s;
}

// A 1000 kg, 0.5 m cube on a slider along x, free between x = -0.2 and 0.5 m, starting at 0
// toward the upper stop at `speed`.
Scenario slider_stop() {
  Scenario s;
  s.info = {"slider stop",
            "speed into the stop, m/s",
            "a 1000 kg, 0.5 m cube on a slider along x (free from -0.2 to 0.5 m) sent from 0 into "
            "its upper stop, 2 s: it reaches the stop, never passes either stop by 1 cm, never "
            "leaves the axis by 1 mm and never gains speed",
            {1, 10, 100, 1e3, 1e4},
            true};
  s.build = [](double speed) {
    BodyDef block;
    block.shape = BoxDef{Vec3::Constant(0.25)};
    block.mass = 1000;
    block.position = Vec3(0, 0, 1);
    block.linear_velocity = Vec3(speed, 0, 0);
    SceneDef scene =
        one_joint_scene("slider-stop", block, JointKind::kSlider, block.position, Vec3::UnitX());
    // The offset of b's anchor (fixed in the world) from a's (the block's): minus the block's x.
    scene.joints[0].def.limit = {true, -0.5, 0.2};
    return scene;
  };
  s.checker = [](double speed, const SceneDef& scene) {
    Checker together = holds_together(scene, 1e-3);
    auto reached = std::make_shared<double>(-1e300);
    return [=](const bench::Simulation& sim, double t, bool last) -> std::string {
      if (std::string f = together(sim, t, last); !f.empty()) return f;
      const bench::BodyState b = sim.body(0);
      const double x = b.position.x();
      *reached = std::max(*reached, x);
      if (x > 0.51 || x < -0.21) return format("passed a stop (x = %.3g m)", x);
      if (b.linear_velocity.norm() > 1.01 * speed)
        return format("gained speed (%.6g m/s)", b.linear_velocity.norm());
      if (last && *reached < 0.49)
        return format("never reached its stop (x at most %.3g m)", *reached);
      return "";
    };
  };
  return s;
}

// A 1 m, 2 kg rod hinged at one end about y, level, sent down at `speed` toward a stop 30 degrees
// below level.
Scenario hinge_stop() {
  Scenario s;
  s.info = {"hinge stop",
            "speed into the stop, rad/s",
            "a 1 m rod of 2 kg hinged at one end about y, free from 0.1 rad above level to 30 "
            "degrees below, sent down from level, 2 s: it ends resting within 1 degree of the "
            "stop (gravity holds it there), the hinge never 1 cm apart",
            {1, 10, 100, 1e3},
            true};
  s.build = [](double speed) {
    BodyDef rod;
    rod.shape = BoxDef{Vec3(0.5, 0.025, 0.025)};
    rod.mass = 2;
    rod.position = Vec3(0.5, 0, 1);
    rod.angular_velocity = Vec3(0, speed, 0);  // +y turns +x down
    rod.linear_velocity = Vec3(0, 0, -0.5 * speed);
    SceneDef scene =
        one_joint_scene("hinge-stop", rod, JointKind::kHinge, Vec3(0, 0, 1), Vec3::UnitY());
    // b's (the world's) turn against the rod's: minus the rod's turn down.
    scene.joints[0].def.limit = {true, -std::numbers::pi / 6, 0.1};
    return scene;
  };
  s.checker = [](double, const SceneDef& scene) {
    Checker together = holds_together(scene, 0.01);
    return [=](const bench::Simulation& sim, double t, bool last) -> std::string {
      if (std::string f = together(sim, t, last); !f.empty()) return f;
      if (!last) return "";
      const Vec3 along = sim.body(0).orientation * Vec3::UnitX();
      const double down = std::atan2(-along.z(), along.x());
      const double off = down - std::numbers::pi / 6;
      if (std::abs(off) > std::numbers::pi / 180)
        return format("ended %.3g degrees from its stop", off * 180 / std::numbers::pi);
      return "";
    };
  };
  return s;
}

// `balls` balls (5 cm, 1 kg, restitution 1, no friction) on hinges about y 1 m above their
// centres, hanging touching; the first pulled out 45 degrees and released.
Scenario cradle() {
  Scenario s;
  s.info = {"Newton's cradle",
            "balls",
            "balls of 5 cm and 1 kg (restitution 1, no friction) hanging touching on hinges 1 m "
            "above them, the first released from 45 degrees, 1.5 s: the last ball leaves at 90% "
            "of the first's impact speed or more, and the energy never grows by 1% of what the "
            "first ball brought",
            {2, 3, 5, 10, 20},
            true};
  s.build = [](double count) {
    SceneDef scene = hinged_cradle_scene(static_cast<int>(count));
    scene.name = "cradle";
    return scene;
  };
  s.checker = [](double, const SceneDef& scene) {
    const bench::PeerScene peer = bench::peer_scene(scene);
    const double brought = kG * (1 - std::cos(std::numbers::pi / 4));  // 1 kg, 1 m
    const double impact = std::sqrt(2 * brought);
    double initial = 0;
    for (const BodyDef& def : scene.bodies)
      initial += def.mass * kG * def.position.z();
    std::vector<Vec3> start = start_positions(scene);
    auto fastest_last = std::make_shared<double>(0);
    return [=](const bench::Simulation& sim, double, bool last) -> std::string {
      if (std::string f = common_failure(sim, start); !f.empty()) return f;
      double energy = 0;
      for (std::size_t i = 0; i < sim.body_count(); ++i) {
        const bench::BodyState b = sim.body(i);
        energy +=
            kinetic_energy(b, peer.mass[i], peer.inertia[i]) + peer.mass[i] * kG * b.position.z();
      }
      if (energy > initial + 0.01 * brought)
        return format("energy grew by %.3g of what the first ball brought",
                      (energy - initial) / brought);
      *fastest_last =
          std::max(*fastest_last, sim.body(sim.body_count() - 1).linear_velocity.norm());
      if (last && *fastest_last < 0.9 * impact)
        return format("the last ball left at %.3g of the impact speed", *fastest_last / impact);
      return "";
    };
  };
  return s;
}

}  // namespace

std::vector<Scenario> joint_scenarios() {
  return {chain_mass_ratio(), chain_length(), motor_speed(), hinge_stop(), slider_stop(), cradle()};
}

namespace {

// One engine's run of a cost scene, stepped by turns with the others' (measure_joint_cost).
struct CostRun {
  std::unique_ptr<bench::Simulation> sim;
  CostRow row;
  double gap_sum = 0;
  double seconds = 0;  // in the timed steps, for the time limit
};

}  // namespace

std::vector<CostRow> measure_joint_cost(const std::vector<Engine>& engines,
                                        const StabilityOptions& options) {
  std::vector<CostRow> rows;
  const char* specs[] = {"chain:100", "ragdolls:8"};
  const std::size_t total = std::size(specs) * engines.size();
  for (const char* spec : specs) {
    SceneDef scene = standard_scene(spec).value();
    scene.duration = options.quick ? 0.5 : 5;
    // Awake, and without the ragdolls' joint friction (it lets them sleep, and no peer adapter
    // maps it): every engine steps the same bodies and joints the whole time.
    scene.world.solver.sleeping = false;
    for (SceneJoint& joint : scene.joints)
      joint.def.friction = 0;
    const JointGaps gaps(scene);
    bench::PeerOptions peer_options;
    peer_options.sleeping = false;
    std::vector<CostRun> runs(engines.size());
    std::vector<bench::TurnTimes> times(engines.size());
    std::size_t reference = runs.size();  // Bullet float's, where it runs
    for (std::size_t e = 0; e < engines.size(); ++e) {
      CostRun& run = runs[e];
      run.row = CostRow{spec, engines[e].label, "", 0, 0, 0, ""};
      std::string why_not;
      run.sim = engines[e].make(scene, peer_options, &why_not);
      if (!run.sim) {
        run.row.note = "not supported: " + why_not;
        times[e].stopped = true;
        continue;
      }
      run.row.settings = run.sim->settings();
      if (engines[e].label == "Bullet float") reference = e;
    }
    // The engines take turns (bench/timing.h): run one after the other, the ratios of two
    // engines' times moved by a fifth between reports.
    const long steps = std::lround(scene.duration / scene.dt);
    bench::take_turns(
        std::span<bench::TurnTimes>(times), steps,
        [&](std::size_t e, long) {
          if (runs[e].sim->step()) return true;
          runs[e].row.note =
              "engine stopped: it reported it cannot go on (buffers full or unstable)";
          return false;
        },
        [&](std::size_t e, long k, double ms) {
          // The cost's error beside it (outside the timed steps): an iterative solver's chain is
          // cheap where it has come apart.
          CostRun& run = runs[e];
          const double gap = gaps.largest(*run.sim);
          run.row.worst_gap = std::max(run.row.worst_gap, gap);
          run.gap_sum += gap;
          if (!std::isnan(ms)) run.seconds += 1e-3 * ms;
          if (run.seconds <= options.time_limit) return true;
          run.row.note =
              "too slow: over " + std::to_string(static_cast<int>(options.time_limit)) +
              " s of wall time at t = " + std::to_string(static_cast<double>(k + 1) * scene.dt) +
              " s";
          return false;
        });
    for (std::size_t e = 0; e < runs.size(); ++e) {
      CostRun& run = runs[e];
      CostRow& row = run.row;
      const bench::TurnTimes& time = times[e];
      if (row.note.empty() && !time.step_ms.empty()) {
        row.ms_per_step = 1e3 * run.seconds / static_cast<double>(time.step_ms.size());
        row.mean_gap = run.gap_sum / static_cast<double>(time.steps);
        if (reference < runs.size() && runs[reference].row.note.empty())
          row.ratio_to_reference = bench::median_turn_ratio(time, times[reference]);
      } else {
        row.worst_gap = 0;
      }
      rows.push_back(row);
      if (options.progress)
        options.progress(std::string("cost ") + spec + ", " + row.engine, rows.size(), total);
    }
  }
  return rows;
}

}  // namespace tumble::report
