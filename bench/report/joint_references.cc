// The joints' scenes with known answers: a hinged pendulum's period at small and large swings
// against the complete elliptic integral, a hinged double pendulum's energy (conserved exactly),
// and how far a falling chain's joints come apart (zero by their definition). Hinges and ball
// joints only, so that every peer maps them (Bullet's btHingeConstraint and
// btPoint2PointConstraint, Bullet's btMultiBody, ODE's hinge and ball, MuJoCo's hinge and ball in
// generalised coordinates).
#include <cmath>
#include <limits>
#include <numbers>

#include "joint_gaps.h"
#include "reference.h"
#include "run.h"
#include "scenes/standard.h"

namespace tumble::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kG = 9.81, kRadius = 0.05, kRod = 1;

BodyDef bob(const Vec3& position) {
  BodyDef def;
  def.shape = SphereDef{kRadius};
  def.mass = 1;
  def.position = position;
  return def;
}

SceneJoint hinge(std::size_t a, std::optional<std::size_t> b, const Vec3& anchor) {
  SceneJoint joint;
  joint.def.kind = JointKind::kHinge;
  joint.def.anchor = anchor;
  joint.def.axis = Vec3::UnitY();
  joint.a = a;
  joint.b = b;
  return joint;
}

// The period of a ball (1 kg, r 5 cm) whose centre swings 1 m from a hinge, from amplitude
// theta0: 4 K(sin(theta0/2)) sqrt(I / (m g L)), I = m L^2 + 2/5 m r^2 about the pivot.
double exact_period(double theta0) {
  const double inertia = kRod * kRod + 0.4 * kRadius * kRadius;
  return 4 * std::comp_ellint_1(std::sin(theta0 / 2)) * std::sqrt(inertia / (kG * kRod));
}

// The mean period between the bob's passes through the bottom moving +x (interpolated between
// steps), over every pass in the run.
class PendulumPeriod final : public ErrorMeter {
 public:
  PendulumPeriod(Vec3 pivot, double exact) : pivot_(std::move(pivot)), exact_(exact) {}
  void observe(const bench::Simulation& sim, double t) override {
    const double x = sim.body(0).position.x() - pivot_.x();
    if (!std::isfinite(x)) broken_ = true;
    if (previous_x_ < 0 && x >= 0) {
      const double pass = previous_t_ + (t - previous_t_) * -previous_x_ / (x - previous_x_);
      if (passes_ == 0) first_ = pass;
      last_ = pass;
      ++passes_;
    }
    previous_x_ = x;
    previous_t_ = t;
  }
  double error() const override {
    if (broken_ || passes_ < 2) return kNaN;
    return std::abs((last_ - first_) / (passes_ - 1) / exact_ - 1);
  }

 private:
  Vec3 pivot_;
  double exact_, previous_x_ = 1, previous_t_ = 0, first_ = 0, last_ = 0;
  int passes_ = 0;
  bool broken_ = false;
};

Reference pendulum(double degrees) {
  const double theta0 = degrees * std::numbers::pi / 180;
  const double period = exact_period(theta0);
  const Vec3 pivot(0, 0, 2);
  SceneDef scene;
  scene.name = "pendulum-" + std::to_string(std::lround(degrees));
  scene.world.solver.sleeping = false;
  scene.duration = std::ceil(3 * period);  // three passes through the bottom
  scene.bodies = {bob(pivot + kRod * Vec3(std::sin(theta0), 0, -std::cos(theta0)))};
  scene.joints = {hinge(0, std::nullopt, pivot)};
  char reference[128];
  std::snprintf(reference, sizeof reference,
                "4 K(sin(theta0/2)) sqrt(I/(m g L)) = %.6f s (complete elliptic integral)", period);
  ReferenceInfo info{scene.name,
                     "period of a ball (1 kg, r 5 cm) on a hinge 1 m above its centre, released " +
                         std::to_string(std::lround(degrees)) +
                         " degrees from the bottom: mean time between passes through the bottom",
                     reference, "relative", true};
  return {info, scene, [pivot, period] { return std::make_unique<PendulumPeriod>(pivot, period); }};
}

// The largest departure of kinetic plus potential energy from its start, relative to the 3 m g
// (29.4 J) the pendulum can swing through from level to hanging.
class EnergyDrift final : public ErrorMeter {
 public:
  explicit EnergyDrift(const SceneDef& scene) : peer_(bench::peer_scene(scene)), scene_(scene) {}
  void observe(const bench::Simulation& sim, double) override {
    double energy = 0;
    for (std::size_t i = 0; i < sim.body_count(); ++i) {
      const bench::BodyState s = sim.body(i);
      energy +=
          kinetic_energy(s, peer_.mass[i], peer_.inertia[i]) + peer_.mass[i] * kG * s.position.z();
    }
    if (std::isnan(start_)) start_ = initial();
    worst_ = std::isfinite(energy) ? std::max(worst_, std::abs(energy - start_) / (3 * kG)) : kNaN;
  }
  double error() const override { return worst_; }

 private:
  double initial() const {
    double energy = 0;
    for (std::size_t i = 0; i < scene_.bodies.size(); ++i)
      energy += peer_.mass[i] * kG * scene_.bodies[i].position.z();
    return energy;  // released from rest
  }
  bench::PeerScene peer_;
  SceneDef scene_;
  double start_ = kNaN, worst_ = 0;
};

Reference double_pendulum(bool quick) {
  SceneDef scene;
  scene.name = "double-pendulum";
  scene.world.solver.sleeping = false;
  scene.duration = quick ? 5 : 20;
  const Vec3 pivot(0, 0, 3);
  scene.bodies = {bob(pivot + Vec3(kRod, 0, 0)), bob(pivot + Vec3(2 * kRod, 0, 0))};
  scene.joints = {hinge(0, std::nullopt, pivot), hinge(1, 0, pivot + Vec3(kRod, 0, 0))};
  ReferenceInfo info{scene.name,
                     "energy of two 1 kg balls on hinges 1 m apart (the second hinged at the "
                     "first's centre), released level: its largest departure from the start over " +
                         std::to_string(std::lround(scene.duration)) + " s",
                     "conserved exactly", "relative to 3 m g (29.4 J)", true};
  return {info, scene, [scene] { return std::make_unique<EnergyDrift>(scene); }};
}

class LargestGap final : public ErrorMeter {
 public:
  explicit LargestGap(const SceneDef& scene) : gaps_(scene) {}
  void observe(const bench::Simulation& sim, double) override {
    const double gap = gaps_.largest(sim);
    worst_ = std::isfinite(gap) ? std::max(worst_, gap) : kNaN;
  }
  double error() const override { return worst_; }

 private:
  JointGaps gaps_;
  double worst_ = 0;
};

Reference chain(bool quick) {
  SceneDef scene = chain_scene(20);
  scene.name = "chain-gap";
  scene.world.solver.sleeping = false;
  scene.duration = quick ? 3 : 10;
  ReferenceInfo info{scene.name,
                     "a chain of 20 ball-jointed links (0.2 m, 0.5 kg) released level from a "
                     "fixed point: the largest gap at any joint over " +
                         std::to_string(std::lround(scene.duration)) +
                         " s (one run: once the chain lies in a heap its figure moves by two "
                         "decades with the last bit anywhere; bench_chain_gap gives the spread)",
                     "0 (the joints' definition)", "m", true};
  return {info, scene, [scene] { return std::make_unique<LargestGap>(scene); }};
}

}  // namespace

std::vector<Reference> joint_references(bool quick) {
  return {pendulum(10), pendulum(170), double_pendulum(quick), chain(quick)};
}

}  // namespace tumble::report
