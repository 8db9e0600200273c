// One interface over every engine's world (ours and the peers'), so that a scene is built from the
// same SceneDef and measured the same way in each. Adapters map what SceneDef says onto each
// engine as ../shared/SCENES.md prescribes; a scene with a shape an adapter cannot express is
// refused with the reason, never approximated.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "physics/math.h"
#include "physics/step.h"
#include "scenes/scene.h"

namespace tumble::bench {

// A dynamic body's state, world frame, read the same way from every engine.
struct BodyState {
  Vec3 position = Vec3::Zero();  // m, centre of mass
  Quat orientation = Quat::Identity();
  Vec3 linear_velocity = Vec3::Zero();   // m/s
  Vec3 angular_velocity = Vec3::Zero();  // rad/s
};

class Simulation {
 public:
  virtual ~Simulation() = default;
  // One step of the scene's dt. False when the engine reports it cannot go on.
  virtual bool step() = 0;
  // The scene's dynamic bodies, in scene order.
  virtual std::size_t body_count() const = 0;
  virtual BodyState body(std::size_t i) const = 0;
  // Deepest penetration the engine itself reported in the last step, m (0 when it reports none).
  virtual double reported_depth() const { return 0; }
  // What a run of this engine must be labelled with: name, solver, iterations, options.
  const std::string& engine() const { return engine_; }
  const std::string& settings() const { return settings_; }

 protected:
  std::string engine_, settings_;
};

// A scene as the peers receive it: every body's mass (kg) and principal moments of inertia
// (kg m^2, about its shape axes) computed once by our engine from the same definition, so that
// every engine simulates the same bodies; peers are set up from these, never from a formula of
// their own.
struct PeerScene {
  const SceneDef* scene = nullptr;
  std::vector<double> mass;
  std::vector<Vec3> inertia;  // the diagonal of inertia_tensor: the principal moments but for
                              // hulls and compounds, whose axes need not be principal
  std::vector<Vec3> centre_of_mass;  // m, in the shape's frame (off its origin for hulls and
                                     // compounds)
  std::vector<Mat3> inertia_tensor;  // kg m^2, about the centre of mass, in the shape's axes
};
PeerScene peer_scene(const SceneDef& scene);

// Choices a peer may be given beside the scene.
struct PeerOptions {
  bool sleeping = true;  // Bullet: deactivation; ODE and MuJoCo never sleep here
  bool ccd = false;      // Bullet: swept-sphere CCD as SCENES.md's "bullet-ccd" sets it
  // ODE: dWorldStep (its direct, pivoting LCP solver: cubic in a island's rows) instead of
  // dWorldQuickStep; offered on scenes with joints only, where it is ODE's accurate choice.
  bool ode_world_step = false;
  // Bullet: sequential-impulse iterations a step (0: Bullet's default, 10), to see how its error
  // falls as it is given more time.
  int iterations = 0;
};

// Ours, with the scene's world settings (solver, threads, sleeping) as they are.
std::unique_ptr<Simulation> make_tumble(const SceneDef& scene, std::string* why_not);

// The peers; null with *why_not set when the scene cannot be expressed (a shape the adapter does
// not map) or the engine is not built in. `peers_available()` names those built in.
std::unique_ptr<Simulation> make_bullet(const PeerScene& scene, const PeerOptions& options,
                                        std::string* why_not);
std::unique_ptr<Simulation> make_bullet_double(const PeerScene& scene, const PeerOptions& options,
                                               std::string* why_not);
// Bullet's btMultiBody (generalised coordinates: joint trees hanging from the world alone).
std::unique_ptr<Simulation> make_bullet_multibody(const PeerScene& scene,
                                                  const PeerOptions& options, std::string* why_not);
std::unique_ptr<Simulation> make_ode(const PeerScene& scene, const PeerOptions& options,
                                     std::string* why_not);
std::unique_ptr<Simulation> make_mujoco(const PeerScene& scene, const PeerOptions& options,
                                        std::string* why_not);

}  // namespace tumble::bench
