// A box sliding across a triangulated floor beside the same box on a plane: Tumble's floor is a
// triangle mesh (0.5 m cells, two triangles each, 161 x 161 vertices), Bullet's the same triangles
// as a btBvhTriangleMeshShape without its internal-edge utility (btAdjustInternalEdgeContacts),
// as a user gets it by default. A 0.5 m box (1 kg, friction 0.5) starts at 5 m/s across many inner
// edges at an angle to both diagonals. For each engine: where the box stops on the plane, how far
// from there it stops on the mesh, the largest upward speed and tilt it picks up on the mesh (on a
// plane both stay 0: bumps on inner edges show as both), and the median time per step on each.
//
// Usage: bench_mesh_slide [STEPS]   (default 240: 4 s at 60 Hz)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "physics/world.h"

#ifdef TUMBLE_HAVE_BULLET
#include <btBulletDynamicsCommon.h>

#include "bullet_triangles.h"
#include "timing.h"
#endif

using namespace tumble;

namespace {

constexpr double kDt = 1.0 / 60;
constexpr double kHalf = 0.25;
const Vec3 kStart(-12, -3.1, kHalf);
const Vec3 kVelocity(4.5, 2.18, 0);  // 5 m/s, at an angle to both diagonals

TriangleMeshDef floor_mesh() {
  HeightFieldDef def;
  def.samples_x = def.samples_y = 161;
  def.spacing_x = def.spacing_y = 0.5;
  def.heights.assign(161 * 161, 0.0);
  return mesh_of_height_field(HeightField::create(def).value());
}

struct Slide {
  Vec3 stop = Vec3::Zero();
  double fastest_up = 0;  // m/s
  double most_tilt = 0;   // rad
  double ms_per_step = 0;
};

using tumble::bench::median;

Slide tumble_slide(bool on_mesh, int steps) {
  World world;
  BodyDef ground;
  ground.type = BodyType::kStatic;
  ground.shape = HalfSpaceDef{};
  if (on_mesh) ground.shape = floor_mesh();
  world.create_body(ground).value();
  BodyDef box;
  box.shape = BoxDef{Vec3::Constant(kHalf)};
  box.mass = 1;
  box.friction = 0.5;
  box.position = kStart;
  box.linear_velocity = kVelocity;
  const BodyId id = world.create_body(box).value();
  Slide out;
  std::vector<double> times;
  for (int k = 0; k < steps; ++k) {
    const auto start = std::chrono::steady_clock::now();
    (void)world.step(kDt);
    times.push_back(
        1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    const BodyView b = world.body(id);
    out.fastest_up = std::max(out.fastest_up, b.linear_velocity().z());
    out.most_tilt = std::max(
        out.most_tilt, std::acos(std::clamp((b.orientation() * Vec3::UnitZ()).z(), -1.0, 1.0)));
  }
  out.stop = world.body(id)->position();
  out.ms_per_step = median(times);
  return out;
}

#ifdef TUMBLE_HAVE_BULLET
Slide bullet_slide(bool on_mesh, int steps) {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
  world.setGravity(btVector3(0, 0, -9.81));
  const BulletTriangles arrays(floor_mesh());
  btBvhTriangleMeshShape mesh_shape(arrays.arrays.get(), true);
  btStaticPlaneShape plane(btVector3(0, 0, 1), 0);
  btCollisionShape* ground_shape = on_mesh ? static_cast<btCollisionShape*>(&mesh_shape) : &plane;
  btRigidBody ground(0, nullptr, ground_shape);
  ground.setFriction(0.5);
  world.addRigidBody(&ground);
  btBoxShape box_shape(btVector3(kHalf, kHalf, kHalf));
  btVector3 inertia;
  box_shape.calculateLocalInertia(1, inertia);
  btDefaultMotionState motion(
      btTransform(btQuaternion::getIdentity(), btVector3(kStart.x(), kStart.y(), kStart.z())));
  btRigidBody box(1, &motion, &box_shape, inertia);
  box.setFriction(0.5);
  box.setLinearVelocity(btVector3(kVelocity.x(), kVelocity.y(), kVelocity.z()));
  box.setActivationState(DISABLE_DEACTIVATION);
  world.addRigidBody(&box);
  Slide out;
  std::vector<double> times;
  for (int k = 0; k < steps; ++k) {
    const auto start = std::chrono::steady_clock::now();
    world.stepSimulation(static_cast<btScalar>(kDt), 0);
    times.push_back(
        1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    out.fastest_up = std::max(out.fastest_up, static_cast<double>(box.getLinearVelocity().z()));
    const btVector3 up = box.getWorldTransform().getBasis().getColumn(2);
    out.most_tilt =
        std::max(out.most_tilt, std::acos(std::clamp(static_cast<double>(up.z()), -1.0, 1.0)));
  }
  const btVector3 p = box.getWorldTransform().getOrigin();
  out.stop = Vec3(p.x(), p.y(), p.z());
  out.ms_per_step = median(times);
  world.removeRigidBody(&box);
  world.removeRigidBody(&ground);
  return out;
}
#endif

void print(const char* engine, const Slide& plane, const Slide& mesh) {
  std::printf(
      "%-14s stop on the plane (%.6f, %.6f); on the mesh %.3g m from it; on the mesh: "
      "fastest upward %.3g m/s, most tilt %.3g rad; ms/step plane %.4f, mesh %.4f\n",
      engine, plane.stop.x(), plane.stop.y(), (mesh.stop - plane.stop).norm(), mesh.fastest_up,
      mesh.most_tilt, plane.ms_per_step, mesh.ms_per_step);
}

}  // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::atoi(argv[1]) : 240;
  if (steps < 1 || steps > 100000) {
    std::fprintf(stderr, "bench_mesh_slide: STEPS must be 1 to 100000\n");
    return 2;
  }
  std::printf(
      "a 0.5 m box at 5 m/s across a floor of 51,200 triangles and across a plane, "
      "%d steps at 60 Hz\n",
      steps);
  const Slide tumble_plane = tumble_slide(false, steps), tumble_mesh = tumble_slide(true, steps);
  print("Tumble", tumble_plane, tumble_mesh);
#ifdef TUMBLE_HAVE_BULLET
  const Slide bullet_plane = bullet_slide(false, steps), bullet_mesh = bullet_slide(true, steps);
  print("Bullet (float)", bullet_plane, bullet_mesh);
#else
  std::printf("Bullet: not installed (scripts/install-deps bench)\n");
#endif
  return (tumble_mesh.stop - tumble_plane.stop).norm() <= 1e-6 ? 0 : 1;
}
