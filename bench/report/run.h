// Runs one scene in one engine, timing only the engine's steps, and hands every step's states to
// an observer that measures error or judges stability.
#pragma once

#include <functional>
#include <string>

#include "engines.h"

namespace tumble::report {

struct RunOutcome {
  bool ran = false;            // false: the engine could not build the scene (why_not says why)
  std::string why_not;         // "not supported: ...", "engine stopped: ...", "too slow: ..."
  std::string settings;        // the engine's own account of its settings
  double step_seconds = 0;     // wall time inside step() over the whole run
  long steps = 0;              // steps taken
  bool stopped_early = false;  // the observer (or the time limit) ended the run
};

// Called after every step with the simulated time; returns false to stop the run (a verdict is
// reached). `last` is true on the final step.
using Observer = std::function<bool(const bench::Simulation&, double t, bool last)>;

// Runs `scene` for scene.duration. A run that spends more than `time_limit` seconds of wall time
// stops there with why_not "too slow".
RunOutcome run_scene(const Engine& engine, const SceneDef& scene, const bench::PeerOptions& options,
                     const Observer& observe, double time_limit);

// The static ground plane z = 0 that the report's own scenes stand on.
BodyDef ground();

// Kinetic energy of a body from its state and principal inertia (body axes = shape axes).
double kinetic_energy(const bench::BodyState& s, double mass, const Vec3& inertia);
// World angular momentum about the centre of mass.
Vec3 angular_momentum(const bench::BodyState& s, const Vec3& inertia);
// A state with a NaN or infinity anywhere.
bool non_finite(const bench::BodyState& s);

}  // namespace tumble::report
