// MuJoCo 2.2.2 (Debian) as SCENES.md maps it: MJCF generated in code, Newton solver, 100
// iterations, pyramidal cone, Euler integrator, default soft contacts (solref/solimp); each
// dynamic body a freejoint with explicit inertia; geom friction "mu 0.005 0.0001", condim 3.
// MuJoCo 2.x preallocates contacts: nconmax = 12 per body + 64 (6 per body above 500 bodies),
// njmax = 4 nconmax; a step that overflows them is reported as a failure, not run on.
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "peers/simulation.h"

namespace tumble::bench {
namespace {

class MujocoSimulation final : public Simulation {
 public:
  MujocoSimulation(mjModel* model, std::size_t dynamic) : model_(model), dynamic_(dynamic) {
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

  bool step() override {
    mj_step(model_, data_);
    return data_->warning[mjWARN_CONTACTFULL].number == 0 &&
           data_->warning[mjWARN_CNSTRFULL].number == 0;
  }
  std::size_t body_count() const override { return dynamic_; }
  // Dynamic bodies are MuJoCo's bodies 1..n in order (body 0 is the world).
  BodyState body(std::size_t i) const override {
    const mjtNum* p = data_->xpos + 3 * (i + 1);
    const mjtNum* q = data_->xquat + 4 * (i + 1);
    const mjtNum* v = data_->qvel + 6 * i;
    const Quat orientation(q[0], q[1], q[2], q[3]);
    // Free joints: linear velocity in world axes, angular in body axes.
    return {Vec3(p[0], p[1], p[2]), orientation, Vec3(v[0], v[1], v[2]),
            orientation * Vec3(v[3], v[4], v[5])};
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
  std::size_t dynamic_;
};

void write_vector(std::ostream& out, const Vec3& v) {
  out << v.x() << ' ' << v.y() << ' ' << v.z();
}

}  // namespace

std::unique_ptr<Simulation> make_mujoco(const PeerScene& peer, const PeerOptions& /*options*/,
                                        std::string* why_not) {
  const SceneDef& scene = *peer.scene;
  if (!scene.joints.empty()) {
    *why_not = "joints are not mapped to MuJoCo yet";
    return nullptr;
  }
  std::size_t dynamic = 0;
  for (const BodyDef& def : scene.bodies) {
    dynamic += def.type == BodyType::kDynamic ? 1 : 0;
    if (def.restitution > 0) {
      *why_not = "MuJoCo's soft contacts have no coefficient of restitution";
      return nullptr;
    }
  }
  const std::size_t contacts = (scene.bodies.size() > 500 ? 6 : 12) * dynamic + 64;
  std::ostringstream xml;
  xml.precision(17);
  xml << "<mujoco><option timestep=\"" << scene.dt << "\" gravity=\"";
  write_vector(xml, scene.world.gravity);
  xml << "\" integrator=\"Euler\" cone=\"pyramidal\" solver=\"Newton\" iterations=\"100\"/>"
      << "<size nconmax=\"" << contacts << "\" njmax=\"" << 4 * contacts << "\"/><worldbody>";
  // Static geoms first, in the world body; then one body per dynamic definition, in order.
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const BodyDef& def = scene.bodies[i];
      const bool is_static = def.type == BodyType::kStatic;
      if (is_static != (pass == 0)) continue;
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
        *why_not = "hulls are not mapped to MuJoCo";
        return nullptr;
      }
      geom << " friction=\"" << def.friction << " 0.005 0.0001\" condim=\"3\"";
      const Quat& q = def.orientation;
      std::ostringstream pose;
      pose.precision(17);
      pose << "pos=\"";
      write_vector(pose, def.position);
      pose << "\" quat=\"" << q.w() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << '"';
      if (is_static) {
        xml << "<geom " << pose.str() << ' ' << geom.str() << "/>";
        continue;
      }
      xml << "<body " << pose.str() << "><freejoint/><inertial pos=\"0 0 0\" mass=\""
          << peer.mass[i] << "\" diaginertia=\"";
      write_vector(xml, peer.inertia[i]);
      xml << "\"/><geom " << geom.str() << "/></body>";
    }
  }
  xml << "</worldbody></mujoco>";

  const std::string path = "/tmp/tumble_mujoco_" + std::to_string(getpid()) + ".xml";
  std::ofstream(path) << xml.str();
  char error[1000] = "";
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  std::remove(path.c_str());
  if (model == nullptr) {
    *why_not = std::string("MuJoCo could not load the model: ") + error;
    return nullptr;
  }
  auto simulation = std::make_unique<MujocoSimulation>(model, dynamic);
  std::size_t k = 0;
  for (const BodyDef& def : scene.bodies) {
    if (def.type != BodyType::kDynamic) continue;
    const Vec3 w_body = def.orientation.conjugate() * def.angular_velocity;
    for (int c = 0; c < 3; ++c) {
      simulation->data()->qvel[6 * k + c] = def.linear_velocity[c];
      simulation->data()->qvel[6 * k + 3 + c] = w_body[c];
    }
    ++k;
  }
  mj_forward(simulation->model(), simulation->data());
  return simulation;
}

}  // namespace tumble::bench
