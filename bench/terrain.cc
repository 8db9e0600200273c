// The standard pile dropped on rolling hills, as a heightfield (the standard scene terrain:N) and
// as a triangle mesh of the same triangles (terrain-mesh:N), beside the same pile on the plane
// (pile:N): the whole 10 s run of each, alternated round by round, its median time per step and
// the ratios; and whether the pile came through the ground, sampled every
// tenth step: the boxes whose centre was ever under the surface (through it), those with a vertex
// ever more than 1 cm under it (dipped), and the deepest any vertex went.
//
// Usage: bench_terrain [BOXES [ROUNDS [THREADS]]]   (defaults 1000, 3, 1)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "physics/world.h"
#include "scenes/scene.h"
#include "scenes/standard.h"

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
  int through = 0;         // boxes whose centre was under the ground
  int dipped = 0;          // boxes that had a vertex more than 1 cm under it
  double deepest = 0;      // m: the deepest any vertex went under it
  double fastest = 0;      // m/s: the fastest box at the end
  std::size_t points = 0;  // contact points in the last step
};

// How far below the ground (the plane z = 0, or the hills at the ground's pose) a point lies.
double under(const HeightField* field, const Pose& pose, const Vec3& p) {
  if (field == nullptr) return -p.z();
  const Vec3 local = pose.inverse_transform(p);
  return field->height_at(local.x(), local.y()) - local.z();
}

// hills: the hills' surface (the mesh's triangles are the heightfield's).
Run run(const std::string& name, int threads, const HeightField& hills) {
  SceneDef scene = standard_scene(name).value();
  scene.world.threads = threads;
  World world = make_world(scene).value();
  const int steps = static_cast<int>(scene.duration / scene.dt + 0.5);
  std::vector<BodyId> ids;
  BodyId ground_id;
  for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot) {
    const BodyId id = world.id_at(slot);
    if (!id.is_valid()) continue;
    if (world.body(id).is_static())
      ground_id = id;
    else
      ids.push_back(id);
  }
  const bool terrain = is_terrain(world.body(ground_id).shape().type());
  std::vector<std::uint8_t> through(ids.size(), 0), dipped(ids.size(), 0);
  Run out;
  double seconds = 0;
  for (int step = 0; step < steps; ++step) {
    const auto start = std::chrono::steady_clock::now();
    (void)world.step(scene.dt);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (step % 10 != 9) continue;  // sampled, untimed
    const BodyView ground = world.body(ground_id);
    const HeightField* field = terrain ? &hills : nullptr;
    const Pose pose{ground.position(), ground.orientation()};
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const BodyView body = world.body(ids[k]);
      const Vec3 h = body.shape().half_extents();
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3 local((corner & 1 ? 1 : -1) * h.x(), (corner & 2 ? 1 : -1) * h.y(),
                         (corner & 4 ? 1 : -1) * h.z());
        const double depth = under(field, pose, body.position() + body.orientation() * local);
        out.deepest = std::max(out.deepest, depth);
        if (depth > 0.01) dipped[k] = 1;
      }
      if (under(field, pose, body.position()) > 0) through[k] = 1;
    }
  }
  for (std::size_t k = 0; k < ids.size(); ++k) {
    out.through += through[k];
    out.dipped += dipped[k];
    out.fastest = std::max(out.fastest, world.body(ids[k]).linear_velocity().norm());
  }
  out.points = world.last_step().contact_points;
  out.ms_per_step = 1e3 * seconds / steps;
  return out;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int boxes = argument(argc, argv, 1, 1000, 1, 100000);
  const int rounds = argument(argc, argv, 2, 3, 1, 100);
  const int threads = argument(argc, argv, 3, 1, 1, 256);
  const std::string plane = "pile:" + std::to_string(boxes);
  const std::string field = "terrain:" + std::to_string(boxes);
  const std::string mesh = "terrain-mesh:" + std::to_string(boxes);
  const HeightField hills =
      HeightField::create(std::get<HeightFieldDef>(terrain_pile_scene(boxes).bodies[0].shape))
          .value();
  std::printf(
      "%d boxes dropped on the plane and on rolling hills (0.5 m cells; a heightfield, then the "
      "same triangles as a mesh), 10 s at 60 Hz, %d thread(s)\n",
      boxes, threads);
  std::printf(
      "round  scene               ms/step  through  dipped  deepest(m)  fastest(m/s)  points\n");
  std::vector<double> times[3];
  const std::string names[3] = {plane, field, mesh};
  for (int round = 0; round < rounds; ++round) {
    for (int k = 0; k < 3; ++k) {
      const Run r = run(names[k], threads, hills);
      times[k].push_back(r.ms_per_step);
      std::printf("%5d  %-18s %8.3f  %7d  %6d  %10.4f  %12.4f  %6zu\n", round, names[k].c_str(),
                  r.ms_per_step, r.through, r.dipped, r.deepest, r.fastest, r.points);
    }
  }
  const double a = median(times[0]), b = median(times[1]), c = median(times[2]);
  std::printf(
      "median ms/step: plane %.3f, heightfield %.3f, mesh %.3f; heightfield / plane %.2f, "
      "mesh / plane %.2f\n",
      a, b, c, b / a, c / a);
  return 0;
}
