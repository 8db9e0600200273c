// The exact contact solver: every contact of an island at once, as one linear complementarity
// problem with Coulomb friction on a polyhedral cone, solved by Lemke's algorithm.
//
// Formulation after Stewart and Trinkle (1996) and Anitescu and Potra (1997): per contact point
// a normal impulse cn, impulses b_j >= 0 along k directions spanning the tangent plane, and a
// multiplier l (the sliding speed):
//   v_n(+) - target  >= 0  _|_  cn >= 0
//   v_j(+) + l       >= 0  _|_  b_j >= 0
//   mu cn - sum_j b_j >= 0  _|_  l >= 0
// with v(+) the velocities after the impulses. The friction cone is the polygon with k vertices
// mu cn d_j; its first direction is the sliding direction, where the polygon touches the circle.
#pragma once

#include <span>
#include <vector>

#include "contact_solver.h"
#include "joint_state.h"
#include "lemke.h"

namespace tumble {

// Proximal-point passes allowed when the regularised answer misses exact_velocity_tolerance.
constexpr int kExactRefinements = 3;

struct ExactSolveResult {
  LemkeResult lemke;
  // The largest velocity error of the accepted answer (m/s; exact_velocity_error).
  double velocity_error = 0;
  // Penetration was pushed out (or there was none); false leaves it to position correction.
  bool pushed_out = false;
  bool solved() const { return lemke.outcome == LemkeOutcome::kSolved; }
};

// How far an LCP answer z is from right, in m/s: the worst violation of w = M z + q >= 0 and of
// its complementarity with z, over the velocity rows with M's true diagonal `diagonal` (M itself
// may be regularised) and over the friction-cone rows that follow them, whose impulses are made
// velocities by the stiffness of their point's normal row.
double exact_velocity_error(const Eigen::Ref<const Eigen::MatrixXd>& m,
                            std::span<const double> diagonal,
                            const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& z, int velocity_rows);

// Solves the island's rows over a step h and applies the impulses to `bodies` on success; on
// failure nothing is changed. An answer whose velocity error exceeds
// settings.exact_velocity_tolerance is a failure (kInaccurate). On success, penetration is
// pushed out through the bodies' pseudo-velocities (push_v, push_w), not their velocities.
ExactSolveResult solve_contacts_exact(std::span<ContactRow> rows,
                                      std::span<const ContactRowCold> cold,
                                      std::span<const std::uint32_t> ids,
                                      std::span<SolverBody> bodies, const SolverSettings& settings,
                                      double h);

// What the exact solve of an island with joints (exact_joints.h) shares with the contacts' own.
namespace exact_detail {

// One velocity row J v on two bodies (b: kWorldAnchor for a joint's limit against the world),
// with A J^T beside it (A: the inverse mass matrix).
struct Jacobian {
  std::uint32_t body[2];
  Eigen::Matrix<double, 6, 1> j[2];
  Eigen::Matrix<double, 6, 1> aj[2];
};
Jacobian contact_jacobian(const ContactRow& row, const ContactRowCold& cold, const Vec3& direction,
                          std::span<const SolverBody> bodies);
double velocity_along(const Jacobian& jac, std::span<const SolverBody> bodies);

// The unknowns, in order: the velocity rows (each point's normal, then `bounds` one-sided rows of
// the joints, then each point's k friction directions), then each point's sliding speed.
struct Layout {
  int points = 0, bounds = 0, k = 0;
  int velocity_rows() const { return points + bounds + points * k; }
  int size() const { return velocity_rows() + (k > 0 ? points : 0); }
  int tangent(int point, int j) const { return points + bounds + point * k + j; }
};
// k: none for a frictionless island, else the settings' count.
Layout layout_of(std::span<const ContactRow> rows, std::span<const std::uint32_t> ids, int bounds,
                 const SolverSettings& settings);
// A point's friction direction j of k (the polygon's vertex directions).
Vec3 friction_direction(const ContactRow& row, int j, int k);

// The LCP's memory, one per thread (islands are solved on any thread), reused from island to
// island and step to step.
struct Workspace {
  std::vector<Jacobian> jacobians;
  std::vector<double> m, q, z, w, diagonal;
  std::vector<double> push_m, push_q, push_z;
  std::vector<double> refined_q, refined_z;
  LemkeWorkspace lemke;
};
Workspace& thread_workspace();
// Sizes the workspace for a problem of n unknowns, m and q zero, then fills the velocity block
// from workspace.jacobians: m(r, c) = coupling(r, c) for r <= c, mirrored (the block is
// symmetric), and q the rows' velocities now.
template <class Coupling>
void set_velocity_block(Workspace& workspace, int n, int velocity_rows,
                        std::span<const SolverBody> bodies, Coupling coupling) {
  workspace.m.assign(static_cast<std::size_t>(n) * n, 0.0);
  workspace.q.assign(n, 0.0);
  workspace.z.resize(n);
  workspace.w.resize(n);
  Eigen::Map<Eigen::MatrixXd> m(workspace.m.data(), n, n);
  for (int r = 0; r < velocity_rows; ++r) {
    for (int c = r; c < velocity_rows; ++c) {
      const double value = coupling(r, c);
      m(r, c) = value;
      m(c, r) = value;
    }
    workspace.q[r] = velocity_along(workspace.jacobians[r], bodies);
  }
}

// With the velocity block of m and q filled (q: the rows' velocities and the gaps' closing): the
// friction cones' rows, the compliance and perturbation that keep Lemke's pivots well defined,
// Lemke, the refinement and the check of the answer in velocities. The answer is in
// workspace.z; solved() says whether it may be used.
ExactSolveResult solve_problem(const Layout& layout, std::span<const ContactRow> rows,
                               std::span<const std::uint32_t> ids, const SolverSettings& settings,
                               Workspace& workspace);
// The answer's impulses kept in the contact rows (normal and tangent).
void store_contact_impulses(const Layout& layout, std::span<ContactRow> rows,
                            std::span<const std::uint32_t> ids,
                            const Eigen::Ref<const Eigen::VectorXd>& z);

// The push-out LCP over the normal rows (the block of m the solve used), with the bodies'
// velocities after the solve, each point's gap its separation (at the step's start, or the
// substep's with `substep_gaps`). Its answer, the normal rows' pseudo-impulses, is left in
// workspace.push_z (all 0 where nothing needed pushing) for the caller to give the bodies. False
// when it found none (penetration is then left to position correction). With `bound_gaps`, the
// joints' bound rows that follow the normals in the layout (exact_joints.h) join it, each held
// from passing its bound (by more than it is past already): without them a push between a heavy
// body and a light one on its limit moved the light one through the limit alone, and the heavy
// one sank on at its answer's compliance.
bool push_out(std::span<const ContactRow> rows, std::span<const std::uint32_t> ids,
              bool substep_gaps, std::span<const SolverBody> bodies, const SolverSettings& settings,
              double h, Workspace& workspace, ExactSolveResult* result,
              std::span<const double> bound_gaps = {});

}  // namespace exact_detail

}  // namespace tumble
