// The sweep shared by the process-wide tables of weakly held polyhedra (box_polyhedra.cc,
// hull_polyhedra.cc): entries whose polyhedron was freed are dropped when a table has doubled
// since its last sweep, so a client making ever new shapes and removing them holds a table to
// twice the live ones.
#pragma once

#include <algorithm>
#include <cstddef>

namespace tumble {

// The tables are swept no smaller than this.
inline constexpr std::size_t kSweptAtLeast = 64;

template <class Map, class Dead>
void sweep_when_doubled(Map& map, std::size_t& swept_at, Dead dead) {
  if (map.size() < 2 * swept_at) return;
  std::erase_if(map, dead);
  swept_at = std::max<std::size_t>(kSweptAtLeast, map.size());
}

}  // namespace tumble
