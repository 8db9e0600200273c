// The standard pile dropped on rolling hills, as a heightfield (the standard scene terrain:N) and
// as a triangle mesh of the same triangles (terrain-mesh:N), beside the same pile on the plane
// (pile:N): the whole 10 s run of each, alternated round by round, its median time per step and
// the ratios; and whether the pile came through the ground, sampled after every step (untimed):
// the boxes whose centre was ever under the surface (through it), those with a vertex ever more
// than 1 cm under it (dipped), the deepest any vertex went (a box landing hard, for a step or
// two), and the deepest any vertex lies at the end (the pile settled). Beside the whole run's
// time, its first 5 s alone (every box still awake on either ground: the piles' costs step for
// step before the plane's towers sleep while some of the hills' topple).
//
// With the peers built (make bench), Bullet 3.24 (float, its deactivation on as our sleeping is)
// takes the same three scenes each round, its heightfield a btHeightfieldTerrainShape and its mesh
// a btBvhTriangleMeshShape (bench/peers/bullet_sim.cc): the hills' cost over the plane's in an
// engine the goal did not shape, and ours beside it.
//
// Usage: bench_terrain [BOXES [ROUNDS [THREADS [FLAT]]]]   (defaults 1000, 3, 1, 0)
//   FLAT 1: the hills levelled (every height 0), as a heightfield and as a mesh: the pile lands on
//   them as on the plane (the face rule gives a flat terrain the plane's contacts), so the ratios
//   are the terrain's own cost.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "physics/triangle_mesh.h"
#include "physics/world.h"
#include "scenes/scene.h"
#include "scenes/standard.h"
#ifdef TUMBLE_HAVE_PEERS
#include "peers/simulation.h"
#endif

namespace {

using namespace tumble;

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
  int through = 0;         // boxes whose centre was under the ground
  int dipped = 0;          // boxes that had a vertex more than 1 cm under it
  double deepest = 0;      // m: the deepest any vertex went under it
  double settled = 0;      // m: the deepest any vertex lies under it after the last step
  double fastest = 0;      // m/s: the fastest box at the end
  std::size_t points = 0;  // contact points in the last step
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

// The scene's whole run timed step by step (`step` returns false to stop), its boxes' depths
// under the ground sampled after every step untimed (every tenth missed a landing box's vertex
// 4.6 cm under the mesh for the one step it lasted), and their speeds (`speed_of`) at the end.
// `hills`: the hills' surface (the mesh's triangles are the heightfield's); the static ground is
// the scene's.
template <class Step, class BoxAt, class SpeedOf>
Run timed_run(const SceneDef& scene, const HeightField& hills, std::size_t boxes, Step step,
              BoxAt box_at, SpeedOf speed_of) {
  const BodyDef* ground = nullptr;
  for (const BodyDef& body : scene.bodies)
    if (body.type == BodyType::kStatic) ground = &body;
  const HeightField* field = std::holds_alternative<HalfSpaceDef>(ground->shape) ? nullptr : &hills;
  const Pose ground_pose{ground->position, ground->orientation};
  const int steps = static_cast<int>(scene.duration / scene.dt + 0.5);
  const int first_steps = std::min(steps, static_cast<int>(5 / scene.dt + 0.5));
  std::vector<std::uint8_t> through(boxes, 0), dipped(boxes, 0);
  Run out;
  double seconds = 0, first_seconds = 0;
  int taken = 0;
  for (; taken < steps; ++taken) {
    const auto start = std::chrono::steady_clock::now();
    if (!step()) {
      out.stopped_after = taken;
      break;
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (taken + 1 == first_steps) first_seconds = seconds;
    sample_depths(field, ground_pose, boxes, box_at, &through, &dipped, &out.deepest);
  }
  if (taken < first_steps) first_seconds = seconds;
  std::vector<std::uint8_t> unused_through(boxes, 0), unused_dipped(boxes, 0);
  sample_depths(field, ground_pose, boxes, box_at, &unused_through, &unused_dipped, &out.settled);
  for (std::size_t k = 0; k < boxes; ++k) {
    out.through += through[k];
    out.dipped += dipped[k];
    out.fastest = std::max(out.fastest, speed_of(k));
  }
  out.ms_per_step = taken > 0 ? 1e3 * seconds / taken : 0.0;
  out.first_ms_per_step = taken > 0 ? 1e3 * first_seconds / std::min(taken, first_steps) : 0.0;
  return out;
}

Run run(SceneDef scene, int threads, const HeightField& hills) {
  scene.world.threads = threads;
  World world = make_world(scene).value();
  std::vector<BodyId> ids;
  for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot) {
    const BodyId id = world.id_at(slot);
    if (id.is_valid() && !world.body(id).is_static()) ids.push_back(id);
  }
  Run out = timed_run(
      scene, hills, ids.size(), [&] { return world.step(scene.dt).is_ok(); },
      [&](std::size_t k) {
        const BodyView body = world.body(ids[k]);
        return BoxPose{body.position(), body.orientation(), body.shape().half_extents()};
      },
      [&](std::size_t k) { return world.body(ids[k]).linear_velocity().norm(); });
  out.points = world.last_step().contact_points;
  return out;
}

#ifdef TUMBLE_HAVE_PEERS
// The same run in Bullet (float): its time a step and the same marks (no contact count).
Run run_bullet(const SceneDef& scene, const HeightField& hills) {
  std::string why_not;
  const std::unique_ptr<bench::Simulation> sim =
      bench::make_bullet(bench::peer_scene(scene), bench::PeerOptions{}, &why_not);
  if (!sim) {
    std::fprintf(stderr, "bench_terrain: Bullet: %s\n", why_not.c_str());
    std::exit(1);
  }
  std::vector<Vec3> half_extents;  // the dynamic bodies', in the scene's order (the adapter's)
  for (const BodyDef& body : scene.bodies)
    if (body.type != BodyType::kStatic)
      half_extents.push_back(std::get<BoxDef>(body.shape).half_extents);
  return timed_run(
      scene, hills, half_extents.size(), [&] { return sim->step(); },
      [&](std::size_t k) {
        const bench::BodyState state = sim->body(k);
        return BoxPose{state.position, state.orientation, half_extents[k]};
      },
      [&](std::size_t k) { return sim->body(k).linear_velocity.norm(); });
}
#endif

std::string stop_note(const Run& r) {
  return r.stopped_after < 0 ? ""
                             : "  (stopped after " + std::to_string(r.stopped_after) + " steps)";
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
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
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const int boxes = argument(argc, argv, 1, 1000, 1, 100000);
  const int rounds = argument(argc, argv, 2, 3, 1, 100);
  const int threads = argument(argc, argv, 3, 1, 1, 256);
  const bool flat = argument(argc, argv, 4, 0, 0, 1) == 1;
  SceneDef scenes[3] = {pile_scene(boxes), terrain_pile_scene(boxes), terrain_pile_scene(boxes)};
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
      "same triangles as a mesh), 10 s at 60 Hz, %d thread(s)\n",
      boxes, ground, threads);
  std::printf(
      "round  scene                    ms/step  first 5 s  through  dipped  deepest(m)  at end(m)  "
      "fastest(m/s)  points\n");
  std::vector<double> times[3], first[3], bullet_times[3], bullet_first[3];
  for (int round = 0; round < rounds; ++round) {
    for (int k = 0; k < 3; ++k) {
      const Run r = run(scenes[k], threads, hills);
      times[k].push_back(r.ms_per_step);
      first[k].push_back(r.first_ms_per_step);
      std::printf("%5d  %-23s %8.3f  %9.3f  %7d  %6d  %10.4f  %9.4f  %12.4f  %6zu%s\n", round,
                  names[k].c_str(), r.ms_per_step, r.first_ms_per_step, r.through, r.dipped,
                  r.deepest, r.settled, r.fastest, r.points, stop_note(r).c_str());
    }
#ifdef TUMBLE_HAVE_PEERS
    // Bullet steps on one thread: beside ours on one alone.
    for (int k = 0; k < 3 && threads == 1; ++k) {
      const Run r = run_bullet(scenes[k], hills);
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
