#include "tall_stacks.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace tumble {
namespace {

// Levels of a breadth-first walk up from the bodies touching a static, found by relaxing the
// links until nothing changes (a stack listed bottom to top settles in one pass, a pass per level
// at worst). Bounded: after kMaxDepthPasses the bodies not reached yet are left out, the depth
// found is at least the bound, far past what any substeps hold, and `exhausted` says so.
constexpr int kMaxDepthPasses = 256;

std::uint32_t support_depth(std::span<const std::uint32_t> island_bodies,
                            std::span<const std::uint32_t> island_links,
                            std::span<const IslandLink> links,
                            std::span<const std::uint8_t> touching,
                            std::span<const std::uint8_t> dynamic,
                            std::vector<std::uint32_t>& level, bool* exhausted) {
  for (std::uint32_t body : island_bodies)
    level[body] = 0;  // not reached
  for (std::uint32_t l : island_links) {
    if (!touching[l]) continue;
    const IslandLink& link = links[l];
    if (!dynamic[link.a]) level[link.b] = 1;
    if (!dynamic[link.b]) level[link.a] = 1;
  }
  *exhausted = true;
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
    if (!changed) {
      *exhausted = false;
      break;
    }
  }
  std::uint32_t depth = 0;
  for (std::uint32_t body : island_bodies)
    depth = std::max(depth, level[body]);
  return depth;
}

// The height of a body along `up`.
double height_along(const Body& body, const Vec3& up) {
  const Vec3 d = body.orientation.conjugate() * up;
  return body.shape.support(d).dot(d) + body.shape.support(-d).dot(-d);
}

// What a level's bodies resist a tilt with: the soft spring's stiffness in a mode is the mode's
// inertia times w^2, and a level turning as one slab about a horizontal axis has its bodies'
// own moments of inertia plus their masses times the square of their distance from the axis
// through the level's centre of mass. A tower's level is one block (its moment of inertia); a
// pile's level spreads over metres, and its slab is far stiffer than any single block.
void add_to_level(const Body& body, const Vec3& across1, const Vec3& across2, LevelSums* sums) {
  const double mass = 1 / body.inverse_mass;
  const double c1 = body.position.dot(across1), c2 = body.position.dot(across2);
  sums->mass += mass;
  sums->first1 += mass * c1;
  sums->first2 += mass * c2;
  sums->second1 += mass * c1 * c1;
  sums->second2 += mass * c2 * c2;
  // Turning about across1 moves the bodies along across2, and the other way round.
  sums->own_about1 += 1 / across1.dot(body.inverse_inertia_world * across1);
  sums->own_about2 += 1 / across2.dot(body.inverse_inertia_world * across2);
}

double tilt_inertia(const LevelSums& sums) {
  if (!(sums.mass > 0)) return 0;
  const double spread2 = std::max(0.0, sums.second2 - sums.first2 * sums.first2 / sums.mass);
  const double spread1 = std::max(0.0, sums.second1 - sums.first1 * sums.first1 / sums.mass);
  return std::min(sums.own_about1 + spread2, sums.own_about2 + spread1);
}

// An island's column: its support depth (levels above the statics), whether the walk that
// measured it reached its pass bound, and sum over levels of (weight above x height x block
// height) over the level's tilt inertia, which over the spring's w^2 is the buckling number.
struct Column {
  std::uint32_t depth = 0;
  bool exhausted = false;
  double load_over_inertia = 0;  // 1/s^2
};

Column measure_column(std::span<const std::uint32_t> island_bodies,
                      std::span<const std::uint32_t> island_links,
                      std::span<const IslandLink> links, std::span<const std::uint8_t> touching,
                      std::span<const std::uint8_t> dynamic, std::span<const Body* const> body_of,
                      const Vec3& gravity, std::vector<std::uint32_t>* level,
                      std::vector<LevelSums>* level_sums) {
  Column result;
  const double g = gravity.norm();
  if (!(g > 0) || island_links.empty()) return result;
  const std::uint32_t levels_found = support_depth(island_bodies, island_links, links, touching,
                                                   dynamic, *level, &result.exhausted);
  result.depth = levels_found;
  const double depth = levels_found;
  // Two blocks high cannot buckle: a face tilts only under a load offset beyond its own edge.
  if (depth < 2) return result;
  const Vec3 up = -gravity / g;
  const Vec3 across1 = up.unitOrthogonal();
  const Vec3 across2 = up.cross(across1);
  // The buckling number of a column whose level l carries the mass above it on its own tilt
  // stiffness: a Rayleigh-type sum over levels of (weight above x its height x block height)
  // over the level's tilt inertia. For a tower of blocks of mass m, height s and moment of
  // inertia I it is g m s sum (D - l)^2 / I, about g m s D^3 / (3 I); a one-block-thick pyramid
  // shares each level's load among its blocks (half a tower's); a pile's wide levels add little.
  std::vector<LevelSums>& levels = *level_sums;
  levels.assign(levels_found + 1, LevelSums{});
  double tallest = 0;
  for (std::uint32_t index : island_bodies) {
    const std::uint32_t l = (*level)[index];
    const Body& body = *body_of[index];
    if (l == 0 || !(body.inverse_mass > 0)) continue;
    add_to_level(body, across1, across2, &levels[l]);
    tallest = std::max(tallest, height_along(body, up));
  }
  double column = 0, mass_above = 0;
  for (std::uint32_t l = levels_found; l >= 1; --l) {
    const double inertia = tilt_inertia(levels[l]);
    if (inertia > 0) column += g * mass_above * (depth - l) * tallest / inertia;
    mass_above += levels[l].mass;
  }
  result.load_over_inertia = column;
  return result;
}

// The buckling number of a column at the settings' spring, and that spring.
double buckling_at_settings(const Column& column, double dt, const SolverSettings& solver,
                            double* hertz) {
  const double h = dt / solver.substeps;
  *hertz = std::min(solver.contact_hertz, 0.25 / h);
  const double omega = 2 * std::numbers::pi * *hertz;
  return 2 * 3 * column.load_over_inertia / (omega * omega);
}

}  // namespace

IslandStiffness island_stiffness(
    std::span<const std::uint32_t> island_bodies, std::span<const std::uint32_t> island_links,
    std::span<const IslandLink> links, std::span<const std::uint8_t> touching,
    std::span<const std::uint8_t> dynamic, std::span<const Body* const> body_of,
    const Vec3& gravity, double dt, const SolverSettings& solver, std::vector<std::uint32_t>* level,
    std::vector<LevelSums>* level_sums) {
  IslandStiffness result;
  const Column column = measure_column(island_bodies, island_links, links, touching, dynamic,
                                       body_of, gravity, level, level_sums);
  result.capped = column.exhausted;
  if (column.depth < 2) return result;
  double hertz = 0;
  const double buckling = buckling_at_settings(column, dt, solver, &hertz);
  if (!(buckling > kBucklingBound) || !(hertz > 0)) return result;
  const double needed_hertz = hertz * std::sqrt(buckling / kBucklingBound);
  // The spring may be a quarter of the substep rate: 4 f dt substeps, within the bound.
  const double wanted = std::ceil(4 * needed_hertz * dt);
  const int most = std::max(kMaxStiffenedSubsteps, solver.substeps);
  int substeps = wanted > most ? most : std::max(static_cast<int>(wanted), solver.substeps);
  result.capped = result.capped || wanted > most;
  // Past what the bound's spring can nearly reach (a light block under a billion times its mass),
  // more substeps would cost their time and hold nothing: the island keeps the settings.
  const double at_most = std::min(needed_hertz, 0.25 * substeps / dt);
  if (buckling * (hertz / at_most) * (hertz / at_most) > kHopelessBuckling) return result;
  // The settings' substeps may already allow the stiffer spring (soft with 8 substeps and the
  // tower of 20): the island then takes the spring alone. It used to keep the settings' spring
  // then, and its tower stood or swayed 5 cm by the last bits of the run.
  if (!(at_most > hertz)) return result;
  result.substeps = substeps;
  result.contact_hertz = at_most;
  return result;
}

int tall_pgs_iterations(std::span<const std::uint32_t> island_bodies,
                        std::span<const std::uint32_t> island_links,
                        std::span<const IslandLink> links, std::span<const std::uint8_t> touching,
                        std::span<const std::uint8_t> dynamic, const SolverSettings& solver,
                        std::vector<std::uint32_t>* level, bool* capped) {
  if (island_links.empty()) return 0;
  const double depth =
      support_depth(island_bodies, island_links, links, touching, dynamic, *level, capped);
  if (depth < kTallPgsDepth) return 0;
  const double wanted = std::ceil(depth * depth / 8);
  *capped = *capped || wanted > kMaxTallPgsIterations;
  const int most = std::max(kMaxTallPgsIterations, solver.iterations);
  return wanted > most ? most : std::max(static_cast<int>(wanted), solver.iterations);
}

}  // namespace tumble
