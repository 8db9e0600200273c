#include "auto_solver.h"

#include <algorithm>
#include <numbers>

namespace tumble {

bool soft_would_differ(std::span<const std::uint32_t> island_bodies,
                       std::span<const std::uint32_t> island_links,
                       std::span<const IslandLink> links, std::span<const Body* const> body_of,
                       std::span<const std::uint8_t> dynamic, double gravity,
                       const SolverSettings& solver, double mass_ratio) {
  for (const std::uint32_t manifold : island_links) {
    const IslandLink link = links[manifold];
    if (!dynamic[link.a] || !dynamic[link.b]) continue;
    const double a = body_of[link.a]->mass, b = body_of[link.b]->mass;
    if (std::max(a, b) > mass_ratio * std::min(a, b)) return true;
  }
  const double omega = 2 * std::numbers::pi * solver.contact_hertz;
  const double smallest = kAutoExactSagMultiple * gravity / (omega * omega);
  return std::any_of(island_bodies.begin(), island_bodies.end(), [&](std::uint32_t body) {
    return body_of[body]->shape.inner_radius() < smallest;
  });
}

}  // namespace tumble
