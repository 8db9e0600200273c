// Bullet 3.24 (Debian's single-precision build) on a standard scene, as SCENES.md maps it.
#include <btBulletDynamicsCommon.h>

#include <chrono>
#include <memory>

#include "peers/peer_world.h"

namespace tumble::bench {

RunResult run_bullet(const SceneDef& scene, long steps, bool sleeping) {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
  const Vec3 g = scene.world.gravity;
  world.setGravity(btVector3(g.x(), g.y(), g.z()));

  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<btRigidBody*> dynamic;
  std::vector<Vec3> halves;
  for (const BodyDef& def : scene.bodies) {
    Vec3 half = Vec3::Zero();
    if (std::holds_alternative<HalfSpaceDef>(def.shape)) {
      shapes.push_back(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0));
    } else {
      half = std::get<BoxDef>(def.shape).half_extents;
      shapes.push_back(std::make_unique<btBoxShape>(btVector3(half.x(), half.y(), half.z())));
    }
    const bool is_static = def.type == BodyType::kStatic;
    const double mass = is_static ? 0 : def.mass;
    btVector3 inertia(0, 0, 0);
    if (!is_static)  // m/12 (b^2 + c^2), as SCENES.md sets it
      inertia = btVector3(mass / 3 * (half.y() * half.y() + half.z() * half.z()),
                          mass / 3 * (half.x() * half.x() + half.z() * half.z()),
                          mass / 3 * (half.x() * half.x() + half.y() * half.y()));
    const Quat& q = def.orientation;
    btTransform pose(btQuaternion(q.x(), q.y(), q.z(), q.w()),
                     btVector3(def.position.x(), def.position.y(), def.position.z()));
    states.push_back(std::make_unique<btDefaultMotionState>(pose));
    btRigidBody::btRigidBodyConstructionInfo info(mass, states.back().get(), shapes.back().get(),
                                                  inertia);
    info.m_friction = std::sqrt(def.friction);  // Bullet multiplies the two bodies' values
    info.m_restitution = 0;
    bodies.push_back(std::make_unique<btRigidBody>(info));
    btRigidBody* body = bodies.back().get();
    body->setLinearVelocity(
        btVector3(def.linear_velocity.x(), def.linear_velocity.y(), def.linear_velocity.z()));
    body->setAngularVelocity(
        btVector3(def.angular_velocity.x(), def.angular_velocity.y(), def.angular_velocity.z()));
    if (!sleeping) body->setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(body);
    if (!is_static) {
      dynamic.push_back(body);
      halves.push_back(half);
    }
  }

  RunResult result;
  result.engine = "Bullet 3.24 float";
  result.settings = std::string("sequential impulse, 10 iterations, split impulse, sleeping ") +
                    (sleeping ? "on" : "off");
  auto read = [&](std::vector<Vec3>* out) {
    out->clear();
    for (btRigidBody* b : dynamic) {
      const btVector3 p = b->getCenterOfMassPosition();
      out->push_back(Vec3(p.x(), p.y(), p.z()));
    }
  };
  read(&result.start);
  const long last_second = steps - std::lround(1 / scene.dt);
  for (long s = 0; s < steps; ++s) {
    const auto start = std::chrono::steady_clock::now();
    world.stepSimulation(scene.dt, 0);
    result.step_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    for (std::size_t i = 0; i < dynamic.size(); ++i) {
      const btTransform& t = dynamic[i]->getCenterOfMassTransform();
      const btQuaternion r = t.getRotation();
      const Vec3 p(t.getOrigin().x(), t.getOrigin().y(), t.getOrigin().z());
      if (!p.allFinite() || p.cwiseAbs().maxCoeff() > 1000) result.blew_up = true;
      if (s >= last_second && scene.world.gravity.norm() > 0)
        result.deepest_corner_last_second =
            std::max(result.deepest_corner_last_second,
                     corner_depth(p, Quat(r.w(), r.x(), r.y(), r.z()), halves[i]));
    }
  }
  read(&result.end);
  for (btRigidBody* b : dynamic) {
    const btVector3 v = b->getLinearVelocity();
    result.end_velocity.push_back(Vec3(v.x(), v.y(), v.z()));
  }
  for (auto& body : bodies)
    world.removeRigidBody(body.get());
  return result;
}

}  // namespace tumble::bench
