// MuJoCo 2.2.2 (Debian) on a standard scene: MJCF generated in code with SCENES.md's settings
// (Newton solver, 100 iterations, pyramidal cone, Euler integrator, default soft contacts).
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "peers/peer_world.h"

namespace tumble::bench {

RunResult run_mujoco(const SceneDef& scene, long steps) {
  RunResult result;
  result.engine = "MuJoCo 2.2.2";
  result.settings = "Newton, 100 iterations, pyramidal cone, Euler, soft contacts";
  std::size_t dynamic_count = 0;
  for (const BodyDef& def : scene.bodies)
    dynamic_count += def.type == BodyType::kDynamic ? 1 : 0;
  // SCENES.md: 12 contacts per body + 64 (pile: 6), njmax 4 x nconmax.
  const std::size_t contacts = (scene.bodies.size() > 500 ? 6 : 12) * dynamic_count + 64;

  std::ostringstream xml;
  xml.precision(17);
  const Vec3 g = scene.world.gravity;
  xml << "<mujoco><option timestep=\"" << scene.dt << "\" gravity=\"" << g.x() << ' ' << g.y()
      << ' ' << g.z()
      << "\" integrator=\"Euler\" cone=\"pyramidal\" solver=\"Newton\" iterations=\"100\"/>"
      << "<size nconmax=\"" << contacts << "\" njmax=\"" << 4 * contacts << "\"/><worldbody>";
  const char* material = "friction=\"0.5 0.005 0.0001\" condim=\"3\"";
  std::vector<Vec3> halves;
  for (const BodyDef& def : scene.bodies) {
    const Quat& q = def.orientation;
    if (std::holds_alternative<HalfSpaceDef>(def.shape)) {
      xml << "<geom type=\"plane\" size=\"0 0 1\" " << material << "/>";
      continue;
    }
    const Vec3 h = std::get<BoxDef>(def.shape).half_extents;
    const Vec3& p = def.position;
    std::ostringstream pose;
    pose.precision(17);
    pose << "pos=\"" << p.x() << ' ' << p.y() << ' ' << p.z() << "\" quat=\"" << q.w() << ' '
         << q.x() << ' ' << q.y() << ' ' << q.z() << "\"";
    std::ostringstream box;
    box.precision(17);
    box << "type=\"box\" size=\"" << h.x() << ' ' << h.y() << ' ' << h.z() << "\" " << material;
    if (def.type == BodyType::kStatic) {
      xml << "<geom " << pose.str() << ' ' << box.str() << "/>";
      continue;
    }
    const double m = def.mass;
    xml << "<body " << pose.str() << "><freejoint/><inertial pos=\"0 0 0\" mass=\"" << m
        << "\" diaginertia=\"" << m / 3 * (h.y() * h.y() + h.z() * h.z()) << ' '
        << m / 3 * (h.x() * h.x() + h.z() * h.z()) << ' ' << m / 3 * (h.x() * h.x() + h.y() * h.y())
        << "\"/><geom " << box.str() << "/></body>";
    halves.push_back(h);
  }
  xml << "</worldbody></mujoco>";

  const std::string path = "/tmp/tumble_mujoco_" + std::to_string(getpid()) + ".xml";
  std::ofstream(path) << xml.str();
  char error[1000] = "";
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  std::remove(path.c_str());
  if (model == nullptr) {
    result.settings = std::string("could not load: ") + error;
    result.blew_up = true;
    return result;
  }
  mjData* data = mj_makeData(model);
  // Free joints: qvel is (linear velocity in world axes, angular velocity in body axes).
  std::size_t k = 0;
  for (const BodyDef& def : scene.bodies) {
    if (def.type != BodyType::kDynamic) continue;
    const Vec3 w_body = def.orientation.conjugate() * def.angular_velocity;
    for (int i = 0; i < 3; ++i) {
      data->qvel[6 * k + i] = def.linear_velocity[i];
      data->qvel[6 * k + 3 + i] = w_body[i];
    }
    ++k;
  }
  mj_forward(model, data);
  auto position = [&](std::size_t i) {
    const mjtNum* p = data->xpos + 3 * (i + 1);
    return Vec3(p[0], p[1], p[2]);
  };
  for (std::size_t i = 0; i < dynamic_count; ++i)
    result.start.push_back(position(i));
  const long last_second = steps - std::lround(1 / scene.dt);
  for (long s = 0; s < steps; ++s) {
    const auto start = std::chrono::steady_clock::now();
    mj_step(model, data);
    result.step_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    for (std::size_t i = 0; i < dynamic_count; ++i) {
      const Vec3 p = position(i);
      if (!p.allFinite() || p.cwiseAbs().maxCoeff() > 1000) result.blew_up = true;
      if (s >= last_second && g.norm() > 0) {
        const mjtNum* q = data->xquat + 4 * (i + 1);
        result.deepest_corner_last_second =
            std::max(result.deepest_corner_last_second,
                     corner_depth(p, Quat(q[0], q[1], q[2], q[3]), halves[i]));
      }
    }
  }
  if (data->warning[mjWARN_CONTACTFULL].number > 0) result.settings += "; CONTACT BUFFER FULL";
  for (std::size_t i = 0; i < dynamic_count; ++i) {
    result.end.push_back(position(i));
    result.end_velocity.push_back(
        Vec3(data->qvel[6 * i], data->qvel[6 * i + 1], data->qvel[6 * i + 2]));
  }
  mj_deleteData(data);
  mj_deleteModel(model);
  return result;
}

}  // namespace tumble::bench
