// A scene with a known answer, as the error-against-run-time measurement runs it: the scene, what
// its error measures, and a fresh meter for each run.
#pragma once

#include <functional>
#include <memory>

#include "peers/simulation.h"
#include "work_precision.h"

namespace tumble::report {

// Measures one run's error from the states after each step.
class ErrorMeter {
 public:
  virtual ~ErrorMeter() = default;
  virtual void observe(const bench::Simulation& sim, double t) = 0;
  virtual double error() const = 0;
};

struct Reference {
  ReferenceInfo info;
  SceneDef scene;  // dt is set per run
  std::function<std::unique_ptr<ErrorMeter>()> meter;
};

// The joints' scenes (joint_references.cc): pendulum periods, the double pendulum's energy, a
// chain's length.
std::vector<Reference> joint_references(bool quick);

}  // namespace tumble::report
