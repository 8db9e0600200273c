// Bullet 3.24's btMultiBody (Featherstone's articulated-body algorithm, float): the jointed bodies
// in generalised coordinates, so a chain holds its length by construction, as MuJoCo's does. Each
// tree of joints hanging from the world (joint_forest.h) is one btMultiBody on a fixed base at the
// world's origin; a ball joint is a spherical link, a hinge a revolute one, a slider a prismatic
// one, a fixed joint a fixed link. btMultiBodyDynamicsWorld with its btMultiBodyConstraintSolver
// (sequential impulses, 10 iterations) for the contacts, btDbvtBroadphase, one
// stepSimulation(dt, 0) per step; the links' damping off (Bullet's default damps every link by
// 0.04), their rates clamped at Bullet's default 100 rad/s (unclamped, a chain of 20 falling from
// level blew up within a second at dt 1/60: its explicit step in generalised coordinates, as
// MuJoCo's Euler; with it, a step that leaves a joint's rate at the clamp is reported as the engine
// unable to go on). Links collide with each other but not with the link they are jointed to, as
// ours. A hinge's or slider's motor is a btMultiBodyJointMotor (its impulse bounded by the force
// over a step), its limits a btMultiBodyJointLimitConstraint. Springs, cones, joint friction,
// distance joints, free bodies beside the trees and trees not hanging from the world are refused.
// (Bullet's multibody headers leave parameters unused.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <btBulletDynamicsCommon.h>
#pragma GCC diagnostic pop

#include <cmath>
#include <memory>
#include <vector>

#include "peers/joint_forest.h"
#include "peers/simulation.h"

namespace tumble::bench {
namespace {

btVector3 to_bt(const Vec3& v) {
  return btVector3(v.x(), v.y(), v.z());
}
btQuaternion to_bt(const Quat& q) {
  return btQuaternion(q.x(), q.y(), q.z(), q.w());
}
Vec3 from_bt(const btVector3& v) {
  return Vec3(v.x(), v.y(), v.z());
}

// Where a dynamic body is in the multibodies: which one, and its link there.
struct LinkOf {
  std::size_t tree = 0;
  int link = 0;
};

class MultibodySimulation final : public Simulation {
 public:
  MultibodySimulation()
      : dispatcher_(&configuration_),
        world_(&dispatcher_, &broadphase_, &solver_, &configuration_) {
    engine_ = "Bullet 3.24 multibody float";
    settings_ =
        "btMultiBody (Featherstone), fixed base, joint rates clamped at 100 rad/s (Bullet's "
        "default), contacts by sequential impulse, 10 iterations";
  }
  ~MultibodySimulation() override {
    for (auto& constraint : constraints_)
      world_.removeMultiBodyConstraint(constraint.get());
    for (auto& collider : colliders_)
      world_.removeCollisionObject(collider.get());
    for (auto& body : statics_)
      world_.removeRigidBody(body.get());
    for (auto& tree : trees_)
      world_.removeMultiBody(tree.get());
  }

  bool build(const PeerScene& peer, const PeerOptions& options, std::string* why_not);

  bool step() override {
    // (The world clears the links' forces after each step: the kicks act in the first alone.)
    for (const auto& [link, force] : kicks_)
      trees_[link.tree]->addLinkForce(link.link, to_bt(force));
    kicks_.clear();
    world_.stepSimulation(dt_, 0);
    current_ = false;
    // A joint rate at Bullet's clamp means the motion has left what the step resolves (a chain
    // of a hundred released level flails at kilometres a second within seconds, its joints held
    // by construction): reported as the engine unable to go on, as MuJoCo's warnings are.
    for (const auto& tree : trees_)
      for (int link = 0; link < tree->getNumLinks(); ++link) {
        const btScalar* rates = tree->getJointVelMultiDof(link);
        for (int d = 0; d < tree->getLink(link).m_dofCount; ++d)
          if (!(std::abs(rates[d]) < 0.999 * tree->getMaxCoordinateVelocity())) return false;
      }
    return true;
  }
  std::size_t body_count() const override { return links_.size(); }
  BodyState body(std::size_t i) const override {
    if (!current_) read_velocities();
    const LinkOf& at = links_[i];
    const btTransform& pose =
        trees_[at.tree]->getLink(at.link).m_collider->getWorldTransform();
    const btQuaternion q = pose.getRotation();
    const Quat orientation(q.w(), q.x(), q.y(), q.z());
    // compTreeLinkVelocities gives each link's velocities in its own axes (0 is the base).
    const std::vector<btVector3>& omega = omega_[at.tree];
    const std::vector<btVector3>& velocity = velocity_[at.tree];
    return {from_bt(pose.getOrigin()), orientation,
            orientation * from_bt(velocity[at.link + 1]),
            orientation * from_bt(omega[at.link + 1])};
  }

 private:
  void read_velocities() const {
    for (std::size_t t = 0; t < trees_.size(); ++t) {
      omega_[t].resize(trees_[t]->getNumLinks() + 1);
      velocity_[t].resize(trees_[t]->getNumLinks() + 1);
      trees_[t]->compTreeLinkVelocities(omega_[t].data(), velocity_[t].data());
    }
    current_ = true;
  }
  std::unique_ptr<btCollisionShape> shape_of(const BodyDef& def, std::string* why_not);

  btDefaultCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btMultiBodyConstraintSolver solver_;
  btMultiBodyDynamicsWorld world_;
  double dt_ = 1.0 / 60;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states_;
  std::vector<std::unique_ptr<btRigidBody>> statics_;
  std::vector<std::unique_ptr<btMultiBody>> trees_;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders_;
  std::vector<std::unique_ptr<btMultiBodyConstraint>> constraints_;  // motors and limits
  std::vector<LinkOf> links_;  // by dynamic body, in scene order
  std::vector<std::pair<LinkOf, Vec3>> kicks_;  // forces on links during the first step
  mutable std::vector<std::vector<btVector3>> omega_, velocity_;
  mutable bool current_ = false;
};

std::unique_ptr<btCollisionShape> MultibodySimulation::shape_of(const BodyDef& def,
                                                                std::string* why_not) {
  if (std::holds_alternative<HalfSpaceDef>(def.shape)) {
    const Vec3 normal = def.orientation * Vec3::UnitZ();
    return std::make_unique<btStaticPlaneShape>(to_bt(normal), normal.dot(def.position));
  }
  if (const auto* box = std::get_if<BoxDef>(&def.shape))
    return std::make_unique<btBoxShape>(to_bt(box->half_extents));
  if (const auto* sphere = std::get_if<SphereDef>(&def.shape))
    return std::make_unique<btSphereShape>(sphere->radius);
  if (const auto* capsule = std::get_if<CapsuleDef>(&def.shape))
    return std::make_unique<btCapsuleShapeZ>(capsule->radius, 2 * capsule->half_height);
  *why_not = "hulls, heightfields, meshes and compounds are not mapped to Bullet's multibodies";
  return nullptr;
}

bool MultibodySimulation::build(const PeerScene& peer, const PeerOptions& options,
                                std::string* why_not) {
  const SceneDef& scene = *peer.scene;
  dt_ = scene.dt;
  world_.setGravity(to_bt(scene.world.gravity));
  for (const SceneJoint& joint : scene.joints) {
    const JointDef& def = joint.def;
    const bool hinge_or_slider = def.kind == JointKind::kHinge || def.kind == JointKind::kSlider;
    if (def.kind == JointKind::kDistance || def.spring.enabled || def.friction > 0 ||
        def.max_swing < 3.14159265358979 ||
        ((def.motor.enabled || def.limit.enabled) && !hinge_or_slider)) {
      *why_not =
          "distance joints, springs, joint friction, cones, and limits and motors on other joints "
          "than hinges and sliders are not mapped to Bullet's multibodies";
      return false;
    }
  }
  std::vector<Placement> placements;
  if (!place(scene, &placements, why_not)) return false;
  // The trees: each dynamic body held through joints from the world, parents before children.
  std::vector<std::vector<std::size_t>> children(scene.bodies.size());
  std::vector<std::size_t> roots;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    if (scene.bodies[i].type != BodyType::kDynamic) continue;
    if (!placements[i].joint) {
      *why_not = "free bodies and trees not hanging from the world are not mapped to Bullet's "
                 "multibodies";
      return false;
    }
    if (placements[i].parent)
      children[*placements[i].parent].push_back(i);
    else
      roots.push_back(i);
  }
  // Static bodies: Bullet's static rigid bodies, as in the sequential-impulse adapter.
  for (const BodyDef& def : scene.bodies) {
    if (def.type != BodyType::kStatic) continue;
    std::unique_ptr<btCollisionShape> shape = shape_of(def, why_not);
    if (shape == nullptr) return false;
    btTransform pose(to_bt(def.orientation), to_bt(def.position));
    if (std::holds_alternative<HalfSpaceDef>(def.shape)) pose.setIdentity();
    auto motion = std::make_unique<btDefaultMotionState>(pose);
    btRigidBody::btRigidBodyConstructionInfo info(0, motion.get(), shape.get());
    info.m_friction = def.friction;
    info.m_restitution = def.restitution;
    auto body = std::make_unique<btRigidBody>(info);
    world_.addRigidBody(body.get());
    shapes_.push_back(std::move(shape));
    motion_states_.push_back(std::move(motion));
    statics_.push_back(std::move(body));
  }
  links_.assign(scene.bodies.size(), {});
  std::vector<bool> is_link(scene.bodies.size(), false);
  for (std::size_t root : roots) {
    // The tree's bodies in depth-first order: every link after its parent.
    std::vector<std::size_t> order;
    std::vector<std::size_t> stack{root};
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      order.push_back(i);
      for (auto c = children[i].rbegin(); c != children[i].rend(); ++c)
        stack.push_back(*c);
    }
    std::vector<int> link_of(scene.bodies.size(), -1);
    for (std::size_t k = 0; k < order.size(); ++k)
      link_of[order[k]] = static_cast<int>(k);
    const std::size_t tree_index = trees_.size();
    auto tree = std::make_unique<btMultiBody>(static_cast<int>(order.size()), 0,
                                              btVector3(0, 0, 0), true, options.sleeping);
    tree->setBasePos(btVector3(0, 0, 0));
    tree->setWorldToBaseRot(btQuaternion::getIdentity());
    for (std::size_t k = 0; k < order.size(); ++k) {
      const std::size_t i = order[k];
      const BodyDef& def = scene.bodies[i];
      const JointDef& joint = scene.joints[*placements[i].joint].def;
      const std::optional<std::size_t> parent = placements[i].parent;
      const Vec3 parent_position = parent ? scene.bodies[*parent].position : Vec3::Zero();
      const Quat parent_orientation =
          parent ? scene.bodies[*parent].orientation : Quat::Identity();
      // Link frames are the bodies' (centre of mass, principal axes: the inertia is diagonal
      // about the shape's axes); the base is the world's.
      const Quat parent_to_this = def.orientation.conjugate() * parent_orientation;
      const Vec3 parent_to_pivot = parent_orientation.conjugate() * (joint.anchor - parent_position);
      const Vec3 pivot_to_this = def.orientation.conjugate() * (def.position - joint.anchor);
      const int parent_link = parent ? link_of[*parent] : -1;
      const btVector3 inertia = to_bt(peer.inertia[i]);
      const bool apart = !joint.collide_connected;
      switch (joint.kind) {
        case JointKind::kBall:
          tree->setupSpherical(static_cast<int>(k), peer.mass[i], inertia, parent_link,
                               to_bt(parent_to_this), to_bt(parent_to_pivot), to_bt(pivot_to_this),
                               apart);
          break;
        case JointKind::kHinge:
          tree->setupRevolute(static_cast<int>(k), peer.mass[i], inertia, parent_link,
                              to_bt(parent_to_this),
                              to_bt(def.orientation.conjugate() * joint.axis.normalized()),
                              to_bt(parent_to_pivot), to_bt(pivot_to_this), apart);
          break;
        case JointKind::kSlider:
          tree->setupPrismatic(static_cast<int>(k), peer.mass[i], inertia, parent_link,
                               to_bt(parent_to_this),
                               to_bt(def.orientation.conjugate() * joint.axis.normalized()),
                               to_bt(parent_to_pivot), to_bt(pivot_to_this), apart);
          break;
        case JointKind::kFixed:
          tree->setupFixed(static_cast<int>(k), peer.mass[i], inertia, parent_link,
                           to_bt(parent_to_this), to_bt(parent_to_pivot), to_bt(pivot_to_this));
          break;
        case JointKind::kDistance:
          break;  // refused above
      }
      links_[i] = {tree_index, static_cast<int>(k)};
      is_link[i] = true;
    }
    tree->finalizeMultiDof();
    tree->setLinearDamping(0);
    tree->setAngularDamping(0);
    tree->setHasSelfCollision(true);
    tree->setCanSleep(options.sleeping);
    world_.addMultiBody(tree.get());
    // Colliders at the links' poses.
    btAlignedObjectArray<btQuaternion> world_to_local;
    btAlignedObjectArray<btVector3> local_origin;
    world_to_local.resize(tree->getNumLinks() + 1);
    local_origin.resize(tree->getNumLinks() + 1);
    tree->forwardKinematics(world_to_local, local_origin);
    for (std::size_t k = 0; k < order.size(); ++k) {
      const BodyDef& def = scene.bodies[order[k]];
      std::unique_ptr<btCollisionShape> shape = shape_of(def, why_not);
      if (shape == nullptr) return false;
      auto collider = std::make_unique<btMultiBodyLinkCollider>(tree.get(), static_cast<int>(k));
      collider->setCollisionShape(shape.get());
      collider->setFriction(def.friction);
      collider->setRestitution(def.restitution);
      btTransform pose;
      pose.setOrigin(local_origin[k + 1]);
      pose.setRotation(world_to_local[k + 1].inverse());
      collider->setWorldTransform(pose);
      world_.addCollisionObject(collider.get(), btBroadphaseProxy::DefaultFilter,
                                btBroadphaseProxy::AllFilter);
      tree->getLink(static_cast<int>(k)).m_collider = collider.get();
      // The mapping must put every link where the scene has its body (to float's rounding,
      // compounded down a chain of a hundred links; a wrong frame is off by a link's size).
      const Vec3 at = from_bt(local_origin[k + 1]);
      const btQuaternion turn = world_to_local[k + 1].inverse();
      const Quat orientation(turn.w(), turn.x(), turn.y(), turn.z());
      if ((at - def.position).norm() > 1e-3 ||
          orientation.angularDistance(def.orientation) > 1e-3) {
        *why_not = "internal: a link's pose does not match its body's";
        return false;
      }
      shapes_.push_back(std::move(shape));
      colliders_.push_back(std::move(collider));
    }
    // Initial velocities as the MuJoCo adapter sets them: each joint's share of its body's turn
    // relative to its parent, in the body's axes.
    for (std::size_t k = 0; k < order.size(); ++k) {
      const std::size_t i = order[k];
      const BodyDef& def = scene.bodies[i];
      const JointDef& joint = scene.joints[*placements[i].joint].def;
      const std::optional<std::size_t> parent = placements[i].parent;
      Vec3 angular = def.angular_velocity;
      if (parent) angular -= scene.bodies[*parent].angular_velocity;
      const Vec3 local = def.orientation.conjugate() * angular;
      if (joint.kind == JointKind::kBall) {
        double rates[3] = {local.x(), local.y(), local.z()};
        tree->setJointVelMultiDof(static_cast<int>(k), rates);
      } else if (joint.kind == JointKind::kHinge) {
        tree->setJointVel(static_cast<int>(k),
                          local.dot(def.orientation.conjugate() * joint.axis.normalized()));
      }
    }
    // Motors (btMultiBodyJointMotor, its impulse bounded by the force over a step) and limits
    // (btMultiBodyJointLimitConstraint). The link's coordinate is its body's motion against its
    // parent, zero where the scene starts, as ours is; ours is b's against a.
    for (std::size_t k = 0; k < order.size(); ++k) {
      const std::size_t i = order[k];
      const SceneJoint& joint = scene.joints[*placements[i].joint];
      const double sign = i == joint.a ? -1 : 1;
      const auto keep = [this](std::unique_ptr<btMultiBodyConstraint> constraint) {
        world_.addMultiBodyConstraint(constraint.get());
        constraints_.push_back(std::move(constraint));
      };
      if (joint.def.motor.enabled)
        keep(std::make_unique<btMultiBodyJointMotor>(tree.get(), static_cast<int>(k),
                                                     sign * joint.def.motor.speed,
                                                     joint.def.motor.max_force * scene.dt));
      if (joint.def.limit.enabled) {
        const double lower = sign > 0 ? joint.def.limit.lower : -joint.def.limit.upper;
        const double upper = sign > 0 ? joint.def.limit.upper : -joint.def.limit.lower;
        keep(std::make_unique<btMultiBodyJointLimitConstraint>(tree.get(), static_cast<int>(k),
                                                               lower, upper));
      }
    }
    trees_.push_back(std::move(tree));
  }
  // Keep only the dynamic bodies' entries, in scene order.
  std::vector<LinkOf> dynamic;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    if (is_link[i]) dynamic.push_back(links_[i]);
  links_ = std::move(dynamic);
  omega_.resize(trees_.size());
  velocity_.resize(trees_.size());
  // A body's own velocity that its joint does not carry (the kicked end of a hanging chain) is
  // its momentum given as a force over the first step, as the MuJoCo adapter gives it.
  std::size_t k = 0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    if (scene.bodies[i].type != BodyType::kDynamic) continue;
    const Vec3 missing = scene.bodies[i].linear_velocity - body(k).linear_velocity;
    if (missing.norm() > 1e-9) kicks_.push_back({links_[k], peer.mass[i] * missing / scene.dt});
    ++k;
  }
  current_ = false;
  return true;
}

}  // namespace

std::unique_ptr<Simulation> make_bullet_multibody(const PeerScene& scene,
                                                  const PeerOptions& options,
                                                  std::string* why_not) {
  auto simulation = std::make_unique<MultibodySimulation>();
  if (!simulation->build(scene, options, why_not)) return nullptr;
  return simulation;
}

}  // namespace tumble::bench
