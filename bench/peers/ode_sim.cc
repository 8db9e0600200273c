// ODE 0.16 (Debian, double precision) as SCENES.md maps it: dWorldQuickStep with 20 iterations,
// ERP 0.2 and CFM 1e-10 (its defaults), dHashSpace, up to 8 contacts per geom pair,
// dContactApprox1 so that mu is a Coulomb coefficient. Friction sqrt(mu_a mu_b) and the larger
// restitution per pair, as ours combines them; impacts slower than 1 m/s do not bounce (ours).
// Joints as ODE's own of the same kind (ball, hinge, slider, fixed; a distance joint as dDBall),
// limits as its stops and motors as its motor rows, both exact rows of its LCP; cones, twist
// limits, springs and distance ranges are refused. With `ode_world_step`, dWorldStep.
#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <set>
#include <utility>
#include <vector>

#include "peers/simulation.h"

namespace tumble::bench {
namespace {

struct Material {
  double friction = 0.5, restitution = 0;
};

class OdeSimulation final : public Simulation {
 public:
  OdeSimulation(const SceneDef& scene, bool world_step) : dt_(scene.dt), world_step_(world_step) {
    static std::once_flag once;
    std::call_once(once, [] { dInitODE2(0); });
    engine_ = "ODE 0.16 double";
    settings_ = world_step ? "dWorldStep (direct LCP), ERP 0.2, CFM 1e-10"
                           : "quickstep, 20 iterations, ERP 0.2, CFM 1e-10";
    world_ = dWorldCreate();
    space_ = dHashSpaceCreate(nullptr);
    contacts_ = dJointGroupCreate(0);
    const Vec3& g = scene.world.gravity;
    dWorldSetGravity(world_, g.x(), g.y(), g.z());
    dWorldSetQuickStepNumIterations(world_, 20);
    materials_.reserve(scene.bodies.size());
  }
  ~OdeSimulation() override {
    dJointGroupDestroy(contacts_);
    dSpaceDestroy(space_);
    dWorldDestroy(world_);
  }

  bool add(const BodyDef& def, double mass_kg, const Vec3& inertia, std::string* why_not) {
    if (def.type == BodyType::kKinematic) {
      *why_not = "kinematic bodies are not mapped to this peer";
      return false;
    }
    scene_bodies_.push_back(nullptr);
    dGeomID geom = nullptr;
    if (std::holds_alternative<HalfSpaceDef>(def.shape)) {
      const Vec3 n = def.orientation * Vec3::UnitZ();
      geom = dCreatePlane(space_, n.x(), n.y(), n.z(), n.dot(def.position));
    } else if (const auto* box = std::get_if<BoxDef>(&def.shape)) {
      const Vec3 size = 2 * box->half_extents;
      geom = dCreateBox(space_, size.x(), size.y(), size.z());
    } else if (const auto* sphere = std::get_if<SphereDef>(&def.shape)) {
      geom = dCreateSphere(space_, sphere->radius);
    } else if (const auto* capsule = std::get_if<CapsuleDef>(&def.shape)) {
      geom = dCreateCapsule(space_, capsule->radius, 2 * capsule->half_height);
    } else {
      *why_not = "hulls, heightfields, meshes and compounds are not mapped to ODE";
      return false;
    }
    materials_.push_back({def.friction, def.restitution});
    dGeomSetData(geom, &materials_.back());
    if (std::holds_alternative<HalfSpaceDef>(def.shape)) return true;
    const Quat& q = def.orientation;
    const dQuaternion rotation = {q.w(), q.x(), q.y(), q.z()};
    if (def.type == BodyType::kStatic) {
      dGeomSetPosition(geom, def.position.x(), def.position.y(), def.position.z());
      dGeomSetQuaternion(geom, rotation);
      return true;
    }
    dBodyID body = dBodyCreate(world_);
    dMass mass;
    dMassSetParameters(&mass, mass_kg, 0, 0, 0, inertia.x(), inertia.y(), inertia.z(), 0, 0, 0);
    dBodySetMass(body, &mass);
    dBodySetPosition(body, def.position.x(), def.position.y(), def.position.z());
    dBodySetQuaternion(body, rotation);
    dBodySetLinearVel(body, def.linear_velocity.x(), def.linear_velocity.y(),
                      def.linear_velocity.z());
    dBodySetAngularVel(body, def.angular_velocity.x(), def.angular_velocity.y(),
                       def.angular_velocity.z());
    dGeomSetBody(geom, body);
    dynamic_.push_back(body);
    scene_bodies_.back() = body;
    return true;
  }
  // The ODE body of the scene's body `i`: null for a static one, as ODE's joints take the world.
  dBodyID body_of(std::size_t i) const { return scene_bodies_[i]; }

  // ODE measures a hinge's angle and a slider's offset as its first body's against its second
  // (the world's when that is null), ours as b's against a: attached as (a, b), every bound and
  // speed changes sign.
  bool join(const SceneJoint& joint, std::string* why_not) {
    const JointDef& def = joint.def;
    if (def.spring.enabled || def.friction > 0 || def.max_swing < 3.14159265358979 ||
        (def.limit.enabled && def.kind != JointKind::kHinge && def.kind != JointKind::kSlider)) {
      *why_not =
          "joint springs, friction, cones, twist limits and distance ranges are not mapped to ODE";
      return false;
    }
    dBodyID a = body_of(joint.a), b = joint.b ? body_of(*joint.b) : nullptr;
    const Vec3& p = def.anchor;
    const Vec3 axis = def.axis.normalized();
    dJointID made = nullptr;
    switch (def.kind) {
      case JointKind::kBall:
        made = dJointCreateBall(world_, nullptr);
        dJointAttach(made, a, b);
        dJointSetBallAnchor(made, p.x(), p.y(), p.z());
        break;
      case JointKind::kHinge:
        made = dJointCreateHinge(world_, nullptr);
        dJointAttach(made, a, b);
        dJointSetHingeAnchor(made, p.x(), p.y(), p.z());
        dJointSetHingeAxis(made, axis.x(), axis.y(), axis.z());
        break;
      case JointKind::kSlider:
        made = dJointCreateSlider(world_, nullptr);
        dJointAttach(made, a, b);
        dJointSetSliderAxis(made, axis.x(), axis.y(), axis.z());
        break;
      case JointKind::kFixed:
        made = dJointCreateFixed(world_, nullptr);
        dJointAttach(made, a, b);
        dJointSetFixed(made);
        break;
      case JointKind::kDistance: {
        made = dJointCreateDBall(world_, nullptr);
        dJointAttach(made, a, b);
        const Vec3& q = def.anchor_b;
        dJointSetDBallAnchor1(made, p.x(), p.y(), p.z());
        dJointSetDBallAnchor2(made, q.x(), q.y(), q.z());
        dJointSetDBallDistance(made, def.length > 0 ? def.length : (q - p).norm());
        break;
      }
    }
    if (def.kind == JointKind::kHinge || def.kind == JointKind::kSlider) {
      auto set = [&](int parameter, double value) {
        if (def.kind == JointKind::kHinge) {
          dJointSetHingeParam(made, parameter, value);
        } else {
          dJointSetSliderParam(made, parameter, value);
        }
      };
      if (def.limit.enabled) {
        set(dParamLoStop, -def.limit.upper);
        set(dParamHiStop, -def.limit.lower);
      }
      if (def.motor.enabled) {
        set(dParamVel, -def.motor.speed);
        set(dParamFMax, def.motor.max_force);
      }
    } else if (def.motor.enabled) {
      *why_not = "motors on balls, fixed and distance joints do not exist";
      return false;
    }
    if (!def.collide_connected && a != nullptr && b != nullptr) apart_.insert(std::minmax(a, b));
    return true;
  }

  bool step() override {
    depth_ = 0;
    dSpaceCollide(space_, this, &OdeSimulation::near_callback);
    if (world_step_) {
      dWorldStep(world_, dt_);
    } else {
      dWorldQuickStep(world_, dt_);
    }
    dJointGroupEmpty(contacts_);
    return true;
  }
  std::size_t body_count() const override { return dynamic_.size(); }
  BodyState body(std::size_t i) const override {
    const dReal* p = dBodyGetPosition(dynamic_[i]);
    const dReal* q = dBodyGetQuaternion(dynamic_[i]);
    const dReal* v = dBodyGetLinearVel(dynamic_[i]);
    const dReal* w = dBodyGetAngularVel(dynamic_[i]);
    return {Vec3(p[0], p[1], p[2]), Quat(q[0], q[1], q[2], q[3]), Vec3(v[0], v[1], v[2]),
            Vec3(w[0], w[1], w[2])};
  }
  double reported_depth() const override { return depth_; }

 private:
  static void near_callback(void* data, dGeomID a, dGeomID b) {
    auto* self = static_cast<OdeSimulation*>(data);
    dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
    if (ba == nullptr && bb == nullptr) return;
    if (self->apart_.contains(std::minmax(ba, bb))) return;
    const auto* ma = static_cast<const Material*>(dGeomGetData(a));
    const auto* mb = static_cast<const Material*>(dGeomGetData(b));
    dContact contact[8];
    const int n = dCollide(a, b, 8, &contact[0].geom, sizeof(dContact));
    for (int i = 0; i < n; ++i) {
      contact[i].surface.mode = dContactApprox1;
      contact[i].surface.mu = std::sqrt(ma->friction * mb->friction);
      const double e = std::max(ma->restitution, mb->restitution);
      if (e > 0) {
        contact[i].surface.mode |= dContactBounce;
        contact[i].surface.bounce = e;
        contact[i].surface.bounce_vel = 1.0;
      }
      self->depth_ = std::max(self->depth_, static_cast<double>(contact[i].geom.depth));
      dJointAttach(dJointCreateContact(self->world_, self->contacts_, &contact[i]), ba, bb);
    }
  }

  dWorldID world_;
  dSpaceID space_;
  dJointGroupID contacts_;
  double dt_, depth_ = 0;
  bool world_step_;
  std::vector<Material> materials_;
  std::vector<dBodyID> dynamic_, scene_bodies_;
  std::set<std::pair<dBodyID, dBodyID>> apart_;  // jointed pairs that do not collide
};

}  // namespace

std::unique_ptr<Simulation> make_ode(const PeerScene& peer, const PeerOptions& options,
                                     std::string* why_not) {
  if (options.ode_world_step && peer.scene->joints.empty()) {
    *why_not = "dWorldStep is measured on the scenes with joints only";
    return nullptr;
  }
  auto simulation = std::make_unique<OdeSimulation>(*peer.scene, options.ode_world_step);
  for (std::size_t i = 0; i < peer.scene->bodies.size(); ++i)
    if (!simulation->add(peer.scene->bodies[i], peer.mass[i], peer.inertia[i], why_not))
      return nullptr;
  for (const SceneJoint& joint : peer.scene->joints)
    if (!simulation->join(joint, why_not)) return nullptr;
  return simulation;
}

}  // namespace tumble::bench
