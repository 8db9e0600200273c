// The standard pile dropped on rolling hills, as a heightfield (the standard scene terrain:N) and
// as a triangle mesh of the same triangles (terrain-mesh:N), beside the same pile on the plane
// (pile:N): the whole 10 s run of each, the scenes (and Bullet's runs of them) taking turns of 20
// steps (run_round), its median time per step over the rounds and the ratios; and whether the
// pile came through the ground, sampled after every step (untimed): the boxes whose centre was
// ever under the surface (through it), those with a vertex ever more than 1 cm under it (dipped),
// the deepest any vertex went (a box landing hard, for a step or two), and the deepest any vertex
// lies at the end (the pile settled). Beside the whole run's time, its first 5 s alone (every box
// still awake on either ground: the piles' costs step for step before the plane's towers sleep
// while some of the hills' topple).
//
// With the peers built (make bench), Bullet 3.24 (float, its deactivation on as our sleeping is)
// takes the same three scenes each round, its heightfield a btHeightfieldTerrainShape and its mesh
// a btBvhTriangleMeshShape (bench/peers/bullet_sim.cc): the hills' cost over the plane's in an
// engine the goal did not shape, and ours beside it.
//
// Usage: bench_terrain [BOXES [ROUNDS [THREADS [FLAT [AWAKE]]]]]   (defaults 1000, 3, 1, 0, 0)
//   FLAT 1: the hills levelled (every height 0), as a heightfield and as a mesh: the pile lands on
//   them as on the plane (the face rule gives a flat terrain the plane's contacts), so the ratios
//   are the terrain's own cost.
//   AWAKE 1: sleeping off in every run (Bullet's deactivation too): each step's cost with every
//   box awake on either ground, where with sleeping the plane's pile falls asleep seconds before
//   the hills' (the towers toppling on the slopes keep their islands awake).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "physics/triangle_mesh.h"
#include "physics/world.h"
#include "scenes/scene.h"
#include "scenes/standard.h"
#include "timing.h"
#ifdef TUMBLE_HAVE_PEERS
#include "peers/simulation.h"
#endif

namespace {

using namespace tumble;
using bench::median;

int argument(int argc, char** argv, int index, int fallback, int least, int most) {
  if (argc <= index) return fallback;
  const int value = std::atoi(argv[index]);
  if (value < least || value > most) {
    std::fprintf(stderr, "bench_terrain: argument %d must be %d to %d\n", index, least, most);
    std::exit(2);
  }
  return value;
}

struct Run {
  double ms_per_step = 0;
  double first_ms_per_step = 0;  // over the first 5 s
  int through = 0;               // boxes whose centre was under the ground
  int dipped = 0;                // boxes that had a vertex more than 1 cm under it
  double deepest = 0;            // m: the deepest any vertex went under it
  double settled = 0;            // m: the deepest any vertex lies under it after the last step
  double fastest = 0;            // m/s: the fastest box at the end
  // Where the engine reported that it cannot go on: the steps it took (the times are theirs).
  int stopped_after = -1;
};

// How far below the ground (the plane z = 0, or the hills at the ground's pose) a point lies.
double under(const HeightField* field, const Pose& pose, const Vec3& p) {
  if (field == nullptr) return -p.z();
  const Vec3 local = pose.inverse_transform(p);
  return field->height_at(local.x(), local.y()) - local.z();
}

// The boxes' depth under the ground (`field`: the hills, or null for the plane), into the run's
// marks: a box's centre under it, a vertex more than 1 cm under it, the deepest vertex.
template <class BoxAt>
void sample_depths(const HeightField* field, const Pose& ground, std::size_t boxes, BoxAt box_at,
                   std::vector<std::uint8_t>* through, std::vector<std::uint8_t>* dipped,
                   double* deepest) {
  for (std::size_t k = 0; k < boxes; ++k) {
    const auto [position, orientation, h] = box_at(k);
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 local((corner & 1 ? 1 : -1) * h.x(), (corner & 2 ? 1 : -1) * h.y(),
                       (corner & 4 ? 1 : -1) * h.z());
      const double depth = under(field, ground, position + orientation * local);
      *deepest = std::max(*deepest, depth);
      if (depth > 0.01) (*dipped)[k] = 1;
    }
    if (under(field, ground, position) > 0) (*through)[k] = 1;
  }
}

struct BoxPose {
  Vec3 position;
  Quat orientation;
  Vec3 half_extents;
};

// One engine's run of one scene, stepped a turn at a time (run_round): each step timed (but a
// turn's first), its boxes' depths under the ground sampled after every step untimed (every tenth
// missed a landing box's vertex 4.6 cm under the mesh for the one step it lasted), and their
// speeds at the end. `hills`: the hills' surface (the mesh's triangles are the heightfield's); the
// static ground is the scene's.
class TimedRun {
 public:
  TimedRun(const SceneDef& scene, const HeightField& hills, std::size_t boxes,
           std::function<bool()> step, std::function<BoxPose(std::size_t)> box_at,
           std::function<double(std::size_t)> speed_of)
      : boxes_(boxes),
        step_(std::move(step)),
        box_at_(std::move(box_at)),
        speed_of_(std::move(speed_of)),
        through_(boxes, 0),
        dipped_(boxes, 0) {
    const BodyDef* ground = nullptr;
    for (const BodyDef& body : scene.bodies)
      if (body.type == BodyType::kStatic) ground = &body;
    field_ = std::holds_alternative<HalfSpaceDef>(ground->shape) ? nullptr : &hills;
    ground_pose_ = Pose{ground->position, ground->orientation};
  }
  // Step `index` of the run (0 first); false where the engine cannot go on.
  bool step(int index) {
    if (step_()) return true;
    out_.stopped_after = index;
    return false;
  }
  // After step `index`, untimed: its time (`ms`; NaN where it is not timed) and the depths.
  void record(int index, double ms, int first_steps) {
    if (!std::isnan(ms)) {
      ms_ += ms;
      ++timed_;
      if (index < first_steps) {
        first_ms_ += ms;
        ++first_timed_;
      }
    }
    sample_depths(field_, ground_pose_, boxes_, box_at_, &through_, &dipped_, &out_.deepest);
  }

  Run finish() {
    std::vector<std::uint8_t> unused_through(boxes_, 0), unused_dipped(boxes_, 0);
    sample_depths(field_, ground_pose_, boxes_, box_at_, &unused_through, &unused_dipped,
                  &out_.settled);
    for (std::size_t k = 0; k < boxes_; ++k) {
      out_.through += through_[k];
      out_.dipped += dipped_[k];
      out_.fastest = std::max(out_.fastest, speed_of_(k));
    }
    out_.ms_per_step = timed_ > 0 ? ms_ / timed_ : 0.0;
    out_.first_ms_per_step = first_timed_ > 0 ? first_ms_ / first_timed_ : 0.0;
    return out_;
  }

 private:
  std::size_t boxes_;
  std::function<bool()> step_;
  std::function<BoxPose(std::size_t)> box_at_;
  std::function<double(std::size_t)> speed_of_;
  const HeightField* field_ = nullptr;
  Pose ground_pose_;
  std::vector<std::uint8_t> through_, dipped_;
  double ms_ = 0, first_ms_ = 0;
  int timed_ = 0, first_timed_ = 0;
  Run out_;
};

// Ours on one scene. (Its run's steps call back into it: it stays where it was made.)
struct OurRun {
  OurRun(const SceneDef& scene, const HeightField& hills) : world(make_world(scene).value()) {
    for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot) {
      const BodyId id = world.id_at(slot);
      if (id.is_valid() && !world.body(id).is_static()) ids.push_back(id);
    }
    run = std::make_unique<TimedRun>(
        scene, hills, ids.size(), [this, dt = scene.dt] { return world.step(dt).is_ok(); },
        [this](std::size_t k) {
          const BodyView body = world.body(ids[k]);
          return BoxPose{body.position(), body.orientation(), body.shape().half_extents()};
        },
        [this](std::size_t k) { return world.body(ids[k]).linear_velocity().norm(); });
  }
  OurRun(const OurRun&) = delete;
  OurRun& operator=(const OurRun&) = delete;
  World world;
  std::vector<BodyId> ids;
  std::unique_ptr<TimedRun> run;
};

#ifdef TUMBLE_HAVE_PEERS
// The same scene in Bullet (float), with the same marks (no contact count); as OurRun, it stays
// where it was made.
struct BulletRun {
  BulletRun(const SceneDef& scene, const HeightField& hills) {
    std::string why_not;
    bench::PeerOptions options;
    options.sleeping = scene.world.solver.sleeping;
    sim = bench::make_bullet(bench::peer_scene(scene), options, &why_not);
    if (!sim) {
      std::fprintf(stderr, "bench_terrain: Bullet: %s\n", why_not.c_str());
      std::exit(1);
    }
    for (const BodyDef& body : scene.bodies)  // the dynamic bodies, in the adapter's order
      if (body.type != BodyType::kStatic)
        half_extents.push_back(std::get<BoxDef>(body.shape).half_extents);
    run = std::make_unique<TimedRun>(
        scene, hills, half_extents.size(), [this] { return sim->step(); },
        [this](std::size_t k) {
          const bench::BodyState state = sim->body(k);
          return BoxPose{state.position, state.orientation, half_extents[k]};
        },
        [this](std::size_t k) { return sim->body(k).linear_velocity.norm(); });
  }
  BulletRun(const BulletRun&) = delete;
  BulletRun& operator=(const BulletRun&) = delete;
  std::unique_ptr<bench::Simulation> sim;
  std::vector<Vec3> half_extents;
  std::unique_ptr<TimedRun> run;
};
#endif

// A round: every run of the round's scenes (ours on the plane, the heightfield and the mesh, then
// Bullet's where `runs` holds them) stepped together by turns (bench/timing.h): run whole one
// after another, the plane's first 5 s and the hills' ran at speeds up to a half apart (the
// plane's first 5 s 3.8 to 6.2 ms a step in three rounds), which went straight into their ratio.
void run_round(std::span<TimedRun* const> runs, int steps, int first_steps) {
  std::vector<bench::TurnTimes> times(runs.size());
  bench::take_turns(
      std::span<bench::TurnTimes>(times), steps,
      [&](std::size_t i, long k) { return runs[i]->step(static_cast<int>(k)); },
      [&](std::size_t i, long k, double ms) {
        runs[i]->record(static_cast<int>(k), ms, first_steps);
        return true;
      });
}

std::string stop_note(const Run& r) {
  return r.stopped_after < 0 ? ""
                             : "  (stopped after " + std::to_string(r.stopped_after) + " steps)";
}

// The three scenes' medians (plane, heightfield, mesh), whole runs and first 5 s, printed with
// the hills' ratios to the plane.
struct Medians {
  double whole[3], first[3];
};
Medians print_medians(const char* engine, const std::vector<double> (&times)[3],
                      const std::vector<double> (&first)[3]) {
  Medians m;
  for (int k = 0; k < 3; ++k) {
    m.whole[k] = median(times[k]);
    m.first[k] = median(first[k]);
  }
  for (const auto& [label, v] : {std::pair{"whole run", m.whole}, std::pair{"first 5 s", m.first}})
    std::printf(
        "%s%s, median ms/step: plane %.3f, heightfield %.3f, mesh %.3f; heightfield / plane "
        "%.2f, mesh / plane %.2f\n",
        engine, label, v[0], v[1], v[2], v[1] / v[0], v[2] / v[0]);
  // The rounds' own ratios: each round's scenes ran together, so its ratio is the steadier figure.
  for (const auto& [label, v] : {std::pair{"whole run", &times}, std::pair{"first 5 s", &first}}) {
    std::printf("%s%s, each round's hills / plane:", engine, label);
    for (int k = 1; k < 3; ++k) {
      std::vector<double> ratios;
      for (std::size_t round = 0; round < (*v)[0].size(); ++round)
        ratios.push_back((*v)[k][round] / (*v)[0][round]);
      std::printf("%s", k == 1 ? " heightfield" : "; mesh");
      for (double ratio : ratios)
        std::printf(" %.2f", ratio);
      std::printf(" (median %.2f)", median(ratios));
    }
    std::printf("\n");
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const int boxes = argument(argc, argv, 1, 1000, 1, 100000);
  const int rounds = argument(argc, argv, 2, 3, 1, 100);
  const int threads = argument(argc, argv, 3, 1, 1, 256);
  const bool flat = argument(argc, argv, 4, 0, 0, 1) == 1;
  const bool awake = argument(argc, argv, 5, 0, 0, 1) == 1;
  SceneDef scenes[3] = {pile_scene(boxes), terrain_pile_scene(boxes), terrain_pile_scene(boxes)};
  for (SceneDef& scene : scenes) {
    scene.world.threads = threads;
    scene.world.solver.sleeping = scene.world.solver.sleeping && !awake;
  }
  auto& heights = std::get<HeightFieldDef>(scenes[1].bodies[0].shape);
  if (flat) std::fill(heights.heights.begin(), heights.heights.end(), 0.0);
  const HeightField hills = HeightField::create(heights).value();
  scenes[2].bodies[0].shape = mesh_of_height_field(hills);
  const char* ground = flat ? "levelled hills" : "rolling hills";
  const std::string names[3] = {
      "pile:" + std::to_string(boxes),
      std::string(flat ? "flat-" : "") + "terrain:" + std::to_string(boxes),
      std::string(flat ? "flat-" : "") + "terrain-mesh:" + std::to_string(boxes)};
  std::printf(
      "%d boxes dropped on the plane and on %s (0.5 m cells; a heightfield, then the "
      "same triangles as a mesh), 10 s at 60 Hz, %d thread(s)%s\n",
      boxes, ground, threads, awake ? ", sleeping off" : "");
  std::printf(
      "round  scene                    ms/step  first 5 s  through  dipped  deepest(m)  at end(m)  "
      "fastest(m/s)  points\n");
  std::vector<double> times[3], first[3], bullet_times[3], bullet_first[3];
  const int steps = static_cast<int>(scenes[0].duration / scenes[0].dt + 0.5);
  const int first_steps = std::min(steps, static_cast<int>(5 / scenes[0].dt + 0.5));
  for (int round = 0; round < rounds; ++round) {
    std::vector<std::unique_ptr<OurRun>> ours;
    std::vector<TimedRun*> runs;
    for (int k = 0; k < 3; ++k) {
      ours.push_back(std::make_unique<OurRun>(scenes[k], hills));
      runs.push_back(ours.back()->run.get());
    }
#ifdef TUMBLE_HAVE_PEERS
    // Bullet steps on one thread: beside ours on one alone.
    std::vector<std::unique_ptr<BulletRun>> bullet;
    for (int k = 0; k < 3 && threads == 1; ++k) {
      bullet.push_back(std::make_unique<BulletRun>(scenes[k], hills));
      runs.push_back(bullet.back()->run.get());
    }
#endif
    run_round(runs, steps, first_steps);
    for (int k = 0; k < 3; ++k) {
      const Run r = ours[k]->run->finish();
      times[k].push_back(r.ms_per_step);
      first[k].push_back(r.first_ms_per_step);
      std::printf("%5d  %-23s %8.3f  %9.3f  %7d  %6d  %10.4f  %9.4f  %12.4f  %6u%s\n", round,
                  names[k].c_str(), r.ms_per_step, r.first_ms_per_step, r.through, r.dipped,
                  r.deepest, r.settled, r.fastest, ours[k]->world.last_step().contact_points,
                  stop_note(r).c_str());
    }
#ifdef TUMBLE_HAVE_PEERS
    for (int k = 0; k < 3 && threads == 1; ++k) {
      const Run r = bullet[k]->run->finish();
      bullet_times[k].push_back(r.ms_per_step);
      bullet_first[k].push_back(r.first_ms_per_step);
      std::printf("%5d  %-23s %8.3f  %9.3f  %7d  %6d  %10.4f  %9.4f  %12.4f       -%s\n", round,
                  ("Bullet " + names[k]).c_str(), r.ms_per_step, r.first_ms_per_step, r.through,
                  r.dipped, r.deepest, r.settled, r.fastest, stop_note(r).c_str());
    }
#endif
  }
  const Medians ours = print_medians("", times, first);
#ifdef TUMBLE_HAVE_PEERS
  if (threads == 1) {
    const Medians bullet = print_medians("Bullet, ", bullet_times, bullet_first);
    std::printf(
        "ours / Bullet's step, whole run: plane %.2f, heightfield %.2f, mesh %.2f; first 5 s: "
        "%.2f, %.2f, %.2f\n",
        ours.whole[0] / bullet.whole[0], ours.whole[1] / bullet.whole[1],
        ours.whole[2] / bullet.whole[2], ours.first[0] / bullet.first[0],
        ours.first[1] / bullet.first[1], ours.first[2] / bullet.first[2]);
  }
#else
  (void)ours;
#endif
  return 0;
}
