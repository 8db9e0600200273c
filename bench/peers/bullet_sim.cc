// Bullet 3.24 as SCENES.md maps it: btDiscreteDynamicsWorld, sequential impulses (10 iterations,
// split impulse), btDbvtBroadphase, default margins, one stepSimulation(dt, 0) per step. Compiled
// twice: into the benchmarks against Debian's float build, and with BT_USE_DOUBLE_PRECISION into
// a module of its own against the float64 build (both export the same symbols, so the module is
// loaded with RTLD_DEEPBIND and hands out its simulations through one C entry point).
#include <BulletCollision/CollisionShapes/btHeightfieldTerrainShape.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "peers/simulation.h"

namespace tumble::bench {
namespace {

#ifdef BT_USE_DOUBLE_PRECISION
constexpr const char* kEngine = "Bullet 3.24 double";
#else
constexpr const char* kEngine = "Bullet 3.24 float";
#endif

btVector3 to_bt(const Vec3& v) {
  return btVector3(v.x(), v.y(), v.z());
}
Vec3 from_bt(const btVector3& v) {
  return Vec3(v.x(), v.y(), v.z());
}

class BulletSimulation final : public Simulation {
 public:
  BulletSimulation(const SceneDef& scene, const PeerOptions& options)
      : dispatcher_(&configuration_),
        world_(&dispatcher_, &broadphase_, &solver_, &configuration_),
        dt_(scene.dt) {
    engine_ = kEngine;
    if (options.iterations > 0) world_.getSolverInfo().m_numIterations = options.iterations;
    settings_ = "sequential impulse, " + std::to_string(world_.getSolverInfo().m_numIterations) +
                " iterations, split impulse, sleeping " + (options.sleeping ? "on" : "off") +
                (options.ccd ? ", swept-sphere CCD" : "");
    world_.setGravity(to_bt(scene.world.gravity));
  }

  ~BulletSimulation() override {
    for (auto& constraint : constraints_)
      world_.removeConstraint(constraint.get());
    for (auto& body : bodies_)
      world_.removeRigidBody(body.get());
  }

  // False (with the reason) for a shape this adapter does not map.
  bool add(const BodyDef& def, double mass, Vec3 inertia, const Vec3& centre_of_mass,
           const Mat3& inertia_tensor, const PeerOptions& options, std::string* why_not) {
    std::unique_ptr<btCollisionShape> shape;
    // Bullet's body frame is its centre of mass on its principal axes: the shape's frame turned
    // by `principal` and moved to the centre of mass (the identity but for compounds).
    Quat principal = Quat::Identity();
    btTransform pose(btQuaternion(def.orientation.x(), def.orientation.y(), def.orientation.z(),
                                  def.orientation.w()),
                     to_bt(def.position));
    if (std::holds_alternative<HalfSpaceDef>(def.shape)) {
      const Vec3 normal = def.orientation * Vec3::UnitZ();
      shape = std::make_unique<btStaticPlaneShape>(to_bt(normal), normal.dot(def.position));
      pose.setIdentity();
    } else if (const auto* box = std::get_if<BoxDef>(&def.shape)) {
      shape = std::make_unique<btBoxShape>(to_bt(box->half_extents));
    } else if (const auto* sphere = std::get_if<SphereDef>(&def.shape)) {
      shape = std::make_unique<btSphereShape>(sphere->radius);
    } else if (const auto* capsule = std::get_if<CapsuleDef>(&def.shape)) {
      shape = std::make_unique<btCapsuleShapeZ>(capsule->radius, 2 * capsule->half_height);
    } else if (const auto* compound = std::get_if<CompoundDef>(&def.shape)) {
      // A btCompoundShape of the parts at their poses in Bullet's body frame: from the shape's
      // frame, moved to the centre of mass and turned onto the principal axes of the inertia
      // tensor (its eigenvectors; the shape's own axes where the tensor is diagonal already, as
      // for a compound symmetric about them). The body is placed there, and body() turns its
      // orientation back to the shape's, as ours reports it.
      const bool diagonal =
          (inertia_tensor - Mat3(inertia_tensor.diagonal().asDiagonal())).cwiseAbs().maxCoeff() ==
          0;
      if (!diagonal) {
        const Eigen::SelfAdjointEigenSolver<Mat3> axes(inertia_tensor);
        Mat3 turn = axes.eigenvectors();
        if (turn.determinant() < 0) turn.col(2) = -turn.col(2);
        principal = Quat(turn).normalized();
        inertia = axes.eigenvalues();
      }
      const Quat to_principal = principal.conjugate();
      auto parts = std::make_unique<btCompoundShape>();
      for (const CompoundPart& part : compound->parts) {
        std::unique_ptr<btCollisionShape> child;
        if (const auto* box = std::get_if<BoxDef>(&part.shape))
          child = std::make_unique<btBoxShape>(to_bt(box->half_extents));
        else if (const auto* sphere = std::get_if<SphereDef>(&part.shape))
          child = std::make_unique<btSphereShape>(sphere->radius);
        else if (const auto* capsule = std::get_if<CapsuleDef>(&part.shape))
          child = std::make_unique<btCapsuleShapeZ>(capsule->radius, 2 * capsule->half_height);
        if (child == nullptr) {
          *why_not = "hull parts of compounds are not mapped to Bullet";
          return false;
        }
        const Quat q = to_principal * part.pose.orientation;
        parts->addChildShape(
            btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()),
                        to_bt(to_principal * (part.pose.position - centre_of_mass))),
            child.get());
        shapes_.push_back(std::move(child));
      }
      shape = std::move(parts);
      const Quat placed = def.orientation * principal;
      pose = btTransform(btQuaternion(placed.x(), placed.y(), placed.z(), placed.w()),
                         to_bt(def.position + def.orientation * centre_of_mass));
    } else if (const auto* mesh = std::get_if<TriangleMeshDef>(&def.shape)) {
      // A btBvhTriangleMeshShape as a user makes one, without btAdjustInternalEdgeContacts (an
      // optional contact callback): its inner edges are what the mesh scenes measure.
      auto triangles = std::make_unique<btTriangleMesh>();
      for (const auto& t : mesh->triangles)
        triangles->addTriangle(to_bt(mesh->vertices[t[0]]), to_bt(mesh->vertices[t[1]]),
                               to_bt(mesh->vertices[t[2]]));
      shape = std::make_unique<btBvhTriangleMeshShape>(triangles.get(), true);
      meshes_.push_back(std::move(triangles));
    } else if (const auto* field = std::get_if<HeightFieldDef>(&def.shape)) {
      // Bullet's heightfield reads the heights where they lie (kept here, in double) and centres
      // itself on its bounds, the up axis included: the body's frame is shifted up by the middle
      // of the heights so that the grid lies where ours does. Its quads split along
      // (x, y)-(x + 1, y + 1), as ours do, with flipQuadEdges.
      height_fields_.push_back(field->heights);
      const std::vector<double>& heights = height_fields_.back();
      const auto [low, high] = std::minmax_element(heights.begin(), heights.end());
      auto terrain = std::make_unique<btHeightfieldTerrainShape>(
          static_cast<int>(field->samples_x), static_cast<int>(field->samples_y), heights.data(),
          *low, *high, 2, true);
      terrain->setLocalScaling(btVector3(field->spacing_x, field->spacing_y, 1));
      pose.setOrigin(pose.getOrigin() +
                     pose.getBasis() * btVector3(0, 0, 0.5 * (*low + *high)));
      shape = std::move(terrain);
    } else {
      *why_not = "hulls are not mapped to Bullet";
      return false;
    }
    // A kinematic body is Bullet's: no mass, CF_KINEMATIC_OBJECT, moved through its motion state
    // each step (step()), from which Bullet takes its velocity.
    const bool kinematic = def.type == BodyType::kKinematic;
    const bool is_static = def.type == BodyType::kStatic || kinematic;
    states_.push_back(std::make_unique<btDefaultMotionState>(pose));
    btRigidBody::btRigidBodyConstructionInfo info(is_static ? 0 : mass, states_.back().get(),
                                                  shape.get(),
                                                  is_static ? btVector3(0, 0, 0) : to_bt(inertia));
    // Bullet multiplies the two bodies' values; ours takes sqrt(fa fb) for friction and the
    // larger restitution, which the square roots reproduce whenever both bodies agree.
    info.m_friction = std::sqrt(def.friction);
    info.m_restitution = std::sqrt(def.restitution);
    shapes_.push_back(std::move(shape));
    bodies_.push_back(std::make_unique<btRigidBody>(info));
    btRigidBody* body = bodies_.back().get();
    body->setLinearVelocity(to_bt(def.linear_velocity));
    body->setAngularVelocity(to_bt(def.angular_velocity));
    if (!options.sleeping) body->setActivationState(DISABLE_DEACTIVATION);
    if (options.ccd && !is_static) {
      body->setCcdMotionThreshold(0.05);
      body->setCcdSweptSphereRadius(0.04);
    }
    if (kinematic) {
      body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
      body->setActivationState(DISABLE_DEACTIVATION);
      kinematic_.push_back({states_.back().get(), def.linear_velocity, def.angular_velocity});
    }
    world_.addRigidBody(body);
    if (!is_static) {
      dynamic_.push_back(body);
      principal_.push_back(principal);
    }
    return true;
  }

  // The joint as Bullet's constraint of the same kind, each built from one frame at the joint
  // (origin at the anchor, z or for cones x along the axis) taken into both bodies' frames at
  // their poses now, so that every angle starts at zero: a ball as btPoint2PointConstraint, or
  // btConeTwistConstraint where it has a cone (its twist limit symmetric); a hinge as
  // btHingeConstraint (its motor as the angular motor with the force bound as the impulse of a
  // step; its limits); a fixed joint as btFixedConstraint. False (with the reason) for what this
  // adapter does not map: springs, friction, asymmetric twist limits, sliders, distance joints.
  bool join(const SceneJoint& joint, std::string* why_not) {
    const JointDef& def = joint.def;
    const bool cone = def.kind == JointKind::kBall && def.max_swing < 3.14159265358979;
    if (def.spring.enabled || def.friction > 0 ||
        (def.kind == JointKind::kBall && def.limit.enabled &&
         (!cone || def.limit.lower != -def.limit.upper))) {
      *why_not =
          "joint springs and friction, and twist limits other than symmetric ones within a cone, "
          "are not mapped to Bullet";
      return false;
    }
    btRigidBody& a = *bodies_[joint.a];
    btRigidBody& b = joint.b ? *bodies_[*joint.b] : btTypedConstraint::getFixedBody();
    // A world frame at the anchor whose `along` axis (0 x, 2 z) is the joint's axis.
    auto joint_frame = [&](int along) {
      const Vec3 axis = def.axis.normalized();
      const Quat turn = Quat::FromTwoVectors(along == 0 ? Vec3::UnitX() : Vec3::UnitZ(), axis);
      const Quat r = turn.normalized();
      btTransform frame;
      frame.setOrigin(to_bt(def.anchor));
      frame.setRotation(btQuaternion(r.x(), r.y(), r.z(), r.w()));
      return frame;
    };
    auto in_body = [](const btRigidBody& body, const btTransform& world) {
      return body.getCenterOfMassTransform().inverse() * world;
    };
    std::unique_ptr<btTypedConstraint> constraint;
    switch (def.kind) {
      case JointKind::kBall:
        if (cone) {
          const btTransform frame = joint_frame(0);
          auto cone_twist =
              std::make_unique<btConeTwistConstraint>(a, b, in_body(a, frame), in_body(b, frame));
          cone_twist->setLimit(def.max_swing, def.max_swing,
                               def.limit.enabled ? def.limit.upper : 3.14159265358979);
          constraint = std::move(cone_twist);
        } else {
          constraint = std::make_unique<btPoint2PointConstraint>(
              a, b, in_body(a, joint_frame(2)).getOrigin(), in_body(b, joint_frame(2)).getOrigin());
        }
        break;
      case JointKind::kHinge: {
        const btTransform frame = joint_frame(2);
        auto hinge =
            std::make_unique<btHingeConstraint>(a, b, in_body(a, frame), in_body(b, frame));
        // Bullet's angle and motor are a's turn against b's; ours, b's against a's.
        if (def.limit.enabled) hinge->setLimit(-def.limit.upper, -def.limit.lower);
        if (def.motor.enabled)
          hinge->enableAngularMotor(true, -def.motor.speed, def.motor.max_force * dt_);
        constraint = std::move(hinge);
        break;
      }
      case JointKind::kFixed: {
        const btTransform frame = joint_frame(2);
        constraint =
            std::make_unique<btFixedConstraint>(a, b, in_body(a, frame), in_body(b, frame));
        break;
      }
      default:
        *why_not = "sliders and distance joints are not mapped to Bullet";
        return false;
    }
    world_.addConstraint(constraint.get(), !def.collide_connected);
    constraints_.push_back(std::move(constraint));
    return true;
  }

  bool step() override {
    for (const Kinematic& k : kinematic_) {
      btTransform pose;
      k.state->getWorldTransform(pose);
      const btVector3 turn = to_bt(k.angular_velocity * dt_);
      const btScalar angle = turn.length();
      btQuaternion q = pose.getRotation();
      if (angle > 0) q = btQuaternion(turn / angle, angle) * q;
      pose.setRotation(q.normalized());
      pose.setOrigin(pose.getOrigin() + to_bt(k.linear_velocity * dt_));
      k.state->setWorldTransform(pose);
    }
    world_.stepSimulation(dt_, 0);
    return true;
  }
  std::size_t body_count() const override { return dynamic_.size(); }
  BodyState body(std::size_t i) const override {
    const btRigidBody* b = dynamic_[i];
    const btTransform& t = b->getCenterOfMassTransform();
    const btQuaternion r = t.getRotation();
    return {from_bt(t.getOrigin()), Quat(r.w(), r.x(), r.y(), r.z()) * principal_[i].conjugate(),
            from_bt(b->getLinearVelocity()), from_bt(b->getAngularVelocity())};
  }

 private:
  btDefaultCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  btDiscreteDynamicsWorld world_;
  double dt_;
  // The triangles of shapes_' meshes, declared first so that the shapes go before them.
  std::vector<std::unique_ptr<btTriangleMesh>> meshes_;
  // The heights of shapes_' heightfields, which Bullet reads in place (a deque: they stay put).
  std::deque<std::vector<double>> height_fields_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btDefaultMotionState>> states_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<btRigidBody*> dynamic_;
  std::vector<Quat> principal_;  // dynamic_[i]'s principal axes in its shape's frame
  struct Kinematic {
    btDefaultMotionState* state;
    Vec3 linear_velocity, angular_velocity;
  };
  std::vector<Kinematic> kinematic_;
  std::vector<std::unique_ptr<btTypedConstraint>> constraints_;
};

Simulation* build(const PeerScene& peer, const PeerOptions& options, std::string* why_not) {
  auto simulation = std::make_unique<BulletSimulation>(*peer.scene, options);
  for (std::size_t i = 0; i < peer.scene->bodies.size(); ++i)
    if (!simulation->add(peer.scene->bodies[i], peer.mass[i], peer.inertia[i],
                         peer.centre_of_mass[i], peer.inertia_tensor[i], options, why_not))
      return nullptr;
  for (const SceneJoint& joint : peer.scene->joints)
    if (!simulation->join(joint, why_not)) return nullptr;
  return simulation.release();
}

}  // namespace

#ifdef BT_USE_DOUBLE_PRECISION
extern "C" __attribute__((visibility("default"))) Simulation* tumble_make_bullet_double(
    const PeerScene* scene, const PeerOptions* options, std::string* why_not) {
  return build(*scene, *options, why_not);
}
#else
std::unique_ptr<Simulation> make_bullet(const PeerScene& scene, const PeerOptions& options,
                                        std::string* why_not) {
  return std::unique_ptr<Simulation>(build(scene, options, why_not));
}
#endif

}  // namespace tumble::bench
