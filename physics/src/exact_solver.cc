#include "exact_solver.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace tumble {
namespace exact_detail {

Jacobian contact_jacobian(const ContactRow& row, const ContactRowCold& cold, const Vec3& direction,
                          std::span<const SolverBody> bodies) {
  Jacobian out;
  out.body[0] = row.a;
  out.body[1] = row.b;
  out.j[0] << -direction, -cold.ra.cross(direction);
  out.j[1] << direction, cold.rb.cross(direction);
  for (int s = 0; s < 2; ++s) {
    const SolverBody& body = bodies[out.body[s]];
    out.aj[s] << body.inverse_mass * out.j[s].head<3>(), body.inverse_inertia * out.j[s].tail<3>();
  }
  return out;
}

double velocity_along(const Jacobian& jac, std::span<const SolverBody> bodies) {
  double v = 0;
  for (int s = 0; s < 2; ++s) {
    if (jac.body[s] == kWorldAnchor) continue;
    const SolverBody& body = bodies[jac.body[s]];
    v += jac.j[s].head<3>().dot(body.v) + jac.j[s].tail<3>().dot(body.w);
  }
  return v;
}

Layout layout_of(std::span<const ContactRow> rows, std::span<const std::uint32_t> ids, int bounds,
                 const SolverSettings& settings) {
  bool any_friction = false;
  for (std::uint32_t id : ids)
    any_friction |= rows[id].friction > 0;
  Layout layout;
  layout.points = static_cast<int>(ids.size());
  layout.bounds = bounds;
  // Frictionless islands need no tangent rows at all.
  layout.k = any_friction ? std::clamp(settings.friction_directions, 4, 32) : 0;
  return layout;
}

Vec3 friction_direction(const ContactRow& row, int j, int k) {
  const double angle = 2 * std::numbers::pi * j / k;
  return std::cos(angle) * row.tangent1 + std::sin(angle) * row.tangent2;
}

Workspace& thread_workspace() {
  thread_local Workspace workspace;
  return workspace;
}

ExactSolveResult solve_problem(const Layout& layout, std::span<const ContactRow> rows,
                               std::span<const std::uint32_t> ids, const SolverSettings& settings,
                               Workspace& workspace) {
  const int n = layout.size(), velocity_rows = layout.velocity_rows(), points = layout.points;
  const int k = layout.k;
  Eigen::Map<Eigen::MatrixXd> m(workspace.m.data(), n, n);
  Eigen::Map<Eigen::VectorXd> q(workspace.q.data(), n);
  Eigen::Map<Eigen::VectorXd> z(workspace.z.data(), n);
  if (k > 0) {
    const int lambda0 = velocity_rows;
    for (int p = 0; p < points; ++p) {
      for (int j = 0; j < k; ++j) {
        m(layout.tangent(p, j), lambda0 + p) = 1;
        m(lambda0 + p, layout.tangent(p, j)) = -1;
      }
      m(lambda0 + p, p) = rows[ids[p]].friction;
    }
  }
  // Four points on a face, and k friction directions on three degrees of freedom, make the
  // velocity block singular; Lemke then pivots on round-off and can stop on a false ray. A
  // compliance of 1e-6 of each row's own stiffness keeps the pivots well defined and leaves a
  // velocity error of one millionth of what the row's impulse does.
  workspace.diagonal.resize(velocity_rows);
  for (int r = 0; r < velocity_rows; ++r) {
    workspace.diagonal[r] = m(r, r);
    m(r, r) *= 1 + 1e-6;
  }

  // Resting contacts make the problem degenerate (many rows of q exactly 0: the sliding rows,
  // the friction of still contacts), and round-off then decides ties that the lexicographic rule
  // is meant to decide. A distinct perturbation of each row, 1e-11 of q's scale at most (Charnes'
  // perturbation method, of which the lexicographic rule is the symbolic form), makes the ties
  // real numbers again; it changes velocities by 1e-11 m/s.
  const double perturbation = 1e-11 * std::max(1.0, q.cwiseAbs().maxCoeff());
  for (int i = 0; i < n; ++i)
    q[i] += perturbation * (i + 1) / n;

  ExactSolveResult result;
  const int max_pivots = std::max(100, settings.lemke_pivots_per_unknown * n);
  result.lemke = solve_lcp_lemke(m, q, max_pivots, z, &workspace.lemke);
  if (!result.solved()) {
    // Rarely the pivots still meet round-off: once more with a hundred times the compliance
    // (1e-4, still far below what a step shows) before giving the island to PGS.
    for (int r = 0; r < velocity_rows; ++r)
      m(r, r) *= 1 + 1e-4;
    const int spent = result.lemke.pivots;
    result.lemke = solve_lcp_lemke(m, q, max_pivots, z, &workspace.lemke);
    result.lemke.pivots += spent;
  }
  if (result.solved()) {
    // Trust but verify, in velocities: a path that ended on round-off can report success with a
    // wrong basis, and impulses of 1e10 N s can satisfy any test relative to themselves.
    result.velocity_error = exact_velocity_error(m, workspace.diagonal, q, z, velocity_rows);
    // The compliance leaves a velocity error of itself times the row's own velocity change, which
    // a heavy load on a light body makes large (1e-4 x 160 m/s under 1000 kg). Proximal-point
    // refinement (Rockafellar 1976) removes it with the same well-conditioned matrix: solving
    // LCP(M + E, q - E z) again has the answer of the problem without E as its fixed point.
    workspace.refined_q.resize(n);
    workspace.refined_z.resize(n);
    Eigen::Map<Eigen::VectorXd> refined_q(workspace.refined_q.data(), n);
    Eigen::Map<Eigen::VectorXd> refined_z(workspace.refined_z.data(), n);
    for (int pass = 0;
         pass < kExactRefinements && result.velocity_error > settings.exact_velocity_tolerance;
         ++pass) {
      refined_q = q;
      for (int r = 0; r < velocity_rows; ++r)
        refined_q[r] -= (m(r, r) - workspace.diagonal[r]) * z[r];
      const LemkeResult again =
          solve_lcp_lemke(m, refined_q, max_pivots, refined_z, &workspace.lemke);
      result.lemke.pivots += again.pivots;
      if (again.outcome != LemkeOutcome::kSolved || !refined_z.allFinite()) break;
      const double error = exact_velocity_error(m, workspace.diagonal, q, refined_z, velocity_rows);
      if (!(error < result.velocity_error)) break;
      z = refined_z;
      result.velocity_error = error;
    }
    if (!(result.velocity_error <= settings.exact_velocity_tolerance))
      result.lemke.outcome = LemkeOutcome::kInaccurate;
  }
  if (result.solved() && !z.allFinite()) result.lemke.outcome = LemkeOutcome::kNotFinite;
  return result;
}

void store_contact_impulses(const Layout& layout, std::span<ContactRow> rows,
                            std::span<const std::uint32_t> ids,
                            const Eigen::Ref<const Eigen::VectorXd>& z) {
  for (int p = 0; p < layout.points; ++p) {
    ContactRow& row = rows[ids[p]];
    row.normal_impulse = z[p];
    // The largest of the step's (its substeps'), as the sweeps keep it: restitution reads it.
    row.max_normal_impulse = std::max(row.max_normal_impulse, z[p]);
    double t1 = 0, t2 = 0;
    for (int j = 0; j < layout.k; ++j) {
      const double angle = 2 * std::numbers::pi * j / layout.k;
      t1 += z[layout.tangent(p, j)] * std::cos(angle);
      t2 += z[layout.tangent(p, j)] * std::sin(angle);
    }
    row.tangent_impulse1 = t1;
    row.tangent_impulse2 = t2;
  }
}

// Moves the island's bodies out of penetration without giving them velocity (split impulse,
// Catto 2006; Bullet's "split impulse"): the normal rows once more, as their own LCP, with the
// velocities the solve left and a target separating speed for penetration beyond the slop;
// the answer is a pseudo-velocity that only the position update sees. Solved exactly, so a
// 1 kg box is pushed out from under 1000 kg as surely as the velocities are.
bool push_out(std::span<const ContactRow> rows, std::span<const std::uint32_t> ids,
              bool substep_gaps, std::span<const SolverBody> bodies, const SolverSettings& settings,
              double h, Workspace& workspace, ExactSolveResult* result,
              std::span<const double> bound_gaps) {
  const int points = static_cast<int>(ids.size());
  const int rows_pushed = points + static_cast<int>(bound_gaps.size());
  const Eigen::Index n = static_cast<Eigen::Index>(workspace.q.size());
  const Eigen::Map<const Eigen::MatrixXd> m(workspace.m.data(), n, n);
  workspace.push_q.resize(rows_pushed);
  workspace.push_z.assign(rows_pushed, 0.0);
  Eigen::Map<Eigen::VectorXd> q(workspace.push_q.data(), rows_pushed);
  for (std::size_t b = 0; b < bound_gaps.size(); ++b)
    q[points + static_cast<Eigen::Index>(b)] =
        velocity_along(workspace.jacobians[points + b], bodies) + std::max(bound_gaps[b], 0.0) / h;
  bool any = false;
  for (int p = 0; p < points; ++p) {
    const ContactRow& row = rows[ids[p]];
    const double separation = substep_gaps ? row.substep_separation : row.separation;
    q[p] = velocity_along(workspace.jacobians[p], bodies);
    if (separation > 0) {
      q[p] += separation / h;
    } else if (separation + settings.slop < 0) {
      q[p] -= std::min(settings.baumgarte * -(separation + settings.slop) / h,
                       settings.max_push_velocity);
    }
    any |= q[p] < 0;
  }
  if (!any) return true;
  workspace.push_m.resize(static_cast<std::size_t>(rows_pushed) * rows_pushed);
  Eigen::Map<Eigen::MatrixXd> mp(workspace.push_m.data(), rows_pushed, rows_pushed);
  Eigen::Map<Eigen::VectorXd> z(workspace.push_z.data(), rows_pushed);
  mp = m.topLeftCorner(rows_pushed, rows_pushed);
  const LemkeResult lemke = solve_lcp_lemke(
      mp, q, std::max(100, settings.lemke_pivots_per_unknown * rows_pushed), z, &workspace.lemke);
  result->lemke.pivots += lemke.pivots;
  if (lemke.outcome != LemkeOutcome::kSolved || !z.allFinite()) return false;
  const double error =
      exact_velocity_error(mp, std::span(workspace.diagonal).first(rows_pushed), q, z, rows_pushed);
  return error <= settings.exact_velocity_tolerance;
}

}  // namespace exact_detail

namespace {

using namespace exact_detail;

double coupling(const Jacobian& r, const Jacobian& c, std::span<const SolverBody> bodies) {
  double sum = 0;
  for (int s = 0; s < 2; ++s) {
    if (bodies[r.body[s]].inverse_mass == 0) continue;
    for (int t = 0; t < 2; ++t)
      if (r.body[s] == c.body[t]) sum += r.j[s].dot(c.aj[t]);
  }
  return sum;
}

}  // namespace

double exact_velocity_error(const Eigen::Ref<const Eigen::MatrixXd>& m,
                            std::span<const double> diagonal,
                            const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& z, int velocity_rows) {
  const Eigen::Index n = q.size();
  double worst = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    double w = m.row(i).dot(z) + q[i];
    if (i < velocity_rows) {
      // The velocity of the problem without the regularisation: the compliance that keeps the
      // pivots well defined must not hide a wrong velocity either.
      w -= (m(i, i) - diagonal[i]) * z[i];
      worst = std::max({worst, -w, std::min(w, z[i] * diagonal[i])});
    } else {
      // A friction-cone row, in N s: mu cn - sum b >= 0 against the sliding speed z[i], m/s. The
      // impulse is made a velocity by the stiffness of the point's normal row.
      const Eigen::Index point = (i - velocity_rows);
      const double stiffness = diagonal[point];
      worst = std::max({worst, -w * stiffness, std::min(w * stiffness, z[i])});
    }
  }
  return worst;
}

ExactSolveResult solve_contacts_exact(std::span<ContactRow> rows,
                                      std::span<const ContactRowCold> cold,
                                      std::span<const std::uint32_t> ids,
                                      std::span<SolverBody> bodies, const SolverSettings& settings,
                                      double h) {
  const Layout layout = layout_of(rows, ids, 0, settings);
  const int points = layout.points, k = layout.k;
  const int velocity_rows = layout.velocity_rows(), n = layout.size();

  // Velocity rows: the normals first, then each point's k directions.
  Workspace& workspace = thread_workspace();
  std::vector<Jacobian>& jac = workspace.jacobians;
  jac.clear();
  for (std::uint32_t id : ids)
    jac.push_back(contact_jacobian(rows[id], cold[id], rows[id].normal, bodies));
  for (std::uint32_t id : ids)
    for (int j = 0; j < k; ++j)
      jac.push_back(
          contact_jacobian(rows[id], cold[id], friction_direction(rows[id], j, k), bodies));

  set_velocity_block(workspace, n, velocity_rows, bodies,
                     [&](int r, int c) { return coupling(jac[r], jac[c], bodies); });
  Eigen::Map<Eigen::VectorXd> q(workspace.q.data(), n);
  Eigen::Map<Eigen::VectorXd> z(workspace.z.data(), n);
  // A gap may close within the step, no more (the speculative contact). Penetration is not
  // pushed out here: a push velocity would stay in the bodies (two boxes spawned overlapping
  // would fly apart); push_out below moves them instead.
  for (int p = 0; p < points; ++p)
    if (rows[ids[p]].separation > 0) q[p] += rows[ids[p]].separation / h;

  ExactSolveResult result = solve_problem(layout, rows, ids, settings, workspace);
  if (!result.solved()) return result;

  for (int r = 0; r < velocity_rows; ++r) {
    if (z[r] == 0) continue;
    for (int s = 0; s < 2; ++s) {
      SolverBody& body = bodies[jac[r].body[s]];
      if (body.inverse_mass == 0) continue;
      body.v += z[r] * jac[r].aj[s].head<3>();
      body.w += z[r] * jac[r].aj[s].tail<3>();
    }
  }
  store_contact_impulses(layout, rows, ids, z);
  result.pushed_out = push_out(rows, ids, false, bodies, settings, h, workspace, &result);
  if (!result.pushed_out) return result;
  for (int p = 0; p < points; ++p) {
    const double push = workspace.push_z[p];
    if (push == 0) continue;
    for (int s = 0; s < 2; ++s) {
      SolverBody& body = bodies[jac[p].body[s]];
      if (body.inverse_mass == 0) continue;
      body.push_v += push * jac[p].aj[s].head<3>();
      body.push_w += push * jac[p].aj[s].tail<3>();
    }
  }
  return result;
}

}  // namespace tumble
