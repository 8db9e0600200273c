// MuJoCo 2.2.2 (Debian) as SCENES.md maps it: MJCF generated in code, Newton solver, 100
// iterations, pyramidal cone, Euler integrator, default soft contacts (solref/solimp); each
// dynamic body a freejoint with explicit inertia; geom friction "mu 0.005 0.0001", condim 3.
// MuJoCo 2.x preallocates contacts: nconmax = 12 per body + 64 (6 per body above 500 bodies),
// njmax = 4 nconmax; a step that overflows them is reported as a failure, not run on.
// Joints in MuJoCo's own way, generalised coordinates: the jointed bodies become a tree of nested
// bodies (a ball joint as "ball", a hinge as "hinge", a slider as "slide", a fixed joint as no
// joint at all), their limits as ranges and springs as joint stiffness and damping; a loop of
// joints, distance joints, motors (MuJoCo's velocity actuators are dampers, not bounded motors),
// cones and twist limits are refused.
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>

#include "peers/joint_forest.h"
#include "peers/simulation.h"

namespace tumble::bench {
namespace {

class MujocoSimulation final : public Simulation {
 public:
  MujocoSimulation(mjModel* model, std::vector<int> bodies)
      : model_(model), bodies_(std::move(bodies)) {
    // step() reads MuJoCo's warning counters; its default handler would print each warning and
    // append it to MUJOCO_LOG.TXT in the working directory.
    mju_user_warning = [](const char*) {};
    engine_ = "MuJoCo 2.2.2";
    settings_ = "Newton, 100 iterations, pyramidal cone, Euler, soft contacts";
    data_ = mj_makeData(model_);
  }
  ~MujocoSimulation() override {
    mj_deleteData(data_);
    mj_deleteModel(model_);
  }
  mjData* data() { return data_; }
  mjModel* model() { return model_; }

  // False once MuJoCo reports full buffers or a non-finite acceleration: on the latter it
  // resets the state to the model's start and would go on as if nothing happened.
  // A force (world axes, at the centre) on dynamic body i during the next step alone.
  void kick(std::size_t i, const Vec3& force) {
    mjtNum* applied = data_->xfrc_applied + 6 * bodies_[i];
    for (int c = 0; c < 3; ++c)
      applied[c] = force[c];
    kicked_ = true;
  }

  bool step() override {
    mj_step(model_, data_);
    if (kicked_) {
      mju_zero(data_->xfrc_applied, 6 * model_->nbody);
      kicked_ = false;
    }
    current_ = false;
    return data_->warning[mjWARN_CONTACTFULL].number == 0 &&
           data_->warning[mjWARN_CNSTRFULL].number == 0 &&
           data_->warning[mjWARN_BADQACC].number == 0;
  }
  std::size_t body_count() const override { return bodies_.size(); }
  BodyState body(std::size_t i) const override {
    // mj_step leaves the poses of the state it started from: bring them to the new one (not
    // timed: the run times step() alone).
    if (!current_) {
      mj_kinematics(model_, data_);
      mj_comPos(model_, data_);
      mj_comVel(model_, data_);
      current_ = true;
    }
    const int id = bodies_[i];
    const mjtNum* p = data_->xpos + 3 * id;
    const mjtNum* q = data_->xquat + 4 * id;
    mjtNum velocity[6];  // angular, then linear at the body's origin (its centre), world axes
    mj_objectVelocity(model_, data_, mjOBJ_BODY, id, velocity, 0);
    return {Vec3(p[0], p[1], p[2]), Quat(q[0], q[1], q[2], q[3]),
            Vec3(velocity[3], velocity[4], velocity[5]),
            Vec3(velocity[0], velocity[1], velocity[2])};
  }
  double reported_depth() const override {
    double deepest = 0;
    for (int c = 0; c < data_->ncon; ++c)
      deepest = std::max(deepest, -static_cast<double>(data_->contact[c].dist));
    return deepest;
  }

 private:
  mjModel* model_;
  mjData* data_ = nullptr;
  std::vector<int> bodies_;  // MuJoCo's body id of each dynamic body, in scene order
  mutable bool current_ = false;
  bool kicked_ = false;  // xfrc_applied holds a kick for the next step
};

void write_vector(std::ostream& out, const Vec3& v) {
  out << v.x() << ' ' << v.y() << ' ' << v.z();
}

void write_pose(std::ostream& out, const Vec3& position, const Quat& q) {
  out << "pos=\"";
  write_vector(out, position);
  out << "\" quat=\"" << q.w() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << '"';
}

// MuJoCo's coordinate is the child's motion against its parent; ours is b's against a.
double coordinate_sign(const SceneJoint& joint, std::size_t child) {
  return child == joint.a ? -1 : 1;
}

}  // namespace

std::unique_ptr<Simulation> make_mujoco(const PeerScene& peer, const PeerOptions& /*options*/,
                                        std::string* why_not) {
  const SceneDef& scene = *peer.scene;
  std::size_t dynamic = 0;
  for (const BodyDef& def : scene.bodies) {
    dynamic += def.type == BodyType::kDynamic ? 1 : 0;
    if (def.restitution > 0) {
      *why_not = "MuJoCo's soft contacts have no coefficient of restitution";
      return nullptr;
    }
  }
  for (const SceneJoint& joint : scene.joints) {
    const JointDef& def = joint.def;
    if (def.kind == JointKind::kDistance || def.motor.enabled || def.collide_connected ||
        def.friction > 0 || def.max_swing < 3.14159265358979 ||
        (def.kind == JointKind::kBall && def.limit.enabled)) {
      *why_not =
          "distance joints, motors, joint friction, cones, twist limits and colliding joined "
          "bodies are not mapped to MuJoCo";
      return nullptr;
    }
  }
  std::vector<Placement> placements;
  if (!place(scene, &placements, why_not)) return nullptr;
  // MuJoCo 2.2.2 reads models from XML, and its parser stops at 100 nested elements.
  for (std::size_t i = 0; i < placements.size(); ++i) {
    if (depth_of(placements, i) > 90) {
      *why_not = "a joint tree over 90 bodies deep (MuJoCo 2.2.2's XML parser stops at 100 levels)";
      return nullptr;
    }
  }

  const std::size_t contacts = (scene.bodies.size() > 500 ? 6 : 12) * dynamic + 64;
  std::ostringstream xml;
  xml.precision(17);
  xml << "<mujoco><compiler angle=\"radian\"/><option timestep=\"" << scene.dt << "\" gravity=\"";
  write_vector(xml, scene.world.gravity);
  xml << "\" integrator=\"Euler\" cone=\"pyramidal\" solver=\"Newton\" iterations=\"100\"/>"
      << "<size nconmax=\"" << contacts << "\" njmax=\"" << 4 * contacts << "\"/><worldbody>";
  std::string failure;
  auto geom_of = [&](const BodyDef& def) -> std::string {
    std::ostringstream geom;
    geom.precision(17);
    if (std::holds_alternative<HalfSpaceDef>(def.shape)) {
      geom << "type=\"plane\" size=\"0 0 1\"";
    } else if (const auto* box = std::get_if<BoxDef>(&def.shape)) {
      geom << "type=\"box\" size=\"";
      write_vector(geom, box->half_extents);
      geom << '"';
    } else if (const auto* sphere = std::get_if<SphereDef>(&def.shape)) {
      geom << "type=\"sphere\" size=\"" << sphere->radius << '"';
    } else if (const auto* capsule = std::get_if<CapsuleDef>(&def.shape)) {
      geom << "type=\"capsule\" size=\"" << capsule->radius << ' ' << capsule->half_height << '"';
    } else {
      failure = "hulls, heightfields, meshes and compounds are not mapped to MuJoCo";
    }
    geom << " friction=\"" << def.friction << " 0.005 0.0001\" condim=\"3\"";
    return geom.str();
  };
  // Static geoms first, in the world body.
  for (const BodyDef& def : scene.bodies) {
    if (def.type != BodyType::kStatic) continue;
    xml << "<geom ";
    write_pose(xml, def.position, def.orientation);
    xml << ' ' << geom_of(def) << "/>";
  }
  // Then every dynamic body within its parent, poses relative to the parent's frame.
  std::vector<std::vector<std::size_t>> children(scene.bodies.size());
  std::vector<std::size_t> roots;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    if (scene.bodies[i].type != BodyType::kDynamic) continue;
    if (placements[i].parent) {
      children[*placements[i].parent].push_back(i);
    } else {
      roots.push_back(i);
    }
  }
  std::function<void(std::size_t)> emit = [&](std::size_t i) {
    const BodyDef& def = scene.bodies[i];
    const Placement& at = placements[i];
    Vec3 position = def.position;
    Quat orientation = def.orientation;
    if (at.parent) {
      const BodyDef& parent = scene.bodies[*at.parent];
      position = parent.orientation.conjugate() * (def.position - parent.position);
      orientation = parent.orientation.conjugate() * def.orientation;
    }
    xml << "<body name=\"b" << i << "\" ";
    write_pose(xml, position, orientation);
    xml << '>';
    if (!at.joint) {
      xml << "<freejoint name=\"j" << i << "\"/>";
    } else {
      const SceneJoint& joint = scene.joints[*at.joint];
      const JointDef& j = joint.def;
      const double sign = coordinate_sign(joint, i);
      const Vec3 anchor = def.orientation.conjugate() * (j.anchor - def.position);
      const Vec3 axis = def.orientation.conjugate() * j.axis.normalized();
      if (j.kind != JointKind::kFixed) {
        const char* type = j.kind == JointKind::kBall    ? "ball"
                           : j.kind == JointKind::kHinge ? "hinge"
                                                         : "slide";
        xml << "<joint name=\"j" << i << "\" type=\"" << type << "\" pos=\"";
        write_vector(xml, anchor);
        xml << "\" axis=\"";
        write_vector(xml, axis);
        xml << '"';
        if (j.limit.enabled) {
          const double low = sign > 0 ? j.limit.lower : -j.limit.upper;
          const double high = sign > 0 ? j.limit.upper : -j.limit.lower;
          xml << " limited=\"true\" range=\"" << low << ' ' << high << '"';
        }
        if (j.spring.enabled)
          xml << " stiffness=\"" << j.spring.stiffness << "\" damping=\"" << j.spring.damping
              << "\" springref=\"" << sign * j.spring.target << '"';
        xml << "/>";
      }
    }
    xml << "<inertial pos=\"0 0 0\" mass=\"" << peer.mass[i] << "\" diaginertia=\"";
    write_vector(xml, peer.inertia[i]);
    xml << "\"/><geom " << geom_of(def) << "/>";
    for (std::size_t child : children[i])
      emit(child);
    xml << "</body>";
  };
  for (std::size_t root : roots)
    emit(root);
  xml << "</worldbody></mujoco>";
  if (!failure.empty()) {
    *why_not = failure;
    return nullptr;
  }

  const std::string path = "/tmp/tumble_mujoco_" + std::to_string(getpid()) + ".xml";
  std::ofstream(path) << xml.str();
  char error[1000] = "";
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  std::remove(path.c_str());
  if (model == nullptr) {
    *why_not = std::string("MuJoCo could not load the model: ") + error;
    return nullptr;
  }
  std::vector<int> ids;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    if (scene.bodies[i].type == BodyType::kDynamic)
      ids.push_back(mj_name2id(model, mjOBJ_BODY, ("b" + std::to_string(i)).c_str()));
  auto simulation = std::make_unique<MujocoSimulation>(model, ids);
  mjData* data = simulation->data();
  // Initial velocities: a free body's as given (angular in its own axes); a jointed body's
  // relative to its parent, along what its joint lets move.
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodyDef& def = scene.bodies[i];
    if (def.type != BodyType::kDynamic) continue;
    const int joint = mj_name2id(model, mjOBJ_JOINT, ("j" + std::to_string(i)).c_str());
    if (joint < 0) continue;  // welded to its parent
    mjtNum* qvel = data->qvel + model->jnt_dofadr[joint];
    const Placement& at = placements[i];
    Vec3 linear = def.linear_velocity, angular = def.angular_velocity;
    if (at.parent) {
      linear -= scene.bodies[*at.parent].linear_velocity;
      angular -= scene.bodies[*at.parent].angular_velocity;
    }
    const Vec3 w_body = def.orientation.conjugate() * angular;
    switch (model->jnt_type[joint]) {
      case mjJNT_FREE:
        for (int c = 0; c < 3; ++c) {
          qvel[c] = linear[c];
          qvel[3 + c] = w_body[c];
        }
        break;
      case mjJNT_BALL:
        for (int c = 0; c < 3; ++c)
          qvel[c] = w_body[c];
        break;
      case mjJNT_HINGE:
        qvel[0] = angular.dot(scene.joints[*at.joint].def.axis.normalized());
        break;
      case mjJNT_SLIDE:
        qvel[0] = linear.dot(scene.joints[*at.joint].def.axis.normalized());
        break;
    }
  }
  mj_forward(simulation->model(), simulation->data());
  // A body's own velocity that its joint does not carry (the kicked end of a hanging chain) is
  // its momentum given as a force over the first step: through the joints, the answer our solve
  // gives the same kick (the velocities projected onto the joints in the bodies' masses).
  std::size_t k = 0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    if (scene.bodies[i].type != BodyType::kDynamic) continue;
    const Vec3 missing = scene.bodies[i].linear_velocity - simulation->body(k).linear_velocity;
    if (missing.norm() > 1e-9) simulation->kick(k, peer.mass[i] * missing / scene.dt);
    ++k;
  }
  return simulation;
}

}  // namespace tumble::bench
