// Why the standard pile costs more on the rolling hills than on the plane after its first seconds:
// stacks of the pile's boxes (1 m, 1 kg, friction 0.5), far enough apart that none touches
// another, dropped (the bottom box 0.7 m above the plane, 0.15 m above the hills' highest point)
// onto the hills of terrain:1000 (a heightfield) and onto the plane, and stepped 10 s at 60 Hz
// with sleeping off. For each stack: when it last moved (any box faster
// than the sleep speeds, 0.05 m/s or 0.05 rad/s: a stack that sleeps could start its sleep delay
// only after that) and whether it toppled (its top box less than half its height above its
// bottom one).
//
// On the plane every stack lands flat and is still within half a second. On the hills a stack
// lands on a slope (up to about 8 degrees, the slopes of neighbouring cells up to about 7 degrees
// apart) and about half the stacks of three topple; those left standing rock on the faceted
// ground for seconds. They rock as long with the exact solver (one LCP a step, rigid contacts, no
// spring) and longer with more substeps (less damping from the step), and Bullet's stacks rock
// longer still: the hills' pile stays awake because its stacks move, which is the scene's
// dynamics, not the cost of the terrain's contacts (bench_terrain with FLAT 1 times those).
//
// Usage: bench_stacks_on_hills [BOXES]   (boxes a stack, default 3, 1 to 12)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "physics/world.h"
#include "scenes/scene.h"
#include "scenes/standard.h"
#ifdef TUMBLE_HAVE_PEERS
#include "peers/simulation.h"
#endif

namespace {

using namespace tumble;

constexpr double kDuration = 10;  // s

// The stacks on `ground` (the plane or the hills), `boxes` high, on a square grid as wide as fits
// the hills with a box's height to spare between neighbours (7 x 7 stacks of three, 4 x 4 of ten).
SceneDef stacks_scene(bool hills, int boxes, int* stacks) {
  SceneDef scene = hills ? terrain_pile_scene(1000) : pile_scene(1000);
  const BodyDef box = scene.bodies[1];
  scene.bodies.resize(1);  // the ground
  const double spacing = boxes + 3.0;
  const int side = std::min(7, static_cast<int>(48 / spacing) + 1);
  *stacks = side * side;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      for (int k = 0; k < boxes; ++k) {
        BodyDef body = box;
        body.orientation = Quat::Identity();
        // Off the grid's lines by a few centimetres each, so that no two stacks meet the hills
        // alike.
        const double x = (i - 0.5 * (side - 1)) * spacing + 0.13 * j;
        const double y = (j - 0.5 * (side - 1)) * spacing + 0.07 * i;
        body.position = Vec3(x, y, 1.2 + k);  // the hills reach 0.55 m: every stack drops
        scene.bodies.push_back(body);
      }
  scene.world.solver.sleeping = false;
  return scene;
}

struct Outcome {
  std::vector<double> last_moved;  // s, per stack
  std::vector<bool> toppled;       // per stack
  bool stopped = false;            // the engine could not go on
};

// Steps a run (`step`, false when it cannot go on) and reads its boxes (`box`: position, linear
// and angular speed of dynamic body k, in scene order) after every step.
struct BoxRead {
  Vec3 position;
  double speed, spin;
};
Outcome follow(const SceneDef& scene, int boxes, int stacks, const std::function<bool()>& step,
               const std::function<BoxRead(std::size_t)>& box) {
  Outcome out;
  out.last_moved.assign(stacks, 0.0);
  out.toppled.assign(stacks, false);
  const int steps = static_cast<int>(kDuration / scene.dt + 0.5);
  // Quiet as sleeping counts it (the stacks run awake, but with its speeds).
  const double quiet_speed = scene.world.solver.sleep_linear_speed;
  const double quiet_spin = scene.world.solver.sleep_angular_speed;
  for (int n = 1; n <= steps; ++n) {
    if (!step()) {
      out.stopped = true;
      break;
    }
    for (int s = 0; s < stacks; ++s)
      for (int k = 0; k < boxes; ++k) {
        const BoxRead read = box(static_cast<std::size_t>(s * boxes + k));
        if (read.speed > quiet_speed || read.spin > quiet_spin) out.last_moved[s] = n * scene.dt;
      }
  }
  for (int s = 0; s < stacks; ++s) {
    const double rise = box(static_cast<std::size_t>(s * boxes + boxes - 1)).position.z() -
                        box(static_cast<std::size_t>(s * boxes)).position.z();
    out.toppled[s] = rise < 0.5 * (boxes - 1);
  }
  return out;
}

Outcome ours(SceneDef scene, int boxes, int stacks, SolverKind kind, int substeps) {
  scene.world.solver.kind = kind;
  scene.world.solver.substeps = substeps;
  World world = make_world(scene).value();
  std::vector<BodyId> ids;
  for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot) {
    const BodyId id = world.id_at(slot);
    if (id.is_valid() && !world.body(id).is_static()) ids.push_back(id);
  }
  return follow(
      scene, boxes, stacks, [&] { return world.step(scene.dt).is_ok(); },
      [&](std::size_t k) {
        const BodyView body = world.body(ids[k]);
        return BoxRead{body.position(), body.linear_velocity().norm(),
                       body.angular_velocity().norm()};
      });
}

#ifdef TUMBLE_HAVE_PEERS
Outcome bullet(const SceneDef& scene, int boxes, int stacks) {
  bench::PeerOptions options;
  options.sleeping = false;
  std::string why_not;
  std::unique_ptr<bench::Simulation> sim =
      bench::make_bullet(bench::peer_scene(scene), options, &why_not);
  if (!sim) {
    std::fprintf(stderr, "bench_stacks_on_hills: Bullet: %s\n", why_not.c_str());
    std::exit(1);
  }
  return follow(
      scene, boxes, stacks, [&] { return sim->step(); },
      [&](std::size_t k) {
        const bench::BodyState state = sim->body(k);
        return BoxRead{state.position, state.linear_velocity.norm(), state.angular_velocity.norm()};
      });
}
#endif

// "median / latest" of the stacks' last moves where `toppled` is as given, "-" for none.
std::string spread(const Outcome& out, bool toppled) {
  std::vector<double> times;
  for (std::size_t s = 0; s < out.last_moved.size(); ++s)
    if (out.toppled[s] == toppled) times.push_back(out.last_moved[s]);
  if (times.empty()) return "-";
  std::sort(times.begin(), times.end());
  char text[40];
  std::snprintf(text, sizeof text, "%.2f / %.2f", times[times.size() / 2], times.back());
  return text;
}

void print(const char* ground, const std::string& engine, const Outcome& out) {
  const auto moving = std::count_if(out.last_moved.begin(), out.last_moved.end(),
                                    [](double t) { return t > kDuration - 0.5; });
  const auto toppled = std::count(out.toppled.begin(), out.toppled.end(), true);
  std::printf("%-6s  %-18s  %13s  %13s  %7td  %6td%s\n", ground, engine.c_str(),
              spread(out, false).c_str(), spread(out, true).c_str(), toppled, moving,
              out.stopped ? "  (stopped early)" : "");
}

}  // namespace

int main(int argc, char** argv) {
  int boxes = 3;
  if (argc > 1) {
    char* end = nullptr;
    const long value = std::strtol(argv[1], &end, 10);
    if (end == argv[1] || *end != '\0' || value < 1 || value > 12) {
      std::fprintf(stderr, "bench_stacks_on_hills: BOXES must be a whole number from 1 to 12\n");
      return 2;
    }
    boxes = static_cast<int>(value);
  }
  int stacks = 0;
  const SceneDef scenes[2] = {stacks_scene(false, boxes, &stacks),
                              stacks_scene(true, boxes, &stacks)};
  std::printf(
      "%d stacks of %d boxes dropped (bottom 0.7 m up) onto the plane and the hills of "
      "terrain:1000, 10 s at "
      "60 Hz, sleeping off.\nLast moved: the last time a box of the stack was faster than 0.05 m/s "
      "or 0.05 rad/s, s (median / latest), of the stacks standing at the end and of those that "
      "toppled;\nmoving: stacks that moved in the last 0.5 s.\n",
      stacks, boxes);
  std::printf("ground  engine              standing: last  toppled: last  toppled  moving\n");
  const struct {
    const char* name;
    SolverKind kind;
    int substeps;
  } runs[] = {{"auto (4 substeps)", SolverKind::kAuto, 4},
              {"auto, 8 substeps", SolverKind::kAuto, 8},
              {"auto, 16 substeps", SolverKind::kAuto, 16},
              {"pgs", SolverKind::kPgs, 4},
              {"exact", SolverKind::kExact, 4}};
  for (int g = 0; g < 2; ++g) {
    const char* ground = g == 0 ? "plane" : "hills";
    for (const auto& run : runs)
      print(ground, run.name, ours(scenes[g], boxes, stacks, run.kind, run.substeps));
#ifdef TUMBLE_HAVE_PEERS
    print(ground, "Bullet float", bullet(scenes[g], boxes, stacks));
#endif
  }
  return 0;
}
