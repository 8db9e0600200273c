// Contact constraints of one step and the iterative passes over them: warm start, projected
// Gauss-Seidel with or without soft bias, restitution, and the position correction.
//
// Ideas from Catto's sequential impulses (GDC 2006-2014) and Box2D v3's soft step (Catto,
// "Solver2D", 2024): anchors move with the bodies during substeps, so each substep sees its own
// separation, and penetration is pushed out by a spring of fixed stiffness, then the velocity the
// push added is relaxed away.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <span>
#include <vector>

#include "body_state.h"
#include "contact_record.h"
#include "physics/collision.h"
#include "physics/math.h"
#include "physics/step.h"

namespace tumble {

// Velocities and what the solvers need of a body; statics have zero inverse mass. What every
// sweep reads (velocities, inverse mass, motion since the step start) comes first, in two cache
// lines; the rest is read once a substep or less.
struct SolverBody {
  Vec3 v = Vec3::Zero(), w = Vec3::Zero();
  double inverse_mass = 0;
  // Motion since the start of the step, for the separation of moving anchors: the translation
  // and the rotation vector (sum of w h over substeps; a step turns a body by little).
  Vec3 delta_position = Vec3::Zero();
  Vec3 delta_angle = Vec3::Zero();
  Mat3 inverse_inertia = Mat3::Zero();  // world, fixed during the step
  // Pseudo-velocities that push the body out of penetration (exact solver): the position update
  // moves the body by them once, and no velocity is left behind.
  Vec3 push_v = Vec3::Zero(), push_w = Vec3::Zero();
  // The free rotation over the coming position update (world frame), and the angular velocity it
  // belongs to: the position update turns the body by free_turn, and by w - w_free only for what
  // the contacts changed (integrate.h says why).
  Quat free_turn = Quat::Identity();
  Vec3 w_free = Vec3::Zero();
  // A kinematic body with a velocity: v and w are that velocity, which nothing changes, and its
  // motion since the step start is that velocity times the time since (the islands that share it
  // each keep their own time, so its delta_position and delta_angle stay 0).
  bool kinematic = false;
};

// One contact point between bodies `a` and `b` (the step's solver indices, StepScratch): what the
// velocity sweeps read and
// write, every sweep (the rest is in ContactRowCold, so that the sweeps stream through less).
struct ContactRow {
  std::uint32_t a = 0, b = 0;
  Vec3 normal, tangent1, tangent2;  // world; normal from a to b
  // ra x n, rb x n (ra, rb: the lever arms from the centres of mass at the step start) and the
  // inverse inertias applied to them: the normal row's angular parts.
  Vec3 ra_cross_n, rb_cross_n, angular_a, angular_b;
  // The same for the two tangent rows.
  Vec3 ra_cross_t1, rb_cross_t1, ra_cross_t2, rb_cross_t2;
  Vec3 angular_a_t1, angular_b_t1, angular_a_t2, angular_b_t2;
  double separation = 0;  // m at the step start; < 0 overlapping
  // The separation after the bodies' last move (current_separation): sweeps do not move bodies,
  // so it is computed once for all the sweeps between two moves.
  double substep_separation = 0;
  double normal_mass = 0, tangent_mass1 = 0, tangent_mass2 = 0;
  // Their inverses (J M^-1 J^T): the velocity change per unit impulse, which measures how much a
  // sweep changed a contact without a division.
  double normal_response = 0, tangent_response1 = 0, tangent_response2 = 0;
  double friction = 0;
  double normal_impulse = 0, tangent_impulse1 = 0, tangent_impulse2 = 0;
  double max_normal_impulse = 0;
  std::uint32_t manifold = 0;                    // index of its NormalBlock
  std::uint8_t block_index = 0, block_size = 1;  // place among its manifold's rows
};

// What a contact point needs outside the sweeps, row for row beside ContactRow: the warm start and
// the exact solver (lever arms), restitution (once a step), position correction and matching the
// next step's points to this step's impulses (anchors in body axes, feature id).
struct ContactRowCold {
  Vec3 ra, rb;            // lever arms from the centres of mass at the step start, world
  Vec3 local_a, local_b;  // the same anchors in body axes
  std::uint64_t feature = 0;
  double restitution = 0;
  double relative_velocity = 0;  // normal velocity at the step start, m/s
  // Soft solver: the normal impulses of the step's substeps before the last. Each substep starts
  // from the last one's impulse (warm start) and ends with its own in normal_impulse, so the
  // step's whole impulse, which is what the world reports, is this sum plus normal_impulse.
  double earlier_substeps_impulse = 0;
};

// The normal rows of one manifold solved together: K = J A J^T over its points and the inverse of
// K slightly regularised. Four points on a face make K singular; that inverse spreads the load
// evenly instead of by the order in which single points would be visited, which is what keeps
// a tall stack from tilting (sequential single points push one corner, then the next).
struct NormalBlock {
  Eigen::Matrix4d inverse = Eigen::Matrix4d::Zero();
};

// Writes the manifold.count rows of one manifold to `rows` and `cold` and its block to `block`,
// which is blocks[block_index]. A row starts from the impulse of the point in `previous` (the
// pair's record of the last step; null: none) with its feature id, or else of the nearest one
// close enough.
void prepare_rows(const ContactManifold& manifold, std::uint32_t solver_a, const Body& a,
                  std::uint32_t solver_b, const Body& b, const ContactPairRecord* previous,
                  std::uint32_t block_index, ContactRow* rows, ContactRowCold* cold,
                  NormalBlock* block);

// Spring parameters of a soft contact over a substep h (Catto 2011, "Soft constraints").
struct Softness {
  double bias_rate = 0, mass_scale = 1, impulse_scale = 0;
};
Softness contact_softness(double hertz, double damping_ratio, double h);

// Sets each row's substep_separation from where the bodies are now: after every move, before the
// sweeps that follow it.
// `kinematic_elapsed`: the time since the step start where kinematic bodies move (else 0; as
// current_separation, and below).
void update_separations(std::span<ContactRow> rows, std::span<const std::uint32_t> ids,
                        std::span<const SolverBody> bodies, double kinematic_elapsed = 0);

// Sets each row's substep_separation (update_separations) and applies its impulse, which
// it starts the sweeps from. With `keep_last_substep` (the soft
// solver's substeps after the first) that impulse is the last substep's whole and is added to the
// row's earlier_substeps_impulse on the way.
void warm_start(std::span<ContactRow> rows, std::span<ContactRowCold> cold,
                std::span<const std::uint32_t> ids, std::span<SolverBody> bodies,
                bool keep_last_substep, double kinematic_elapsed = 0);

// One Gauss-Seidel sweep. With `soft` set, penetration beyond the slop is pushed out through the
// spring; without it contacts are rigid and only gaps (speculative contacts) add bias. Sweeps
// alternate direction (`backward`), so that no end of a stack is always solved last. Returns the
// largest velocity change the sweep gave any contact (m/s): a converged sweep changes nothing.
double solve_contacts(std::span<ContactRow> rows, std::span<const std::uint32_t> ids,
                      std::span<const NormalBlock> blocks, std::span<SolverBody> bodies,
                      const SolverSettings& settings, const Softness* soft, double h,
                      bool backward);

// A manifold's rows: rows[ids[0..count)].
struct ManifoldRows {
  const std::uint32_t* ids = nullptr;
  int count = 0;
};

// One manifold's part of a sweep: its friction point by point, then its normals as a block
// (NormalBlock) when that keeps every impulse non-negative, else point by point. Returns the
// largest velocity change it gave a contact (m/s).
double solve_manifold(std::span<ContactRow> rows, const ManifoldRows& manifold,
                      std::span<const NormalBlock> blocks, std::span<SolverBody> bodies,
                      const SolverSettings& settings, const Softness* soft, double h);

// Gives bouncing contacts their outgoing velocity, e times the approach velocity.
void apply_restitution(std::span<ContactRow> rows, std::span<const ContactRowCold> cold,
                       std::span<const std::uint32_t> ids, std::span<const NormalBlock> blocks,
                       std::span<SolverBody> bodies, const SolverSettings& settings);

// Impacts passed on through bodies that touch, before the solve (Guendelman, Bridson and Fedkiw
// 2003, "Nonconvex rigid bodies with stacking", section 6): each contact that approaches faster
// than the restitution threshold and closes within `reach` s takes, alone, the impulse that sends
// it apart at e times its approach speed, from the velocities as they are by then; the contacts are
// swept again until none approaches, so a blow travels along a row of touching bodies contact by
// contact (Newton's cradle), where one solve of all of them at once moves the row off together.
// Runs only where a blow can travel: some contact bounces and another manifold of the island has
// restitution. Its impulses count in the step's (earlier_substeps_impulse); the contacts it settled
// take no bounce after the solve (relative_velocity 0). Sweeps are bounded (twice the manifolds and
// eight, at most kMostImpactSweeps): past that, the contacts still approaching are left to the
// solve and apply_restitution, as without it, and it returns true.
constexpr int kMostImpactSweeps = 256;
// pass_impacts' gate: the island's manifolds where a blow can travel, else 0.
int impact_manifolds(std::span<const ContactRow> rows, std::span<const ContactRowCold> cold,
                     std::span<const std::uint32_t> ids, const SolverSettings& settings);
bool pass_impacts(std::span<const ContactRow> rows, std::span<ContactRowCold> cold,
                  std::span<const std::uint32_t> ids, std::span<const NormalBlock> blocks,
                  std::span<SolverBody> bodies, const SolverSettings& settings, double reach);

// Nonlinear Gauss-Seidel on positions (Catto, Box2D 2.x): moves bodies out of penetration
// without touching velocities. Point by point, each point's push turns its body and moves the
// points corrected after it, so one order run every time leans a face the same way each step: a
// tower of ten pgs boxes dropped 0.7 m, kept awake, settled and then swayed ever wider until it
// fell at 27 s (twenty and thirty high, within 60 s). Callers alternate `backward` (the rows in
// reverse) from one iteration to the next, as the velocity sweeps alternate theirs (symmetric
// Gauss-Seidel), and the towers stand (tests/test_tall_stacks.cc).
void correct_positions(std::span<const ContactRow> rows, std::span<const ContactRowCold> cold,
                       std::span<const std::uint32_t> ids, std::span<const SolverBody> bodies,
                       std::span<Pose> poses, const SolverSettings& settings, bool backward);

// |min(impulse / effective mass, normal velocity - target)| over the normal rows, m/s.
double normal_residual(std::span<const ContactRow> rows, std::span<const std::uint32_t> ids,
                       std::span<const SolverBody> bodies, double h,
                       double kinematic_elapsed = 0);

inline double normal_velocity(const ContactRow& row, std::span<const SolverBody> bodies) {
  const SolverBody& a = bodies[row.a];
  const SolverBody& b = bodies[row.b];
  return row.normal.dot(b.v - a.v) + b.w.dot(row.rb_cross_n) - a.w.dot(row.ra_cross_n);
}

// Static bodies (inverse mass 0) are never written: islands and colours solved in parallel
// share them.
inline void apply_normal_impulse(const ContactRow& row, double impulse,
                                 std::span<SolverBody> bodies) {
  SolverBody& a = bodies[row.a];
  SolverBody& b = bodies[row.b];
  if (a.inverse_mass > 0) {
    a.v -= (a.inverse_mass * impulse) * row.normal;
    a.w -= impulse * row.angular_a;
  }
  if (b.inverse_mass > 0) {
    b.v += (b.inverse_mass * impulse) * row.normal;
    b.w += impulse * row.angular_b;
  }
}

// Impulses t1 and t2 along the row's tangents, through their angular parts (as the sweeps apply
// friction).
inline void apply_tangent_impulses(const ContactRow& row, double t1, double t2,
                                   std::span<SolverBody> bodies) {
  SolverBody& a = bodies[row.a];
  SolverBody& b = bodies[row.b];
  const Vec3 linear = t1 * row.tangent1 + t2 * row.tangent2;
  if (a.inverse_mass > 0) {
    a.v -= a.inverse_mass * linear;
    a.w -= t1 * row.angular_a_t1 + t2 * row.angular_a_t2;
  }
  if (b.inverse_mass > 0) {
    b.v += b.inverse_mass * linear;
    b.w += t1 * row.angular_b_t1 + t2 * row.angular_b_t2;
  }
}

// The separation of a row now, from the bodies' motion since the step start (to first order in
// the rotation: (dR - 1) r . n ~ (theta x r) . n = theta . (r x n)).
inline double current_separation(const ContactRow& row, std::span<const SolverBody> bodies) {
  const SolverBody& a = bodies[row.a];
  const SolverBody& b = bodies[row.b];
  return row.separation + row.normal.dot(b.delta_position - a.delta_position) +
         b.delta_angle.dot(row.rb_cross_n) - a.delta_angle.dot(row.ra_cross_n);
}

// The same with kinematic bodies (SolverBody::kinematic), `elapsed` seconds after the step start
// (the island's own clock); 0 gives current_separation's answer. Its arithmetic is the packs'
// (contact_packs.cc), bit for bit.
inline double current_separation(const ContactRow& row, std::span<const SolverBody> bodies,
                                 double elapsed) {
  if (elapsed == 0) return current_separation(row, bodies);
  const SolverBody& a = bodies[row.a];
  const SolverBody& b = bodies[row.b];
  Vec3 moved_a = a.delta_position, turned_a = a.delta_angle;
  Vec3 moved_b = b.delta_position, turned_b = b.delta_angle;
  if (a.kinematic) {
    moved_a = moved_a + elapsed * a.v;
    turned_a = turned_a + elapsed * a.w;
  }
  if (b.kinematic) {
    moved_b = moved_b + elapsed * b.v;
    turned_b = turned_b + elapsed * b.w;
  }
  return row.separation + row.normal.dot(moved_b - moved_a) + turned_b.dot(row.rb_cross_n) -
         turned_a.dot(row.ra_cross_n);
}

}  // namespace tumble
