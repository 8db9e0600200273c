// Stage "sweeps": each island's manifolds laid out for the solver's sweeps: large iterative
// islands coloured for the whole team, their colours packed four manifolds to a vector, the
// others one island per thread; and the step's counts in StepStats.
#include <omp.h>

#include <algorithm>
#include <array>
#include <span>
#include <tuple>

#include "auto_solver.h"
#include "colouring.h"
#include "contact_packs.h"
#include "contact_pairs.h"
#include "contact_solver.h"
#include "islands.h"
#include "parallel.h"
#include "physics/world.h"
#include "step_scratch.h"
#include "step_stages.h"
#include "tall_stacks.h"
#include "world_slot.h"

namespace tumble {
namespace {

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

}  // namespace

void World::group_for_sweeps() {
  StepScratch& s = *scratch_;
  const int threads = team_size(settings_.threads);
  const std::size_t islands = s.islands.count();
  // Each island's manifolds as row-id spans, for sweeping several islands at once.
  s.island_manifolds.clear();
  s.island_manifold_begin.assign(1, 0);
  // (An island's rows are its manifolds' in link order, so the manifolds' sizes come from
  // row_begin, without reading the rows themselves.)
  for (std::size_t i = 0; i < islands; ++i) {
    std::uint32_t r = s.island_row_begin[i];
    for (std::uint32_t l = s.islands.link_begin[i]; l < s.islands.link_begin[i + 1]; ++l) {
      const std::uint32_t manifold = s.islands.links[l];
      const int count = static_cast<int>(s.row_begin[manifold + 1] - s.row_begin[manifold]);
      s.island_manifolds.push_back({&s.island_rows[r], count});
      r += count;
    }
    TUMBLE_ASSERT(r == s.island_row_begin[i + 1]);
    s.island_manifold_begin.push_back(static_cast<std::uint32_t>(s.island_manifolds.size()));
  }

  // Large iterative islands are coloured for the team; the others go one island per thread. A
  // large island with joints (not exact) is coloured too, for its contacts' sweeps in packs, but
  // stays one thread's (SerialIsland: its joints are not solved colour by colour).
  s.colouring.clear();
  s.island_colour_begin.assign(1, 0);
  s.team_islands.clear();
  s.single_islands.clear();
  for (std::size_t i = 0; i < islands; ++i) {
    const std::uint32_t links = s.islands.link_begin[i + 1] - s.islands.link_begin[i];
    const IslandReport& report = s.reports[i];
    const bool coloured =
        links >= kColouredIsland && report.solver != IslandSolver::kExact && !report.exact_joints;
    stats_.coloured_islands += coloured ? 1 : 0;
    if (coloured)
      colour_manifolds(std::span(s.islands.links).subspan(s.islands.link_begin[i], links),
                       s.colours, &s.colouring_scratch, &s.colouring);
    if (coloured && report.joints == 0)
      s.team_islands.push_back(static_cast<std::uint32_t>(i));
    else
      s.single_islands.push_back(static_cast<std::uint32_t>(i));
    s.island_colour_begin.push_back(static_cast<std::uint32_t>(s.colouring.colour_count()));
  }

  s.packed = packed_sweeps();
  s.pack_manifolds.clear();
  s.colour_pack_begin.assign(1, 0);
  const std::int64_t colours = static_cast<std::int64_t>(s.colouring.colour_count());
  if (s.packed) {
    // Colours are grouped independently, over the team (a thread's own scratch).
    s.thread_grouped.resize(threads);
    for_indices(
        threads,
        colours > 1 && worth_a_team(static_cast<std::int64_t>(s.colouring.manifolds.size()), 50),
        colours,
        [&](std::int64_t c) {
          if (s.colouring.serial[c]) return;
          const std::uint32_t begin = s.colouring.colour_begin[c],
                              end = s.colouring.colour_begin[c + 1];
          group_by_points(std::span(s.colouring.manifolds).subspan(begin, end - begin), s.row_begin,
                          &s.thread_grouped[omp_get_thread_num()]);
        },
        1);
    // As large as the largest colour needed, on every thread: the next step allocates nothing.
    std::size_t most = 0;
    for (const std::vector<std::uint32_t>& grouped : s.thread_grouped)
      most = std::max(most, grouped.capacity());
    for (std::vector<std::uint32_t>& grouped : s.thread_grouped)
      grouped.reserve(most);
  }
  for (std::size_t c = 0; c < s.colouring.colour_count(); ++c) {
    const std::uint32_t end = s.colouring.colour_begin[c + 1];
    if (s.packed && !s.colouring.serial[c]) {
      for (std::uint32_t first = s.colouring.colour_begin[c]; first < end; first += kWideLanes)
        s.pack_manifolds.push_back({first, std::min<std::uint32_t>(kWideLanes, end - first)});
    }
    s.colour_pack_begin.push_back(static_cast<std::uint32_t>(s.pack_manifolds.size()));
  }
  resize_for_overwrite(s.packs, s.pack_manifolds.size());
  const std::int64_t packs = static_cast<std::int64_t>(s.packs.size());
  for_indices(threads, worth_a_team(packs, 225), packs, [&](std::int64_t k) {
    std::uint32_t lanes[kWideLanes];
    for (std::uint32_t lane = 0; lane < kWideLanes; ++lane)
      lanes[lane] = lane < s.pack_manifolds[k].count
                        ? s.colouring.manifolds[s.pack_manifolds[k].first + lane]
                        : kNoManifold;
    pack_manifolds(lanes, s.row_begin, s.rows, s.blocks, s.bodies, &s.packs[k]);
  });

  stats_.solver_bodies = static_cast<std::uint32_t>(s.solver_slot.size());
  stats_.pairs = static_cast<std::uint32_t>(pairs_.size());
  stats_.manifolds = static_cast<std::uint32_t>(contacts_.size());
  stats_.contact_points = static_cast<std::uint32_t>(s.rows.size());
  stats_.islands = static_cast<std::uint32_t>(islands);
  stats_.colours = static_cast<std::uint32_t>(s.colouring.colour_count());
  for (std::size_t c = 0; c < s.colouring.colour_count(); ++c)
    if (s.colouring.serial[c])
      stats_.overflow_manifolds += s.colouring.colour_begin[c + 1] - s.colouring.colour_begin[c];
  stats_.collision_flags = collision_flags_;
}

}  // namespace tumble
