#include "broad_phase.h"

#include <omp.h>

#include <algorithm>
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

// The sorted runs[0 .. count) merged into one sorted `out`; `buffer` is scratch.
template <class T>
void merge_sorted(const std::vector<std::vector<T>>& runs, int count, std::vector<T>* out,
                  std::vector<T>* buffer) {
  out->clear();
  for (int t = 0; t < count; ++t) {
    buffer->swap(*out);
    out->resize(buffer->size() + runs[t].size());
    std::merge(buffer->begin(), buffer->end(), runs[t].begin(), runs[t].end(), out->begin());
  }
}

}  // namespace

void HashGrid::find_pairs(const BroadPhaseInput& input, std::vector<BodyPair>* pairs) {
  pairs->clear();
  const auto& bounds = input.bounds;
  const std::size_t n = bounds.size();
  const int threads = std::max(1, input.threads);
  thread_entries_.resize(threads);
  thread_scratch_.resize(threads);
  thread_pairs_.resize(threads);

  // Base cell size: the median extent of the bounded bodies.
  sizes_.clear();
  unbounded_.clear();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (is_dead(bounds[i])) continue;
    if (!bounds[i].is_bounded()) {
      unbounded_.push_back(i);
      continue;
    }
    sizes_.push_back(bounds[i].extent().maxCoeff());
  }
  double base = 1.0;
  if (!sizes_.empty()) {
    auto middle = sizes_.begin() + static_cast<std::ptrdiff_t>(sizes_.size() / 2);
    std::nth_element(sizes_.begin(), middle, sizes_.end());
    if (*middle > 0) base = kCellPerMedianExtent * *middle;
  }
  // A body larger than the top level's cells, or so far out that its cell numbers would not fit
  // an integer, would cover cells without bound (memory in proportion to its size): it joins the
  // unbounded bodies and meets every body directly.
  level_.assign(n, kDeadSlot);
  const double top_cell = base * std::ldexp(1.0, kMaxLevels - 1);
  const double farthest = base * kFarthestCell;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (is_dead(bounds[i])) continue;
    const Aabb& box = bounds[i];
    if (!box.is_bounded() || box.extent().maxCoeff() > top_cell ||
        box.min.cwiseAbs().maxCoeff() > farthest || box.max.cwiseAbs().maxCoeff() > farthest) {
      level_[i] = kMeetsEveryone;
      if (box.is_bounded()) unbounded_.push_back(i);
    }
  }
  std::sort(unbounded_.begin(), unbounded_.end());
  std::uint64_t occupied = 0;  // bit per level

  // (1) Cells of each body on its own level.
  run_region(threads, true, [&] {
    const int t = omp_get_thread_num();
    auto& out = thread_entries_[t];
    out.clear();
    std::uint64_t mine = 0;
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
      const Aabb& box = bounds[i];
      if (is_dead(box) || level_[i] == kMeetsEveryone) continue;
      const double extent = box.extent().maxCoeff();
      int level = 0;
      double cell = base;
      while (cell < extent && level < kMaxLevels - 1) {
        cell *= 2;
        ++level;
      }
      level_[i] = static_cast<std::int8_t>(level);
      mine |= 1ull << level;
      const Eigen::Array3d lo = (box.min / cell).array().floor();
      const Eigen::Array3d hi = (box.max / cell).array().floor();
      for (auto x = static_cast<std::int64_t>(lo.x()); x <= static_cast<std::int64_t>(hi.x()); ++x)
        for (auto y = static_cast<std::int64_t>(lo.y()); y <= static_cast<std::int64_t>(hi.y());
             ++y)
          for (auto z = static_cast<std::int64_t>(lo.z()); z <= static_cast<std::int64_t>(hi.z());
               ++z)
            out.emplace_back(cell_key(level, x, y, z), static_cast<std::uint32_t>(i));
    }
#pragma omp atomic update
    occupied |= mine;
    sort_by_high_half(&out, &thread_scratch_[t]);
  });
  // (2) One sorted array: the threads' sorted runs merged in thread order.
  merge_sorted(thread_entries_, threads, &entries_, &merge_buffer_);

  // Whether a and b may touch: two bodies, one of them movable, bounds overlapping.
  const auto may_touch = [&](std::uint32_t a, std::uint32_t b) {
    return a != b && (input.movable[a] || input.movable[b]) && bounds[a].overlaps(bounds[b]);
  };
  // Bodies off the grid meet the others directly, once.
  const auto meet = [&](std::uint32_t a, std::uint32_t b, std::vector<BodyPair>& out) {
    if (may_touch(a, b)) out.push_back(a < b ? BodyPair{a, b} : BodyPair{b, a});
  };
  // Two boxes that overlap share every cell their overlap covers, but a pair is emitted only from
  // the cell holding its overlap's lowest corner (on the level where it was found): once, not once
  // per shared cell, so that the threads' lists are not mostly duplicates to sort away. (Cells
  // whose keys collide can still give a pair twice; the reduction's unique pass removes those.)
  const auto emit = [&](std::uint32_t a, std::uint32_t b, int level, std::uint32_t key,
                        std::vector<BodyPair>& out) {
    if (!may_touch(a, b)) return;
    const double cell = base * std::ldexp(1.0, level);
    // Floored as the boxes' corners were when their cells were listed, so the corner's cell is one
    // both boxes listed.
    const Eigen::Array3d corner = (bounds[a].min.cwiseMax(bounds[b].min) / cell).array().floor();
    if (cell_key(level, static_cast<std::int64_t>(corner.x()),
                 static_cast<std::int64_t>(corner.y()),
                 static_cast<std::int64_t>(corner.z())) != key)
      return;
    out.push_back(a < b ? BodyPair{a, b} : BodyPair{b, a});
  };

  // (3) Candidate pairs.
  const std::int64_t entry_count = static_cast<std::int64_t>(entries_.size());
  run_region(threads, true, [&] {
    auto& out = thread_pairs_[omp_get_thread_num()];
    out.clear();
    // Same cell: each run of equal keys, visited from its first entry.
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < entry_count; ++i) {
      const std::uint32_t key = entries_[i].key();
      if (i > 0 && entries_[i - 1].key() == key) continue;
      for (std::int64_t j = i; j < entry_count && entries_[j].key() == key; ++j) {
        const std::uint32_t a = entries_[j].body();
        for (std::int64_t k = j + 1; k < entry_count && entries_[k].key() == key; ++k) {
          const std::uint32_t b = entries_[k].body();
          // Bodies of different levels meet in the coarser level's lookup below (here only
          // through a collision of keys).
          if (level_[a] == level_[b]) emit(a, b, level_[a], key, out);
        }
      }
    }
    // Coarser levels: each body looks up the cells it covers there.
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
      const int own = level_[i];
      if (own < 0) continue;  // dead, or meets everyone below
      const Aabb& box = bounds[i];
      // Only the occupied coarser levels (most scenes have one or two levels in all).
      for (std::uint64_t above = occupied & ~((2ull << own) - 1); above != 0; above &= above - 1) {
        const int level = std::countr_zero(above);
        const double cell = base * std::ldexp(1.0, level);
        const Eigen::Array3d lo = (box.min / cell).array().floor();
        const Eigen::Array3d hi = (box.max / cell).array().floor();
        for (auto x = static_cast<std::int64_t>(lo.x()); x <= static_cast<std::int64_t>(hi.x());
             ++x)
          for (auto y = static_cast<std::int64_t>(lo.y()); y <= static_cast<std::int64_t>(hi.y());
               ++y)
            for (auto z = static_cast<std::int64_t>(lo.z()); z <= static_cast<std::int64_t>(hi.z());
                 ++z) {
              const std::uint32_t key = cell_key(level, x, y, z);
              auto it = std::lower_bound(entries_.begin(), entries_.end(), Entry(key, 0));
              for (; it != entries_.end() && it->key() == key; ++it)
                if (level_[it->body()] == level)
                  emit(static_cast<std::uint32_t>(i), it->body(), level, key, out);
            }
      }
    }
    // Unbounded and oversized bodies meet everyone (each such pair once).
#pragma omp for schedule(static) nowait
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
      if (level_[i] == kDeadSlot) continue;
      for (std::uint32_t u : unbounded_)
        if (level_[i] == kMeetsEveryone ? u < i : true) meet(static_cast<std::uint32_t>(i), u, out);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  });
  // (4) Reduction: merge the threads' sorted lists, then drop pairs found by several threads.
  merge_sorted(thread_pairs_, threads, pairs, &pair_buffer_);
  pairs->erase(std::unique(pairs->begin(), pairs->end()), pairs->end());
}

void sweep_and_prune(const BroadPhaseInput& input, std::vector<BodyPair>* pairs) {
  pairs->clear();
  const auto& bounds = input.bounds;
  // Kept per thread and reused, so that stepping small worlds allocates nothing.
  thread_local std::vector<std::uint32_t> order, unbounded;
  order.clear();
  unbounded.clear();
  for (std::uint32_t i = 0; i < bounds.size(); ++i) {
    if (is_dead(bounds[i])) continue;
    (bounds[i].is_bounded() ? order : unbounded).push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return bounds[a].min.x() < bounds[b].min.x() ||
           (bounds[a].min.x() == bounds[b].min.x() && a < b);
  });
  auto emit = [&](std::uint32_t a, std::uint32_t b) {
    if (!(input.movable[a] || input.movable[b]) || !bounds[a].overlaps(bounds[b])) return;
    pairs->push_back(a < b ? BodyPair{a, b} : BodyPair{b, a});
  };
  for (std::size_t i = 0; i < order.size(); ++i)
    for (std::size_t j = i + 1;
         j < order.size() && bounds[order[j]].min.x() <= bounds[order[i]].max.x(); ++j)
      emit(order[i], order[j]);
  for (std::size_t k = 0; k < unbounded.size(); ++k) {
    for (std::uint32_t i : order)
      emit(i, unbounded[k]);
    for (std::size_t m = k + 1; m < unbounded.size(); ++m)
      emit(unbounded[k], unbounded[m]);
  }
  std::sort(pairs->begin(), pairs->end());
}

}  // namespace tumble
