#include "tall_stacks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

namespace tumble {
namespace {

// Levels of a breadth-first walk up from the bodies touching a static, found by relaxing the
// links until nothing changes (a stack listed bottom to top settles in one pass). Bounded: a
// depth past the bound is counted as the bound, which already asks for the most substeps.
constexpr int kMaxDepthPasses = 256;

std::uint32_t support_depth(std::span<const std::uint32_t> island_bodies,
                            std::span<const std::uint32_t> island_links,
                            std::span<const IslandLink> links,
                            std::span<const std::uint8_t> touching,
                            std::span<const std::uint8_t> dynamic,
                            std::vector<std::uint32_t>& level) {
  for (std::uint32_t slot : island_bodies)
    level[slot] = 0;  // not reached
  for (std::uint32_t l : island_links) {
    if (!touching[l]) continue;
    const IslandLink& link = links[l];
    if (!dynamic[link.a]) level[link.b] = 1;
    if (!dynamic[link.b]) level[link.a] = 1;
  }
  for (int pass = 0; pass < kMaxDepthPasses; ++pass) {
    bool changed = false;
    for (std::uint32_t l : island_links) {
      const IslandLink& link = links[l];
      if (!touching[l] || !dynamic[link.a] || !dynamic[link.b]) continue;
      auto lift = [&](std::uint32_t from, std::uint32_t to) {
        if (level[from] > 0 && (level[to] == 0 || level[to] > level[from] + 1)) {
          level[to] = level[from] + 1;
          changed = true;
        }
      };
      lift(link.a, link.b);
      lift(link.b, link.a);
    }
    if (!changed) break;
  }
  std::uint32_t depth = 0;
  for (std::uint32_t slot : island_bodies)
    depth = std::max(depth, level[slot]);
  return depth;
}

// m s / I of a body: mass times height along `up` over its smaller moment of inertia about a
// horizontal axis. The soft spring's stiffness in a mode is the mode's inertia times w^2, so a
// face resists a tilt with the bodies' moments of inertia, not with its width.
double tilt_slenderness(const Body& body, const Vec3& up, const Vec3& across1,
                        const Vec3& across2) {
  const Quat to_body = body.orientation.conjugate();
  const Vec3 d = to_body * up;
  const double height = body.shape.support(d).dot(d) + body.shape.support(-d).dot(-d);
  const Mat3& inverse_inertia = body.inverse_inertia_world;
  const double most_turnable =
      std::max(across1.dot(inverse_inertia * across1), across2.dot(inverse_inertia * across2));
  return body.inverse_mass > 0 ? height * most_turnable / body.inverse_mass : 0.0;
}

}  // namespace

IslandStiffness island_stiffness(
    std::span<const std::uint32_t> island_bodies, std::span<const std::uint32_t> island_links,
    std::span<const IslandLink> links, std::span<const std::uint8_t> touching,
    std::span<const std::uint8_t> dynamic, std::span<const Body* const> body_of_slot,
    const Vec3& gravity, double dt, const SolverSettings& solver, std::vector<std::uint32_t>* level,
    std::vector<std::uint32_t>* bodies_per_level) {
  IslandStiffness result;
  const double g = gravity.norm();
  if (!(g > 0) || island_links.empty()) return result;
  result.support_depth =
      support_depth(island_bodies, island_links, links, touching, dynamic, *level);
  const double depth = result.support_depth;
  // Two blocks high cannot buckle: a face tilts only under a load offset beyond its own edge.
  if (depth < 2) return result;
  const Vec3 up = -gravity / g;
  const Vec3 across1 = up.unitOrthogonal();
  const Vec3 across2 = up.cross(across1);
  // Bodies per level, and the buckling number of a column whose level l carries the bodies above
  // it on the bodies of its own: a Rayleigh-type sum over levels of (load above over the
  // level's stiffness) times the height of that load, 3 sum (D - l)^2 = D^3 for a tower of
  // single blocks, half that for a wall-like pyramid, little for a pile.
  std::vector<std::uint32_t>& per_level = *bodies_per_level;
  per_level.assign(result.support_depth + 1, 0);
  double most_slender = 0;
  for (std::uint32_t slot : island_bodies) {
    const std::uint32_t l = (*level)[slot];
    if (l == 0) continue;
    ++per_level[l];
    most_slender =
        std::max(most_slender, tilt_slenderness(*body_of_slot[slot], up, across1, across2));
  }
  double column = 0, above = 0;
  for (std::uint32_t l = result.support_depth; l >= 1; --l) {
    if (per_level[l] > 0) column += above / per_level[l] * (depth - l);
    above += per_level[l];
  }
  const double h = dt / solver.substeps;
  const double hertz = std::min(solver.contact_hertz, 0.25 / h);
  const double omega = 2 * std::numbers::pi * hertz;
  const double buckling = 2 * g * 3 * column * most_slender / (omega * omega);
  if (!(buckling > kBucklingBound) || !(hertz > 0)) return result;
  const double needed_hertz = hertz * std::sqrt(buckling / kBucklingBound);
  // The spring may be a quarter of the substep rate: 4 f dt substeps, within the bound.
  const double wanted = std::ceil(4 * needed_hertz * dt);
  const int most = std::max(kMaxStiffenedSubsteps, solver.substeps);
  int substeps = wanted > most ? most : std::max(static_cast<int>(wanted), solver.substeps);
  result.capped = wanted > most;
  if (substeps <= solver.substeps) return result;
  result.substeps = substeps;
  result.contact_hertz = std::min(needed_hertz, 0.25 * substeps / dt);
  return result;
}

}  // namespace tumble
