// Pay only for what is used: each row pair runs a scene that does not use a feature, once with
// the feature available (the default) and once with it switched off or absent — the nearest we
// can come to a build without it. The first must not be slower than the second.
// Usage: bench_features [--steps N] (default 300 steps per run).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "physics/world.h"
#include "scenes/scene.h"
#include "scenes/standard.h"
#include "timing.h"

using namespace tumble;

namespace {

struct Measured {
  double median_ms = 0, narrow_ms = 0, solve_ms = 0;
  StepStats last;
};

using tumble::bench::median;

Measured measure(World& world, double dt, long steps) {
  std::vector<double> total, narrow, solve;
  for (long s = 0; s < steps; ++s) {
    world.step(dt);
    const StageTimes& t = world.last_step().time;
    total.push_back(1e3 * t.total);
    narrow.push_back(1e3 * t.narrow_phase);
    solve.push_back(1e3 * t.solve);
  }
  return {median(total), median(narrow), median(solve), world.last_step()};
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// measure's medians, each step timed with what `before_step(s)` does to the world first (the
// total column; the stage columns are the step's own).
template <class Work>
Measured measure_with(World& world, double dt, long steps, Work&& before_step) {
  std::vector<double> total, narrow, solve;
  for (long s = 0; s < steps; ++s) {
    const auto start = std::chrono::steady_clock::now();
    before_step(s);
    world.step(dt);
    total.push_back(1e3 * seconds_since(start));
    narrow.push_back(1e3 * world.last_step().time.narrow_phase);
    solve.push_back(1e3 * world.last_step().time.solve);
  }
  return {median(total), median(narrow), median(solve), world.last_step()};
}

// "N sleeping, M solver bodies" and what the row did, for the sleeper blocks' rows.
std::string sleepers_note(const StepStats& last, const char* what) {
  std::string note = std::to_string(last.sleeping_bodies) + " sleeping, " +
                     std::to_string(last.solver_bodies) + " solver bodies";
  return *what != '\0' ? note + " " + what : note;
}

World make(const SceneDef& scene) {
  return make_world(scene).value();
}

BodyDef box_at(const Vec3& position, BodyType type = BodyType::kDynamic, double friction = 0.5) {
  BodyDef def;
  def.shape = BoxDef{Vec3::Constant(0.5)};
  def.mass = type == BodyType::kDynamic ? 1 : 0;
  def.type = type;
  def.position = position;
  def.friction = friction;
  return def;
}

BodyDef floor_plane(double friction = 0.5) {
  BodyDef def;
  def.shape = HalfSpaceDef{};
  def.type = BodyType::kStatic;
  def.friction = friction;
  return def;
}

void header(const char* feature) {
  std::printf("\n%s\n", feature);
}

void row(const char* label, const Measured& m, const std::string& note) {
  std::printf("  %-44s %9.3f %9.3f %9.3f  %s\n", label, m.median_ms, m.narrow_ms, m.solve_ms,
              note.c_str());
}

// 32 x 32 boxes resting flat on the floor, 1.5 m apart: 1024 islands of four contacts.
SceneDef resting_grid(double friction, SolverKind kind) {
  SceneDef scene;
  scene.name = "resting-grid";
  scene.world.solver.kind = kind;
  scene.world.solver.sleeping = false;
  scene.bodies.push_back(floor_plane(friction));
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j)
      scene.bodies.push_back(box_at(Vec3(1.5 * i, 1.5 * j, 0.5), BodyType::kDynamic, friction));
  return scene;
}

// side x side boxes resting on the floor 2 m apart (they fall asleep after the sleep delay), one
// thread.
SceneDef field_of_boxes(int side) {
  SceneDef scene;
  scene.name = "field";
  scene.world.threads = 1;
  scene.bodies.push_back(floor_plane());
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      scene.bodies.push_back(box_at(Vec3(2.0 * i, 2.0 * j, 0.5)));
  return scene;
}

// field_of_boxes(side) stepped past the sleep delay (0.5 s): every box asleep.
World asleep_field(int side, double dt) {
  World world = make(field_of_boxes(side));
  for (int s = 0; s < 60; ++s)
    world.step(dt);
  return world;
}

}  // namespace

int main(int argc, char** argv) {
  long steps = 300;
  if (argc == 3 && std::string(argv[1]) == "--steps") steps = std::atol(argv[2]);
  const double dt = 1.0 / 60;
  std::printf(
      "Pay only for what is used: %ld steps per run, one thread unless stated; medians over "
      "steps, ms.\n  %-44s %9s %9s %9s\n",
      steps, "scene / variant", "step", "narrow", "solve");

  {  // warm up: page in the code and the allocator before the first measured run
    SceneDef scene = pile_scene(1000);
    scene.world.threads = 1;
    World world = make(scene);
    measure(world, dt, 120);
  }

  header("Continuous collision, scene with no fast body (pile-1000, awake)");
  for (bool on : {true, false}) {
    SceneDef scene = pile_scene(1000);
    scene.world.threads = 1;
    scene.world.solver.sleeping = false;
    scene.world.solver.continuous = on;
    World world = make(scene);
    const Measured m = measure(world, dt, steps);
    row(on ? "continuous on (default)" : "continuous off", m,
        "swept bodies in the last step: " + std::to_string(m.last.swept_bodies));
  }

  header("Friction, mu = 0 (1024 boxes resting on the floor, awake)");
  for (SolverKind kind : {SolverKind::kAuto, SolverKind::kSoft}) {
    for (double mu : {0.5, 0.0}) {
      SceneDef scene = resting_grid(mu, kind);
      scene.world.threads = 1;
      World world = make(scene);
      const Measured m = measure(world, dt, steps);
      const std::string label = std::string(solver_name(kind)) + ", mu = " + (mu > 0 ? "0.5" : "0");
      row(label.c_str(), m,
          "Lemke pivots " + std::to_string(m.last.lemke_pivots) + ", velocity iterations " +
              std::to_string(m.last.velocity_iterations));
    }
  }

  header("Only spheres: no GJK or EPA (pile lattice of 1000, awake)");
  for (bool spheres : {true, false}) {
    SceneDef scene = pile_scene(1000);
    scene.world.threads = 1;
    scene.world.solver.sleeping = false;
    if (spheres)
      for (BodyDef& def : scene.bodies)
        if (std::holds_alternative<BoxDef>(def.shape)) def.shape = SphereDef{0.5};
    World world = make(scene);
    const Measured m = measure(world, dt, steps);
    char note[96];
    std::snprintf(note, sizeof note, "%u manifolds, narrow %.3f us per pair", m.last.manifolds,
                  1e3 * m.narrow_ms / std::max(1u, m.last.pairs));
    row(spheres ? "spheres" : "boxes (SAT)", m, note);
  }

  header("One thread: no thread team (tower-3, awake)");
  for (int threads : {1, 2}) {
    SceneDef scene = tower_scene(3);
    scene.world.threads = threads;
    scene.world.solver.sleeping = false;
    World world = make(scene);
    const Measured m = measure(world, dt, steps);
    row(threads == 1 ? "threads = 1" : "threads = 2", m, "");
  }

  // Before parallel.h, regions whose `if` was false still made a team of one in libgomp and freed
  // it: 10.9 us a step for this box, 60% of it in the allocator.
  header("One body (a box sliding on the floor): no team, no allocation");
  for (int threads : {1, 2}) {
    SceneDef scene = slide_scene();
    scene.world.threads = threads;
    World world = make(scene);
    const Measured m = measure(world, dt, steps);
    char note[64];
    std::snprintf(note, sizeof note, "%.2f us per step", 1e3 * m.median_ms);
    row(threads == 1 ? "threads = 1" : "threads = 2", m, note);
  }

  header("Sleeping islands (pile-1000 after 10 s) against the same sleepers made static");
  {
    SceneDef scene = pile_scene(1000);
    scene.world.threads = 1;
    World world = make(scene);
    for (int s = 0; s < 600; ++s)
      world.step(dt);
    const Measured asleep = measure(world, dt, steps);
    row("asleep", asleep, std::to_string(asleep.last.sleeping_bodies) + " sleeping bodies");
    SceneDef frozen = scene;
    frozen.bodies.clear();
    frozen.bodies.push_back(floor_plane());
    for (std::uint32_t i = 0; i < world.slot_count(); ++i) {
      const BodyView body = world.body(world.id_at(i));
      if (!body || body->is_static()) continue;
      // Awake bodies stay dynamic, with their velocities: only the sleepers change.
      BodyDef def =
          box_at(body->position(), body->asleep() ? BodyType::kStatic : BodyType::kDynamic);
      def.orientation = body->orientation();
      def.linear_velocity = body->linear_velocity();
      def.angular_velocity = body->angular_velocity();
      frozen.bodies.push_back(def);
    }
    World still = make(frozen);
    row("sleepers made static", measure(still, dt, steps), "");
  }

  header("Static-static pairs: 1000 overlapping static boxes and one falling box");
  for (double spacing : {0.5, 2.0}) {
    SceneDef scene;
    scene.name = "statics";
    scene.world.threads = 1;
    scene.bodies.push_back(floor_plane());
    for (int i = 0; i < 10; ++i)
      for (int j = 0; j < 10; ++j)
        for (int k = 0; k < 10; ++k)
          scene.bodies.push_back(
              box_at(Vec3(spacing * i, spacing * j, 0.5 + spacing * k), BodyType::kStatic));
    scene.bodies.push_back(box_at(Vec3(-5, -5, 30)));
    World world = make(scene);
    const Measured m = measure(world, dt, steps);
    row(spacing < 1 ? "overlapping (0.5 m apart)" : "apart (2 m)", m,
        std::to_string(m.last.pairs) + " pairs");
  }

  header(
      "Sleepers around one moving body: 10,000 boxes asleep on the floor and one falling, "
      "against the falling box alone");
  for (const bool with_sleepers : {true, false}) {
    SceneDef scene = field_of_boxes(with_sleepers ? 100 : 0);
    scene.bodies.push_back(box_at(Vec3(-50, -50, 1000)));
    World world = make(scene);
    for (int s = 0; s < 60; ++s)  // past the sleep delay (0.5 s)
      world.step(dt);
    const Measured m = measure(world, dt, steps);
    row(with_sleepers ? "10,000 asleep, 1 falling" : "1 falling, alone", m,
        sleepers_note(m.last, ""));
  }

  header(
      "Spawning: a box made every step (and removed 30 steps later) among 10,000 sleepers, "
      "against the same in an empty world");
  for (const bool with_sleepers : {true, false}) {
    World world = asleep_field(with_sleepers ? 100 : 0, dt);
    std::vector<BodyId> spawned;
    const Measured m = measure_with(world, dt, steps, [&](long s) {
      // Dropped beside the field, so that no sleeper wakes: what is measured is the spawning.
      spawned.push_back(
          world.create_body(box_at(Vec3(-10.0 - 2.0 * (s % 31), -10.0, 5.0))).value());
      if (spawned.size() > 30) {
        world.remove_body(spawned.front());
        spawned.erase(spawned.begin());
      }
    });
    row(with_sleepers ? "10,000 asleep" : "empty", m,
        sleepers_note(m.last, "(make, remove, step)"));
  }

  header(
      "Waking among sleepers: every step one of 10,000 sleeping boxes is woken (it falls asleep "
      "again 0.5 s later), against the same with none woken");
  for (const bool poke : {true, false}) {
    World world = asleep_field(100, dt);
    const Measured m = measure_with(world, dt, steps, [&](long s) {
      // Slot 0 is the floor; boxes are woken in a stride, so that a woken one is asleep again
      // before its turn comes back.
      if (poke) world.wake(world.id_at(1 + static_cast<std::uint32_t>((s * 37) % 10000)));
    });
    row(poke ? "one woken a step" : "none woken", m, sleepers_note(m.last, "(wake, step)"));
  }

  header(
      "Removing static pedestals from under sleepers (each wakes the box on it): a world of "
      "1,000 against one of 10,000");
  for (const int side : {32, 100}) {
    SceneDef scene;
    scene.name = "pedestals";
    scene.world.threads = 1;
    scene.bodies.push_back(floor_plane());
    for (int i = 0; i < side; ++i)
      for (int j = 0; j < side; ++j) {
        scene.bodies.push_back(box_at(Vec3(3.0 * i, 3.0 * j, 0.5), BodyType::kStatic));
        scene.bodies.push_back(box_at(Vec3(3.0 * i, 3.0 * j, 1.5)));
      }
    World world = make(scene);
    for (int s = 0; s < 60; ++s)
      world.step(dt);
    const int removals = 500;
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < removals; ++k)
      world.remove_body(world.id_at(1 + 2 * k));
    const double us = 1e6 * seconds_since(start);
    std::printf("  %-44s %9.3f us per removal, %u sleeping before\n",
                (std::to_string(side * side) + " boxes on pedestals").c_str(), us / removals,
                world.last_step().sleeping_bodies);
  }

  header(
      "Removing moving bodies: every tenth of 1,000 and of 10,000 awake boxes in one batch, then "
      "the next step (sleeping off)");
  for (const int side : {32, 100}) {
    SceneDef scene = field_of_boxes(side);
    scene.world.solver.sleeping = false;
    World world = make(scene);
    for (int s = 0; s < 5; ++s)
      world.step(dt);
    std::vector<BodyId> doomed;
    for (int k = 1; k <= side * side; k += 10)
      doomed.push_back(world.id_at(k));
    const auto start = std::chrono::steady_clock::now();
    for (BodyId id : doomed)
      world.remove_body(id);
    const auto removed = std::chrono::steady_clock::now();
    world.step(dt);
    const auto stepped = std::chrono::steady_clock::now();
    std::printf(
        "  %-44s %9.3f us per removal, next step %.3f ms (%u solver bodies)\n",
        (std::to_string(side * side) + " awake, " + std::to_string(doomed.size()) + " removed")
            .c_str(),
        1e6 * std::chrono::duration<double>(removed - start).count() / doomed.size(),
        1e3 * std::chrono::duration<double>(stepped - removed).count(),
        world.last_step().solver_bodies);
  }
  return 0;
}
