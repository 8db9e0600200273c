// Substeps for islands tall enough to buckle under the soft contact spring.
//
// A face resting on a face through soft points resists a tilt with a moment proportional to the
// spring's stiffness, so a stack of blocks is an elastic column, and a column under its own
// weight stands only while q L^3 / EI < 7.84 (Greenhill, 1881). The soft spring's stiffness in a
// mode is the mode's inertia times w^2, so a face resists a tilt of the block above with about
// w^2 I / 2 (I its moment of inertia about a horizontal axis); for blocks of mass m and height s
// the number is then about 2 g m s D^3 / (I w^2) for a tower D blocks high (docs/DYNAMICS.md
// derives it and checks it on towers and rods): a tower of 50 unit boxes at the default 60 Hz is
// at 100 and falls; at 240 Hz (16 substeps) it is at 6.5 and stands. The spring cannot be stiffer
// than a quarter of the substep rate, so an island past the bound gets more substeps and the
// stiffer spring they allow; every other island keeps the settings and pays only the walk over its
// contacts that measures its depth.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "body_state.h"
#include "islands.h"
#include "physics/math.h"
#include "physics/step.h"

namespace tumble {

// Largest buckling number an island is left at: Greenhill's 7.84 with a margin of 1.74. Measured
// over 60 s (docs/DYNAMICS.md): the tops of towers of 20, 30, 50 and 100 boxes then stay within
// 1 cm (the tower of 50's within 0.04 mm), the tower of 70's within 1.5 cm; at 6.7 the tower of
// 30 swayed 13 cm after its settling transient. That sway is chaotic and varies with the spring
// without a trend (3.0 and 6.0 were tried), so the bound is set where the tower of 50 stands best.
constexpr double kBucklingBound = 4.5;
// Substeps a stiffened island may take: time stays bounded whatever the stack.
constexpr int kMaxStiffenedSubsteps = 32;
// Sweeps a pgs stack may take (tall_pgs_iterations): time stays bounded.
constexpr int kMaxTallPgsIterations = 256;
// An island still past this with the most substeps (ten times the bound) is not stiffened: it
// would pay for the substeps and fall all the same (the tower of 100 is at 12.8 there and stands).
constexpr double kHopelessBuckling = 10 * kBucklingBound;

// Per level of an island: its mass, first and second moments of mass along two horizontal axes,
// and its bodies' own moments of inertia about them (tall_stacks.cc).
struct LevelSums {
  double mass = 0, first1 = 0, first2 = 0, second1 = 0, second2 = 0;
  double own_about1 = 0, own_about2 = 0;
};

struct IslandStiffness {
  int substeps = 0;  // 0: the settings' substeps and spring
  double contact_hertz = 0;
  // Needed more than kMaxStiffenedSubsteps: it takes that many, or none when even that leaves it
  // past kHopelessBuckling.
  bool capped = false;
};

// One island's bodies (the step's solver indices) and links (indices into `links`): the substeps
// and spring it needs. Only links marked `touching` (overlapping, or apart by less than the slop)
// carry load: speculative contacts between falling bodies make no column. `level` (by body) and
// `level_sums` are working memory.
IslandStiffness island_stiffness(
    std::span<const std::uint32_t> island_bodies, std::span<const std::uint32_t> island_links,
    std::span<const IslandLink> links, std::span<const std::uint8_t> touching,
    std::span<const std::uint8_t> dynamic, std::span<const Body* const> body_of,
    const Vec3& gravity, double dt, const SolverSettings& solver, std::vector<std::uint32_t>* level,
    std::vector<LevelSums>* level_sums);

// Sweeps for a pgs island that is a stack (kTallPgsDepth levels or more above the statics).
// Projected Gauss-Seidel has no spring, but sweeps stopped early (velocity_tolerance) leave every
// face a little compressed, unevenly, step after step: the towers of 10 and 20 leaned and fell
// within 40 and 20 s that way, with 10 sweeps or 30, while with every sweep run the tower of 10
// stands on 10 and the tower of 20 on 30 or 40 (20 fell). Gauss-Seidel carries a column's load
// down in a number of sweeps that grows with the square of its depth: D^2 / 8 here, at least the
// settings' and at most kMaxTallPgsIterations (`capped` says when more were needed; the depth
// walk's own bound too). Returns 0 for the settings (not a stack), else the sweeps it takes, all
// of them (no early stop).
constexpr double kTallPgsDepth = 3;
int tall_pgs_iterations(std::span<const std::uint32_t> island_bodies,
                        std::span<const std::uint32_t> island_links,
                        std::span<const IslandLink> links, std::span<const std::uint8_t> touching,
                        std::span<const std::uint8_t> dynamic, const SolverSettings& solver,
                        std::vector<std::uint32_t>* level, bool* capped);

}  // namespace tumble
