#include "stability.h"

#include <cmath>
#include <cstdio>
#include <memory>

#include "run.h"
#include "scenario.h"
#include "scenes/standard.h"

namespace tumble::report {

std::string format(const char* pattern, double x) {
  char text[160];
  std::snprintf(text, sizeof text, pattern, x);
  return text;
}

std::vector<Vec3> start_positions(const SceneDef& scene) {
  std::vector<Vec3> out;
  for (const BodyDef& def : scene.bodies)
    if (def.type == BodyType::kDynamic) out.push_back(def.position);
  return out;
}

std::string common_failure(const bench::Simulation& sim, const std::vector<Vec3>& start) {
  for (std::size_t i = 0; i < sim.body_count(); ++i) {
    const bench::BodyState s = sim.body(i);
    if (non_finite(s)) return "NaN in the state";
    if ((s.position - start[i]).norm() > 1000) return "escaped (a body 1 km from its start)";
  }
  return "";
}

namespace {

BodyDef box(const Vec3& size, const Vec3& position, double mass) {
  BodyDef def;
  def.shape = BoxDef{0.5 * size};
  def.position = position;
  def.mass = mass;
  return def;
}

BodyDef fixed_box(const Vec3& size, const Vec3& position) {
  BodyDef def = box(size, position, 0);
  def.type = BodyType::kStatic;
  return def;
}

SceneDef scene_of(std::string name, double duration, std::vector<BodyDef> bodies,
                  bool sleeping = false) {
  SceneDef scene;
  scene.name = std::move(name);
  scene.duration = duration;
  scene.world.solver.sleeping = sleeping;
  scene.bodies = std::move(bodies);
  return scene;
}

// Fails when body `i` ends displaced beyond the bounds (checked at the end of the run).
Checker stays_put(std::vector<Vec3> start, std::size_t i, double horizontal, double down,
                  std::string what) {
  return [=](const bench::Simulation& sim, double, bool last) -> std::string {
    if (std::string f = common_failure(sim, start); !f.empty()) return f;
    if (!last) return "";
    const Vec3 d = sim.body(i).position - start[i];
    if (-d.z() > down) return what + format(" sank or fell %.3g m", -d.z());
    if (d.head<2>().norm() > horizontal)
      return what + format(" moved %.3g m sideways", d.head<2>().norm());
    return "";
  };
}

Scenario mass_ratio(bool heavy_on_top) {
  Scenario s;
  s.info = {heavy_on_top ? "mass-ratio heavy on light" : "mass-ratio light on heavy",
            "mass ratio",
            "3 unit boxes stacked, 5 s: the top box sinks less than 2 cm and drifts less than 5 cm",
            {10, 100, 1e3, 1e4, 1e5, 1e6}};
  s.build = [heavy_on_top](double ratio) {
    std::vector<BodyDef> bodies = {ground()};
    for (int k = 0; k < 3; ++k) {
      const bool heavy = heavy_on_top ? k == 2 : k == 0;
      bodies.push_back(box(Vec3::Ones(), Vec3(0, 0, 0.5 + k), heavy ? ratio : 1));
    }
    return scene_of("mass-ratio", 5, bodies);
  };
  s.checker = [](double, const SceneDef& scene) {
    return stays_put(start_positions(scene), 2, 0.05, 0.02, "top box");
  };
  return s;
}

Scenario tower(bool sleeping) {
  Scenario s;
  s.info = {sleeping ? "tower, sleeping on" : "tower, sleeping off",
            "boxes",
            "unit boxes stacked exactly, 10 s: the top box drifts less than 5 cm sideways and "
            "sinks less than 5 cm",
            {10, 20, 30, 50, 70, 100}};
  s.build = [sleeping](double height) {
    SceneDef scene = tower_scene(static_cast<int>(height));
    scene.duration = 10;
    scene.world.solver.sleeping = sleeping;
    return scene;
  };
  s.checker = [](double height, const SceneDef& scene) {
    return stays_put(start_positions(scene), static_cast<std::size_t>(height) - 1, 0.05, 0.05,
                     "top box");
  };
  return s;
}

Scenario pyramid() {
  Scenario s;
  s.info = {"pyramid",
            "base boxes",
            "S2 pyramid, sleeping off, 10 s: no box moves more than 10 cm",
            {10, 20, 30, 40, 50}};
  s.build = [](double base) {
    SceneDef scene = pyramid_scene(static_cast<int>(base));
    scene.duration = 10;
    scene.world.solver.sleeping = false;
    return scene;
  };
  s.checker = [](double, const SceneDef& scene) {
    std::vector<Vec3> start = start_positions(scene);
    return [start](const bench::Simulation& sim, double, bool last) -> std::string {
      if (std::string f = common_failure(sim, start); !f.empty()) return f;
      if (!last) return "";
      double largest = 0;
      for (std::size_t i = 0; i < sim.body_count(); ++i)
        largest = std::max(largest, (sim.body(i).position - start[i]).norm());
      return largest > 0.1 ? format("a box moved %.3g m", largest) : "";
    };
  };
  return s;
}

Scenario fast_thin(double wall) {
  Scenario s;
  s.info = {format("fast 10 cm cube, wall %g cm", wall * 100),
            "speed, m/s",
            "no gravity, the cube starts 2 m before the wall, 0.5 s: it never ends past the "
            "wall's far side",
            {10, 100, 300, 1000, 3000, 5000}};
  s.ccd = true;
  s.build = [wall](double speed) {
    BodyDef cube = box(Vec3::Constant(0.1), Vec3(-2, 0, 0), 1);
    cube.linear_velocity = Vec3(speed, 0, 0);
    SceneDef scene =
        scene_of("fast-thin", 0.5, {cube, fixed_box(Vec3(wall, 10, 10), Vec3::Zero())});
    scene.world.gravity = Vec3::Zero();
    return scene;
  };
  s.checker = [wall](double, const SceneDef& scene) {
    std::vector<Vec3> start = start_positions(scene);
    return [start, wall](const bench::Simulation& sim, double, bool) -> std::string {
      if (std::string f = common_failure(sim, start); !f.empty()) return f;
      const double x = sim.body(0).position.x();
      return x - 0.05 > wall / 2 ? format("tunnelled (x = %.3g m)", x) : "";
    };
  };
  return s;
}

Scenario overlap() {
  Scenario s;
  s.info = {"initial overlap",
            "overlap, %",
            "two unit boxes on the ground spawned overlapping, 3 s: apart by then, both slower "
            "than 0.1 m/s, neither thrown above 1 m",
            {10, 30, 50, 70, 90}};
  s.build = [](double percent) {
    return scene_of("overlap", 3,
                    {ground(), box(Vec3::Ones(), Vec3(0, 0, 0.5), 1),
                     box(Vec3::Ones(), Vec3(1 - percent / 100, 0, 0.5), 1)});
  };
  s.checker = [](double, const SceneDef& scene) {
    std::vector<Vec3> start = start_positions(scene);
    return [start](const bench::Simulation& sim, double, bool last) -> std::string {
      if (std::string f = common_failure(sim, start); !f.empty()) return f;
      for (std::size_t i = 0; i < 2; ++i)
        if (sim.body(i).position.z() > 1.5) return "a box was thrown up";
      if (!last) return "";
      const double apart = (sim.body(1).position - sim.body(0).position).head<2>().norm();
      if (apart < 0.99) return format("still overlapping (centres %.3g m apart)", apart);
      for (std::size_t i = 0; i < 2; ++i)
        if (sim.body(i).linear_velocity.norm() > 0.1)
          return format("kept speed from the push (%.3g m/s)", sim.body(i).linear_velocity.norm());
      return "";
    };
  };
  return s;
}

// Precision, not just rest: a box resting without motion passes in any arithmetic, so it slides.
Scenario far_from_origin() {
  Scenario s;
  s.info = {"far from the origin",
            "distance, m",
            "a unit box sliding at 1 m/s (mu 0.5) on a fixed 8x8x1 m box, both at (d, d, d), "
            "3 s: it stops within 1 cm of v^2/(2 mu g) = 0.102 m and stays on the surface to 1 cm",
            {1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7}};
  s.build = [](double d) {
    const Vec3 at = Vec3::Constant(d);
    BodyDef slider = box(Vec3::Ones(), at + Vec3(-2, 0, 1), 1);
    slider.linear_velocity = Vec3(1, 0, 0);
    return scene_of("far", 3, {fixed_box(Vec3(8, 8, 1), at), slider});
  };
  s.checker = [](double, const SceneDef& scene) {
    std::vector<Vec3> start = start_positions(scene);
    return [start](const bench::Simulation& sim, double, bool last) -> std::string {
      if (std::string f = common_failure(sim, start); !f.empty()) return f;
      if (!last) return "";
      const Vec3 d = sim.body(0).position - start[0];
      const double exact = 1.0 / (2 * 0.5 * 9.81);
      if (std::abs(d.z()) > 0.01) return format("left the surface by %.3g m", d.z());
      if (std::abs(d.x() - exact) > 0.01)
        return format("stopped %.3g m from the exact distance", d.x() - exact);
      return "";
    };
  };
  return s;
}

Scenario spin_rate() {
  Scenario s;
  s.info = {"spin rate",
            "rad/s",
            "a free 1x2x3 box spinning about (0.01, 1, 0.01), no gravity, 5 s: kinetic energy "
            "never above its start by 1e-6, |L| within 1%",
            {1, 10, 100, 1e3, 1e4}};
  s.build = [](double rate) {
    SceneDef scene = spin_scene();
    scene.duration = 5;
    scene.bodies[0].angular_velocity = Vec3(0.01, 1, 0.01) * rate;
    return scene;
  };
  s.checker = [](double, const SceneDef& scene) {
    const bench::PeerScene peer = bench::peer_scene(scene);
    const double mass = peer.mass[0];
    const Vec3 inertia = peer.inertia[0];
    struct State {
      double energy = -1, momentum = 0;
    };
    auto state = std::make_shared<State>();
    std::vector<Vec3> start = start_positions(scene);
    return [=](const bench::Simulation& sim, double, bool) -> std::string {
      if (std::string f = common_failure(sim, start); !f.empty()) return f;
      const bench::BodyState b = sim.body(0);
      const double energy = kinetic_energy(b, mass, inertia);
      const double momentum = angular_momentum(b, inertia).norm();
      if (state->energy < 0) {
        state->energy = energy;
        state->momentum = momentum;
        return "";
      }
      if (energy > state->energy * (1 + 1e-6))
        return format("energy grew by %.3g", energy / state->energy - 1);
      if (std::abs(momentum / state->momentum - 1) > 0.01)
        return format("|L| drifted by %.3g", momentum / state->momentum - 1);
      return "";
    };
  };
  return s;
}

Scenario size_ratio(bool equal_density) {
  Scenario s;
  s.info = {equal_density ? "size ratio, equal density" : "size ratio, equal mass",
            "size ratio",
            "a small box (edge 1/ratio m) resting on a unit box on the ground, 3 s: it stays "
            "within a tenth of its edge of where it was",
            {1, 10, 100, 1e3, 1e4}};
  s.build = [equal_density](double ratio) {
    const double edge = 1 / ratio;
    const double small_mass = equal_density ? edge * edge * edge : 1;
    return scene_of("size-ratio", 3,
                    {ground(), box(Vec3::Ones(), Vec3(0, 0, 0.5), 1),
                     box(Vec3::Constant(edge), Vec3(0, 0, 1 + edge / 2), small_mass)});
  };
  s.checker = [](double ratio, const SceneDef& scene) {
    std::vector<Vec3> start = start_positions(scene);
    const double edge = 1 / ratio;
    return [start, edge](const bench::Simulation& sim, double, bool last) -> std::string {
      if (std::string f = common_failure(sim, start); !f.empty()) return f;
      const double moved = (sim.body(1).position - start[1]).norm();
      if (last && moved > 0.1 * edge)
        return format("the small box moved %.3g of its edge", moved / edge);
      return "";
    };
  };
  return s;
}

// 1 face on face, 2 edge on edge (crossed), 3 vertex on vertex: a unit box exactly touching a
// fixed one in that configuration.
Scenario degenerate() {
  Scenario s;
  s.info = {"degenerate contacts",
            "case (1 face-face, 2 edge-edge, 3 vertex-vertex)",
            "a unit box exactly touching a fixed unit box, 3 s: no NaN, nothing thrown, energy "
            "(kinetic + potential) never above its start by 1 mJ",
            {1, 2, 3}};
  s.build = [](double which) {
    Quat lower = Quat::Identity(), upper = Quat::Identity();
    double reach = 0.5;  // height of the fixed box's top feature above its centre
    if (which == 2) {
      lower = Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX()));
      upper = Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY()));
      reach = std::sqrt(0.5);
    } else if (which == 3) {
      // The body diagonal (1, 1, 1) turned onto z: a vertex up, the other box's vertex down.
      lower = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3::UnitZ());
      upper = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), -Vec3::UnitZ());
      reach = std::sqrt(0.75);
    }
    BodyDef base = fixed_box(Vec3::Ones(), Vec3(0, 0, 2));
    base.orientation = lower;
    BodyDef top = box(Vec3::Ones(), Vec3(0, 0, 2 + 2 * reach), 1);
    top.orientation = upper;
    return scene_of("degenerate", 3, {base, top});
  };
  s.checker = [](double, const SceneDef& scene) {
    std::vector<Vec3> start = start_positions(scene);
    const double g = -scene.world.gravity.z();
    const bench::PeerScene peer = bench::peer_scene(scene);
    const double mass = peer.mass.back();
    const Vec3 inertia = peer.inertia.back();
    const double initial = mass * g * start[0].z();
    return [=](const bench::Simulation& sim, double, bool) -> std::string {
      if (std::string f = common_failure(sim, start); !f.empty()) return f;
      const bench::BodyState b = sim.body(0);
      const double energy = kinetic_energy(b, mass, inertia) + mass * g * b.position.z();
      if (energy > initial + 1e-3) return format("energy grew by %.3g J", energy - initial);
      return "";
    };
  };
  return s;
}

std::vector<Scenario> scenarios(bool quick) {
  std::vector<Scenario> all = {
      mass_ratio(true), mass_ratio(false), tower(false), tower(true),       pyramid(),
      fast_thin(0.01),  fast_thin(0.1),    overlap(),    far_from_origin(), spin_rate(),
      size_ratio(true), size_ratio(false), degenerate()};
  for (Scenario& joints : joint_scenarios())
    all.push_back(std::move(joints));
  if (quick) {
    // Fewer values and shorter runs: the quick report checks the machinery, not the limits.
    for (Scenario& s : all) {
      std::vector<double> few;
      for (std::size_t i = 0; i < s.info.values.size(); i += 2)
        few.push_back(s.info.values[i]);
      if (s.info.name.rfind("tower", 0) == 0 || s.info.name == "pyramid") few = {10};
      if (s.info.joints) few = {s.info.values[0], s.info.values[1]};
      s.info.values = few;
    }
  }
  return all;
}

}  // namespace

std::vector<ScenarioInfo> stability_scenarios(bool quick) {
  std::vector<ScenarioInfo> out;
  for (const Scenario& s : scenarios(quick))
    out.push_back(s.info);
  return out;
}

std::vector<StabilityRow> measure_stability(const std::vector<Engine>& engines,
                                            const StabilityOptions& options) {
  std::vector<StabilityRow> rows;
  std::vector<Scenario> all = scenarios(options.quick);
  if (options.joints_only) std::erase_if(all, [](const Scenario& s) { return !s.info.joints; });
  std::size_t total = 0, done = 0;
  for (const Scenario& s : all)
    for (const Engine& engine : engines)
      total += engine.joints_only && !s.info.joints ? 0 : s.info.values.size();
  for (const Scenario& scenario : all) {
    for (const Engine& engine : engines) {
      if (engine.joints_only && !scenario.info.joints) continue;
      bool failed = false;
      for (double value : scenario.info.values) {
        ++done;
        if (failed) continue;  // the sweep stops at the first failure
        SceneDef scene = scenario.build(value);
        if (options.quick) scene.duration = std::min(scene.duration, 2.0);
        Checker check = scenario.checker(value, scene);
        std::string failure;
        bench::PeerOptions peer_options;
        peer_options.sleeping = scene.world.solver.sleeping;
        peer_options.ccd = scenario.ccd;
        const RunOutcome outcome = run_scene(
            engine, scene, peer_options,
            [&](const bench::Simulation& sim, double t, bool last) {
              failure = check(sim, t, last);
              return failure.empty();
            },
            options.time_limit);
        StabilityRow row;
        row.scenario = scenario.info.name;
        row.engine = engine.label;
        row.settings = outcome.settings;
        row.value = value;
        row.wall_seconds = outcome.step_seconds;
        if (!outcome.ran) {
          row.failure = outcome.why_not;
        } else if (!failure.empty()) {
          row.failure = failure;
        } else if (!outcome.why_not.empty()) {
          row.failure = outcome.why_not;
        } else {
          row.passed = true;
        }
        failed = !row.passed;
        rows.push_back(row);
        if (options.progress)
          options.progress("stability " + scenario.info.name + ", " + engine.label + ", " +
                               format("%g", value) + (row.passed ? ": pass" : ": " + row.failure),
                           done, total);
      }
    }
  }
  return rows;
}

}  // namespace tumble::report
