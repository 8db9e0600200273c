// The contact constraints of the iterative solvers, stored for their sweeps: four manifolds that
// share no moving body to a pack (four of a colour, or the j-th manifolds of four small islands),
// one lane each, every quantity of a point as four doubles side by side (structure of arrays), so
// that one sweep solves four manifolds with each operation (wide.h).
//
// Box2D v3 stores its graph colours' contacts this way (Catto, "SIMD Matters", 2024), as Jolt
// does its own; ours keeps the four-point block solve of a face (NormalBlock) lane by lane, and
// each lane computes exactly what the scalar solver (contact_solver.h) computes for its manifold,
// so that packing changes the speed and not one bit of the answer.
//
// The rows (ContactRow) stay the record of a contact: a pack is a copy of its rows for the
// solve (warm starts, separations, sweeps), and gives the impulses back before the residual and
// restitution, which go through the rows.
#pragma once

#include <cstdint>
#include <span>

#include "contact_solver.h"
#include "wide.h"

namespace tumble {

// Point p of every lane: ContactRow's hot part, lane by lane.
struct PackPoint {
  WideVec3 tangent1, tangent2;
  WideVec3 ra_cross_n, rb_cross_n, angular_a, angular_b;
  WideVec3 ra_cross_t1, rb_cross_t1, ra_cross_t2, rb_cross_t2;
  WideVec3 angular_a_t1, angular_b_t1, angular_a_t2, angular_b_t2;
  Wide separation, substep_separation;
  Wide earlier_substeps_impulse;  // ContactRowCold's
  Wide normal_mass, tangent_mass1, tangent_mass2;
  Wide normal_response, tangent_response1, tangent_response2;
  Wide normal_impulse, tangent_impulse1, tangent_impulse2, max_normal_impulse;
  WideMask present;  // the lane's manifold has a point p
  WideMask rubs;     // present, with friction
};

struct ContactPack {
  WideVec3 normal;
  Wide friction;
  Wide inverse_mass_a, inverse_mass_b;
  WideMask moves_a, moves_b;  // a moving body, which the lane writes back; statics are shared
  WideMask alone;             // one point: solved without its block
  WideMask in_block;          // several points: NormalBlock's solve first
  // NormalBlock::inverse's lower triangle, lane by lane: (i, j) with j <= i at i (i + 1) / 2 + j.
  // The inverse is symmetric to the bit (invert_positive_definite writes each entry to both sides),
  // so the upper half would repeat it: 6 of the pack's 16 block vectors, read every sweep.
  Wide block_inverse[10];
  std::uint32_t a[kWideLanes] = {}, b[kWideLanes] = {};  // solver bodies
  std::uint32_t first_row[kWideLanes] = {};              // the lane's manifold's rows follow it
  std::uint8_t points[kWideLanes] = {};                  // 0 in lanes without a manifold
  std::uint8_t most_points = 0;
  PackPoint point[4];
};

// A lane without a manifold.
constexpr std::uint32_t kNoManifold = UINT32_MAX;

// Fills `pack` with the manifolds manifolds[k] (ids, or kNoManifold) in lanes k, which share no
// moving body, from their rows and blocks as prepare_rows left them.
void pack_manifolds(const std::uint32_t (&manifolds)[kWideLanes],
                    std::span<const std::uint32_t> row_begin, std::span<const ContactRow> rows,
                    std::span<const NormalBlock> blocks, std::span<const SolverBody> bodies,
                    ContactPack* pack);

// The impulses the pack's solve gave, back to its rows.
void store_impulses(const ContactPack& pack, std::span<ContactRow> rows,
                    std::span<ContactRowCold> cold);

// warm_start's and update_separations' bits for a pack's manifolds.
void warm_start(ContactPack& pack, std::span<SolverBody> bodies, bool keep_last_substep,
                double kinematic_elapsed = 0);
void update_separations(ContactPack& pack, std::span<const SolverBody> bodies,
                        double kinematic_elapsed = 0);

// normal_residual's measure for each lane's manifold, in lane_residuals[k] (0 for a lane without
// one): the same bits, so an island's residual does not depend on whether it was packed.
void pack_residuals(const ContactPack& pack, std::span<const SolverBody> bodies, double h,
                    double (&lane_residuals)[kWideLanes], double kinematic_elapsed = 0);

// One Gauss-Seidel sweep over the manifolds of a pack's lanes in `lanes` (solve_manifold's
// bits, lane by lane).
// Returns the largest velocity change it gave a contact (m/s), and each lane's in
// lane_changes[k] when given.
double solve_pack(ContactPack& pack, const WideMask& lanes, std::span<SolverBody> bodies,
                  const SolverSettings& settings, const Softness* soft, double h,
                  double* lane_changes = nullptr);

constexpr WideMask kAllLanes = {-1, -1, -1, -1};

// Whether the step sweeps packs (else it sweeps the rows, manifold by manifold: the same bits).
// Packs pay where a vector holds four doubles (AVX2); with two (plain x86-64, ARM's NEON), GCC
// spills them and the sweeps take twice as long as the rows'. The test of their equality sets it.
bool packed_sweeps();
void set_packed_sweeps(bool on);

}  // namespace tumble
