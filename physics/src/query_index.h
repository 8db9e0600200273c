// The bodies' bounds in a tree for queries (World::cast_ray and kin): a bounding-volume
// hierarchy built on demand, top down by median splits along the widest axis of the boxes'
// centres (O(n log n); a few leaves of at most kLeafSize bodies), and kept until a step or a
// change of bodies makes it stale. A ray walks a copy of it with every other level dropped (four
// children a node, met at once: the mesh's tree does the same, docs/COLLISION.md), nearer children
// first, and skips boxes it enters beyond the nearest hit so far. Bodies without bounds
// (half-spaces) are kept aside and tried by every ray; bodies about as large as all the others
// together (a terrain under them) have a child of the root to themselves (build).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <span>
#include <vector>

#include "physics/math.h"
#include "wide_slabs.h"

namespace tumble {

// The first fraction t in [0, 1] at which `box` moved by t * translation meets `target`;
// infinity when it never does (the slabs of the two boxes' Minkowski difference). Infinite
// targets (a half-space) are met from the start on their unbounded sides.
inline double sweep_entry(const Aabb& box, const Vec3& translation, const Aabb& target) {
  double enter = 0, leave = 1;
  for (int k = 0; k < 3; ++k) {
    const double low = target.min[k] - box.max[k];   // the move along k that starts the overlap
    const double high = target.max[k] - box.min[k];  // and that ends it
    const double d = translation[k];
    if (d == 0) {
      if (!(low <= 0 && high >= 0)) return std::numeric_limits<double>::infinity();
      continue;
    }
    double t0 = low / d, t1 = high / d;
    if (t0 > t1) std::swap(t0, t1);
    if (std::isnan(t0)) t0 = 0;  // an infinite side moved along: met throughout
    if (std::isnan(t1)) t1 = 1;
    enter = std::max(enter, t0);
    leave = std::min(leave, t1);
    if (enter > leave) return std::numeric_limits<double>::infinity();
  }
  return enter;
}

class QueryIndex {
 public:
  struct Entry {
    std::uint32_t slot;
    Aabb bounds;
  };
  // Replaces the tree with one over `entries` (bounded or not).
  void build(std::span<const Entry> entries);

  // Calls visit(slot, t_max) for every body whose box the ray origin + t direction (unit),
  // t in [0, t_max], meets, nearer boxes first; visit returns the new t_max (the ray shortened to
  // the nearest hit so far, or as it was).
  template <class Visit>
  void visit_ray(const Vec3& origin, const Vec3& direction, double t_max, Visit&& visit) const;

  // Calls visit(slot) for every body whose box overlaps `box` (and every unbounded one).
  template <class Visit>
  void visit_box(const Aabb& box, Visit&& visit) const;

  // Calls visit(slot, entry) for every body whose box `box` moved by t * translation, t in
  // [0, 1], meets, with the first such t (sweep_entry); only the nodes along the path are opened.
  template <class Visit>
  void visit_sweep(const Aabb& box, const Vec3& translation, Visit&& visit) const;

  // The version of the world this tree was built for (World's query version), and the lock that
  // lets one thread build it while queries from others wait.
  std::uint64_t version = ~std::uint64_t{0};
  std::mutex building;

 private:
  // Calls visit(entry) for every entry of the leaves whose nodes `meets` accepts (an inner node's
  // rejection skips its subtree).
  template <class Meets, class Visit>
  void visit_nodes(Meets&& meets, Visit&& visit) const;

  static constexpr int kLeafSize = 4;
  // Bodies at least this fraction of all the bodies' extent get a child of the root (build).
  static constexpr double kGiantFraction = 0.25;
  struct Node {
    Aabb bounds;
    std::uint32_t first = 0;  // leaf: its first entry; inner: its second child (the first is next)
    std::uint32_t count = 0;  // leaf: entries; inner: 0
  };
  // The rays' tree: lane k of a node is its child k's bounds (a node when count is 0, else a
  // leaf's entries from first; count kNoChild: none, with empty bounds).
  static constexpr std::uint32_t kNoChild = UINT32_MAX;
  struct alignas(64) WideNode {
    std::array<std::array<double, 4>, 3> min, max;
    std::array<std::uint32_t, 4> first, count;
  };
  std::uint32_t build_node(std::uint32_t begin, std::uint32_t end);
  void build_wide();
  // Where the ray enters the box (t in [0, t_max]), or +infinity if it misses it.
  static double enter(const Aabb& box, const Vec3& origin, const Vec3& inverse, double t_max);

  std::vector<Node> nodes_;
  std::vector<WideNode> wide_nodes_;
  // The collapse's work list (kept: a world queried after every step builds without allocating).
  std::vector<std::array<std::uint32_t, 2>> collapsing_;
  std::vector<Entry> entries_;        // bounded, in the tree's order
  std::vector<std::uint32_t> unbounded_;  // slots of bodies without bounds
};

template <class Visit>
void QueryIndex::visit_ray(const Vec3& origin, const Vec3& direction, double t_max,
                           Visit&& visit) const {
  for (std::uint32_t slot : unbounded_)
    t_max = visit(slot, t_max);
  if (wide_nodes_.empty()) return;
  const Vec3 inverse = direction.cwiseInverse();  // +-inf along an axis the ray does not move on
  const WideRay ray = wide_ray(origin, inverse);
  // Depth is O(log n) (median splits); each node opened leaves at most three children waiting:
  // 96 entries hold any tree of up to 2^60 bodies.
  struct Pending {
    std::uint32_t first, count;
  };
  Pending stack[96];
  int depth = 0;
  stack[depth++] = {0, 0};
  while (depth > 0) {
    const Pending pending = stack[--depth];
    if (pending.count > 0) {
      for (std::uint32_t k = pending.first; k < pending.first + pending.count; ++k)
        if (enter(entries_[k].bounds, origin, inverse, t_max) <= t_max)
          t_max = visit(entries_[k].slot, t_max);
      continue;
    }
    // enter() on four boxes at once (wide_slabs.h).
    const WideNode& node = wide_nodes_[pending.first];
    const auto lanes = [](const std::array<double, 4>& bound) {
      return Wide{bound[0], bound[1], bound[2], bound[3]};
    };
    WideMask reached;
    const Wide near =
        enter_boxes(ray, {lanes(node.min[0]), lanes(node.min[1]), lanes(node.min[2])},
                    {lanes(node.max[0]), lanes(node.max[1]), lanes(node.max[2])}, t_max, &reached);
    farthest_first(
        reached, near, [&](int k) { return node.count[k] != kNoChild; },
        [&](int k) {
          stack[depth++] = {node.first[k], node.count[k]};
        });
  }
}

template <class Meets, class Visit>
void QueryIndex::visit_nodes(Meets&& meets, Visit&& visit) const {
  if (nodes_.empty()) return;
  std::uint32_t stack[64];
  int depth = 0;
  stack[depth++] = 0;
  while (depth > 0) {
    const Node& node = nodes_[stack[--depth]];
    if (!meets(node.bounds)) continue;
    if (node.count > 0) {
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k)
        visit(entries_[k]);
      continue;
    }
    stack[depth++] = node.first;
    stack[depth++] = static_cast<std::uint32_t>(&node - nodes_.data()) + 1;
  }
}

template <class Visit>
void QueryIndex::visit_box(const Aabb& box, Visit&& visit) const {
  for (std::uint32_t slot : unbounded_)
    visit(slot);
  visit_nodes([&](const Aabb& bounds) { return bounds.overlaps(box); },
              [&](const Entry& entry) {
                if (entry.bounds.overlaps(box)) visit(entry.slot);
              });
}

template <class Visit>
void QueryIndex::visit_sweep(const Aabb& box, const Vec3& translation, Visit&& visit) const {
  for (std::uint32_t slot : unbounded_)
    visit(slot, 0.0);
  visit_nodes([&](const Aabb& bounds) { return sweep_entry(box, translation, bounds) <= 1; },
              [&](const Entry& entry) {
                if (const double t = sweep_entry(box, translation, entry.bounds); t <= 1)
                  visit(entry.slot, t);
              });
}

}  // namespace tumble
