// Broad phase: which bodies' bounding boxes overlap.
//
// The hash grid is a hierarchy of uniform grids (Ericson, "Real-Time Collision Detection" 7.2.1;
// Mirtich's hierarchical hash tables): the base cell is the median body size and each level
// doubles it; a body lives on the first level whose cells are at least its size, so it touches at
// most 8 cells there and sizes from 1 mm to 100 m cost the same per body. Unbounded bodies (the
// ground half-space), and bodies too large for the coarsest level or too far out for its cell
// numbers, stay out of the grid and are paired with every body directly: no body costs memory in
// proportion to its size.
//
// Steps: (1) level and cells of every body, in parallel, into per-thread buffers of
// (cell key, body) entries, each sorted by its thread (a radix sort on the key); (2) one sorted
// array of entries, merged; (3) pairs within each cell, and each body against the cells of coarser
// levels it covers (binary search), in parallel into per-thread pair buffers, keeping only pairs
// whose boxes really overlap and that have a dynamic body, each buffer sorted and unique; (4) the
// reduction: merge, drop duplicates (a pair shared by several cells and threads). The result is the
// same for any thread count because it is sorted and unique.
#pragma once

#include <span>
#include <vector>

#include "physics/world.h"

namespace tumble {

struct BroadPhaseInput {
  std::span<const Aabb> bounds;           // by body slot; an empty box is a dead slot
  std::span<const std::uint8_t> movable;  // 1 for dynamic bodies
  int threads = 1;
};

class HashGrid {
 public:
  void find_pairs(const BroadPhaseInput& input, std::vector<BodyPair>* pairs);

 private:
  // A (cell key, body) pair packed in one word, key above, so that ordering the words orders by
  // key, then body; 32-bit keys keep it one word (a collision only adds candidates).
  struct Entry {
    std::uint64_t bits;
    Entry() = default;
    Entry(std::uint32_t key, std::uint32_t body)
        : bits(static_cast<std::uint64_t>(key) << 32 | body) {}
    std::uint32_t key() const { return static_cast<std::uint32_t>(bits >> 32); }
    std::uint32_t body() const { return static_cast<std::uint32_t>(bits); }
    bool operator<(const Entry& o) const { return bits < o.bits; }
  };
  std::vector<std::vector<Entry>> thread_entries_, thread_scratch_;
  std::vector<std::vector<BodyPair>> thread_pairs_;
  std::vector<Entry> entries_, merge_buffer_;
  std::vector<BodyPair> pair_buffer_;
  std::vector<std::int8_t> level_;
  std::vector<double> sizes_;
  std::vector<std::uint32_t> unbounded_;
};

void sweep_and_prune(const BroadPhaseInput& input, std::vector<BodyPair>* pairs);

}  // namespace tumble
