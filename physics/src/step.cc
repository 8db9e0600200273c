// World::step and its stages.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "exact_solver.h"
#include "integrate.h"
#include "physics/world.h"
#include "step_scratch.h"

namespace tumble {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int team_size(int requested) {
  return requested > 0 ? requested : omp_get_max_threads();
}

// Everything one island needs to advance, independent of every other island.
struct IslandContext {
  std::span<const std::uint32_t> bodies;
  std::span<const std::uint32_t> rows;
  StepScratch& scratch;
  const WorldSettings& settings;
  std::span<const Body* const> body_of_slot;
};

void integrate_velocities(const IslandContext& c, double h, IslandReport* report) {
  for (std::uint32_t slot : c.bodies) {
    if (!integrate_velocity(*c.body_of_slot[slot], c.scratch.poses[slot].orientation,
                            c.settings.gravity, h, &c.scratch.bodies[slot]))
      ++report->gyroscopic_limit_hits;
  }
}

void integrate_positions(const IslandContext& c, double h) {
  for (std::uint32_t slot : c.bodies)
    integrate_position(h, &c.scratch.bodies[slot], &c.scratch.poses[slot]);
}

void solve_pgs(const IslandContext& c, double h, IslandReport* report) {
  warm_start(c.scratch.rows, c.rows, c.scratch.bodies);
  const SolverSettings& solver = c.settings.solver;
  for (int i = 0; i < solver.iterations; ++i) {
    ++report->velocity_iterations;
    if (solve_contacts(c.scratch.rows, c.rows, c.scratch.blocks, c.scratch.bodies, solver, nullptr,
                       h, i % 2 == 1) <= solver.velocity_tolerance)
      break;
  }
}

// One step of dt for an island with the solver chosen for it.
void advance_island(const IslandContext& c, double dt, IslandReport* report) {
  const SolverSettings& solver = c.settings.solver;
  std::span<ContactRow> rows = c.scratch.rows;
  std::span<SolverBody> bodies = c.scratch.bodies;
  if (report->solver == IslandSolver::kSoft) {
    const int substeps = solver.substeps;
    const double h = dt / substeps;
    // The spring may not be stiffer than the substep can follow (a quarter of its rate).
    const Softness soft =
        contact_softness(std::min(solver.contact_hertz, 0.25 / h), solver.contact_damping_ratio, h);
    for (int s = 0; s < substeps; ++s) {
      integrate_velocities(c, h, report);
      warm_start(rows, c.rows, bodies);
      for (int i = 0; i < solver.soft_iterations; ++i) {
        ++report->velocity_iterations;
        if (solve_contacts(rows, c.rows, c.scratch.blocks, bodies, solver, &soft, h,
                           (s + i) % 2 == 1) <= solver.velocity_tolerance)
          break;
      }
      integrate_positions(c, h);
      for (int i = 0; i < solver.relax_iterations; ++i) {
        ++report->velocity_iterations;
        if (solve_contacts(rows, c.rows, c.scratch.blocks, bodies, solver, nullptr, h,
                           (s + i) % 2 == 0) <= solver.velocity_tolerance)
          break;
      }
    }
    report->residual = normal_residual(rows, c.rows, bodies, h);
    apply_restitution(rows, c.rows, c.scratch.blocks, bodies, solver);
    return;
  }

  integrate_velocities(c, dt, report);
  if (report->solver == IslandSolver::kExact && !c.rows.empty()) {
    const ExactSolveResult exact = solve_contacts_exact(rows, c.rows, bodies, solver, dt);
    report->lemke_pivots = exact.lemke.pivots;
    if (!exact.solved()) {
      report->exact_failed = true;
      solve_pgs(c, dt, report);
    }
  } else if (!c.rows.empty()) {
    solve_pgs(c, dt, report);
  }
  report->residual = normal_residual(rows, c.rows, bodies, dt);
  integrate_positions(c, dt);
  // After the move, as in the soft path: a body stopped by a speculative contact first lands,
  // then leaves with its bounce.
  apply_restitution(rows, c.rows, c.scratch.blocks, bodies, solver);
}

}  // namespace

Status World::step(double dt) {
  if (!(dt > 0) || !std::isfinite(dt)) return Status::error("dt: must be finite and > 0");
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t step_index = stats_.step + 1;
  stats_ = StepStats{};
  stats_.step = step_index;

  auto stage = std::chrono::steady_clock::now();
  compute_bounds(dt);
  run_broad_phase();
  stats_.time.broad_phase = seconds_since(stage);

  stage = std::chrono::steady_clock::now();
  find_contacts(dt);
  stats_.time.narrow_phase = seconds_since(stage);

  // Sleepers touched by moving bodies wake with their islands, and the woken need their own
  // contacts this step. Islands that touch fall asleep together, so one more pass finds them all.
  if (const std::uint32_t woken = wake_touched(); woken > 0) {
    stats_.woken_bodies = woken;
    stage = std::chrono::steady_clock::now();
    compute_bounds(dt);
    run_broad_phase();
    find_contacts(dt);
    stats_.time.narrow_phase += seconds_since(stage);
  }

  stage = std::chrono::steady_clock::now();
  prepare_contacts(dt);
  stats_.time.prepare = seconds_since(stage);

  stage = std::chrono::steady_clock::now();
  solve_islands(dt);
  stats_.time.solve = seconds_since(stage);

  stage = std::chrono::steady_clock::now();
  correct_positions();
  stats_.time.correct_positions = seconds_since(stage);

  finish_step(dt);
  update_sleep(dt);
  stats_.time.total = seconds_since(start);
  return Status::ok();
}

void World::prepare_contacts(double /*dt*/) {
  StepScratch& s = *scratch_;
  const std::size_t slots = bodies_.size();
  s.bodies.resize(slots);
  s.poses.resize(slots);
  s.dynamic.resize(slots);
  for (std::size_t i = 0; i < slots; ++i) {
    const Slot& slot = bodies_[i];
    SolverBody& sb = s.bodies[i];
    sb = SolverBody{};
    s.dynamic[i] = slot.alive && slot.body.is_moving();
    if (!slot.alive) continue;
    s.poses[i] = slot.body.pose();
    if (!s.dynamic[i]) continue;
    sb.v = slot.body.linear_velocity;
    sb.w = slot.body.angular_velocity;
    sb.inverse_mass = slot.body.inverse_mass;
    sb.inverse_inertia = slot.body.inverse_inertia_world;
  }

  s.rows.clear();
  s.blocks.clear();
  s.row_begin.assign(1, 0);
  s.links.clear();
  double deepest = 0;
  for (const Contact& contact : contacts_) {
    prepare_rows(contact.manifold, contact.a, bodies_[contact.a.index].body, contact.b,
                 bodies_[contact.b.index].body, s.cache, &s.rows, &s.blocks);
    s.row_begin.push_back(static_cast<std::uint32_t>(s.rows.size()));
    s.links.push_back({contact.a.index, contact.b.index});
    deepest = std::max(deepest, contact.manifold.depth);
  }
  build_islands(s.dynamic, s.links, &s.islands);

  const std::size_t islands = s.islands.count();
  s.island_rows.clear();
  s.island_row_begin.assign(1, 0);
  s.reports.assign(islands, IslandReport{});
  const SolverSettings& solver = settings_.solver;
  for (std::size_t i = 0; i < islands; ++i) {
    for (std::uint32_t l = s.islands.link_begin[i]; l < s.islands.link_begin[i + 1]; ++l) {
      const std::uint32_t manifold = s.islands.links[l];
      for (std::uint32_t r = s.row_begin[manifold]; r < s.row_begin[manifold + 1]; ++r)
        s.island_rows.push_back(r);
    }
    s.island_row_begin.push_back(static_cast<std::uint32_t>(s.island_rows.size()));
    const std::uint32_t points = s.island_row_begin[i + 1] - s.island_row_begin[i];
    IslandSolver kind = IslandSolver::kSoft;
    switch (solver.kind) {
      case SolverKind::kExact:
        kind = IslandSolver::kExact;
        break;
      case SolverKind::kPgs:
        kind = IslandSolver::kPgs;
        break;
      case SolverKind::kSoft:
        kind = IslandSolver::kSoft;
        break;
      case SolverKind::kAuto:
        kind = points <= static_cast<std::uint32_t>(solver.exact_max_points) ? IslandSolver::kExact
                                                                             : IslandSolver::kSoft;
        break;
    }
    s.reports[i].solver = kind;
  }

  stats_.pairs = static_cast<std::uint32_t>(pairs_.size());
  stats_.manifolds = static_cast<std::uint32_t>(contacts_.size());
  stats_.contact_points = static_cast<std::uint32_t>(s.rows.size());
  stats_.islands = static_cast<std::uint32_t>(islands);
  stats_.max_penetration = deepest;
  stats_.collision_flags = collision_flags_;
}

void World::solve_islands(double dt) {
  StepScratch& s = *scratch_;
  s.body_of_slot.resize(bodies_.size());  // reused: no allocation once warmed up
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    s.body_of_slot[i] = &bodies_[i].body;
  const std::int64_t islands = static_cast<std::int64_t>(s.islands.count());
  // Islands share no body and no row: any order and any thread gives the same bits.
#pragma omp parallel for schedule(dynamic, 1) \
    num_threads(team_size(settings_.threads)) if (islands > 1 && team_size(settings_.threads) > 1)
  for (std::int64_t i = 0; i < islands; ++i) {
    const IslandContext context{
        std::span(s.islands.bodies)
            .subspan(s.islands.body_begin[i],
                     s.islands.body_begin[i + 1] - s.islands.body_begin[i]),
        std::span(s.island_rows)
            .subspan(s.island_row_begin[i], s.island_row_begin[i + 1] - s.island_row_begin[i]),
        s, settings_, s.body_of_slot};
    advance_island(context, dt, &s.reports[i]);
  }
  for (const IslandReport& report : s.reports) {
    if (report.solver == IslandSolver::kExact)
      ++stats_.exact_islands;
    else
      ++stats_.iterative_islands;
    stats_.exact_fallbacks += report.exact_failed ? 1 : 0;
    stats_.lemke_pivots += report.lemke_pivots;
    stats_.velocity_iterations += report.velocity_iterations;
    stats_.gyroscopic_limit_hits += report.gyroscopic_limit_hits;
    stats_.residual = std::max(stats_.residual, report.residual);
  }
}

void World::correct_positions() {
  StepScratch& s = *scratch_;
  const int iterations = settings_.solver.position_iterations;
  const std::int64_t islands = static_cast<std::int64_t>(s.islands.count());
#pragma omp parallel for schedule(dynamic, 1) \
    num_threads(team_size(settings_.threads)) if (islands > 1 && team_size(settings_.threads) > 1)
  for (std::int64_t i = 0; i < islands; ++i) {
    // Soft islands corrected their penetration inside the substeps, exact ones in the LCP.
    const IslandReport& report = s.reports[i];
    if (report.solver == IslandSolver::kSoft ||
        (report.solver == IslandSolver::kExact && !report.exact_failed))
      continue;
    const auto rows =
        std::span(s.island_rows)
            .subspan(s.island_row_begin[i], s.island_row_begin[i + 1] - s.island_row_begin[i]);
    for (int k = 0; k < iterations; ++k)
      tumble::correct_positions(s.rows, rows, s.bodies, s.poses, settings_.solver);
  }
}

std::uint32_t World::wake_touched() {
  std::uint32_t woken = 0;
  for (const Contact& contact : contacts_) {
    const Body& a = bodies_[contact.a.index].body;
    const Body& b = bodies_[contact.b.index].body;
    if (a.asleep && b.is_moving()) woken += wake_island(a.sleep_island);
    if (b.asleep && a.is_moving()) woken += wake_island(b.sleep_island);
  }
  return woken;
}

void World::update_sleep(double dt) {
  StepScratch& s = *scratch_;
  const SolverSettings& solver = settings_.solver;
  for (std::size_t i = 0; i < s.islands.count(); ++i) {
    double shortest = std::numeric_limits<double>::infinity();
    for (std::uint32_t k = s.islands.body_begin[i]; k < s.islands.body_begin[i + 1]; ++k) {
      Body& body = bodies_[s.islands.bodies[k]].body;
      const bool slow = body.linear_velocity.norm() < solver.sleep_linear_speed &&
                        body.angular_velocity.norm() < solver.sleep_angular_speed;
      body.sleep_timer = slow ? body.sleep_timer + dt : 0.0;
      shortest = std::min(shortest, body.sleep_timer);
    }
    if (!solver.sleeping || shortest < solver.sleep_delay) continue;
    const std::uint32_t island = s.islands.bodies[s.islands.body_begin[i]];
    for (std::uint32_t k = s.islands.body_begin[i]; k < s.islands.body_begin[i + 1]; ++k) {
      Body& body = bodies_[s.islands.bodies[k]].body;
      body.asleep = true;
      body.sleep_island = island;
      body.linear_velocity.setZero();
      body.angular_velocity.setZero();
    }
  }
  for (const Slot& slot : bodies_)
    stats_.sleeping_bodies += slot.alive && slot.body.asleep ? 1 : 0;
}

void World::finish_step(double dt) {
  StepScratch& s = *scratch_;
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    if (!s.dynamic[i]) continue;
    Body& body = bodies_[i].body;
    body.position = s.poses[i].position;
    body.orientation = s.poses[i].orientation;
    body.linear_velocity = s.bodies[i].v;
    body.angular_velocity = s.bodies[i].w;
    body.update_world_inertia();
  }
  // Impulses for the next step's warm start, sorted by body pair as the contacts are.
  s.cache.clear();
  impulses_.clear();
  for (std::size_t m = 0; m < contacts_.size(); ++m) {
    for (std::uint32_t r = s.row_begin[m]; r < s.row_begin[m + 1]; ++r) {
      const ContactRow& row = s.rows[r];
      s.cache.push_back(
          {contacts_[m].a, contacts_[m].b, row.feature, row.local_a, row.normal_impulse,
           row.tangent_impulse1 * row.tangent1 + row.tangent_impulse2 * row.tangent2});
      impulses_.push_back(row.normal_impulse);
    }
  }
  time_ += dt;
}

}  // namespace tumble

namespace tumble {

std::string_view solver_name(SolverKind kind) {
  switch (kind) {
    case SolverKind::kExact:
      return "exact";
    case SolverKind::kPgs:
      return "pgs";
    case SolverKind::kSoft:
      return "soft";
    case SolverKind::kAuto:
      return "auto";
  }
  return "auto";
}

std::optional<SolverKind> solver_from_name(std::string_view name) {
  for (SolverKind kind :
       {SolverKind::kExact, SolverKind::kPgs, SolverKind::kSoft, SolverKind::kAuto})
    if (solver_name(kind) == name) return kind;
  return std::nullopt;
}

}  // namespace tumble
