#include "query_index.h"

#include <algorithm>
#include <limits>

#include "four_wide_tree.h"

namespace tumble {

void QueryIndex::build(std::span<const Entry> entries) {
  entries_.clear();
  unbounded_.clear();
  nodes_.clear();
  wide_nodes_.clear();
  for (const Entry& entry : entries) {
    if (entry.bounds.is_bounded())
      entries_.push_back(entry);
    else
      unbounded_.push_back(entry.slot);
  }
  if (entries_.empty()) return;
  nodes_.reserve(2 * entries_.size() / kLeafSize + 3);
  // A body as large as the world's bodies together (a terrain under them) would share a leaf with
  // the few small ones at its centre, and every node above that leaf would take its size: every
  // ray entered them all. Such bodies get a child of the root to themselves, the rest the other.
  Aabb all;
  for (const Entry& entry : entries_) {
    all.grow(entry.bounds.min);
    all.grow(entry.bounds.max);
  }
  const double giant = kGiantFraction * all.extent().maxCoeff();
  const auto small_end =
      std::stable_partition(entries_.begin(), entries_.end(),
                            [&](const Entry& e) { return e.bounds.extent().maxCoeff() < giant; });
  const auto small = static_cast<std::uint32_t>(small_end - entries_.begin());
  const auto count = static_cast<std::uint32_t>(entries_.size());
  if (small == 0 || small == count) {
    build_node(0, count);
  } else {
    nodes_.push_back({});
    nodes_[0].bounds = all;
    nodes_[0].count = 0;
    build_node(0, small);  // the root's first child: the next node, as build_node places it
    nodes_[0].first = build_node(small, count);
  }
  build_wide();
}

// The rays' copy of the tree (four_wide_tree.h).
void QueryIndex::build_wide() {
  wide_nodes_.reserve(nodes_.size() / 3 + 1);
  collapse_to_four_wide([&](std::uint32_t b) { return nodes_[b].count > 0; },
                        [&](std::uint32_t b) {
                          return std::array<std::uint32_t, 2>{b + 1, nodes_[b].first};
                        },
                        [&] {
                          wide_nodes_.push_back({});
                          return static_cast<std::uint32_t>(wide_nodes_.size() - 1);
                        },
                        [&](std::uint32_t at, int k, std::uint32_t b, std::uint32_t wide) {
                          WideNode& node = wide_nodes_[at];
                          if (b == kNoBinaryNode) {
                            for (int axis = 0; axis < 3; ++axis) {
                              node.min[axis][k] = std::numeric_limits<double>::infinity();
                              node.max[axis][k] = -std::numeric_limits<double>::infinity();
                            }
                            node.first[k] = 0;
                            node.count[k] = kNoChild;
                            return;
                          }
                          const Node& child = nodes_[b];
                          for (int axis = 0; axis < 3; ++axis) {
                            node.min[axis][k] = child.bounds.min[axis];
                            node.max[axis][k] = child.bounds.max[axis];
                          }
                          node.count[k] = child.count;
                          node.first[k] = child.count == 0 ? wide : child.first;
                        },
                        &collapsing_);
}

std::uint32_t QueryIndex::build_node(std::uint32_t begin, std::uint32_t end) {
  const std::uint32_t index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({});
  Aabb bounds, centres;
  for (std::uint32_t k = begin; k < end; ++k) {
    bounds.grow(entries_[k].bounds.min);
    bounds.grow(entries_[k].bounds.max);
    centres.grow(0.5 * (entries_[k].bounds.min + entries_[k].bounds.max));
  }
  nodes_[index].bounds = bounds;
  if (end - begin <= kLeafSize) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  centres.extent().maxCoeff(&axis);
  const std::uint32_t middle = begin + (end - begin) / 2;
  // Ties broken by slot: the same tree for the same bodies, whatever order they came in.
  std::nth_element(entries_.begin() + begin, entries_.begin() + middle, entries_.begin() + end,
                   [axis](const Entry& a, const Entry& b) {
                     const double ca = a.bounds.min[axis] + a.bounds.max[axis];
                     const double cb = b.bounds.min[axis] + b.bounds.max[axis];
                     return ca < cb || (ca == cb && a.slot < b.slot);
                   });
  build_node(begin, middle);  // index + 1
  const std::uint32_t second = build_node(middle, end);
  nodes_[index].first = second;
  nodes_[index].count = 0;
  return index;
}

double QueryIndex::enter(const Aabb& box, const Vec3& origin, const Vec3& inverse, double t_max) {
  double near = 0, far = t_max;
  for (int k = 0; k < 3; ++k) {
    // With inverse = +-inf (a ray parallel to the slab) the products are +-inf, or NaN when the
    // origin lies on the slab's plane; std::min/max with NaN second keep the first, so such an
    // axis is treated as inside, conservatively.
    double a = (box.min[k] - origin[k]) * inverse[k];
    double b = (box.max[k] - origin[k]) * inverse[k];
    if (a > b) std::swap(a, b);
    near = std::max(near, a);
    far = std::min(far, b);
    if (near > far) return std::numeric_limits<double>::infinity();
  }
  return near;
}

}  // namespace tumble
