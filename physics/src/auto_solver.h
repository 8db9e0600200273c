// Where `auto` sends a small island to the exact solver: only where the soft solver's answer
// would differ from it. Measured in docs/report (Stability): the soft solver holds a pile of equal
// bodies as well as Lemke does at a tenth of the cost, and fails in two places only:
// - a heavy body on a light one: at a mass ratio of 100 the top box of a stack sinks (soft 10,
//   exact 1e5);
// - a body small beside the soft contact's own give: a resting contact sags by g / (2 pi f)^2
//   (69 um at 60 Hz), which is half the edge of a 0.1 mm box.
#pragma once

#include <cstdint>
#include <span>

#include "body_state.h"
#include "islands.h"
#include "physics/step.h"

namespace tumble {

// Touching dynamic bodies whose masses differ by more than this go to the exact solver.
inline constexpr double kAutoExactMassRatio = 4;
// The same for an island with joints, whose exact solve (exact_joints.h) costs a solve of its
// joint tree per contact row and substep: from where its soft contacts give way. On a 1 kg hinged
// bar resting on its limit, soft contacts let a box of 10 kg sink 1.6 mm into it in 3 s, 20 kg
// 3.2 mm, 100 kg 1.5 cm, and one of 1000 kg fall through (the LCP: under 1e-6 m); the pile of
// ragdolls (bodies of 1.5 to 15 kg, a ratio of 10 at most) paid twice its step for the LCP at a
// ratio of 4 as it landed, and stays with soft contacts.
inline constexpr double kAutoExactJointedMassRatio = 20;
// A dynamic body whose inner radius is below this many soft sags goes to the exact solver.
inline constexpr double kAutoExactSagMultiple = 100;

// `links`: every manifold's bodies (solver indices); `island_links`: this island's manifolds;
// `island_bodies`: its bodies; `body_of`, `dynamic`: by solver index.
bool soft_would_differ(std::span<const std::uint32_t> island_bodies,
                       std::span<const std::uint32_t> island_links,
                       std::span<const IslandLink> links, std::span<const Body* const> body_of,
                       std::span<const std::uint8_t> dynamic, double gravity,
                       const SolverSettings& solver, double mass_ratio = kAutoExactMassRatio);

}  // namespace tumble
