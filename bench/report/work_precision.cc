#include "work_precision.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>

#include "reference.h"
#include "run.h"
#include "scenes/standard.h"

namespace tumble::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The error of the final value of f(states) against a known one, relative.
class FinalValue final : public ErrorMeter {
 public:
  FinalValue(std::function<double(const bench::Simulation&)> value, double exact)
      : value_(std::move(value)), exact_(exact) {}
  void observe(const bench::Simulation& sim, double) override { last_ = value_(sim); }
  double error() const override { return std::abs(last_ / exact_ - 1); }

 private:
  std::function<double(const bench::Simulation&)> value_;
  double exact_, last_ = kNaN;
};

// S6: stop distance v0^2 / (2 mu g).
Reference slide() {
  SceneDef scene = slide_scene();
  const double exact = 25.0 / (2 * 0.5 * 9.81);
  return {{"slide", "stop distance of a box sliding at 5 m/s, mu 0.5, after 3 s",
           "v0^2/(2 mu g) = 2.548 m", "relative"},
          scene,
          [exact] {
            return std::make_unique<FinalValue>(
                [](const bench::Simulation& s) { return s.body(0).position.x(); }, exact);
          }};
}

// A flat floor of 0.5 m cells, 20 m square: 3,200 triangles.
HeightFieldDef flat_floor() {
  HeightFieldDef floor;
  floor.samples_x = floor.samples_y = 41;
  floor.spacing_x = floor.spacing_y = 0.5;
  floor.heights.assign(41 * 41, 0.0);
  return floor;
}

// The slide on `floor` in place of the plane, named `name`: the same stop distance if no inner
// edge between the floor's triangles catches the box.
Reference slide_across(const std::string& name, const std::string& floor_words, ShapeDef floor) {
  SceneDef scene = slide_scene();
  scene.name = name;
  for (BodyDef& body : scene.bodies)
    if (std::holds_alternative<HalfSpaceDef>(body.shape)) body.shape = floor;
  const double exact = 25.0 / (2 * 0.5 * 9.81);
  return {{name, "stop distance of the slide's box across " + floor_words + ", after 3 s",
           "v0^2/(2 mu g) = 2.548 m", "relative"},
          scene,
          [exact] {
            return std::make_unique<FinalValue>(
                [](const bench::Simulation& s) { return s.body(0).position.x(); }, exact);
          }};
}

// Across the floor as a triangle mesh, and as a heightfield (Bullet's btHeightfieldTerrainShape).
Reference mesh_slide() {
  return slide_across("slide-on-mesh", "a floor of 3,200 triangles (a mesh, 0.5 m cells)",
                      mesh_of_height_field(HeightField::create(flat_floor()).value()));
}

Reference height_field_slide() {
  return slide_across("slide-on-heightfield",
                      "a heightfield of 41 x 41 samples (0.5 m cells, 3,200 triangles)",
                      flat_floor());
}

// A box dropped from 1 m with e = 0.5 rises to e^2 h = 0.25 m after its first bounce.
class ReboundHeight final : public ErrorMeter {
 public:
  void observe(const bench::Simulation& sim, double) override {
    const bench::BodyState s = sim.body(0);
    const double bottom = s.position.z() - 0.5;
    if (!bounced_ && falling_ && s.linear_velocity.z() > 0) bounced_ = true;
    falling_ = s.linear_velocity.z() < 0;
    if (bounced_) apex_ = std::max(apex_, bottom);
    if (!std::isfinite(bottom)) apex_ = kNaN;
  }
  double error() const override { return bounced_ ? std::abs(apex_ / 0.25 - 1) : kNaN; }

 private:
  bool falling_ = false, bounced_ = false;
  double apex_ = 0;
};

Reference bounce() {
  SceneDef scene = bounce_scene(1.0, 0.5);
  scene.duration = 1.2;  // the apex is at 0.68 s
  return {{"bounce", "height of the first rebound of a box dropped 1 m onto the ground, e = 0.5",
           "e^2 h = 0.25 m", "relative"},
          scene,
          [] { return std::make_unique<ReboundHeight>(); }};
}

// S7: a free 1x2x3 box keeps its kinetic energy and world angular momentum.
class Invariants final : public ErrorMeter {
 public:
  Invariants(double mass, Vec3 inertia) : mass_(mass), inertia_(std::move(inertia)) {}
  void observe(const bench::Simulation& sim, double) override {
    const bench::BodyState s = sim.body(0);
    if (non_finite(s)) {
      worst_ = kNaN;
      return;
    }
    const double energy = kinetic_energy(s, mass_, inertia_);
    const Vec3 momentum = angular_momentum(s, inertia_);
    if (!started_) {
      started_ = true;
      energy0_ = energy;
      momentum0_ = momentum;
    }
    worst_ = std::max({worst_, std::abs(energy / energy0_ - 1),
                       (momentum - momentum0_).norm() / momentum0_.norm()});
  }
  double error() const override { return worst_; }

 private:
  double mass_;
  Vec3 inertia_;
  bool started_ = false;
  double energy0_ = 0, worst_ = 0;
  Vec3 momentum0_ = Vec3::Zero();
};

Reference spin(bool quick) {
  SceneDef scene = spin_scene();
  if (quick) scene.duration = 5;
  // Measured from the first step on: engines differ in when they apply the initial spin.
  const bench::PeerScene peer = bench::peer_scene(scene);
  const double mass = peer.mass[0];
  const Vec3 inertia = peer.inertia[0];
  return {{"spin",
           "largest drift of kinetic energy and of world angular momentum of a free 1x2x3 box "
           "spinning near its intermediate axis (Dzhanibekov), over " +
               std::to_string(static_cast<int>(scene.duration)) + " s",
           "both conserved exactly", "relative"},
          scene,
          [mass, inertia] { return std::make_unique<Invariants>(mass, inertia); }};
}

// The Dzhanibekov flip: the first time the intermediate axis turns against the angular momentum,
// c(t) = (R e_y) . L0 / |L0| passing zero (interpolated between steps).
class FirstFlip final : public ErrorMeter {
 public:
  FirstFlip(Vec3 direction, double exact) : direction_(std::move(direction)), exact_(exact) {}
  void observe(const bench::Simulation& sim, double t) override {
    const bench::BodyState s = sim.body(0);
    const double c = (s.orientation * Vec3::UnitY()).dot(direction_);
    if (!std::isfinite(c)) flip_ = kNaN;
    if (std::isnan(flip_) && previous_c_ > 0 && c <= 0)
      flip_ = previous_t_ + (t - previous_t_) * previous_c_ / (previous_c_ - c);
    previous_c_ = c;
    previous_t_ = t;
  }
  double error() const override { return std::abs(flip_ - exact_); }

 private:
  Vec3 direction_;
  double exact_, previous_c_ = 1, previous_t_ = 0, flip_ = kNaN;
};

// Euler's equations of the free body, I dw/dt = (I w) x w in body axes, by RK4 with h = 1e-5 s:
// the first time w_y (and so c) passes zero.
double exact_first_flip(const Vec3& inertia, Vec3 w) {
  const auto rate = [&](const Vec3& x) -> Vec3 {
    return inertia.cwiseInverse().cwiseProduct(inertia.cwiseProduct(x).cross(x));
  };
  const double h = 1e-5;
  for (double t = 0; t < 100; t += h) {
    const Vec3 k1 = rate(w), k2 = rate(w + 0.5 * h * k1), k3 = rate(w + 0.5 * h * k2),
               k4 = rate(w + h * k3);
    const Vec3 next = w + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    if (w.y() > 0 && next.y() <= 0) return t + h * w.y() / (w.y() - next.y());
    w = next;
  }
  return kNaN;
}

Reference flip() {
  SceneDef scene = spin_scene();
  scene.duration = 4;  // the first flip is at 2.77 s
  const bench::PeerScene peer = bench::peer_scene(scene);
  const Vec3 w0 = scene.bodies[0].angular_velocity;  // identity orientation: body = world axes
  const Vec3 momentum = peer.inertia[0].cwiseProduct(w0);
  const double exact = exact_first_flip(peer.inertia[0], w0);
  char reference[96];
  std::snprintf(reference, sizeof reference, "RK4 of Euler's equations, h = 1e-5 s: %.5f s", exact);
  return {{"flip",
           "time of the first Dzhanibekov flip of the same 1x2x3 box (its intermediate axis "
           "turning against L)",
           reference, "s"},
          scene,
          [momentum, exact] { return std::make_unique<FirstFlip>(momentum.normalized(), exact); }};
}

// A ball rolling without slipping down a 20 degree slope: x = 5/14 g sin(theta) t^2. The slope
// is the ground with gravity turned, so every engine's plane serves.
Reference roll() {
  const double theta = 20 * M_PI / 180;
  SceneDef scene;
  scene.name = "roll";
  scene.duration = 2;
  scene.world.gravity = 9.81 * Vec3(std::sin(theta), 0, -std::cos(theta));
  BodyDef ball;
  ball.shape = SphereDef{0.5};
  ball.mass = 1;
  ball.position = Vec3(0, 0, 0.5);
  scene.bodies = {ground(), ball};
  const double exact = 5.0 / 14 * 9.81 * std::sin(theta) * 4;
  return {
      {"roll", "distance a ball (r 0.5 m) rolls from rest down a 20 degree slope in 2 s, mu 0.5",
       "5/14 g sin(theta) t^2 = 4.792 m (rolling without slipping)", "relative"},
      scene,
      [exact] {
        return std::make_unique<FinalValue>(
            [](const bench::Simulation& s) { return s.body(0).position.x(); }, exact);
      }};
}

// A dumbbell (two balls of r 0.25 m on a bar, one compound body) rolling on its balls down the
// same slope: x = g sin(theta) t^2 / (2 (1 + I / (m r^2))), I about the axle from the parts'
// closed forms. Each ball touches with its own manifold; the bar (tangent to the balls, so nothing
// overlaps) never touches.
Reference roll_dumbbell() {
  const double theta = 20 * M_PI / 180, pi = M_PI;
  const double r = 0.25, bar = 0.05, half = 0.2, density = 1000;
  SceneDef scene;
  scene.name = "roll-dumbbell";
  scene.duration = 2;
  scene.world.gravity = 9.81 * Vec3(std::sin(theta), 0, -std::cos(theta));
  CompoundDef dumbbell;
  dumbbell.parts = {
      {SphereDef{r}, Pose{Vec3(0, -0.5, 0), Quat::Identity()}},
      {SphereDef{r}, Pose{Vec3(0, 0.5, 0), Quat::Identity()}},
      {CapsuleDef{bar, half}, Pose{Vec3::Zero(), Quat(Eigen::AngleAxisd(pi / 2, Vec3::UnitX()))}}};
  BodyDef body;
  body.shape = dumbbell;
  body.density = density;
  body.position = Vec3(0, 0, r);
  scene.bodies = {ground(), body};
  // Balls: 2/5 m r^2 each about the axle through their centres; the bar along the axle: a
  // cylinder's 1/2 m a^2 and two hemispheres' 2/5 m a^2.
  const double ball = density * 4.0 / 3.0 * pi * r * r * r;
  const double cylinder = density * pi * bar * bar * 2 * half;
  const double cap = density * 2.0 / 3.0 * pi * bar * bar * bar;
  const double mass = 2 * ball + cylinder + 2 * cap;
  const double axle =
      2 * 0.4 * ball * r * r + 0.5 * cylinder * bar * bar + 2 * 0.4 * cap * bar * bar;
  const double exact = 9.81 * std::sin(theta) * 4 / (2 * (1 + axle / (mass * r * r)));
  return {{"roll-dumbbell",
           "distance a dumbbell (one compound body: two balls of r 0.25 m on a bar) rolls from "
           "rest down a 20 degree slope in 2 s, mu 0.5",
           "g sin(theta) t^2 / (2 (1 + I/(m r^2))) = " + std::to_string(exact).substr(0, 5) +
               " m (rolling without slipping)",
           "relative"},
          scene,
          [exact] {
            return std::make_unique<FinalValue>(
                [](const bench::Simulation& s) { return s.body(0).position.x(); }, exact);
          }};
}

// Free flight under gravity: p = p0 + v0 t + g t^2 / 2.
Reference projectile() {
  SceneDef scene;
  scene.name = "projectile";
  scene.duration = 2;
  BodyDef ball;
  ball.shape = SphereDef{0.1};
  ball.mass = 1;
  ball.linear_velocity = Vec3(10, 0, 10);
  scene.bodies = {ball};
  const Vec3 exact = Vec3(10, 0, 10) * 2 + 0.5 * Vec3(0, 0, -9.81) * 4;
  return {{"projectile", "position of a ball thrown at (10, 0, 10) m/s after 2 s, no ground",
           "p0 + v0 t + g t^2/2", "relative"},
          scene,
          [exact] {
            return std::make_unique<FinalValue>(
                [exact](const bench::Simulation& s) {
                  return 1 + (s.body(0).position - exact).norm() / exact.norm();
                },
                1.0);
          }};
}

// Scenes with no closed form: the RMS distance of every body's final position from a converged
// run of the same scene (ours, pgs with 200 sweeps and no early stop, at a 16th of the step).
class FinalPositions final : public ErrorMeter {
 public:
  explicit FinalPositions(std::shared_ptr<const std::vector<Vec3>> reference)
      : reference_(std::move(reference)) {}
  void observe(const bench::Simulation& sim, double) override {
    double sum = 0;
    for (std::size_t i = 0; i < sim.body_count(); ++i)
      sum += (sim.body(i).position - (*reference_)[i]).squaredNorm();
    error_ = std::sqrt(sum / static_cast<double>(sim.body_count()));
  }
  double error() const override { return error_; }

 private:
  std::shared_ptr<const std::vector<Vec3>> reference_;
  double error_ = kNaN;
};

SceneDef converged(SceneDef scene, bool quick) {
  scene.dt = 1.0 / (quick ? 960 : 1920);
  scene.world.threads = 1;
  scene.world.solver.kind = SolverKind::kPgs;
  scene.world.solver.iterations = 200;
  scene.world.solver.velocity_tolerance = 0;
  scene.world.solver.position_iterations = 20;
  return scene;
}

// The converged run is made the first time a meter needs it, so listing the scenes costs nothing.
class ConvergedPositions {
 public:
  explicit ConvergedPositions(SceneDef fine) : fine_(std::move(fine)) {}
  const std::vector<Vec3>& positions() {
    std::call_once(once_, [this] {
      World world = make_world(fine_).value();
      const long steps = std::lround(fine_.duration / fine_.dt);
      for (long s = 0; s < steps; ++s)
        (void)world.step(fine_.dt);
      for (std::uint32_t i = 0; i < world.slot_count(); ++i)
        if (const BodyView b = world.body(world.id_at(i)); b && !b->is_static())
          positions_.push_back(b->position());
    });
    return positions_;
  }

 private:
  SceneDef fine_;
  std::once_flag once_;
  std::vector<Vec3> positions_;
};

Reference converged_reference(SceneDef scene, std::string what, bool quick) {
  scene.world.solver.sleeping = false;
  auto reference = std::make_shared<ConvergedPositions>(converged(scene, quick));
  std::string name = scene.name;
  return {
      {name, std::move(what),
       std::string("Tumble pgs, 200 sweeps, 20 position sweeps, dt 1/") + (quick ? "960" : "1920"),
       "m (RMS)"},
      scene,
      [reference] {
        return std::make_unique<FinalPositions>(
            std::shared_ptr<const std::vector<Vec3>>(reference, &reference->positions()));
      }};
}

// The standard scene `carousel`: stacks carried round on a kinematic deck turning at 0.5 rad/s
// stay where they stand on it. The error is the farthest any box ends from its place on the
// deck (its creep outward, docs/DYNAMICS.md, "Kinematic bodies"), in m.
class CarriedStacks final : public ErrorMeter {
 public:
  explicit CarriedStacks(SceneDef scene) : scene_(std::move(scene)) {}
  void observe(const bench::Simulation& sim, double t) override {
    const Eigen::AngleAxisd turned(0.5 * t, Vec3::UnitZ());
    worst_ = 0;
    std::size_t box = 0;
    for (const BodyDef& def : scene_.bodies) {
      if (def.type != BodyType::kDynamic) continue;
      const Vec3 place = turned * def.position;
      const Vec3 at = sim.body(box++).position;
      worst_ = at.allFinite() ? std::max(worst_, (at - place).norm()) : kNaN;
    }
  }
  double error() const override { return worst_; }

 private:
  SceneDef scene_;
  double worst_ = kNaN;
};

Reference carousel(bool quick) {
  SceneDef scene = carousel_scene(0.5);
  if (quick) scene.duration = 5;
  return {{"carousel",
           "four stacks of five boxes carried round on a kinematic deck turning at 0.5 rad/s: "
           "the farthest any box ends from its place on the deck after " +
               std::to_string(static_cast<int>(scene.duration)) + " s",
           "0 (each box stays where it stands on the deck)", "m"},
          scene,
          [scene] { return std::make_unique<CarriedStacks>(scene); }};
}

std::vector<Reference> references(bool quick) {
  std::vector<Reference> out = {slide(),       mesh_slide(), height_field_slide(), bounce(),
                                spin(quick),   flip(),       roll(),               roll_dumbbell(),
                                projectile(),  carousel(quick)};
  SceneDef pile = pile_scene(27);
  pile.duration = 1.0;
  out.push_back(converged_reference(
      pile, "27 tilted boxes dropped on the ground: final positions after 1 s (landing at 0.55 s)",
      quick));
  SceneDef pyramid = pyramid_scene(6);
  pyramid.duration = 2;
  out.push_back(
      converged_reference(pyramid, "pyramid of 21 boxes (base 6): positions after 2 s", quick));
  SceneDef tower = tower_scene(10);
  tower.duration = 2;
  out.push_back(converged_reference(tower, "tower of 10 boxes: positions after 2 s", quick));
  for (Reference& joint : joint_references(quick))
    out.push_back(std::move(joint));
  return out;
}

}  // namespace

std::vector<int> swept_rates(bool quick) {
  if (quick) return {30, 60, 120, 240};
  return {30, 60, 120, 240, 480, 960};
}

std::vector<ReferenceInfo> reference_scenes(bool quick) {
  std::vector<ReferenceInfo> out;
  for (const Reference& r : references(quick))
    out.push_back(r.info);
  return out;
}

std::vector<WorkPrecisionRow> measure_work_precision(const std::vector<Engine>& engines,
                                                     const WorkPrecisionOptions& options) {
  std::vector<WorkPrecisionRow> rows;
  std::vector<Reference> scenes = references(options.quick);
  if (options.joints_only) std::erase_if(scenes, [](const Reference& r) { return !r.info.joints; });
  const std::vector<int> rates = swept_rates(options.quick);
  std::size_t total = 0;
  for (const Reference& reference : scenes)
    for (const Engine& engine : engines)
      total += engine.joints_only && !reference.info.joints ? 0 : rates.size();
  for (const Reference& reference : scenes) {
    for (const Engine& engine : engines) {
      if (engine.joints_only && !reference.info.joints) continue;
      for (int rate : rates) {
        SceneDef scene = reference.scene;
        scene.dt = 1.0 / rate;
        std::unique_ptr<ErrorMeter> meter = reference.meter();
        bench::PeerOptions peer_options;
        peer_options.sleeping = scene.world.solver.sleeping;
        const RunOutcome outcome = run_scene(
            engine, scene, peer_options,
            [&](const bench::Simulation& sim, double t, bool) {
              meter->observe(sim, t);
              return true;
            },
            options.time_limit);
        WorkPrecisionRow row;
        row.scene = reference.info.name;
        row.engine = engine.label;
        row.settings = outcome.settings;
        row.dt = scene.dt;
        row.error = outcome.ran && !outcome.stopped_early ? meter->error() : kNaN;
        row.wall_per_second = outcome.step_seconds / (outcome.steps * scene.dt + 1e-300);
        row.note = outcome.why_not;
        rows.push_back(row);
        if (options.progress)
          options.progress("work-precision " + reference.info.name + ", " + engine.label +
                               ", dt 1/" + std::to_string(rate),
                           rows.size(), total);
      }
    }
  }
  return rows;
}

}  // namespace tumble::report
