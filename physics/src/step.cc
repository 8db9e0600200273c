// World::step and its stages.
#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "auto_solver.h"
#include "exact_solver.h"
#include "integrate.h"
#include "parallel.h"
#include "physics/world.h"
#include "step_limits.h"
#include "step_scratch.h"
#include "tall_stacks.h"
#include "world_slot.h"

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
  std::span<const Body* const> body_of;  // by solver index
};

// The velocity recipe of one island, written once for every solver and thread count. `run`
// carries each part out: over the island's rows in order on one thread (SerialIsland, which alone
// has the exact solver's LCP: exact islands are small), or colour by colour over the whole team
// (TeamIsland), which differs only in the order in which Gauss-Seidel visits the rows.
//   soft: per substep, gravity, warm start, iterations with the soft bias, move, relaxation
//         iterations without it (Catto's "Solver2D" soft step, 2024);
//   exact: gravity, one LCP (pgs when its answer is refused);
//   pgs:  gravity, warm start, iterations (then position correction, a later stage);
//   then the normal residual, the move (soft moved in its substeps) and restitution.
template <class Runner>
void advance_with(Runner& run, IslandReport* report, const SolverSettings& solver, double dt) {
  if (report->solver == IslandSolver::kSoft) {
    // Tall stacks take more substeps and a stiffer spring (tall_stacks.h), the rest the settings'.
    const bool stiffened = report->substeps > 0;
    const int substeps = stiffened ? report->substeps : solver.substeps;
    const double hertz = stiffened ? report->contact_hertz : solver.contact_hertz;
    const double h = dt / substeps;
    // The spring may not be stiffer than the substep can follow (a quarter of its rate).
    const Softness soft =
        contact_softness(std::min(hertz, 0.25 / h), solver.contact_damping_ratio, h);
    for (int sub = 0; sub < substeps; ++sub) {
      run.integrate_velocities(h);
      // From the second substep on, the impulse a row starts from is the last substep's whole.
      run.warm_start(sub > 0);
      for (int i = 0; i < solver.soft_iterations; ++i)
        if (run.sweep(&soft, h, (sub + i) % 2 == 1) <= solver.velocity_tolerance) break;
      run.integrate_positions(h);
      run.refresh_separations();  // the relaxation sweeps see where the move left the bodies
      for (int i = 0; i < solver.relax_iterations; ++i)
        if (run.sweep(nullptr, h, (sub + i) % 2 == 0) <= solver.velocity_tolerance) break;
    }
    run.finish(h);
    return;
  }
  run.integrate_velocities(dt);
  bool pgs = run.has_rows();
  if constexpr (Runner::kSolvesExact) {
    if (report->solver == IslandSolver::kExact && run.has_rows()) pgs = !run.solve_exact(dt);
  }
  if (pgs) {
    // A tall pgs island sweeps more and to the end (tall_stacks.h): sweeps stopped early leave
    // the compression it would buckle under.
    const bool tall = report->solver == IslandSolver::kPgs && report->pgs_iterations > 0;
    const int iterations = tall ? report->pgs_iterations : solver.iterations;
    const double tolerance = tall ? 0.0 : solver.velocity_tolerance;
    run.warm_start(false);
    for (int i = 0; i < iterations; ++i)
      if (run.sweep(nullptr, dt, i % 2 == 1) <= tolerance) break;
  }
  // After the move, as in the soft path: a body stopped by a speculative contact first lands,
  // then leaves with its bounce.
  run.finish(dt, [&] { run.integrate_positions(dt); });
}

// advance_with's parts for one island on one thread (any island: exact, soft, pgs).
class SerialIsland {
 public:
  static constexpr bool kSolvesExact = true;
  SerialIsland(const IslandContext& c, IslandReport* report)
      : c_(c),
        report_(report),
        rows_(c.scratch.rows),
        cold_(c.scratch.cold_rows),
        bodies_(c.scratch.bodies) {}

  bool has_rows() const { return !c_.rows.empty(); }
  void integrate_velocities(double h) {
    for (std::uint32_t k : c_.bodies) {
      if (!integrate_velocity(*c_.body_of[k], c_.scratch.poses[k].orientation, c_.settings.gravity,
                              h, &bodies_[k]))
        ++report_->gyroscopic_limit_hits;
    }
  }
  void integrate_positions(double h) {
    for (std::uint32_t k : c_.bodies)
      integrate_position(h, &bodies_[k], &c_.scratch.poses[k]);
  }
  void refresh_separations() { update_separations(rows_, c_.rows, bodies_); }
  void warm_start(bool keep_last_substep) {
    tumble::warm_start(rows_, cold_, c_.rows, bodies_, keep_last_substep);
  }
  double sweep(const Softness* soft, double h, bool backward) {
    ++report_->velocity_iterations;
    return solve_contacts(rows_, c_.rows, c_.scratch.blocks, bodies_, c_.settings.solver, soft, h,
                          backward);
  }
  // True when the LCP's answer was taken; false when it was refused (then pgs solves the island).
  bool solve_exact(double dt) {
    const ExactSolveResult exact =
        solve_contacts_exact(rows_, cold_, c_.rows, bodies_, c_.settings.solver, dt);
    report_->lemke_pivots = exact.lemke.pivots;
    if (!exact.solved()) {
      report_->exact_failed = true;
      return false;
    }
    report_->needs_position_correction = !exact.pushed_out;
    return true;
  }
  // The residual at the velocities solved, then `move` (pgs and exact move here, soft moved in its
  // substeps), then restitution.
  template <class Move = void (*)()>
  void finish(
      double h, Move move = [] {}) {
    report_->residual = normal_residual(rows_, c_.rows, bodies_, h);
    move();
    apply_restitution();
  }
  void apply_restitution() {
    tumble::apply_restitution(rows_, cold_, c_.rows, c_.scratch.blocks, bodies_,
                              c_.settings.solver);
  }

 private:
  const IslandContext& c_;
  IslandReport* report_;
  std::span<ContactRow> rows_;
  std::span<ContactRowCold> cold_;
  std::span<SolverBody> bodies_;
};

IslandContext island_context(StepScratch& s, const WorldSettings& settings, std::size_t i) {
  return {
      std::span(s.islands.bodies)
          .subspan(s.islands.body_begin[i], s.islands.body_begin[i + 1] - s.islands.body_begin[i]),
      std::span(s.island_rows)
          .subspan(s.island_row_begin[i], s.island_row_begin[i + 1] - s.island_row_begin[i]),
      s, settings, s.body_of};
}

// advance_with's parts for up to kWideLanes small islands of the same recipe (soft with the
// settings' substeps, or pgs) at once, on one thread. A small island is too small to split over
// lanes; islands share no moving body, so each takes a lane of the packs (contact_packs.h): pack j
// holds every island's j-th manifold, each island visits its own manifolds in its own order and
// stops its sweeps when it alone has converged: the same bits as solving them one after the other.
class IslandLanes {
 public:
  static constexpr bool kSolvesExact = false;
  IslandLanes(StepScratch& s, const WorldSettings& settings, std::span<const std::uint32_t> islands,
              std::span<ContactPack> packs)
      : s_(s),
        settings_(settings),
        count_(islands.size()),
        packs_(packs),
        // A tall pgs island sweeps to the end (advance_with): none of the item stops early.
        tolerance_(s.reports[islands[0]].pgs_iterations > 0 ? 0.0
                                                            : settings.solver.velocity_tolerance) {
    TUMBLE_ASSERT(count_ <= kWideLanes);
    for (std::size_t k = 0; k < count_; ++k) {
      const std::uint32_t i = islands[k];
      contexts_[k].emplace(island_context(s, settings, i));
      lanes_[k].emplace(*contexts_[k], &s.reports[i]);
      reports_[k] = &s.reports[i];
      manifolds_[k] = s.island_manifold_begin[i + 1] - s.island_manifold_begin[i];
    }
    for (std::size_t j = 0; j < packs_.size(); ++j) {
      std::uint32_t lanes[kWideLanes];
      for (std::size_t k = 0; k < kWideLanes; ++k) {
        lanes[k] = kNoManifold;
        if (k >= count_ || j >= manifolds_[k]) continue;
        const ManifoldRows m = s.island_manifolds[s.island_manifold_begin[islands[k]] + j];
        lanes[k] = s.rows[m.ids[0]].manifold;
      }
      pack_manifolds(lanes, s.row_begin, s.rows, s.blocks, s.bodies, &packs_[j]);
    }
  }
  IslandLanes(const IslandLanes&) = delete;
  IslandLanes& operator=(const IslandLanes&) = delete;

  bool has_rows() const { return true; }  // only islands with rows are given lanes
  void integrate_velocities(double h) {
    for (std::size_t k = 0; k < count_; ++k)
      lanes_[k]->integrate_velocities(h);
  }
  // Each run of sweeps follows a warm start or a move: every island sweeps again.
  void integrate_positions(double h) {
    for (std::size_t k = 0; k < count_; ++k) {
      lanes_[k]->integrate_positions(h);
      active_[k] = -1;
    }
  }
  // The packs solve; the rows take their impulses at the end, for the residual and restitution.
  void refresh_separations() {
    for (ContactPack& pack : packs_)
      update_separations(pack, s_.bodies);
  }
  void warm_start(bool keep_last_substep) {
    for (ContactPack& pack : packs_)
      tumble::warm_start(pack, s_.bodies, keep_last_substep);
    for (std::size_t k = 0; k < count_; ++k)
      active_[k] = -1;
  }
  // Returns the largest change over the islands still sweeping; an island whose own sweep changed
  // nothing beyond the tolerance stops, as it would alone.
  double sweep(const Softness* soft, double h, bool backward) {
    std::size_t most = 0;
    for (std::size_t k = 0; k < count_; ++k) {
      if (!active_[k]) continue;
      ++reports_[k]->velocity_iterations;
      most = std::max<std::size_t>(most, manifolds_[k]);
    }
    double change[kWideLanes] = {};
    for (std::size_t j = 0; j < most; ++j) {
      double changes[kWideLanes];
      solve_pack(packs_[backward ? most - 1 - j : j], active_, s_.bodies, settings_.solver, soft, h,
                 changes);
      for (std::size_t k = 0; k < count_; ++k)
        change[k] = std::max(change[k], changes[k]);
    }
    double largest = 0;
    for (std::size_t k = 0; k < count_; ++k) {
      if (!active_[k]) continue;
      largest = std::max(largest, change[k]);
      if (change[k] <= tolerance_) active_[k] = 0;
    }
    return largest;
  }
  template <class Move = void (*)()>
  void finish(
      double h, Move move = [] {}) {
    double residual[kWideLanes] = {};
    for (const ContactPack& pack : packs_) {
      store_impulses(pack, s_.rows, s_.cold_rows);
      double lane_residuals[kWideLanes];
      pack_residuals(pack, s_.bodies, h, lane_residuals);
      for (std::size_t k = 0; k < count_; ++k)
        residual[k] = std::max(residual[k], lane_residuals[k]);
    }
    for (std::size_t k = 0; k < count_; ++k)
      reports_[k]->residual = residual[k];
    move();
    for (std::size_t k = 0; k < count_; ++k)
      lanes_[k]->apply_restitution();
  }

 private:
  StepScratch& s_;
  const WorldSettings& settings_;
  std::size_t count_;
  std::span<ContactPack> packs_;
  double tolerance_;  // an island whose sweep changed no more stops sweeping
  std::array<std::optional<IslandContext>, kWideLanes> contexts_;
  std::array<std::optional<SerialIsland>, kWideLanes> lanes_;
  std::array<IslandReport*, kWideLanes> reports_{};
  std::array<std::uint32_t, kWideLanes> manifolds_{};  // each island's count
  WideMask active_{};                                  // islands still sweeping: their lanes
};

// --- Islands solved by the whole team, colour by colour. Every function below is called by
// every thread of the team (or by one thread outside any team) and contains the worksharing.

// Orders one colour's manifolds by their number of points, most first, keeping their order
// otherwise. A colour's manifolds share no moving body, so any order gives the same bits; this one
// packs manifolds of one size together, and a lane no longer pays for its neighbours' points (a
// pack sweeps as many points as its largest manifold has) or for the point-by-point solve that a
// single point in one lane would otherwise run for all four.
void group_by_points(std::span<std::uint32_t> manifolds, std::span<const std::uint32_t> row_begin,
                     std::vector<std::uint32_t>* scratch) {
  constexpr int kMostPoints = std::tuple_size_v<decltype(ContactManifold::points)>;
  const auto rank = [&](std::uint32_t m) {
    return kMostPoints - static_cast<int>(row_begin[m + 1] - row_begin[m]);
  };
  std::array<std::uint32_t, kMostPoints + 1> next{};
  for (std::uint32_t m : manifolds) {
    TUMBLE_ASSERT(rank(m) >= 0 && rank(m) < kMostPoints);  // 1 to 4 points (prepare_rows)
    ++next[rank(m) + 1];
  }
  if (std::count(next.begin(), next.end(), 0) == kMostPoints) return;  // one size already
  for (int r = 1; r <= kMostPoints; ++r)
    next[r] += next[r - 1];
  scratch->assign(manifolds.begin(), manifolds.end());
  for (std::uint32_t m : *scratch)
    manifolds[next[rank(m)]++] = m;
}

std::span<const std::uint32_t> manifold_rows(const StepScratch& s, std::uint32_t manifold) {
  return std::span(s.row_ids).subspan(s.row_begin[manifold],
                                      s.row_begin[manifold + 1] - s.row_begin[manifold]);
}

// The largest of the threads' values, returned to every thread.
double team_max(double local, std::vector<double>& values) {
  const int threads = omp_get_num_threads();
  if (threads == 1) return local;
  values[omp_get_thread_num()] = local;
#pragma omp barrier
  double largest = 0;
  for (int t = 0; t < threads; ++t)
    largest = std::max(largest, values[t]);
#pragma omp barrier
  return largest;
}

ManifoldRows manifold_rows_of(const StepScratch& s, std::uint32_t manifold) {
  const std::span<const std::uint32_t> ids = manifold_rows(s, manifold);
  return {ids.data(), static_cast<int>(ids.size())};
}

// Calls pack_fn(pack) for the packs of colours [first, last), forwards or backwards, where
// `packed`, the team splitting each colour's packs, and manifold_fn(manifold rows) for the
// manifolds not packed: the overflow colour's on one thread, in order, and every colour's, split,
// without `packed` (the same order: packs only group a colour's manifolds, which share no moving
// body). Returns the largest value they returned, on every thread (0 without `reduce`, which
// spares the two barriers of the reduction).
template <class PackFn, class ManifoldFn>
double visit_colours(StepScratch& s, std::uint32_t first, std::uint32_t last, bool backward,
                     bool packed, PackFn&& pack_fn, ManifoldFn&& manifold_fn, bool reduce) {
  const Colouring& colouring = s.colouring;
  double local = 0;
  for (std::uint32_t k = first; k < last; ++k) {
    const std::uint32_t c = backward ? first + last - 1 - k : k;
    const std::int64_t begin = colouring.colour_begin[c], end = colouring.colour_begin[c + 1];
    if (colouring.serial[c]) {
#pragma omp single
      for (std::int64_t i = begin; i < end; ++i) {
        const std::int64_t at = backward ? begin + end - 1 - i : i;
        local = std::max(local, manifold_fn(manifold_rows_of(s, colouring.manifolds[at])));
      }
    } else if (!packed) {
#pragma omp for schedule(static)
      for (std::int64_t i = begin; i < end; ++i)
        local = std::max(local, manifold_fn(manifold_rows_of(s, colouring.manifolds[i])));
    } else {
      const std::int64_t packs_begin = s.colour_pack_begin[c],
                         packs_end = s.colour_pack_begin[c + 1];
#pragma omp for schedule(static)
      for (std::int64_t p = packs_begin; p < packs_end; ++p)
        local = std::max(local, pack_fn(s.packs[p]));
    }
  }
  return reduce ? team_max(local, s.team_values) : 0.0;
}

// The step's packs where it sweeps them, else the rows.
template <class PackFn, class ManifoldFn>
double sweep_packs(StepScratch& s, std::uint32_t first, std::uint32_t last, bool backward,
                   PackFn&& pack_fn, ManifoldFn&& manifold_fn, bool reduce = true) {
  return visit_colours(s, first, last, backward, s.packed, pack_fn, manifold_fn, reduce);
}

// fn(row ids of a manifold) for every manifold, through the rows.
template <class Fn>
double sweep_colours(StepScratch& s, std::uint32_t first, std::uint32_t last, bool backward,
                     Fn&& fn, bool reduce = true) {
  return visit_colours(
      s, first, last, backward, false, [](const ContactPack&) { return 0.0; },
      [&](const ManifoldRows& m) { return fn(std::span<const std::uint32_t>(m.ids, m.count)); },
      reduce);
}

std::uint32_t team_integrate_velocities(const IslandContext& c, double h) {
  std::uint32_t hits = 0;
  const std::int64_t n = static_cast<std::int64_t>(c.bodies.size());
#pragma omp for schedule(static)
  for (std::int64_t k = 0; k < n; ++k) {
    const std::uint32_t body = c.bodies[k];
    if (!integrate_velocity(*c.body_of[body], c.scratch.poses[body].orientation, c.settings.gravity,
                            h, &c.scratch.bodies[body]))
      ++hits;
  }
  return hits;
}

void team_integrate_positions(const IslandContext& c, double h) {
  const std::int64_t n = static_cast<std::int64_t>(c.bodies.size());
#pragma omp for schedule(static)
  for (std::int64_t k = 0; k < n; ++k) {
    const std::uint32_t body = c.bodies[k];
    integrate_position(h, &c.scratch.bodies[body], &c.scratch.poses[body]);
  }
}

// advance_with's parts for a coloured island (soft or pgs) over the whole team: every member
// is called by every thread of the team and contains the worksharing.
class TeamIsland {
 public:
  static constexpr bool kSolvesExact = false;
  TeamIsland(const IslandContext& c, std::uint32_t first, std::uint32_t last, IslandReport* report)
      : c_(c), s_(c.scratch), first_(first), last_(last), report_(report) {}

  bool has_rows() const { return true; }  // coloured islands have many
  void integrate_velocities(double h) { hits_ += team_integrate_velocities(c_, h); }
  void integrate_positions(double h) { team_integrate_positions(c_, h); }
  // The packs solve; the rows take their impulses at the end, for the residual and restitution.
  void refresh_separations() {
    sweep_packs(
        s_, first_, last_, false,
        [&](ContactPack& pack) {
          update_separations(pack, s_.bodies);
          return 0.0;
        },
        [&](const ManifoldRows& manifold) {
          update_separations(s_.rows, std::span(manifold.ids, manifold.count), s_.bodies);
          return 0.0;
        },
        false);
  }
  void warm_start(bool keep_last_substep) {
    sweep_packs(
        s_, first_, last_, false,
        [&](ContactPack& pack) {
          tumble::warm_start(pack, s_.bodies, keep_last_substep);
          return 0.0;
        },
        [&](const ManifoldRows& manifold) {
          tumble::warm_start(s_.rows, s_.cold_rows, std::span(manifold.ids, manifold.count),
                             s_.bodies, keep_last_substep);
          return 0.0;
        },
        false);
  }
  double sweep(const Softness* soft, double h, bool backward) {
    ++iterations_;
    return sweep_packs(
        s_, first_, last_, backward,
        [&](ContactPack& pack) {
          return solve_pack(pack, kAllLanes, s_.bodies, c_.settings.solver, soft, h);
        },
        [&](const ManifoldRows& manifold) {
          return solve_manifold(s_.rows, manifold, s_.blocks, s_.bodies, c_.settings.solver, soft,
                                h);
        });
  }
  template <class Move = void (*)()>
  void finish(
      double h, Move move = [] {}) {
    // One pass over the packs for both: a large island's packs come from memory each pass.
    const double residual = sweep_packs(
        s_, first_, last_, false,
        [&](const ContactPack& pack) {
          store_impulses(pack, s_.rows, s_.cold_rows);
          double lane_residuals[kWideLanes];
          pack_residuals(pack, s_.bodies, h, lane_residuals);
          return *std::max_element(std::begin(lane_residuals), std::end(lane_residuals));
        },
        [&](const ManifoldRows& manifold) {
          return normal_residual(s_.rows, std::span(manifold.ids, manifold.count), s_.bodies, h);
        });
    move();
    each_manifold([&](std::span<const std::uint32_t> ids) {
      apply_restitution(s_.rows, s_.cold_rows, ids, s_.blocks, s_.bodies, c_.settings.solver);
    });
#pragma omp atomic
    report_->gyroscopic_limit_hits += hits_;
    if (omp_get_thread_num() == 0) {
      report_->velocity_iterations = iterations_;
      report_->residual = residual;
    }
  }

 private:
  template <class Fn>
  void each_manifold(Fn&& fn) {
    sweep_colours(
        s_, first_, last_, false,
        [&](std::span<const std::uint32_t> ids) {
          fn(ids);
          return 0.0;
        },
        false);
  }
  const IslandContext& c_;
  StepScratch& s_;
  std::uint32_t first_, last_;
  IslandReport* report_;
  std::uint64_t iterations_ = 0;
  std::uint32_t hits_ = 0;
};

}  // namespace

Status World::step(double dt) {
  if (Status s = check_time_step(dt, settings_.limits); !s) return s;
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

  if (fast_count_ > 0) {
    stage = std::chrono::steady_clock::now();
    sweep_fast_bodies(dt);
    stats_.time.continuous = seconds_since(stage);
  }

  finish_step(dt);
  update_sleep(dt);
  stats_.time.total = seconds_since(start);
  return Status::ok();
}

void World::number_solver_bodies() {
  StepScratch& s = *scratch_;
  // Only the slots the last step numbered are cleared: no pass over every slot.
  for (std::uint32_t slot : s.solver_slot)
    if (slot < s.solver_of_slot.size()) s.solver_of_slot[slot] = kNoSolverBody;
  s.solver_of_slot.resize(bodies_.size(), kNoSolverBody);
  const std::span<const std::uint32_t> awake = awake_slots();
  s.solver_slot.assign(awake.begin(), awake.end());
  s.moving = static_cast<std::uint32_t>(awake.size());
  for (std::uint32_t k = 0; k < s.moving; ++k) {
    TUMBLE_ASSERT(bodies_[awake[k]].alive && bodies_[awake[k]].body.is_moving());
    s.solver_of_slot[awake[k]] = k;
  }
  for (const Contact& contact : contacts_) {
    for (const std::uint32_t slot : {contact.a.index, contact.b.index}) {
      if (s.solver_of_slot[slot] != kNoSolverBody) continue;
      s.solver_of_slot[slot] = static_cast<std::uint32_t>(s.solver_slot.size());
      s.solver_slot.push_back(slot);
    }
  }
}

void World::prepare_contacts(double dt) {
  StepScratch& s = *scratch_;
  number_solver_bodies();
  const std::uint32_t solver_bodies = static_cast<std::uint32_t>(s.solver_slot.size());
  s.bodies.resize(solver_bodies);
  s.poses.resize(solver_bodies);
  s.dynamic.resize(solver_bodies);
  s.body_of.resize(solver_bodies);
  const int threads = team_size(settings_.threads);
  for_indices(threads, solver_bodies > 256, solver_bodies, [&](std::int64_t k) {
    const Body& body = bodies_[s.solver_slot[k]].body;
    SolverBody& sb = s.bodies[k];
    sb = SolverBody{};
    s.dynamic[k] = k < s.moving;
    s.body_of[k] = &body;
    s.poses[k] = body.pose();
    if (!s.dynamic[k]) return;
    sb.v = body.linear_velocity;
    sb.w = body.angular_velocity;
    sb.inverse_mass = body.inverse_mass;
    sb.inverse_inertia = body.inverse_inertia_world;
  });

  // Every manifold's rows have a place known in advance, so they are built in parallel.
  const std::size_t manifolds = contacts_.size();
  s.row_begin.resize(manifolds + 1);
  s.row_begin[0] = 0;
  s.links.resize(manifolds);
  s.touching.resize(manifolds);
  s.kept_colours.resize(manifolds);
  s.colours.resize(manifolds);
  double deepest = 0;
  for (std::size_t m = 0; m < manifolds; ++m) {
    const Contact& contact = contacts_[m];
    s.row_begin[m + 1] = s.row_begin[m] + static_cast<std::uint32_t>(contact.manifold.count);
    s.links[m] = {s.solver_of_slot[contact.a.index], s.solver_of_slot[contact.b.index]};
    s.touching[m] = contact.manifold.depth > -settings_.solver.slop;
    stats_.reused_manifolds += s.reused[m];
    deepest = std::max(deepest, contact.manifold.depth);
    const std::uint32_t previous = s.previous_pair[m];
    s.kept_colours[m] = previous == kNoRecord ? kNoColour : s.pairs[previous].colour;
  }
  // A pair keeps the colour it was given when it started touching (colouring.h); its record
  // carries it to the next step.
  keep_manifold_colours(s.links, s.dynamic, s.kept_colours, &s.colouring_scratch, s.colours);
  for (std::size_t m = 0; m < manifolds; ++m)
    s.next_pairs[m].colour = s.colours[m];
  s.rows.resize(s.row_begin[manifolds]);
  s.cold_rows.resize(s.rows.size());
  s.blocks.resize(manifolds);
  if (s.row_ids.size() < s.rows.size()) {
    const std::size_t from = s.row_ids.size();
    s.row_ids.resize(s.rows.size());
    for (std::size_t r = from; r < s.row_ids.size(); ++r)
      s.row_ids[r] = static_cast<std::uint32_t>(r);
  }
  const std::int64_t count = static_cast<std::int64_t>(manifolds);
  for_indices(threads, count > 64, count, [&](std::int64_t m) {
    const Contact& contact = contacts_[m];
    const std::uint32_t previous = s.previous_pair[m];
    prepare_rows(contact.manifold, s.links[m].a, bodies_[contact.a.index].body, s.links[m].b,
                 bodies_[contact.b.index].body,
                 previous == kNoRecord ? nullptr : &s.pairs[previous],
                 static_cast<std::uint32_t>(m), &s.rows[s.row_begin[m]],
                 &s.cold_rows[s.row_begin[m]], &s.blocks[m]);
  });
  build_islands(s.dynamic, s.links, &s.islands);
  s.support_level.resize(solver_bodies);

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
    const auto island_bodies = std::span(s.islands.bodies)
                                   .subspan(s.islands.body_begin[i],
                                            s.islands.body_begin[i + 1] - s.islands.body_begin[i]);
    const auto island_links = std::span(s.islands.links)
                                  .subspan(s.islands.link_begin[i],
                                           s.islands.link_begin[i + 1] - s.islands.link_begin[i]);
    switch (solver.kind) {
      case SolverKind::kExact:
        // A dense LCP of 10 unknowns a point: past the bound, memory and pivots would grow
        // with the square and cube of the island (a pyramid of 20 is 2,360 points, 8.7 GB).
        if (points > static_cast<std::uint32_t>(solver.exact_max_island_points)) {
          kind = IslandSolver::kSoft;
          s.reports[i].exact_oversized = true;
        } else {
          kind = IslandSolver::kExact;
        }
        break;
      case SolverKind::kPgs:
        kind = IslandSolver::kPgs;
        break;
      case SolverKind::kSoft:
        kind = IslandSolver::kSoft;
        break;
      case SolverKind::kAuto: {
        // One body against statics gains nothing from solving its contacts together with
        // others' (there are none), and the soft step resolves it at a fraction of a Lemke
        // solve's cost (8-direction pyramids make 10 unknowns per point). Of the small islands
        // of several bodies, only those where the soft answer would differ pay for Lemke
        // (auto_solver.h): in a pile of like bodies, none. A body touching nothing takes the
        // plain step of dt.
        const bool alone = island_bodies.size() == 1;
        const bool small = points <= static_cast<std::uint32_t>(std::min(
                                         solver.exact_max_points, solver.exact_max_island_points));
        const bool exact =
            points == 0 || (!alone && small &&
                            soft_would_differ(island_bodies, island_links, s.links, s.body_of,
                                              s.dynamic, settings_.gravity.norm(), solver));
        kind = exact ? IslandSolver::kExact : IslandSolver::kSoft;
        break;
      }
    }
    s.reports[i].solver = kind;
    if (kind == IslandSolver::kSoft) {
      const IslandStiffness stiffness =
          island_stiffness(island_bodies, island_links, s.links, s.touching, s.dynamic, s.body_of,
                           settings_.gravity, dt, solver, &s.support_level, &s.level_sums);
      s.reports[i].substeps = stiffness.substeps;
      s.reports[i].contact_hertz = stiffness.contact_hertz;
      s.reports[i].stiffness_capped = stiffness.capped;
    } else if (kind == IslandSolver::kPgs) {
      bool capped = false;
      s.reports[i].pgs_iterations =
          tall_pgs_iterations(island_bodies, island_links, s.links, s.touching, s.dynamic, solver,
                              &s.support_level, &capped);
      s.reports[i].stiffness_capped = capped;
    }
  }

  // Each island's manifolds as row-id spans, for sweeping several islands at once.
  s.island_manifolds.clear();
  s.island_manifold_begin.assign(1, 0);
  for (std::size_t i = 0; i < islands; ++i) {
    for (std::uint32_t r = s.island_row_begin[i]; r < s.island_row_begin[i + 1];) {
      const int count = s.rows[s.island_rows[r]].block_size;
      s.island_manifolds.push_back({&s.island_rows[r], count});
      r += count;
    }
    s.island_manifold_begin.push_back(static_cast<std::uint32_t>(s.island_manifolds.size()));
  }

  // Large iterative islands are coloured for the team; the others go one island per thread.
  s.colouring.clear();
  s.island_colour_begin.assign(1, 0);
  s.team_islands.clear();
  s.single_islands.clear();
  for (std::size_t i = 0; i < islands; ++i) {
    const std::uint32_t links = s.islands.link_begin[i + 1] - s.islands.link_begin[i];
    if (links >= kColouredIsland && s.reports[i].solver != IslandSolver::kExact) {
      colour_manifolds(std::span(s.islands.links).subspan(s.islands.link_begin[i], links),
                       s.colours, &s.colouring_scratch, &s.colouring);
      s.team_islands.push_back(static_cast<std::uint32_t>(i));
    } else {
      s.single_islands.push_back(static_cast<std::uint32_t>(i));
    }
    s.island_colour_begin.push_back(static_cast<std::uint32_t>(s.colouring.colour_count()));
  }

  s.packed = packed_sweeps();
  s.pack_manifolds.clear();
  s.colour_pack_begin.assign(1, 0);
  for (std::size_t c = 0; c < s.colouring.colour_count(); ++c) {
    const std::uint32_t end = s.colouring.colour_begin[c + 1];
    if (s.packed && !s.colouring.serial[c]) {
      group_by_points(std::span(s.colouring.manifolds)
                          .subspan(s.colouring.colour_begin[c], end - s.colouring.colour_begin[c]),
                      s.row_begin, &s.grouped);
      for (std::uint32_t first = s.colouring.colour_begin[c]; first < end; first += kWideLanes)
        s.pack_manifolds.push_back({first, std::min<std::uint32_t>(kWideLanes, end - first)});
    }
    s.colour_pack_begin.push_back(static_cast<std::uint32_t>(s.pack_manifolds.size()));
  }
  s.packs.resize(s.pack_manifolds.size());
  const std::int64_t packs = static_cast<std::int64_t>(s.packs.size());
  for_indices(threads, packs > 16, packs, [&](std::int64_t k) {
    std::uint32_t lanes[kWideLanes];
    for (std::uint32_t lane = 0; lane < kWideLanes; ++lane)
      lanes[lane] = lane < s.pack_manifolds[k].count
                        ? s.colouring.manifolds[s.pack_manifolds[k].first + lane]
                        : kNoManifold;
    pack_manifolds(lanes, s.row_begin, s.rows, s.blocks, s.bodies, &s.packs[k]);
  });

  stats_.solver_bodies = solver_bodies;
  stats_.pairs = static_cast<std::uint32_t>(pairs_.size());
  stats_.manifolds = static_cast<std::uint32_t>(contacts_.size());
  stats_.contact_points = static_cast<std::uint32_t>(s.rows.size());
  stats_.islands = static_cast<std::uint32_t>(islands);
  stats_.coloured_islands = static_cast<std::uint32_t>(s.team_islands.size());
  stats_.colours = static_cast<std::uint32_t>(s.colouring.colour_count());
  for (std::size_t c = 0; c < s.colouring.colour_count(); ++c)
    if (s.colouring.serial[c])
      stats_.overflow_manifolds += s.colouring.colour_begin[c + 1] - s.colouring.colour_begin[c];
  stats_.max_penetration = deepest;
  stats_.collision_flags = collision_flags_;
}

void World::solve_islands(double dt) {
  StepScratch& s = *scratch_;
  const int threads = team_size(settings_.threads);
  if (s.team_values.size() < static_cast<std::size_t>(threads)) s.team_values.resize(threads);
  // The small islands as work: soft (with the settings' substeps) and pgs islands with rows in
  // groups of kWideLanes (IslandLanes) where the step sweeps packs (tall pgs islands with those
  // of their sweep count), every other one alone (SerialIsland).
  s.work_islands.clear();
  s.work_begin.assign(1, 0);
  auto lane_kind = [&](std::uint32_t i) -> int {
    const IslandReport& report = s.reports[i];
    if (s.island_row_begin[i + 1] == s.island_row_begin[i]) return -1;
    if (!s.packed) return -1;
    if (report.solver == IslandSolver::kSoft && report.substeps == 0) return 0;
    if (report.solver == IslandSolver::kPgs) return 1;
    return -1;
  };
  auto manifold_count = [&](std::uint32_t i) {
    return s.island_manifold_begin[i + 1] - s.island_manifold_begin[i];
  };
  // Tall pgs islands sweep their own count to the end (tall_stacks.h): only islands with the same
  // count share an item.
  auto sweeps = [&](std::uint32_t i) { return s.reports[i].pgs_iterations; };
  for (int kind = 0; kind < 2; ++kind) {
    // Islands of like sizes side by side, largest first: a pack's lanes then run out of
    // manifolds together (four islands of 30, 5, 5 and 2 manifolds would fill 30 packs, 42
    // lanes of 120), and the largest items are handed out first.
    s.lane_candidates.clear();
    for (std::uint32_t i : s.single_islands)
      if (lane_kind(i) == kind) s.lane_candidates.push_back(i);
    std::sort(s.lane_candidates.begin(), s.lane_candidates.end(),
              [&](std::uint32_t x, std::uint32_t y) {
                if (sweeps(x) != sweeps(y)) return sweeps(x) < sweeps(y);
                if (manifold_count(x) != manifold_count(y))
                  return manifold_count(x) > manifold_count(y);
                return x < y;
              });
    for (std::uint32_t i : s.lane_candidates) {
      const std::uint32_t item_size =
          static_cast<std::uint32_t>(s.work_islands.size()) - s.work_begin.back();
      if (item_size == kWideLanes ||
          (item_size > 0 && sweeps(s.work_islands[s.work_begin.back()]) != sweeps(i)))
        s.work_begin.push_back(static_cast<std::uint32_t>(s.work_islands.size()));
      s.work_islands.push_back(i);
    }
    if (s.work_islands.size() > s.work_begin.back())
      s.work_begin.push_back(static_cast<std::uint32_t>(s.work_islands.size()));
  }
  for (std::uint32_t i : s.single_islands) {
    if (lane_kind(i) >= 0) continue;
    s.work_islands.push_back(i);
    s.work_begin.push_back(static_cast<std::uint32_t>(s.work_islands.size()));
  }
  const std::int64_t work = static_cast<std::int64_t>(s.work_begin.size()) - 1;
  // Room for the packs of islands solved together, which each item fills itself.
  s.lane_pack_begin.assign(1, 0);
  for (std::int64_t k = 0; k < work; ++k) {
    std::uint32_t most = 0;
    if (s.work_begin[k + 1] - s.work_begin[k] > 1) {
      for (std::uint32_t w = s.work_begin[k]; w < s.work_begin[k + 1]; ++w) {
        most = std::max(most, manifold_count(s.work_islands[w]));
        stats_.packed_manifolds += manifold_count(s.work_islands[w]);
      }
    }
    s.lane_pack_begin.push_back(s.lane_pack_begin.back() + most);
  }
  s.lane_packs.resize(s.lane_pack_begin.back());
  for (const StepScratch::PackedManifolds& pack : s.pack_manifolds)
    stats_.packed_manifolds += pack.count;
  const bool parallel = threads > 1 && (work > 1 || !s.team_islands.empty());
  // Large islands one after the other with the whole team, then the rest one island per thread:
  // islands share no body and no row, and colours share no moving body, so any thread count gives
  // the same bits.
  run_region(threads, parallel, [&] {
    for (std::uint32_t i : s.team_islands) {
      const IslandContext context = island_context(s, settings_, i);
      TeamIsland team(context, s.island_colour_begin[i], s.island_colour_begin[i + 1],
                      &s.reports[i]);
      advance_with(team, &s.reports[i], settings_.solver, dt);
    }
    team_for_dynamic(work, [&](std::int64_t k) {
      const std::span<const std::uint32_t> islands =
          std::span(s.work_islands).subspan(s.work_begin[k], s.work_begin[k + 1] - s.work_begin[k]);
      if (islands.size() == 1) {
        const IslandContext context = island_context(s, settings_, islands[0]);
        SerialIsland island(context, &s.reports[islands[0]]);
        advance_with(island, &s.reports[islands[0]], settings_.solver, dt);
      } else {
        IslandLanes lanes(
            s, settings_, islands,
            std::span(s.lane_packs)
                .subspan(s.lane_pack_begin[k], s.lane_pack_begin[k + 1] - s.lane_pack_begin[k]));
        advance_with(lanes, &s.reports[islands[0]], settings_.solver, dt);
      }
    });
  });
  for (const IslandReport& report : s.reports) {
    if (report.solver == IslandSolver::kExact)
      ++stats_.exact_islands;
    else
      ++stats_.iterative_islands;
    stats_.exact_fallbacks += report.exact_failed ? 1 : 0;
    stats_.exact_oversized += report.exact_oversized ? 1 : 0;
    stats_.stiffened_islands += report.substeps > 0 || report.pgs_iterations > 0 ? 1 : 0;
    stats_.stiffness_capped += report.stiffness_capped ? 1 : 0;
    stats_.lemke_pivots += report.lemke_pivots;
    stats_.velocity_iterations += report.velocity_iterations;
    stats_.gyroscopic_limit_hits += report.gyroscopic_limit_hits;
    stats_.residual = std::max(stats_.residual, report.residual);
  }
}

void World::correct_positions() {
  StepScratch& s = *scratch_;
  const SolverSettings& solver = settings_.solver;
  // Soft islands corrected their penetration inside the substeps, exact ones by their push-out
  // LCP unless it failed.
  auto needs_correction = [&](std::uint32_t i) {
    const IslandReport& report = s.reports[i];
    return report.solver == IslandSolver::kPgs ||
           (report.solver == IslandSolver::kExact &&
            (report.exact_failed || report.needs_position_correction));
  };
  bool any = false;
  for (std::uint32_t i = 0; i < s.reports.size(); ++i)
    any |= needs_correction(i);
  if (!any || solver.position_iterations == 0) return;
  const int threads = team_size(settings_.threads);
  const std::int64_t singles = static_cast<std::int64_t>(s.single_islands.size());
  run_region(threads, true, [&] {
    for (std::uint32_t i : s.team_islands) {
      if (!needs_correction(i)) continue;
      for (int k = 0; k < solver.position_iterations; ++k)
        sweep_colours(
            s, s.island_colour_begin[i], s.island_colour_begin[i + 1], false,
            [&](std::span<const std::uint32_t> ids) {
              tumble::correct_positions(s.rows, s.cold_rows, ids, s.bodies, s.poses, solver);
              return 0.0;
            },
            false);
    }
    team_for_dynamic(singles, [&](std::int64_t k) {
      const std::uint32_t i = s.single_islands[k];
      if (!needs_correction(i)) return;
      const auto rows = island_context(s, settings_, i).rows;
      for (int n = 0; n < solver.position_iterations; ++n)
        tumble::correct_positions(s.rows, s.cold_rows, rows, s.bodies, s.poses, solver);
    });
  });
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
  drop_woken_contacts();  // before islands fall asleep, perhaps under the ids of woken ones
  // Room for every contact of this step to come to rest, reserved ahead (doubling): a resting
  // scene moves its manifolds from contacts_ to here, and the step allocates nothing for it.
  const auto reserve = [](auto& store, std::size_t room) {
    if (store.capacity() < room) store.reserve(std::max(room, 2 * store.capacity()));
  };
  reserve(resting_contacts_, resting_contacts_.size() + contacts_.size());
  reserve(resting_island_, resting_island_.size() + contacts_.size());
  reserve(resting_forces_, resting_forces_.size() + impulses_.size());
  bool fell_asleep = false;
  for (std::size_t i = 0; i < s.islands.count(); ++i) {
    double shortest = std::numeric_limits<double>::infinity();
    for (std::uint32_t k = s.islands.body_begin[i]; k < s.islands.body_begin[i + 1]; ++k) {
      Body& body = bodies_[s.solver_slot[s.islands.bodies[k]]].body;
      const bool slow = body.linear_velocity.norm() < solver.sleep_linear_speed &&
                        body.angular_velocity.norm() < solver.sleep_angular_speed;
      body.sleep_timer = slow ? body.sleep_timer + dt : 0.0;
      shortest = std::min(shortest, body.sleep_timer);
    }
    if (!solver.sleeping || shortest < solver.sleep_delay) continue;
    // Named by its lowest slot (solver indices keep the slots' order).
    const std::uint32_t island = s.solver_slot[s.islands.bodies[s.islands.body_begin[i]]];
    keep_resting_contacts(island, static_cast<std::uint32_t>(i), dt);
    for (std::uint32_t k = s.islands.body_begin[i]; k < s.islands.body_begin[i + 1]; ++k) {
      const std::uint32_t slot = s.solver_slot[s.islands.bodies[k]];
      Body& body = bodies_[slot].body;
      body.asleep = true;
      body.sleep_island = island;
      link_sleeper(slot, island);
      resting_changed(slot);
      if (sleepers_indexed_) recent_sleepers_.push_back(slot);
      body.linear_velocity.setZero();
      body.angular_velocity.setZero();
      note_event(slot, kBodyFellAsleep);
      fell_asleep = true;
    }
  }
  if (fell_asleep) {
    awake_stale_ = true;  // the sleepers leave the moving set
  }
  stats_.sleeping_bodies = static_cast<std::uint32_t>(sleeping_count_);
  stats_.resting_contact_points = static_cast<std::uint32_t>(resting_forces_.size());
}

void World::finish_step(double dt) {
  StepScratch& s = *scratch_;
  const int threads = team_size(settings_.threads);
  const std::int64_t moving = s.moving;
  const std::int64_t manifolds = static_cast<std::int64_t>(contacts_.size());
  TUMBLE_ASSERT(s.cold_rows.size() == s.rows.size() && s.row_begin.size() == contacts_.size() + 1 &&
                s.row_begin.back() == s.rows.size());
  TUMBLE_ASSERT(s.next_pairs.size() == contacts_.size());
  impulses_.resize(s.rows.size());
  std::uint32_t non_finite = 0, slowed = 0, stopped = 0;
  run_region(threads, std::max(moving, manifolds) > 256, [&] {
    std::uint32_t my_non_finite = 0, my_slowed = 0, my_stopped = 0;
#pragma omp for schedule(static) nowait
    for (std::int64_t k = 0; k < moving; ++k) {
      Body& body = bodies_[s.solver_slot[k]].body;
      const std::uint8_t guard =
          take_step_result(&body, s.poses[k], s.bodies[k].v, s.bodies[k].w, settings_.limits);
      my_non_finite += (guard & kStepNonFinite) != 0;
      my_slowed += (guard & kStepSlowed) != 0;
      my_stopped += (guard & kStepAtEdge) != 0;
    }
#pragma omp atomic update
    non_finite += my_non_finite;
#pragma omp atomic update
    slowed += my_slowed;
#pragma omp atomic update
    stopped += my_stopped;
#pragma omp for schedule(static)
    for (std::int64_t m = 0; m < manifolds; ++m) {
      for (std::uint32_t r = s.row_begin[m]; r < s.row_begin[m + 1]; ++r) {
        const ContactRow& row = s.rows[r];
        // The impulses stay with the pair's record for the next step's warm start.
        ContactPointRecord& point = s.next_pairs[m].points[row.block_index];
        point.normal_impulse = row.normal_impulse;
        point.friction_impulse =
            row.tangent_impulse1 * row.tangent1 + row.tangent_impulse2 * row.tangent2;
        impulses_[r] = s.cold_rows[r].earlier_substeps_impulse + row.normal_impulse;
      }
    }
  });
  // Every body the step integrated moved (listed after the parallel loop: the list is ordered).
  for (std::int64_t k = 0; k < moving; ++k)
    note_event(s.solver_slot[k], kBodyMoved);
  stats_.non_finite_bodies = non_finite;
  stats_.slowed_bodies = slowed;
  stats_.bodies_at_edge = stopped;
  std::swap(s.pairs, s.next_pairs);
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
