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
// Bodies that do not move (statics and sleepers: "resting") never pair with one another, and keep
// their cells from call to call while the caller says they have not changed (resting_version), so
// that a world of sleepers with a few moving bodies pays for the moving ones: each call lists the
// moving bodies' cells, pairs them among themselves, and looks each one up among the resting
// bodies' kept cells (Box2D v3 and Jolt keep static and sleeping bodies in trees of their own for
// the same reason).
//
// Steps: (1) level and cells of every moving body (every resting body too when they changed), in
// parallel, into per-thread buffers of (cell key, body) entries, each sorted by its thread (a radix
// sort on the key), merged into one sorted array per set; (2) pairs within each cell, and each
// moving body against the cells of coarser levels it covers (binary search) of both sets and of
// the resting set's finer levels (or that level's bodies one by one, when they are fewer than the
// cells), in parallel into per-thread pair buffers, keeping only pairs whose boxes really overlap,
// each buffer sorted and unique; (3) the reduction: merge, drop duplicates. The result is the same
// for any thread count, and whether resting cells were kept or listed anew, because it is the
// sorted set of overlapping pairs.
#pragma once

#include <span>
#include <vector>

#include "physics/world.h"

namespace tumble {

struct BroadPhaseInput {
  std::span<const Aabb> bounds;           // by body slot; an empty box is a dead slot
  std::span<const std::uint8_t> movable;  // 1 for moving bodies (dynamic and awake)
  int threads = 1;
  // The movable slots, ascending, when the caller keeps them (else found from `movable`).
  std::span<const std::uint32_t> moving = {};
  bool moving_listed = false;
  // A number the caller changes whenever a body that is not movable changed its bounds, came,
  // went, or became movable or not: while it stays, the grid keeps those bodies' cells from the
  // last call (slots added since must be movable or dead). 0: list them every call.
  std::uint64_t resting_version = 0;
  // The slots whose resting state or bounds changed since version `changes_since` (one the caller
  // gave an earlier call; versions only grow), when the caller kept them all: a grid that kept the
  // cells of that version or a later one relists these slots alone. A slot may appear more than
  // once. changes_since 0: no list.
  std::span<const std::uint32_t> resting_changes = {};
  std::uint64_t changes_since = 0;
  // The most pairs to return: past it, the first ones in (a, b) order are kept, the same for any
  // thread count, and the call says the bound was hit. Bodies heaped on one another (a thousand
  // boxes spawned at one point) have pairs in the square of their number; this keeps the memory
  // of the broad phase and of every later stage in proportion to the bound.
  std::size_t max_pairs = static_cast<std::size_t>(-1);
};

// Sorts `pairs`, drops repeats and keeps the first `max_pairs`; true when some were dropped.
bool keep_first_pairs(std::vector<BodyPair>* pairs, std::size_t max_pairs);

class HashGrid {
 public:
  // The pairs, sorted; true when input.max_pairs cut them short.
  bool find_pairs(const BroadPhaseInput& input, std::vector<BodyPair>* pairs);
  // The resting bodies of the last find_pairs whose cells meet `box` (and those off the grid),
  // appended to `out`, possibly more than once: candidates, which the caller checks, since the
  // bodies may have changed since.
  void resting_near(const Aabb& box, std::vector<std::uint32_t>* out) const;

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
  // Lists the cells of `bodies` (all on the grid) into `out`, sorted by key, and sets their
  // levels; `occupied` gets a bit per level used.
  void list_cells(std::span<const Aabb> bounds, std::span<const std::uint32_t> bodies, int threads,
                  std::vector<Entry>* out, std::uint64_t* occupied);
  // Chooses the base cell and lists the resting bodies' cells.
  void list_resting(const BroadPhaseInput& input);
  // Relists the resting cells of input.resting_changes' slots alone, on the kept base cell.
  void update_resting(const BroadPhaseInput& input);

  std::vector<std::vector<Entry>> thread_entries_, thread_scratch_;
  std::vector<std::vector<BodyPair>> thread_pairs_, thread_spare_;
  std::vector<std::vector<std::uint32_t>> thread_counts_;
  std::vector<Entry> moving_entries_, resting_entries_, merge_buffer_;
  std::vector<Aabb> entry_bounds_;  // by moving entry: its body's box
  std::vector<BodyPair> pair_buffer_;
  std::vector<std::int8_t> level_;  // by slot
  std::vector<double> sizes_;
  std::vector<std::uint32_t> moving_found_, moving_on_grid_, moving_unbounded_;
  std::vector<std::uint32_t> resting_, resting_unbounded_;
  // update_resting's scratch: a flag by slot (all zero between calls), the slots that came to
  // rest, their cells.
  std::vector<std::uint8_t> changed_;
  std::vector<std::uint32_t> joined_, joined_merged_;
  std::vector<Entry> joined_entries_;
  // The resting bodies of each level, for a moving body that would cover more cells of that level
  // than it has bodies.
  std::vector<std::vector<std::uint32_t>> resting_on_level_;
  std::uint64_t resting_occupied_ = 0;
  std::uint64_t resting_version_ = 0;  // of the kept resting cells; 0: none kept
  double base_ = 1.0;                  // level 0's cell, m; kept with the resting cells
};

// Sweep and prune along x, for small worlds (World picks it below a body count). A world keeps
// one: the bodies' order along x barely changes from step to step, so each call starts from the
// last call's order and insertion-sorts it, a pass over the bodies where they moved little (Baraff
// 1992's coherent sort; Bullet's btAxisSweep3 and Jolt's broad phase keep theirs sorted too). The
// pairs come out in (a, b) order by two counting passes over the body slots, not a comparison
// sort. The result is the sorted set of overlapping pairs, whatever order the last call left.
class SweepAndPrune {
 public:
  // The pairs, sorted; true when input.max_pairs cut them short.
  bool find_pairs(const BroadPhaseInput& input, std::vector<BodyPair>* pairs);

 private:
  struct Entry {
    double min_x;
    std::uint32_t body;
    bool operator<(const Entry& o) const {
      return min_x < o.min_x || (min_x == o.min_x && body < o.body);
    }
  };
  // Sorts order_ (the last call's order, then the bodies new to it), insertion first; past a
  // budget of moves in proportion to the bodies (a shuffled scene), a comparison sort.
  void sort_order();

  std::vector<Entry> order_;
  std::vector<std::uint32_t> unbounded_;
  std::vector<std::uint8_t> listed_;  // by slot: in order_ this call
  std::vector<std::uint32_t> counts_;
  std::vector<BodyPair> spare_;
};

// A SweepAndPrune of the calling thread's (tests and benchmarks; the world keeps its own).
bool sweep_and_prune(const BroadPhaseInput& input, std::vector<BodyPair>* pairs);

}  // namespace tumble
