#include "islands.h"

#include <numeric>

namespace tumble {
namespace {

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];  // path halving
    x = parent[x];
  }
  return x;
}

}  // namespace

void build_islands(std::span<const std::uint8_t> dynamic, std::span<const IslandLink> links,
                   Islands* out) {
  build_islands(dynamic, links, {}, out);
}

void build_islands(std::span<const std::uint8_t> dynamic, std::span<const IslandLink> links,
                   std::span<const IslandLink> joint_links, Islands* out) {
  const std::uint32_t body_count = static_cast<std::uint32_t>(dynamic.size());
  std::vector<std::uint32_t>& parent = out->parent;
  parent.resize(body_count);
  std::iota(parent.begin(), parent.end(), 0u);
  for (const std::span<const IslandLink> list : {links, joint_links})
    for (const IslandLink& link : list) {
      if (!dynamic[link.a] || !dynamic[link.b]) continue;
      const std::uint32_t ra = find_root(parent, link.a), rb = find_root(parent, link.b);
      // The lower index becomes the root, so roots are the islands' lowest bodies.
      if (ra < rb)
        parent[rb] = ra;
      else if (rb < ra)
        parent[ra] = rb;
    }

  constexpr std::uint32_t kNone = UINT32_MAX;
  std::vector<std::uint32_t>& island_of = out->island_of;
  island_of.assign(body_count, kNone);
  std::vector<std::uint32_t>& body_counts = out->body_counts;
  body_counts.clear();
  for (std::uint32_t s = 0; s < body_count; ++s) {
    if (!dynamic[s]) continue;
    const std::uint32_t root = find_root(parent, s);
    if (root == s) {
      island_of[s] = static_cast<std::uint32_t>(body_counts.size());
      body_counts.push_back(0);
    } else {
      island_of[s] = island_of[root];  // the root has a lower index: already numbered
    }
    ++body_counts[island_of[s]];
  }
  const std::size_t count = body_counts.size();

  out->body_begin.assign(count + 1, 0);
  for (std::size_t i = 0; i < count; ++i)
    out->body_begin[i + 1] = out->body_begin[i] + body_counts[i];
  out->bodies.resize(out->body_begin[count]);
  std::vector<std::uint32_t>& cursor = out->cursor;
  cursor.assign(out->body_begin.begin(), out->body_begin.end() - 1);
  for (std::uint32_t s = 0; s < body_count; ++s)
    if (dynamic[s]) out->bodies[cursor[island_of[s]]++] = s;

  std::vector<std::uint32_t>& link_counts = out->link_counts;
  link_counts.assign(count, 0);
  auto island_of_link = [&](const IslandLink& link) {
    return island_of[dynamic[link.a] ? link.a : link.b];
  };
  for (const IslandLink& link : links)
    ++link_counts[island_of_link(link)];
  out->link_begin.assign(count + 1, 0);
  for (std::size_t i = 0; i < count; ++i)
    out->link_begin[i + 1] = out->link_begin[i] + link_counts[i];
  out->links.resize(out->link_begin[count]);
  cursor.assign(out->link_begin.begin(), out->link_begin.end() - 1);
  for (std::uint32_t l = 0; l < links.size(); ++l)
    out->links[cursor[island_of_link(links[l])]++] = l;

  // The joints, the same way (most worlds have none, and pay for none).
  if (joint_links.empty()) {
    out->joint_begin.assign(count + 1, 0);
    out->joints.clear();
    return;
  }
  link_counts.assign(count, 0);
  for (const IslandLink& link : joint_links)
    ++link_counts[island_of_link(link)];
  out->joint_begin.assign(count + 1, 0);
  for (std::size_t i = 0; i < count; ++i)
    out->joint_begin[i + 1] = out->joint_begin[i] + link_counts[i];
  out->joints.resize(out->joint_begin[count]);
  cursor.assign(out->joint_begin.begin(), out->joint_begin.end() - 1);
  for (std::uint32_t l = 0; l < joint_links.size(); ++l)
    out->joints[cursor[island_of_link(joint_links[l])]++] = l;
}

}  // namespace tumble
