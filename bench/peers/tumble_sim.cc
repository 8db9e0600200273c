// Ours behind the Simulation interface, and the mass properties every peer is given.
#include <dlfcn.h>

#include <cstdio>

#include "peers/simulation.h"
#include "physics/world.h"

namespace tumble::bench {
namespace {

class TumbleSimulation final : public Simulation {
 public:
  TumbleSimulation(World world, const SceneDef& scene) : world_(std::move(world)), dt_(scene.dt) {
    const SolverSettings& s = scene.world.solver;
    engine_ = "Tumble " + std::string(solver_name(s.kind));
    switch (s.kind) {
      case SolverKind::kSoft:
        settings_ = "soft, " + std::to_string(s.substeps) + " substeps x " +
                    std::to_string(s.soft_iterations) + " iterations";
        break;
      case SolverKind::kPgs:
        settings_ = "pgs, " + std::to_string(s.iterations) + " iterations";
        break;
      case SolverKind::kAuto:
        settings_ = "soft, " + std::to_string(s.substeps) +
                    (s.substeps == 1 ? " substep" : " substeps") +
                    "; exact where soft would differ (<= " + std::to_string(s.exact_max_points) +
                    " points, a mass ratio > 4 or a body under 100 soft sags)";
        break;
      case SolverKind::kExact:
        settings_ = "Lemke, " + std::to_string(s.friction_directions) + "-sided friction pyramid";
        break;
    }
    if (s.joint_position_passes != SolverSettings{}.joint_position_passes)
      settings_ += "; " + std::to_string(s.joint_position_passes) + " joint position passes";
    const int threads = scene.world.threads;
    settings_ += "; " + (threads > 0 ? std::to_string(threads) : std::string("all")) + " thread" +
                 (threads == 1 ? "" : "s") + "; sleeping " + (s.sleeping ? "on" : "off");
    for (std::uint32_t i = 0; i < world_.slot_count(); ++i)
      if (const BodyView b = world_.body(world_.id_at(i)); b && b->type() == BodyType::kDynamic)
        dynamic_.push_back(world_.id_at(i));
  }
  bool step() override { return world_.step(dt_).is_ok(); }
  std::size_t body_count() const override { return dynamic_.size(); }
  BodyState body(std::size_t i) const override {
    const BodyView b = world_.body(dynamic_[i]);
    return {b->position(), b->orientation(), b->linear_velocity(), b->angular_velocity()};
  }
  double reported_depth() const override { return world_.last_step().max_penetration; }
  const World& world() const { return world_; }

 private:
  World world_;
  double dt_;
  std::vector<BodyId> dynamic_;
};

}  // namespace

std::unique_ptr<Simulation> make_tumble(const SceneDef& scene, std::string* why_not) {
  Result<World> world = make_world(scene);
  if (!world) {
    *why_not = world.error();
    return nullptr;
  }
  return std::make_unique<TumbleSimulation>(std::move(world).value(), scene);
}

PeerScene peer_scene(const SceneDef& scene) {
  PeerScene peer;
  peer.scene = &scene;
  for (const BodyDef& def : scene.bodies) {
    Result<MassProperties> body = body_mass_properties(def);
    peer.mass.push_back(body ? body.value().mass : 0);
    peer.inertia.push_back(body ? Vec3(body.value().inertia.diagonal()) : Vec3::Zero());
    peer.centre_of_mass.push_back(body ? body.value().center_of_mass : Vec3::Zero());
    peer.inertia_tensor.push_back(body ? body.value().inertia : Mat3::Zero());
  }
  return peer;
}

#ifndef TUMBLE_HAVE_PEERS
std::unique_ptr<Simulation> make_bullet(const PeerScene&, const PeerOptions&, std::string* why) {
  *why = "not built (Debian's libbullet-dev was not found)";
  return nullptr;
}
std::unique_ptr<Simulation> make_bullet_multibody(const PeerScene&, const PeerOptions&,
                                                  std::string* why) {
  *why = "not built (Debian's libbullet-dev was not found)";
  return nullptr;
}
std::unique_ptr<Simulation> make_ode(const PeerScene&, const PeerOptions&, std::string* why) {
  *why = "not built (Debian's libode-dev was not found)";
  return nullptr;
}
std::unique_ptr<Simulation> make_mujoco(const PeerScene&, const PeerOptions&, std::string* why) {
  *why = "not built (Debian's libmujoco-dev was not found)";
  return nullptr;
}
#endif

std::unique_ptr<Simulation> make_bullet_double(const PeerScene& scene, const PeerOptions& options,
                                               std::string* why_not) {
#ifdef TUMBLE_BULLET_DOUBLE_MODULE
  using Entry = Simulation* (*)(const PeerScene*, const PeerOptions*, std::string*);
  static const Entry entry = []() -> Entry {
    void* module = dlopen(TUMBLE_BULLET_DOUBLE_MODULE, RTLD_NOW | RTLD_LOCAL | RTLD_DEEPBIND);
    if (module == nullptr) return nullptr;
    return reinterpret_cast<Entry>(dlsym(module, "tumble_make_bullet_double"));
  }();
  if (entry == nullptr) {
    *why_not = std::string("cannot load ") + TUMBLE_BULLET_DOUBLE_MODULE;
    return nullptr;
  }
  return std::unique_ptr<Simulation>(entry(&scene, &options, why_not));
#else
  (void)scene;
  (void)options;
  *why_not = "not built (Debian's libbullet-dev with bullet-float64 was not found)";
  return nullptr;
#endif
}

}  // namespace tumble::bench
