// Islands: dynamic bodies joined by contacts, which the solvers treat independently. Statics join
// nothing (a floor under two piles does not make them one island).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace tumble {

struct IslandLink {
  std::uint32_t a, b;  // bodies: the step's solver indices (step_scratch.h)
};

struct Islands {
  // Island i holds bodies[body_begin[i] .. body_begin[i+1]) and links[link_begin[i] ..
  // link_begin[i+1]) (indices into the links given), both in ascending order.
  std::vector<std::uint32_t> bodies, body_begin;
  std::vector<std::uint32_t> links, link_begin;
  // Island i's joints: joints[joint_begin[i] .. joint_begin[i+1]) (indices into the joint links
  // given), ascending.
  std::vector<std::uint32_t> joints, joint_begin;
  std::size_t count() const { return body_begin.empty() ? 0 : body_begin.size() - 1; }

  // Working memory of build_islands, kept to be reused.
  std::vector<std::uint32_t> parent, island_of, body_counts, link_counts, cursor;
};

// `dynamic[body]` marks the bodies that move; every link touches at least one of them. Islands
// come in the order of their lowest body, so the result does not depend on link order
// beyond the lists' own order.
void build_islands(std::span<const std::uint8_t> dynamic, std::span<const IslandLink> links,
                   Islands* out);
// The same, bodies joined by contacts' links and by joints' (a joint to the world links its body
// to itself).
void build_islands(std::span<const std::uint8_t> dynamic, std::span<const IslandLink> links,
                   std::span<const IslandLink> joint_links, Islands* out);

}  // namespace tumble
