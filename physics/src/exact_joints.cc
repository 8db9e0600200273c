#include "exact_joints.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "joint_axial.h"

namespace tumble {
namespace {

using namespace exact_detail;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// What the solve keeps besides exact_solver's workspace, one per thread.
struct JointWorkspace {
  std::vector<BoundRow> bounds;
  std::vector<std::uint32_t> bound_joint;  // each bound row's joint (index into the rows)
  // The bodies the rows touch that move, and each one's place among them (by solver index).
  std::vector<std::uint32_t> row_bodies, place_of;
  // Each velocity row's response: the velocity change of every row body (6 a body) per unit
  // impulse along it, column by column.
  std::vector<double> response;
  std::vector<JointTree::BodyImpulse> impulses;
  std::vector<Vec6> totals;                  // an impulse per row body
  std::vector<double> tangent_1, tangent_2;  // a point's tangents' responses
  std::vector<double> bound_gaps;            // the bounds' gaps, for the push-out
};

JointWorkspace& joint_workspace() {
  thread_local JointWorkspace workspace;
  return workspace;
}

constexpr std::uint32_t kNoPlace = UINT32_MAX;

Jacobian bound_jacobian(const BoundRow& bound, const JointRow& row,
                        std::span<const SolverBody> bodies) {
  Jacobian out;
  out.body[0] = row.a;
  out.body[1] = row.b;
  out.j[0] << -bound.row.linear, bound.row.angular_a;
  out.j[1] << bound.row.linear, bound.row.angular_b;
  for (int s = 0; s < 2; ++s) {
    if (out.body[s] == kWorldAnchor) {
      out.aj[s].setZero();
      continue;
    }
    const SolverBody& body = bodies[out.body[s]];
    out.aj[s] << body.inverse_mass * out.j[s].head<3>(), body.inverse_inertia * out.j[s].tail<3>();
  }
  return out;
}

bool moving(std::span<const SolverBody> bodies, std::uint32_t body) {
  return body != kWorldAnchor && bodies[body].inverse_mass > 0;
}

// The tree's response to the impulses in `totals` on its bodies (through_tree: whether any act
// on them). False where the tree gives none.
bool respond_in_tree(JointWorkspace& w, JointTree& tree, bool* through_tree) {
  w.impulses.clear();
  for (std::size_t i = 0; i < w.row_bodies.size(); ++i)
    if (tree.holds(w.row_bodies[i]) && !w.totals[i].isZero())
      w.impulses.push_back({w.row_bodies[i], w.totals[i]});
  *through_tree = !w.impulses.empty();
  return !*through_tree || tree.respond(w.impulses);
}

// The velocity change of every row body for the impulses (an impulse per row body, in `totals`),
// through the joints where the tree holds the body, freely where it does not; into `out` (6 a row
// body). False where the tree gives none.
bool response_to(JointWorkspace& w, JointTree& tree, std::span<const SolverBody> bodies,
                 double* out) {
  const std::size_t count = w.row_bodies.size();
  bool through_tree = false;
  if (!respond_in_tree(w, tree, &through_tree)) return false;
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t body = w.row_bodies[i];
    Eigen::Map<Vec6> change(out + 6 * i);
    if (tree.holds(body)) {
      change = through_tree ? tree.change_of(body) : Vec6(Vec6::Zero());
    } else {
      const SolverBody& free = bodies[body];
      change << free.inverse_mass * w.totals[i].head<3>(),
          free.inverse_inertia * w.totals[i].tail<3>();
    }
  }
  return true;
}

// Sets `totals` to the impulses J^T z of the rows (z: one per row of `jacobians`).
void gather(JointWorkspace& w, std::span<const Jacobian> jacobians,
            const Eigen::Ref<const Eigen::VectorXd>& z) {
  w.totals.assign(w.row_bodies.size(), Vec6::Zero());
  for (std::size_t r = 0; r < jacobians.size(); ++r) {
    if (z[static_cast<Eigen::Index>(r)] == 0) continue;
    for (int s = 0; s < 2; ++s) {
      const std::uint32_t body = jacobians[r].body[s];
      if (body == kWorldAnchor || w.place_of[body] == kNoPlace) continue;
      w.totals[w.place_of[body]] += z[static_cast<Eigen::Index>(r)] * jacobians[r].j[s];
    }
  }
}

// Gives the bodies the impulses in `totals`: the tree's bodies through the joints (their rows'
// impulses added, unless `pseudo`), the others freely; as velocities, or as pseudo-velocities.
bool apply_totals(JointWorkspace& w, JointTree& tree, std::span<JointRow> joint_rows,
                  std::span<SolverBody> bodies, bool pseudo) {
  bool through_tree = false;
  if (!respond_in_tree(w, tree, &through_tree)) return false;
  if (through_tree) tree.apply_response(joint_rows, bodies, pseudo);
  for (std::size_t i = 0; i < w.row_bodies.size(); ++i) {
    const std::uint32_t index = w.row_bodies[i];
    if (tree.holds(index)) continue;
    SolverBody& body = bodies[index];
    (pseudo ? body.push_v : body.v) += body.inverse_mass * w.totals[i].head<3>();
    (pseudo ? body.push_w : body.w) += body.inverse_inertia * w.totals[i].tail<3>();
  }
  return true;
}

}  // namespace

ExactSolveResult solve_island_exact(std::span<ContactRow> rows,
                                    std::span<const ContactRowCold> cold,
                                    std::span<const std::uint32_t> ids,
                                    std::span<JointRow> joint_rows,
                                    std::span<const std::uint32_t> joints, JointTree& tree,
                                    std::span<SolverBody> bodies, std::span<const Pose> poses,
                                    const SolverSettings& settings, double h) {
  JointWorkspace& w = joint_workspace();
  Workspace& workspace = thread_workspace();
  // The joints' one-sided rows at the substep's poses.
  w.bounds.clear();
  w.bound_joint.clear();
  for (std::uint32_t j : joints) {
    const JointRow& row = joint_rows[j];
    const bool world_b = row.b == kWorldAnchor;
    BoundRow found[2];
    const int count =
        bound_rows(row.joint, poses[row.a], world_b ? Pose{} : poses[row.b], world_b, found);
    for (int i = 0; i < count; ++i) {
      w.bounds.push_back(found[i]);
      w.bound_joint.push_back(j);
    }
  }
  const Layout layout = layout_of(rows, ids, static_cast<int>(w.bounds.size()), settings);
  const int points = layout.points, k = layout.k, bounds = layout.bounds;
  const int velocity_rows = layout.velocity_rows(), n = layout.size();
  ExactSolveResult result;
  result.pushed_out = true;
  if (n == 0) return result;

  // The rows in the layout's order: normals, bounds, then each point's k directions.
  std::vector<Jacobian>& jac = workspace.jacobians;
  jac.clear();
  for (std::uint32_t id : ids)
    jac.push_back(contact_jacobian(rows[id], cold[id], rows[id].normal, bodies));
  for (int b = 0; b < bounds; ++b)
    jac.push_back(bound_jacobian(w.bounds[b], joint_rows[w.bound_joint[b]], bodies));
  for (std::uint32_t id : ids)
    for (int j = 0; j < k; ++j)
      jac.push_back(
          contact_jacobian(rows[id], cold[id], friction_direction(rows[id], j, k), bodies));

  // The moving bodies the rows touch.
  if (w.place_of.size() < bodies.size()) w.place_of.resize(bodies.size(), kNoPlace);
  w.row_bodies.clear();
  for (const Jacobian& row : jac)
    for (std::uint32_t body : row.body)
      if (moving(bodies, body) && w.place_of[body] == kNoPlace) {
        w.place_of[body] = static_cast<std::uint32_t>(w.row_bodies.size());
        w.row_bodies.push_back(body);
      }
  const int row_body_count = static_cast<int>(w.row_bodies.size());
  struct ClearPlaces {
    JointWorkspace& w;
    ~ClearPlaces() {
      for (std::uint32_t body : w.row_bodies)
        w.place_of[body] = kNoPlace;
    }
  } clear_places{w};

  // Each row's response. A friction direction's is the mix of its point's two tangents'
  // (the response is linear in the row), so a point costs three solves, not 1 + k.
  const int body_values = 6 * row_body_count;
  // Every column is written whole (response_to sets every row body's change).
  w.response.resize(static_cast<std::size_t>(body_values) * velocity_rows);
  Eigen::Map<Eigen::MatrixXd> response(w.response.data(), body_values, velocity_rows);
  auto respond_to_row = [&](const Jacobian& row, double* out) {
    w.totals.assign(w.row_bodies.size(), Vec6::Zero());
    for (int s = 0; s < 2; ++s)
      if (moving(bodies, row.body[s])) w.totals[w.place_of[row.body[s]]] += row.j[s];
    return response_to(w, tree, bodies, out);
  };
  for (int r = 0; r < points + bounds; ++r)
    if (!respond_to_row(jac[r], response.col(r).data())) {
      result.lemke.outcome = LemkeOutcome::kNotFinite;
      return result;
    }
  if (k > 0) {
    w.tangent_1.resize(body_values);
    w.tangent_2.resize(body_values);
    const Eigen::Map<const Eigen::VectorXd> tangent_1(w.tangent_1.data(), body_values);
    const Eigen::Map<const Eigen::VectorXd> tangent_2(w.tangent_2.data(), body_values);
    for (int p = 0; p < points; ++p) {
      const ContactRow& row = rows[ids[p]];
      if (!respond_to_row(contact_jacobian(row, cold[ids[p]], row.tangent1, bodies),
                          w.tangent_1.data()) ||
          !respond_to_row(contact_jacobian(row, cold[ids[p]], row.tangent2, bodies),
                          w.tangent_2.data())) {
        result.lemke.outcome = LemkeOutcome::kNotFinite;
        return result;
      }
      for (int j = 0; j < k; ++j) {
        const double angle = 2 * std::numbers::pi * j / k;
        response.col(layout.tangent(p, j)) =
            std::cos(angle) * tangent_1 + std::sin(angle) * tangent_2;
      }
    }
  }

  // m = J S J^T, S the response (symmetric, as S is).
  set_velocity_block(workspace, n, velocity_rows, bodies, [&](int r, int c) {
    double value = 0;
    for (int s = 0; s < 2; ++s) {
      const std::uint32_t body = jac[r].body[s];
      if (moving(bodies, body))
        value += jac[r].j[s].dot(response.col(c).segment<6>(6 * w.place_of[body]));
    }
    return value;
  });
  Eigen::Map<Eigen::VectorXd> q(workspace.q.data(), n);
  Eigen::Map<Eigen::VectorXd> z(workspace.z.data(), n);
  // A gap may close within the move, no more (the speculative contact, and the limits' margin as
  // their Gauss-Seidel rows keep it); penetration is pushed out below.
  for (int p = 0; p < points; ++p)
    if (rows[ids[p]].substep_separation > 0) q[p] += rows[ids[p]].substep_separation / h;
  for (int b = 0; b < bounds; ++b)
    q[points + b] += std::max(w.bounds[b].gap, 0.0) / h;

  result = solve_problem(layout, rows, ids, settings, workspace);
  if (!result.solved()) return result;
  gather(w, jac, z.head(velocity_rows));
  if (!apply_totals(w, tree, joint_rows, bodies, false)) {
    result.lemke.outcome = LemkeOutcome::kNotFinite;
    return result;
  }
  store_contact_impulses(layout, rows, ids, z);
  for (int b = 0; b < bounds; ++b)
    keep_bound_impulse(joint_rows[w.bound_joint[b]].joint, w.bounds[b].side, z[points + b]);
  // The push-out keeps the bounds too (exact_solver.h, push_out).
  w.bound_gaps.clear();
  for (int b = 0; b < bounds; ++b)
    w.bound_gaps.push_back(w.bounds[b].gap);
  result.pushed_out =
      push_out(rows, ids, true, bodies, settings, h, workspace, &result, w.bound_gaps);
  if (result.pushed_out && points > 0) {
    const Eigen::Map<const Eigen::VectorXd> push(workspace.push_z.data(), points + bounds);
    gather(w, std::span(jac).first(points + bounds), push);
    result.pushed_out = apply_totals(w, tree, joint_rows, bodies, true);
  }
  return result;
}

}  // namespace tumble
