// The standard scenes of ../shared/SCENES.md, built bit for bit as specified there, so our figures
// and the peer engines' compare like for like. Tests, benchmarks and the server share them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "scenes/scene.h"

namespace tumble {

// The generator SCENES.md specifies for the pile's orientations: a 32-bit LCG, seed 12345.
class SceneRandom {
 public:
  std::uint32_t next() {
    state_ = 1664525u * state_ + 1013904223u;
    return state_;
  }
  double uniform() { return (next() >> 8) / 16777216.0; }

 private:
  std::uint32_t state_ = 12345;
};

// Every scene has the conventions of SCENES.md: unit boxes of 1 kg, mu = 0.5, restitution 0,
// dt = 1/60, gravity -9.81 z (none in bullet and spin), the ground a static plane z = 0.
SceneDef pile_scene(int count = 1000);             // S1: a lattice of tilted boxes falling, 10 s
SceneDef terrain_pile_scene(int count = 1000);  // the same pile onto rolling hills (a heightfield)
SceneDef terrain_mesh_pile_scene(int count = 1000);  // the same hills as a triangle mesh
// The pile with each box a body of parts: jacks (three crossing bars) and dumbbells in turn.
SceneDef compound_pile_scene(int count = 1000);
SceneDef pyramid_scene(int base = 20);             // S2: base boxes at the bottom, 20 s
SceneDef tower_scene(int height = 20);             // S3: 20 s
SceneDef mass_ratio_scene(bool inverted = false);  // S4: 1, 1, 1000 kg bottom to top (inverted:
                                                   // 1000, 1, 1), 10 s
SceneDef bullet_scene();                           // S5: 0.1 m box at 300 m/s at a 5 cm wall, 1 s
SceneDef slide_scene(double speed = 5);            // S6: a box sliding on the ground, 3 s
SceneDef spin_scene();                             // S7: a 1x2x3 box spinning near its middle axis
// A kinematic deck (8 x 8 x 0.2 m) turning at `turn` rad/s about its centre over the ground,
// carrying four stacks of five 0.5 m boxes 2.5 m from the centre, started at the deck's velocity
// where they stand; 20 s.
SceneDef carousel_scene(double turn = 0.5);
SceneDef bounce_scene(double height = 1,
                      double restitution = 0.5);  // dropped from `height`
                                                  // (bottom face above ground), 3 s

// Joints (docs/SCENES.md): a 1 m rod pendulum released level with its pivot, 10 s; a chain of
// `links` ball-jointed 0.2 m links of 0.5 kg hung from a fixed point and released level, its last
// link `end_ratio` times heavier, 10 s; the same chain hanging straight down (no ground), its end
// pushed sideways at 1 m/s, 20 s, sleeping off.
SceneDef pendulum_scene();
SceneDef chain_scene(int links = 20, double end_ratio = 1);
SceneDef hanging_chain_scene(int links = 20, double end_ratio = 1);
// Two 1 kg bobs on 1 m rods, released level, 20 s; Newton's cradle (five 1 kg balls of 5 cm on
// 1 m rods, the first pulled out 45 degrees), 10 s; a 20 kg door on a hinge with a stop at a
// quarter turn and a closing spring, pushed open, 10 s; a rope bridge of `planks` hinged planks
// held at both ends (a loop of joints), 10 s.
SceneDef double_pendulum_scene();
SceneDef cradle_scene();
// The report's Newton's cradle: `balls` balls of 5 cm and 1 kg (restitution 1, no friction)
// hanging touching on hinges 1 m above them, the first pulled out 45 degrees; no ground, sleeping
// off, 1.5 s.
SceneDef hinged_cradle_scene(int balls);
SceneDef door_scene();
SceneDef rope_bridge_scene(int planks = 20);
// A six-joint arm (base yaw, shoulder, elbow, wrist roll, pitch and roll: hinges from the world
// out) holding a 5 kg payload at arm's length on a fixed joint, its base turning at 0.5 rad/s
// and every other motor holding its joint still (speed 0, torques bounded), 10 s. `ragdolls`
// ragdolls of 11 bodies each (pelvis, torso, head, arms and legs in two parts; ball joints with
// swing cones at the spine, neck, shoulders and hips, hinges with limits at the elbows and
// knees), dropped in layers of four onto the ground, 10 s.
SceneDef arm_scene();
SceneDef ragdolls_scene(int ragdolls = 20);

// A standard scene by name, with an optional size: "pile", "pile:250", "pyramid:10", "tower:5",
// "mass-ratio", "mass-ratio-inv", "bullet", "slide", "spin", "bounce", "pendulum",
// "double-pendulum", "chain:20", "cradle", "door", "rope-bridge:20", "default". A size whose
// scene would have more than `max_bodies` bodies is refused before anything is built.
Result<SceneDef> standard_scene(std::string_view name, std::size_t max_bodies = 1000000);

// What a program was asked to run: the scene file when given, else the standard scene when
// named, else the built-in default scene.
Result<SceneDef> chosen_scene(const std::string& file, const std::string& standard);

}  // namespace tumble
