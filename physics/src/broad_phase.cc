#include "broad_phase.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>

#include "parallel.h"

namespace tumble {
namespace {

constexpr int kMaxLevels = 48;
// Cell numbers stay below 2^52 so that floor(coordinate / cell) converts to an integer exactly.
constexpr double kFarthestCell = 0x1p52;
// level_ of a body that is not on a grid level.
constexpr std::int8_t kDeadSlot = -1;
constexpr std::int8_t kMeetsEveryone = -2;
// Level 0 cells this many times the median body extent: bodies a little above the median stay on
// level 0 (with cells exactly the median, half of a uniform scene went a level up and looked up
// every cell it covers there).
constexpr double kCellPerMedianExtent = 2.0;
// Entries of a crowded cell tested against one entry at a time (find_pairs).
constexpr int kGathered = 32;

std::uint32_t cell_key(int level, std::int64_t x, std::int64_t y, std::int64_t z) {
  // SplitMix64 finaliser over the packed cell: equal cells give equal keys; a collision between
  // different cells only adds candidates, which the exact box test removes.
  std::uint64_t h = static_cast<std::uint64_t>(level) * 0x9E3779B97F4A7C15ull;
  for (std::int64_t c : {x, y, z}) {
    h ^= static_cast<std::uint64_t>(c) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
    h ^= h >> 31;
  }
  return static_cast<std::uint32_t>(h >> 32);
}

// Sorts words whose low halves already ascend by their high halves, keeping that order among
// equal high halves: LSD radix sort, a byte per pass (stable, so the result is fully sorted).
// Several times faster than a comparison sort on the few thousand entries of a step.
template <class Word>
void sort_by_high_half(std::vector<Word>* words, std::vector<Word>* scratch) {
  const std::size_t n = words->size();
  if (n < 64) {
    std::sort(words->begin(), words->end());
    return;
  }
  scratch->resize(n);
  Word* from = words->data();
  Word* to = scratch->data();
  for (int shift = 32; shift < 64; shift += 8) {
    std::size_t start[257] = {};
    for (std::size_t i = 0; i < n; ++i)
      ++start[(from[i].bits >> shift & 0xFF) + 1];
    for (int b = 0; b < 256; ++b)
      start[b + 1] += start[b];
    for (std::size_t i = 0; i < n; ++i)
      to[start[from[i].bits >> shift & 0xFF]++] = from[i];
    std::swap(from, to);
  }
  // Four passes: the sorted words are back in `words`.
}

bool is_dead(const Aabb& box) {
  return !(box.min.x() <= box.max.x());
}

// The sorted runs[0 .. count) merged into one sorted `out` (equal items in run order); `buffer`
// is scratch. The runs are laid side by side, then merged in pairs, round after round, each
// round's merges spread over the team: the serial part is the last merge, not every run merged in
// turn into a growing list, which copies the items count / 2 times over on one thread (on 16
// cores a fifth of the broad phase's serial time: PERFORMANCE.md, "Measured on 16 cores").
constexpr int kMostRuns = 1024;
template <class T>
void merge_sorted(const std::vector<std::vector<T>>& runs, int count, int threads,
                  std::vector<T>* out, std::vector<T>* buffer) {
  if (count <= 1) {
    out->assign(runs[0].begin(), runs[0].end());
    return;
  }
  if (count > kMostRuns) {  // a team larger than any machine we know: one run after another
    out->clear();
    for (int t = 0; t < count; ++t) {
      buffer->swap(*out);
      out->resize(buffer->size() + runs[t].size());
      std::merge(buffer->begin(), buffer->end(), runs[t].begin(), runs[t].end(), out->begin());
    }
    return;
  }
  std::array<std::size_t, kMostRuns + 1> begin;
  begin[0] = 0;
  for (int t = 0; t < count; ++t)
    begin[t + 1] = begin[t] + runs[t].size();
  const std::size_t total = begin[count];
  int rounds = 0;
  for (int width = 1; width < count; width *= 2)
    ++rounds;
  // The rounds alternate between the two arrays and end in `out`.
  std::vector<T>* first = rounds % 2 == 0 ? out : buffer;
  std::vector<T>* second = rounds % 2 == 0 ? buffer : out;
  first->resize(total);
  second->resize(total);
  run_region(threads, total > 4096, [&] {
    const auto at = [](std::vector<T>* items, std::size_t k) {
      return items->begin() + static_cast<std::ptrdiff_t>(k);
    };
#pragma omp for schedule(static)
    for (int t = 0; t < count; ++t)
      std::copy(runs[t].begin(), runs[t].end(), at(first, begin[t]));
    std::vector<T>* from = first;
    std::vector<T>* to = second;
    for (int width = 1; width < count; width *= 2) {
      const int merges = (count + 2 * width - 1) / (2 * width);
#pragma omp for schedule(static)
      for (int m = 0; m < merges; ++m) {
        const int low = 2 * width * m, middle = std::min(low + width, count),
                  high = std::min(low + 2 * width, count);
        std::merge(at(from, begin[low]), at(from, begin[middle]), at(from, begin[middle]),
                   at(from, begin[high]), at(to, begin[low]));
      }
      std::swap(from, to);
    }
  });
}

// 2^level, the ratio of a level's cell to level 0's, exactly (std::ldexp's value, without its call:
// the broad phase asked for it for every pair it emitted).
double level_scale(int level) {
  static_assert(kMaxLevels <= 63);
  return static_cast<double>(std::uint64_t{1} << level);
}

// A body is on the grid unless it is unbounded (the ground half-space), larger than the top
// level's cells, or so far out that its cell numbers would not fit an integer: such a body would
// cover cells without bound (memory in proportion to its size), so it meets every body directly.
bool off_grid(const Aabb& box, double base) {
  const double top_cell = base * level_scale(kMaxLevels - 1);
  const double farthest = base * kFarthestCell;
  return !box.is_bounded() || box.extent().maxCoeff() > top_cell ||
         box.min.cwiseAbs().maxCoeff() > farthest || box.max.cwiseAbs().maxCoeff() > farthest;
}

// The cells [lo, hi] a box covers on a level of cell size `cell`, floored as every listing and
// lookup floors them (so that two boxes agree on the cells they share).
struct CellRange {
  Eigen::Array3d lo, hi;
  CellRange(const Aabb& box, double cell)
      : lo((box.min / cell).array().floor()), hi((box.max / cell).array().floor()) {}
  double count() const { return (hi - lo + 1).prod(); }
  // Whether a level's `bodies` resting bodies are cheaper met one by one than these cells looked
  // up (also where the count is too large to be a number of cells).
  bool rather_each_of(std::size_t bodies) const { return !(count() < static_cast<double>(bodies)); }
  template <class Fn>
  void each(Fn&& fn) const {
    for (auto x = static_cast<std::int64_t>(lo.x()); x <= static_cast<std::int64_t>(hi.x()); ++x)
      for (auto y = static_cast<std::int64_t>(lo.y()); y <= static_cast<std::int64_t>(hi.y()); ++y)
        for (auto z = static_cast<std::int64_t>(lo.z()); z <= static_cast<std::int64_t>(hi.z());
             ++z)
          fn(x, y, z);
  }
};

}  // namespace

void HashGrid::list_cells(std::span<const Aabb> bounds, std::span<const std::uint32_t> bodies,
                          int threads, std::vector<Entry>* out, std::uint64_t* occupied) {
  std::uint64_t levels = 0;
  const std::int64_t count = static_cast<std::int64_t>(bodies.size());
  // Emptied here too, for a team smaller than asked for (find_pairs).
  for (std::vector<Entry>& run : thread_entries_)
    run.clear();
  run_region(threads, worth_a_team(count, 60), [&] {
    const int t = omp_get_thread_num();
    auto& mine = thread_entries_[t];
    mine.clear();
    std::uint64_t my_levels = 0;
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < count; ++k) {
      const std::uint32_t i = bodies[k];
      const Aabb& box = bounds[i];
      const double extent = box.extent().maxCoeff();
      int level = 0;
      double cell = base_;
      while (cell < extent && level < kMaxLevels - 1) {
        cell *= 2;
        ++level;
      }
      level_[i] = static_cast<std::int8_t>(level);
      my_levels |= 1ull << level;
      CellRange(box, cell).each([&](std::int64_t x, std::int64_t y, std::int64_t z) {
        mine.emplace_back(cell_key(level, x, y, z), i);
      });
    }
#pragma omp atomic update
    levels |= my_levels;
    sort_by_high_half(&mine, &thread_scratch_[t]);
  });
  // One sorted array: the threads' sorted runs merged in thread order.
  merge_sorted(thread_entries_, count > 256 ? threads : 1, threads, out, &merge_buffer_);
  *occupied = levels;
}

void HashGrid::list_resting(const BroadPhaseInput& input) {
  const auto& bounds = input.bounds;
  const std::size_t n = bounds.size();
  // Base cell size: the median extent of the bounded bodies, moving or not. Kept with the resting
  // cells: it changes the speed, never the pairs.
  sizes_.clear();
  for (std::uint32_t i = 0; i < n; ++i)
    if (!is_dead(bounds[i]) && bounds[i].is_bounded())
      sizes_.push_back(bounds[i].extent().maxCoeff());
  base_ = 1.0;
  if (!sizes_.empty()) {
    auto middle = sizes_.begin() + static_cast<std::ptrdiff_t>(sizes_.size() / 2);
    std::nth_element(sizes_.begin(), middle, sizes_.end());
    if (*middle > 0) base_ = kCellPerMedianExtent * *middle;
  }
  level_.assign(n, kDeadSlot);
  resting_.clear();
  resting_unbounded_.clear();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (is_dead(bounds[i]) || input.movable[i]) continue;
    if (off_grid(bounds[i], base_)) {
      level_[i] = kMeetsEveryone;
      resting_unbounded_.push_back(i);
    } else {
      resting_.push_back(i);
    }
  }
  list_cells(bounds, resting_, std::max(1, input.threads), &resting_entries_, &resting_occupied_);
  resting_on_level_.resize(kMaxLevels);
  for (auto& level : resting_on_level_)
    level.clear();
  for (std::uint32_t i : resting_)
    resting_on_level_[level_[i]].push_back(i);
  resting_version_ = input.resting_version;
}

void HashGrid::update_resting(const BroadPhaseInput& input) {
  const auto& bounds = input.bounds;
  const std::size_t n = bounds.size();
  level_.resize(n, kDeadSlot);
  changed_.resize(n, 0);
  for (std::uint32_t slot : input.resting_changes)
    changed_[slot] = 1;
  // What the changed slots had listed goes; what they have now comes back below.
  const auto changed = [&](std::uint32_t slot) { return changed_[slot] != 0; };
  std::erase_if(resting_entries_, [&](const Entry& entry) { return changed(entry.body()); });
  std::erase_if(resting_, changed);
  std::erase_if(resting_unbounded_, changed);
  for (std::uint64_t levels = resting_occupied_; levels != 0; levels &= levels - 1)
    std::erase_if(resting_on_level_[std::countr_zero(levels)], changed);
  joined_.clear();
  bool unbounded_joined = false;
  for (std::uint32_t slot : input.resting_changes) {
    if (!changed_[slot]) continue;  // listed twice
    changed_[slot] = 0;
    level_[slot] = kDeadSlot;
    if (is_dead(bounds[slot]) || input.movable[slot]) continue;
    if (off_grid(bounds[slot], base_)) {
      level_[slot] = kMeetsEveryone;
      resting_unbounded_.push_back(slot);
      unbounded_joined = true;
    } else {
      joined_.push_back(slot);
    }
  }
  if (unbounded_joined) std::sort(resting_unbounded_.begin(), resting_unbounded_.end());
  // The lists stay in slot order, as list_resting makes them.
  std::sort(joined_.begin(), joined_.end());
  std::uint64_t joined_levels = 0;
  list_cells(bounds, joined_, 1, &joined_entries_, &joined_levels);
  merge_buffer_.resize(resting_entries_.size() + joined_entries_.size());
  std::merge(resting_entries_.begin(), resting_entries_.end(), joined_entries_.begin(),
             joined_entries_.end(), merge_buffer_.begin());
  resting_entries_.swap(merge_buffer_);
  joined_merged_.resize(resting_.size() + joined_.size());
  std::merge(resting_.begin(), resting_.end(), joined_.begin(), joined_.end(),
             joined_merged_.begin());
  resting_.swap(joined_merged_);
  std::size_t kept_on_level[kMaxLevels];
  for (int level = 0; level < kMaxLevels; ++level)
    kept_on_level[level] = resting_on_level_[level].size();
  for (std::uint32_t slot : joined_)
    resting_on_level_[level_[slot]].push_back(slot);
  for (std::uint64_t levels = joined_levels; levels != 0; levels &= levels - 1) {
    const int level = std::countr_zero(levels);
    auto& on_level = resting_on_level_[level];
    const auto kept_end = on_level.begin() + static_cast<std::ptrdiff_t>(kept_on_level[level]);
    joined_merged_.resize(on_level.size());
    std::merge(on_level.begin(), kept_end, kept_end, on_level.end(), joined_merged_.begin());
    std::copy(joined_merged_.begin(), joined_merged_.end(), on_level.begin());
  }
  resting_occupied_ = 0;
  for (int level = 0; level < kMaxLevels; ++level)
    if (!resting_on_level_[level].empty()) resting_occupied_ |= 1ull << level;
  resting_version_ = input.resting_version;
}

namespace {

// Puts `pairs` (of bodies below `slots`) in (a, b) order by two stable counting passes, by b and
// then by a: linear, where a comparison sort's branches are a coin toss on pairs found in space
// order (two std::sorts were two thirds of a small world's broad phase).
void count_sort_pairs(std::vector<BodyPair>* pairs, std::size_t slots, std::vector<BodyPair>* spare,
                      std::vector<std::uint32_t>* counts) {
  // One stable pass: `from` into `to` in the order of the body key(p) picks.
  const auto pass = [&](const std::vector<BodyPair>& from, std::vector<BodyPair>& to, auto key) {
    counts->assign(slots + 1, 0);
    for (const BodyPair& p : from)
      ++(*counts)[key(p) + 1];
    for (std::size_t k = 1; k <= slots; ++k)
      (*counts)[k] += (*counts)[k - 1];
    for (const BodyPair& p : from)
      to[(*counts)[key(p)]++] = p;
  };
  spare->resize(pairs->size());
  pass(*pairs, *spare, [](const BodyPair& p) { return p.b; });
  pass(*spare, *pairs, [](const BodyPair& p) { return p.a; });
}

}  // namespace

bool keep_first_pairs(std::vector<BodyPair>* pairs, std::size_t max_pairs) {
  std::sort(pairs->begin(), pairs->end());
  pairs->erase(std::unique(pairs->begin(), pairs->end()), pairs->end());
  if (pairs->size() <= max_pairs) return false;
  pairs->resize(max_pairs);
  return true;
}

bool HashGrid::find_pairs(const BroadPhaseInput& input, std::vector<BodyPair>* pairs) {
  pairs->clear();
  // A thread's list is cut back to its first max_pairs whenever it holds twice that: every pair
  // among the first max_pairs of all threads together is among the first max_pairs of the thread
  // that found it, so the result does not depend on how the work was split.
  const std::size_t max_pairs = input.max_pairs;
  const std::size_t compact_at =
      max_pairs > static_cast<std::size_t>(-1) / 2 ? max_pairs : 2 * max_pairs;
  std::atomic<bool> cut{false};
  const auto& bounds = input.bounds;
  const std::size_t n = bounds.size();
  const int threads = std::max(1, input.threads);
  thread_entries_.resize(threads);
  thread_scratch_.resize(threads);
  thread_pairs_.resize(threads);
  thread_spare_.resize(threads);
  thread_counts_.resize(threads);
  // Every run emptied here, not only by the threads that fill them: a team smaller than asked
  // for (OMP_THREAD_LIMIT) would leave a run of an earlier step to be merged.
  for (std::vector<BodyPair>& run : thread_pairs_)
    run.clear();

  std::span<const std::uint32_t> moving = input.moving;
  if (!input.moving_listed) {
    moving_found_.clear();
    for (std::uint32_t i = 0; i < n; ++i)
      if (!is_dead(bounds[i]) && input.movable[i]) moving_found_.push_back(i);
    moving = moving_found_;
  }
  if (input.resting_version == 0 || input.resting_version != resting_version_) {
    // A few changes are relisted alone; many, and the base cell is chosen afresh with the rest.
    const bool kept_since = input.changes_since != 0 && resting_version_ != 0 &&
                            resting_version_ >= input.changes_since;
    if (kept_since &&
        4 * input.resting_changes.size() <= resting_.size() + resting_unbounded_.size())
      update_resting(input);
    else
      list_resting(input);
  } else if (level_.size() != n) {
    // Slots made since hold moving bodies, or none: the kept cells stand.
    level_.resize(n, kDeadSlot);
  }

  // Resting bodies never pair with one another: with nothing moving there is nothing to find (and
  // no thread team to start).
  if (moving.empty()) return false;

  // (1) The moving bodies' cells, each on its own level.
  moving_unbounded_.clear();
  moving_on_grid_.clear();
  for (std::uint32_t i : moving) {
    if (off_grid(bounds[i], base_)) {
      level_[i] = kMeetsEveryone;
      moving_unbounded_.push_back(i);
    } else {
      moving_on_grid_.push_back(i);
    }
  }
  std::uint64_t moving_occupied = 0;
  list_cells(bounds, moving_on_grid_, threads, &moving_entries_, &moving_occupied);
  const std::span<const std::uint32_t> on_grid = moving_on_grid_;

  // Whether a and b may touch: two bodies, one of them movable, bounds overlapping.
  const auto may_touch = [&](std::uint32_t a, std::uint32_t b) {
    return a != b && (input.movable[a] || input.movable[b]) && bounds[a].overlaps(bounds[b]);
  };
  const auto add = [&](std::uint32_t a, std::uint32_t b, std::vector<BodyPair>& out) {
    out.push_back(a < b ? BodyPair{a, b} : BodyPair{b, a});
    if (out.size() >= compact_at && keep_first_pairs(&out, max_pairs))
      cut.store(true, std::memory_order_relaxed);
  };
  const auto meet = [&](std::uint32_t a, std::uint32_t b, std::vector<BodyPair>& out) {
    if (may_touch(a, b)) add(a, b, out);
  };
  // Two boxes that overlap share every cell their overlap covers, but a pair is emitted only from
  // the cell holding its overlap's lowest corner (on the level where it was found): once, not once
  // per shared cell, so that the threads' lists are not mostly duplicates to sort away. (Cells
  // whose keys collide can still give a pair twice; the reduction's unique pass removes those.)
  const auto emit = [&](std::uint32_t a, std::uint32_t b, int level, std::uint32_t key,
                        std::vector<BodyPair>& out) {
    if (!may_touch(a, b)) return;
    const double cell = base_ * level_scale(level);
    const Eigen::Array3d corner = (bounds[a].min.cwiseMax(bounds[b].min) / cell).array().floor();
    if (cell_key(level, static_cast<std::int64_t>(corner.x()),
                 static_cast<std::int64_t>(corner.y()),
                 static_cast<std::int64_t>(corner.z())) != key)
      return;
    add(a, b, out);
  };
  // Body i against the bodies of `entries` listed on `level`, in the cells i covers there.
  const auto look_up = [&](std::uint32_t i, int level, const std::vector<Entry>& entries,
                           std::vector<BodyPair>& out) {
    CellRange(bounds[i], base_ * level_scale(level))
        .each([&](std::int64_t x, std::int64_t y, std::int64_t z) {
          const std::uint32_t key = cell_key(level, x, y, z);
          auto it = std::lower_bound(entries.begin(), entries.end(), Entry(key, 0));
          for (; it != entries.end() && it->key() == key; ++it)
            if (level_[it->body()] == level) emit(i, it->body(), level, key, out);
        });
  };

  // (2) Candidate pairs.
  const std::int64_t entry_count = static_cast<std::int64_t>(moving_entries_.size());
  const std::int64_t grid_count = static_cast<std::int64_t>(on_grid.size());
  const std::int64_t moving_count = static_cast<std::int64_t>(moving.size());
  entry_bounds_.resize(moving_entries_.size());
  run_region(threads, true, [&] {
    auto& out = thread_pairs_[omp_get_thread_num()];
    out.clear();
    // Each entry's box beside it: a crowded cell tests every two of its entries, most of them
    // apart, and reading the boxes by body for each test went to memory at random (in a pile of
    // 1000 boxes on hills, 28,000 tests a step for 3,800 overlaps).
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < entry_count; ++i)
      entry_bounds_[i] = bounds[moving_entries_[i].body()];
      // Moving bodies in the same cell: each run of equal keys, visited from its first entry.
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < entry_count; ++i) {
      const std::uint32_t key = moving_entries_[i].key();
      if (i > 0 && moving_entries_[i - 1].key() == key) continue;
      std::int64_t end = i + 1;
      while (end < entry_count && moving_entries_[end].key() == key)
        ++end;
      for (std::int64_t j = i; j < end; ++j) {
        const Aabb& box = entry_bounds_[j];
        const std::uint32_t a = moving_entries_[j].body();
        // The entries whose boxes overlap j's, gathered a block at a time without a branch on
        // each test: in a crowded cell one test in seven overlaps, a branch the predictor loses.
        for (std::int64_t from = j + 1; from < end; from += kGathered) {
          const std::int64_t to = std::min(end, from + kGathered);
          std::int64_t hits[kGathered];
          int count = 0;
          for (std::int64_t k = from; k < to; ++k) {
            hits[count] = k;
            count += box.overlaps(entry_bounds_[k]) ? 1 : 0;
          }
          for (int h = 0; h < count; ++h) {
            const std::uint32_t b = moving_entries_[hits[h]].body();
            // Bodies of different levels meet in the coarser level's lookup below (here only
            // through a collision of keys).
            if (level_[a] == level_[b]) emit(a, b, level_[a], key, out);
          }
        }
      }
    }
    // Each moving body on the grid: the moving bodies of coarser levels, and the resting bodies of
    // every level in the cells it covers there, or one by one where they are no more than those
    // cells (a large box over fine gravel; the one terrain under a whole pile, alone on its
    // level, where looking its cell up cost a moving box 470 instructions a step).
#pragma omp for schedule(static)
    for (std::int64_t k = 0; k < grid_count; ++k) {
      const std::uint32_t i = on_grid[k];
      const int own = level_[i];
      for (std::uint64_t above = moving_occupied & ~((2ull << own) - 1); above != 0;
           above &= above - 1)
        look_up(i, std::countr_zero(above), moving_entries_, out);
      for (std::uint64_t levels = resting_occupied_; levels != 0; levels &= levels - 1) {
        const int level = std::countr_zero(levels);
        const auto& on_level = resting_on_level_[level];
        if (CellRange(bounds[i], base_ * level_scale(level)).rather_each_of(on_level.size())) {
          for (std::uint32_t r : on_level)
            meet(i, r, out);
        } else {
          look_up(i, level, resting_entries_, out);
        }
      }
    }
    // Bodies off the grid meet the others directly: resting ones every moving body, moving ones
    // every body.
#pragma omp for schedule(static) nowait
    for (std::int64_t k = 0; k < moving_count; ++k)
      for (std::uint32_t u : resting_unbounded_)
        meet(moving[k], u, out);
    if (!moving_unbounded_.empty()) {
#pragma omp for schedule(static) nowait
      for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
        if (is_dead(bounds[i])) continue;
        for (std::uint32_t u : moving_unbounded_)
          meet(static_cast<std::uint32_t>(i), u, out);
      }
    }
    // Counting over the slots pays where the pairs are not far fewer than the slots.
    if (!cut.load(std::memory_order_relaxed) && 4 * out.size() >= n) {
      const int t = omp_get_thread_num();
      count_sort_pairs(&out, n, &thread_spare_[t], &thread_counts_[t]);
      out.erase(std::unique(out.begin(), out.end()), out.end());
      if (out.size() > max_pairs) {
        out.resize(max_pairs);
        cut.store(true, std::memory_order_relaxed);
      }
    } else if (keep_first_pairs(&out, max_pairs)) {
      cut.store(true, std::memory_order_relaxed);
    }
  });
  // (3) Reduction: merge the threads' sorted lists, then drop pairs found by several threads.
  merge_sorted(thread_pairs_, threads, threads, pairs, &pair_buffer_);
  pairs->erase(std::unique(pairs->begin(), pairs->end()), pairs->end());
  if (pairs->size() > max_pairs) {
    pairs->resize(max_pairs);
    cut = true;
  }
  return cut;
}

void HashGrid::resting_near(const Aabb& box, std::vector<std::uint32_t>* out) const {
  out->insert(out->end(), resting_unbounded_.begin(), resting_unbounded_.end());
  for (std::uint64_t levels = resting_occupied_; levels != 0; levels &= levels - 1) {
    const int level = std::countr_zero(levels);
    const auto& on_level = resting_on_level_[level];
    const CellRange cells(box, base_ * level_scale(level));
    if (cells.rather_each_of(on_level.size())) {
      out->insert(out->end(), on_level.begin(), on_level.end());
      continue;
    }
    cells.each([&](std::int64_t x, std::int64_t y, std::int64_t z) {
      const std::uint32_t key = cell_key(level, x, y, z);
      auto it = std::lower_bound(resting_entries_.begin(), resting_entries_.end(), Entry(key, 0));
      for (; it != resting_entries_.end() && it->key() == key; ++it)
        if (level_[it->body()] == level) out->push_back(it->body());
    });
  }
}

void SweepAndPrune::sort_order() {
  const std::size_t n = order_.size();
  std::size_t moves = 0;
  const std::size_t budget = 8 * n + 64;
  for (std::size_t i = 1; i < n; ++i) {
    const Entry entry = order_[i];
    std::size_t k = i;
    while (k > 0 && entry < order_[k - 1]) {
      order_[k] = order_[k - 1];
      --k;
    }
    order_[k] = entry;
    moves += i - k;
    if (moves > budget) {
      std::sort(order_.begin(), order_.end());
      return;
    }
  }
}

bool SweepAndPrune::find_pairs(const BroadPhaseInput& input, std::vector<BodyPair>* pairs) {
  pairs->clear();
  const std::size_t max_pairs = input.max_pairs;
  const std::size_t compact_at =
      max_pairs > static_cast<std::size_t>(-1) / 2 ? max_pairs : 2 * max_pairs;
  bool cut = false;
  const auto& bounds = input.bounds;
  const std::size_t slots = bounds.size();
  // The last call's order, less the bodies gone, dead or unbounded since, with fresh keys; then
  // the bodies it did not hold.
  listed_.assign(slots, 0);
  std::size_t kept = 0;
  for (const Entry& entry : order_) {
    const std::uint32_t i = entry.body;
    if (i >= slots || is_dead(bounds[i]) || !bounds[i].is_bounded()) continue;
    listed_[i] = 1;
    order_[kept++] = {bounds[i].min.x(), i};
  }
  order_.resize(kept);
  unbounded_.clear();
  for (std::uint32_t i = 0; i < slots; ++i) {
    if (listed_[i] || is_dead(bounds[i])) continue;
    if (bounds[i].is_bounded())
      order_.push_back({bounds[i].min.x(), i});
    else
      unbounded_.push_back(i);
  }
  sort_order();
  auto emit = [&](std::uint32_t a, std::uint32_t b) {
    if (!(input.movable[a] || input.movable[b]) || !bounds[a].overlaps(bounds[b])) return;
    pairs->push_back(a < b ? BodyPair{a, b} : BodyPair{b, a});
    if (pairs->size() >= compact_at && keep_first_pairs(pairs, max_pairs)) cut = true;
  };
  for (std::size_t i = 0; i < order_.size(); ++i) {
    const double max_x = bounds[order_[i].body].max.x();
    for (std::size_t j = i + 1; j < order_.size() && order_[j].min_x <= max_x; ++j)
      emit(order_[i].body, order_[j].body);
  }
  for (std::size_t k = 0; k < unbounded_.size(); ++k) {
    for (const Entry& entry : order_)
      emit(entry.body, unbounded_[k]);
    for (std::size_t m = k + 1; m < unbounded_.size(); ++m)
      emit(unbounded_[k], unbounded_[m]);
  }
  // Each pair was emitted once (a body is in order_ or unbounded_, and the sweep meets each
  // overlapping pair from its first body along x), unless a cut compacted the list meanwhile.
  if (cut) {
    keep_first_pairs(pairs, max_pairs);
    return true;
  }
  count_sort_pairs(pairs, slots, &spare_, &counts_);
  if (pairs->size() <= max_pairs) return false;
  pairs->resize(max_pairs);
  return true;
}

bool sweep_and_prune(const BroadPhaseInput& input, std::vector<BodyPair>* pairs) {
  thread_local SweepAndPrune sweep;
  return sweep.find_pairs(input, pairs);
}

}  // namespace tumble
