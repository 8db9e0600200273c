// ODE 0.16 (Debian, double precision) on a standard scene: quickstep with 20 iterations, up to 8
// contacts per pair, dContactApprox1 so that mu is a Coulomb coefficient.
#include <ode/ode.h>

#include <chrono>

#include "peers/peer_world.h"

namespace tumble::bench {
namespace {

struct OdeWorld {
  dWorldID world;
  dJointGroupID contacts;
};

void near_callback(void* data, dGeomID a, dGeomID b) {
  auto* w = static_cast<OdeWorld*>(data);
  dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
  if (ba == nullptr && bb == nullptr) return;
  dContact contact[8];
  const int n = dCollide(a, b, 8, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < n; ++i) {
    contact[i].surface.mode = dContactApprox1;
    contact[i].surface.mu = 0.5;
    const dJointID joint = dJointCreateContact(w->world, w->contacts, &contact[i]);
    dJointAttach(joint, ba, bb);
  }
}

}  // namespace

RunResult run_ode(const SceneDef& scene, long steps) {
  dInitODE2(0);
  OdeWorld w{dWorldCreate(), dJointGroupCreate(0)};
  dSpaceID space = dHashSpaceCreate(nullptr);
  const Vec3 g = scene.world.gravity;
  dWorldSetGravity(w.world, g.x(), g.y(), g.z());
  dWorldSetQuickStepNumIterations(w.world, 20);
  std::vector<dBodyID> dynamic;
  std::vector<Vec3> halves;
  for (const BodyDef& def : scene.bodies) {
    if (std::holds_alternative<HalfSpaceDef>(def.shape)) {
      dCreatePlane(space, 0, 0, 1, 0);
      continue;
    }
    const Vec3 half = std::get<BoxDef>(def.shape).half_extents;
    dGeomID geom = dCreateBox(space, 2 * half.x(), 2 * half.y(), 2 * half.z());
    const Quat& q = def.orientation;
    const dQuaternion rotation = {q.w(), q.x(), q.y(), q.z()};
    if (def.type == BodyType::kStatic) {
      dGeomSetPosition(geom, def.position.x(), def.position.y(), def.position.z());
      dGeomSetQuaternion(geom, rotation);
      continue;
    }
    dBodyID body = dBodyCreate(w.world);
    dMass mass;
    dMassSetBoxTotal(&mass, def.mass, 2 * half.x(), 2 * half.y(), 2 * half.z());
    dBodySetMass(body, &mass);
    dBodySetPosition(body, def.position.x(), def.position.y(), def.position.z());
    dBodySetQuaternion(body, rotation);
    dBodySetLinearVel(body, def.linear_velocity.x(), def.linear_velocity.y(),
                      def.linear_velocity.z());
    dBodySetAngularVel(body, def.angular_velocity.x(), def.angular_velocity.y(),
                       def.angular_velocity.z());
    dGeomSetBody(geom, body);
    dynamic.push_back(body);
    halves.push_back(half);
  }

  RunResult result;
  result.engine = "ODE 0.16 double";
  result.settings = "quickstep, 20 iterations, ERP 0.2, CFM 1e-10";
  auto position = [](dBodyID b) {
    const dReal* p = dBodyGetPosition(b);
    return Vec3(p[0], p[1], p[2]);
  };
  for (dBodyID b : dynamic)
    result.start.push_back(position(b));
  const long last_second = steps - std::lround(1 / scene.dt);
  for (long s = 0; s < steps; ++s) {
    const auto start = std::chrono::steady_clock::now();
    dSpaceCollide(space, &w, near_callback);
    dWorldQuickStep(w.world, scene.dt);
    dJointGroupEmpty(w.contacts);
    result.step_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    for (std::size_t i = 0; i < dynamic.size(); ++i) {
      const Vec3 p = position(dynamic[i]);
      if (!p.allFinite() || p.cwiseAbs().maxCoeff() > 1000) result.blew_up = true;
      if (s >= last_second && g.norm() > 0) {
        const dReal* q = dBodyGetQuaternion(dynamic[i]);
        result.deepest_corner_last_second =
            std::max(result.deepest_corner_last_second,
                     corner_depth(p, Quat(q[0], q[1], q[2], q[3]), halves[i]));
      }
    }
  }
  for (dBodyID b : dynamic) {
    result.end.push_back(position(b));
    const dReal* v = dBodyGetLinearVel(b);
    result.end_velocity.push_back(Vec3(v[0], v[1], v[2]));
  }
  dJointGroupDestroy(w.contacts);
  dSpaceDestroy(space);
  dWorldDestroy(w.world);
  dCloseODE();
  return result;
}

}  // namespace tumble::bench
