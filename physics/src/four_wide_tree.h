// A binary bounding-volume tree read as a four-wide one: every other level dropped, so that a
// node's children are its binary node's grandchildren (or its children where they are leaves), in
// their left-to-right order. Each child's bounds lie within those of the level dropped, so a walk
// meets the same leaves. Shared by the mesh's tree (triangle_mesh.cc) and the bodies' query tree
// (query_index.cc); wide_slabs.h walks them.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace tumble {

inline constexpr std::uint32_t kNoBinaryNode = UINT32_MAX;

// is_leaf(b) and children_of(b) (two binary nodes) describe the binary tree, rooted at 0;
// add_node() appends an empty wide node and returns its index (the root's, 0, first);
// set_lane(at, k, b, wide) fills lane k of wide node `at` with binary node b (kNoBinaryNode: no
// child) and, for an inner b, the wide node made for it (else kNoBinaryNode). Inner children are
// made one after another (siblings side by side in memory). `pending`: the work list, kept by the
// caller so that a rebuild need not allocate.
template <class IsLeaf, class ChildrenOf, class AddNode, class SetLane>
void collapse_to_four_wide(IsLeaf&& is_leaf, ChildrenOf&& children_of, AddNode&& add_node,
                           SetLane&& set_lane,
                           std::vector<std::array<std::uint32_t, 2>>* pending) {
  pending->assign(1, {add_node(), 0});
  for (std::size_t next = 0; next < pending->size(); ++next) {
    const auto [at, from] = (*pending)[next];
    std::array<std::uint32_t, 4> children{};
    int child_count = 0;
    if (is_leaf(from)) {
      children[child_count++] = from;  // a tree of one leaf
    } else {
      for (std::uint32_t c : children_of(from)) {
        if (is_leaf(c)) {
          children[child_count++] = c;
          continue;
        }
        for (std::uint32_t g : children_of(c))
          children[child_count++] = g;
      }
    }
    for (int k = 0; k < 4; ++k) {
      if (k >= child_count) {
        set_lane(at, k, kNoBinaryNode, kNoBinaryNode);
        continue;
      }
      std::uint32_t wide = kNoBinaryNode;
      if (!is_leaf(children[k])) {
        wide = add_node();
        pending->push_back({wide, children[k]});
      }
      set_lane(at, k, children[k], wide);
    }
  }
}

}  // namespace tumble
