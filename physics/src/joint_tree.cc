#include "joint_tree.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "joint_geometry.h"
#include "rotation.h"
#include "wide.h"

namespace tumble {
namespace {

// Whether a joint has rows the tree holds (a distance joint with a spring or a range has none).
bool holds_rows(const Joint& joint) {
  return joint.kind != JointKind::kDistance || joint_detail::rigid_distance(joint);
}

bool moves(std::span<const SolverBody> bodies, std::uint32_t body) {
  return body != kWorldAnchor && bodies[body].inverse_mass > 0;
}

// The inverse of a symmetric definite N x N block (N = 5 or 6: a joint's rows) through its leading
// 3 x 3 block and that block's Schur complement (N - 3 square): fixed-size closed forms, several
// times faster than a general factorisation of a small matrix. A singular block gives non-finite
// entries.
template <int N>
Eigen::Matrix<double, N, N> inverse_of_definite(const Eigen::Matrix<double, N, N>& m) {
  constexpr int R = N - 3;
  using Corner = Eigen::Matrix<double, 3, R>;
  const Mat3 a_inverse = m.template topLeftCorner<3, 3>().inverse();
  const Corner b = m.template topRightCorner<3, R>();
  const Corner a_inverse_b = a_inverse * b;
  const Eigen::Matrix<double, R, R> schur_inverse =
      (m.template bottomRightCorner<R, R>() - b.transpose() * a_inverse_b).inverse();
  const Corner corner = -a_inverse_b * schur_inverse;
  Eigen::Matrix<double, N, N> inverse;
  inverse.template topLeftCorner<3, 3>() = a_inverse - corner * a_inverse_b.transpose();
  inverse.template topRightCorner<3, R>() = corner;
  inverse.template bottomLeftCorner<R, 3>() = corner.transpose();
  inverse.template bottomRightCorner<R, R>() = schur_inverse;
  return inverse;
}

// A ball joint's 3 x 3 blocks, kept in the top-left corners of 6 x 6 storage (stride 6), worked
// on in place and inline: through Eigen's general block expressions these were calls of their own
// that went through copies of the block. Each sum keeps the order Eigen 3.4 gives it on this
// storage (found against the pinned joint hashes, Determinism.PinnedJointSceneHashes), so the bits
// are the same: a cofactor's products as Eigen's inverse forms them, the products' orders below.
using Corner3 = Eigen::Block<Eigen::Matrix<double, 6, 6>, 3, 3>;
using ConstCorner3 = Eigen::Block<const Eigen::Matrix<double, 6, 6>, 3, 3>;

// m's inverse in place (Eigen's closed form for 3 x 3: cofactors over the determinant).
TUMBLE_INLINE void invert_in_place(Corner3 m) {
  const auto cofactor = [&](int i1, int j1, int i2, int j2) {
    return m(i1, j1) * m(i2, j2) - m(i1, j2) * m(i2, j1);
  };
  // cofactor_3x3<i, j>: rows i+1, i+2 and columns j+1, j+2 (mod 3).
  const double c00 = cofactor(1, 1, 2, 2), c10 = cofactor(2, 1, 0, 2), c20 = cofactor(0, 1, 1, 2);
  const double det = c00 * m(0, 0) + c10 * m(1, 0) + c20 * m(2, 0);
  const double invdet = 1.0 / det;
  const double c01 = cofactor(1, 2, 2, 0), c11 = cofactor(2, 2, 0, 0), c21 = cofactor(0, 2, 1, 0);
  const double c02 = cofactor(1, 0, 2, 1), c12 = cofactor(2, 0, 0, 1), c22 = cofactor(0, 0, 1, 1);
  m(0, 0) = c00 * invdet;
  m(0, 1) = c10 * invdet;
  m(0, 2) = c20 * invdet;
  m(1, 0) = c01 * invdet;
  m(1, 1) = c11 * invdet;
  m(1, 2) = c21 * invdet;
  m(2, 0) = c02 * invdet;
  m(2, 1) = c12 * invdet;
  m(2, 2) = c22 * invdet;
}
// out = a b. Eigen sums this product's first two rows in packets, each left to right, and its third
// alone, where its unrolled reduction adds the last two terms first.
TUMBLE_INLINE void multiply_into(Corner3 out, ConstCorner3 a, ConstCorner3 b) {
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 2; ++i)
      out(i, j) = a(i, 0) * b(0, j) + a(i, 1) * b(1, j) + a(i, 2) * b(2, j);
    out(2, j) = a(2, 0) * b(0, j) + (a(2, 1) * b(1, j) + a(2, 2) * b(2, j));
  }
}
// out -= a^T b (each sum left to right, as Eigen's).
TUMBLE_INLINE void subtract_transposed_product(Corner3 out, ConstCorner3 a, ConstCorner3 b) {
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      out(i, j) -= a(0, i) * b(0, j) + a(1, i) * b(1, j) + a(2, i) * b(2, j);
}

}  // namespace

bool JointTree::build(std::span<const std::uint32_t> joints, std::span<const JointRow> rows,
                      std::span<const SolverBody> bodies, std::size_t body_count) {
  // The same joints between the same bodies as the island built last (a steady scene, each step):
  // the same forest; only what the step changed (the bodies' inertias, the motors) is refreshed.
  shape_.clear();
  for (std::uint32_t j : joints) {
    const JointRow& row = rows[j];
    shape_.push_back({j, row.a, row.b,
                      static_cast<std::uint8_t>((holds_rows(row.joint) ? 1 : 0) |
                                                (moves(bodies, row.a) ? 2 : 0) |
                                                (moves(bodies, row.b) ? 4 : 0))});
  }
  std::vector<std::uint32_t>& node_of_body = index_->node_of_body;
  if (node_of_body.size() < body_count) node_of_body.resize(body_count, kNone);
  if (built_ && shape_ == built_shape_) {
    for (std::size_t k = 0; k < tree_bodies_.size(); ++k)
      node_of_body[tree_bodies_[k].index] = static_cast<std::uint32_t>(k);
    finish_build(rows, bodies);
    return true;
  }
  built_ = false;
  built_shape_ = shape_;
  bodies_used_.clear();
  nodes_.clear();
  first_edge_.clear();
  next_edge_.clear();
  edge_to_.clear();
  // Nodes in the joints' order, then edges joint - moving body.
  auto add_node = [&](bool is_joint, std::uint32_t index) {
    nodes_.push_back({});
    nodes_.back().is_joint = is_joint;
    nodes_.back().index = index;
    first_edge_.push_back(kNone);
    return static_cast<std::uint32_t>(nodes_.size() - 1);
  };
  auto add_edge = [&](std::uint32_t from, std::uint32_t to) {
    edge_to_.push_back(to);
    next_edge_.push_back(first_edge_[from]);
    first_edge_[from] = static_cast<std::uint32_t>(edge_to_.size() - 1);
  };
  for (std::uint32_t j : joints) {
    const JointRow& row = rows[j];
    if (!holds_rows(row.joint)) continue;
    const bool moves_a = moves(bodies, row.a), moves_b = moves(bodies, row.b);
    if (!moves_a && !moves_b) continue;
    const std::uint32_t joint_node = add_node(true, j);
    for (const auto& [body, moving] : {std::pair{row.a, moves_a}, std::pair{row.b, moves_b}}) {
      if (!moving) continue;
      if (node_of_body[body] == kNone) {
        node_of_body[body] = add_node(false, body);
        bodies_used_.push_back(body);
      }
      add_edge(joint_node, node_of_body[body]);
      add_edge(node_of_body[body], joint_node);
    }
  }
  // Each tree rooted at its one joint to a static body or the world, if it has one (a joint's
  // node must have a body below it to be eliminated), else at a body. Depth first; a node met
  // twice, or a second joint to the world in one tree, is a loop.
  const std::size_t n = nodes_.size();
  visited_.assign(n, 0);
  order_.clear();
  std::vector<std::uint32_t>& parent_of = parent_of_;
  parent_of.assign(n, kNone);
  std::vector<std::uint32_t>& pending = pending_;
  auto grounded = [&](std::uint32_t node) {
    if (!nodes_[node].is_joint) return false;
    const JointRow& row = rows[nodes_[node].index];
    return !moves(bodies, row.a) || !moves(bodies, row.b);
  };
  auto visit_tree = [&](std::uint32_t root) {
    pending.clear();
    pending.push_back(root);
    visited_[root] = 1;
    bool grounded_seen = grounded(root);
    while (!pending.empty()) {
      const std::uint32_t node = pending.back();
      pending.pop_back();
      order_.push_back(node);
      for (std::uint32_t e = first_edge_[node]; e != kNone; e = next_edge_[e]) {
        const std::uint32_t next = edge_to_[e];
        if (next == parent_of[node]) continue;
        if (visited_[next]) return false;  // a loop
        if (grounded(next)) {
          if (grounded_seen) return false;  // a loop through the world
          grounded_seen = true;
        }
        visited_[next] = 1;
        parent_of[next] = node;
        pending.push_back(next);
      }
    }
    return true;
  };
  bool forest = true;
  for (std::uint32_t node = 0; forest && node < n; ++node)
    if (grounded(node) && !visited_[node]) forest = visit_tree(node);
  for (std::uint32_t node = 0; forest && node < n; ++node)
    if (!visited_[node]) forest = visit_tree(node);
  auto give_up = [&] {
    detach();
    bodies_used_.clear();
    nodes_.clear();
    joints_.clear();
    tree_bodies_.clear();
    built_shape_.clear();
    return false;
  };
  if (!forest) return give_up();
  // Children before parents: the visit's order reversed. Nodes are renumbered in that order.
  std::vector<std::uint32_t>& new_index = first_edge_;  // no longer needed as edges
  new_index.assign(n, kNone);
  for (std::size_t k = 0; k < n; ++k)
    new_index[order_[n - 1 - k]] = static_cast<std::uint32_t>(k);
  std::vector<Node>& ordered = reordered_;
  ordered.resize(n);
  for (std::size_t old = 0; old < n; ++old) {
    Node& node = ordered[new_index[old]];
    node = nodes_[old];
    node.parent = parent_of[old] == kNone ? kNone : new_index[parent_of[old]];
  }
  nodes_.swap(ordered);
  if (!number_forest(rows, bodies)) return give_up();
  equations_.resize(joints_.size());
  built_ = true;
  finish_build(rows, bodies);
  return true;
}

void JointTree::detach() {
  if (index_ == nullptr) return;
  for (std::uint32_t body : bodies_used_)
    index_->node_of_body[body] = kNone;
  index_ = nullptr;
}

bool JointTree::number_forest(std::span<const JointRow> rows, std::span<const SolverBody> bodies) {
  const std::size_t n = nodes_.size();
  // Joints and bodies numbered in the nodes' order (children before parents).
  std::vector<std::uint32_t>& numbered = numbered_;
  numbered.assign(n, kNone);
  joints_.clear();
  tree_bodies_.clear();
  for (std::size_t k = 0; k < n; ++k) {
    const Node& node = nodes_[k];
    if (node.is_joint) {
      numbered[k] = static_cast<std::uint32_t>(joints_.size());
      joints_.push_back({});
      joints_.back().row = node.index;
    } else {
      numbered[k] = static_cast<std::uint32_t>(tree_bodies_.size());
      index_->node_of_body[node.index] = numbered[k];
      tree_bodies_.push_back({});
      tree_bodies_.back().index = node.index;
    }
  }
  for (TreeJoint& joint : joints_) {
    const JointRow& row = rows[joint.row];
    if (moves(bodies, row.a)) joint.body_a = index_->node_of_body[row.a];
    if (moves(bodies, row.b)) joint.body_b = index_->node_of_body[row.b];
  }
  // Each body's hub: the joints below it in order, then the joint above it.
  std::vector<std::uint32_t>& child_count = child_count_;
  child_count.assign(tree_bodies_.size() + 1, 0);
  for (std::size_t k = 0; k < n; ++k)
    if (nodes_[k].is_joint && nodes_[k].parent != kNone) ++child_count[numbered[nodes_[k].parent]];
  hubs_.clear();
  hub_members_.clear();
  member_side_b_.clear();
  pairs_.clear();
  std::vector<std::uint32_t>& hub_of_body = first_edge_;  // no longer needed as edges
  hub_of_body.assign(tree_bodies_.size(), kNone);
  std::uint32_t pairs = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (nodes_[k].is_joint) continue;
    const std::uint32_t body = numbered[k];
    const std::uint32_t members = child_count[body] + (nodes_[k].parent != kNone ? 1 : 0);
    if (members > kMostHubJoints) return false;
    if (members < 2) continue;
    hub_of_body[body] = static_cast<std::uint32_t>(hubs_.size());
    hubs_.push_back({body, 0, 0, pairs});
    pairs += members * (members - 1) / 2;
  }
  // Members: the children as the nodes' order meets them, the parent joint last.
  std::uint32_t first = 0;
  for (Hub& hub : hubs_) {
    hub.first_member = first;
    first += child_count[hub.body] + 1;
  }
  hub_members_.assign(first, kNone);
  member_side_b_.assign(first, 0);
  auto add_member = [&](Hub& hub, std::uint32_t joint) {
    const std::uint32_t place = hub.members++;
    hub_members_[hub.first_member + place] = joint;
    const JointRow& row = rows[joints_[joint].row];
    member_side_b_[hub.first_member + place] =
        moves(bodies, row.b) && index_->node_of_body[row.b] == hub.body ? 1 : 0;
  };
  for (std::size_t k = 0; k < n; ++k) {
    const Node& node = nodes_[k];
    if (!node.is_joint || node.parent == kNone) continue;
    const std::uint32_t hub = hub_of_body[numbered[node.parent]];
    if (hub == kNone) continue;
    add_member(hubs_[hub], numbered[k]);
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Node& node = nodes_[k];
    if (node.is_joint || node.parent == kNone) continue;
    const std::uint32_t hub = hub_of_body[numbered[k]];
    if (hub != kNone) add_member(hubs_[hub], numbered[node.parent]);  // last: no later ones
  }
  // A joint's later neighbours are the members after it in its parent body's hub; the last
  // member of a hub (the body's parent joint) has none there.
  for (const Hub& hub : hubs_)
    for (std::uint32_t i = 0; i + 1 < hub.members; ++i) {
      TreeJoint& joint = joints_[hub_members_[hub.first_member + i]];
      joint.hub = static_cast<std::uint32_t>(&hub - hubs_.data());
      joint.place = i;
      joint.laters = hub.members - i - 1;
      joint.first_later = hub.first_member + i + 1;
      joint.first_later_pair = pair_index(hub, i, i + 1);
    }
  pairs_.resize(pairs);
  return true;
}

void JointTree::finish_build(std::span<const JointRow> rows, std::span<const SolverBody> bodies) {
  has_motors_ = false;
  loads_unknown_ = false;
  for (const TreeJoint& joint : joints_) {
    has_motors_ = has_motors_ || rows[joint.row].joint.motor.enabled;
    loads_unknown_ = loads_unknown_ || !(rows[joint.row].joint.impulse_time > 0);
  }
  for (TreeBody& body : tree_bodies_) {
    const Mat3& inverse_inertia = bodies[body.index].inverse_inertia;
    body.inertia = inverse_inertia.inverse();
    // (By columns, each the cross product of the other two: a symmetric matrix's adjugate,
    // finite where it has no inverse.)
    body.inverse_inertia_adjugate << inverse_inertia.col(1).cross(inverse_inertia.col(2)),
        inverse_inertia.col(2).cross(inverse_inertia.col(0)),
        inverse_inertia.col(0).cross(inverse_inertia.col(1));
  }
  velocities_factored_ = false;
  share_pending_ = false;
  stiffness_kept_ = false;
  targets_taken_ = false;
}

// A chain's tension turns its links back into line, a stiffness (the constraint forces' change
// with the links' turn: the geometric stiffness) that the velocity solve meets only through the
// next substep's rows: explicitly. Under a heavy end the light links' transverse modes pass the
// explicit limit (a 0.2 m, 0.5 kg bar under a 500 kg end, turning about its centre between its
// two joints, rings at ~770 rad/s: 3.2 rad a 1/240 s substep) and the chain tears. As Andrews,
// Teichmann and Kry (2017, "Geometric stiffness for real-time constrained multibody dynamics",
// Eurographics) do, the stiffness times h^2 is added to the bodies' mass in the velocity solve:
// implicit, so those modes are damped rather than amplified. Implicit Euler also damps the slow
// modes (a pendulum's swing is this stiffness), by (omega h)^2 a substep, so only the part of a
// body's stiffness beyond the explicit scheme's comfortable reach (omega h above kResolvedShift or
// kResolvedTurn) is added: a pendulum or a chain of like links gets none and keeps its energy, a
// light link under a heavy load gets nearly all of it.
//
// The stiffness of a force f on a body at the lever r (for a unit turn about any axis across r):
// |f| |r| (1 - r r^T / |r|^2), and a rod's (a distance joint's) on its ends' positions,
// |f| / length (1 - n n^T); the forces are the joints' impulses over the time they took.
//
// omega is each body's own, its neighbours held; a chain's fastest modes move neighbours against
// each other (a zig-zag) and ring faster than that, so the reach is below the explicit limit
// (omega h = 2) by a margin, measured: ropes of beads on rods (distance joints) tore with shifts
// resolved to 0.85 (ten 2 cm beads 10 cm apart under a 10^4 times heavier end, dt 1/120) and held
// at 0.7; turns, against the inertias below, held every chain of the joints' tests to 1.6 and a
// matrix of 810 chains (bench/hanging_chains.cc: beads of 5 mm to 5 cm and square bars, links of
// 0.1 to 0.5 m, 10 to 40 of them, ends 10 to 10^6 times heavier, dt 1/30 to 1/120) alike from 0.7
// to 1.4.
constexpr double kResolvedShift = 0.5;  // omega h, rad
constexpr double kResolvedTurn = 1.0;   // omega h, rad
// The leading-minors test asks for a reach this much short (set_geometric_stiffness), and the
// loads' bound, which stands in for it, this much shorter again: margins far beyond rounding.
constexpr double kMinorsShortfall = 1e-6;
constexpr double kBoundShortfall = 1e-3;
// How far SHAKE's second iterate of the curvature targets may move them (relative to the first)
// and still be taken (solve_velocities: measured choices there).
constexpr double kConvergedTakes = 0.03;
// A conserving island's takes stop once the last moved the targets by less than this over the
// substep (m, or rad): what the position passes then project out no longer shows in a
// pendulum's period (solve_velocities). At most kMostTakes.
constexpr double kSettledTakeMove = 1e-7;
constexpr int kMostTakes = 6;
// A stiffened velocity factoring starts from the last position pass's factors (refactor_stiffened)
// only where that pass corrected less than this (m, or rad): its rows are then the sweeps' but for
// a turn this small, as step.cc's chord steps take them (kNewtonAfter). Past it the rows are
// formed afresh: in the matrix of hanging chains (bench_hanging_chains 2) the light beads' rows,
// one pass old after passes that corrected millimetres, tore chains by kilometres.
constexpr double kKeptRowsTurn = 1e-5;

bool JointTree::set_geometric_stiffness(std::span<const JointRow> rows,
                                        std::span<const SolverBody> bodies,
                                        std::span<const Pose> poses, double h,
                                        std::span<const JointPoseTerms> terms) {
  const double h2 = h * h;
  const auto anchors_at = [&](const TreeJoint& tree_joint,
                              joint_detail::Anchors* worked_out) -> const joint_detail::Anchors& {
    if (!terms.empty()) return terms[tree_joint.row].anchors;
    const JointRow& row = rows[tree_joint.row];
    const bool world_b = row.b == kWorldAnchor;
    *worked_out =
        joint_detail::anchors_of(row.joint, poses[row.a], world_b ? Pose{} : poses[row.b], world_b);
    return *worked_out;
  };
  const auto node_of = [&](std::uint32_t body) {
    return body == kWorldAnchor ? kNone : index_->node_of_body[body];
  };
  // First a bound on each body's rho (below) from its joints' loads alone, without the matrices
  // (this pass was 8% of chain:100's step, most of it building them): about three quarters of that
  // chain's bodies are below the reach by it, and take no stiffness. Each pull's stiffness, W^1/2
  // K_j W^1/2 with K_j = c [r]x^T [r]x, has the largest eigenvalue c l, l that of [r]x W [r]x^T
  // (rank two: trace t = |r|^2 tr W - r^T W r, second invariant e2 = |r|^2 r^T adj(W) r, so l = (t
  // + sqrt(t^2 - 4 e2)) / 2); the body's rho is at most their sum, with W its inverse inertia (its
  // turning inertia below is at least its inertia). A body whose bound is below the reach, with a
  // margin far beyond rounding, passes the leading-minors test below: zero, the same bits. Rods
  // (distance joints) and levers too short to weigh are left to the full test.
  for (TreeBody& body : tree_bodies_) {
    body.linear_stiffness.setZero();
    body.angular_stiffness.setZero();
    body.rho_bound = 0;
    body.weighed = false;
  }
  for (const TreeJoint& tree_joint : joints_) {
    const JointRow& row = rows[tree_joint.row];
    const Joint& joint = row.joint;
    if (!(joint.impulse_time > 0)) continue;
    const std::uint32_t node_a = node_of(row.a), node_b = node_of(row.b);
    if (joint.kind == JointKind::kDistance) {
      for (const std::uint32_t node : {node_a, node_b})
        if (node != kNone) tree_bodies_[node].weighed = true;
      continue;
    }
    if (joint.kind == JointKind::kSlider) continue;  // no force at its anchors
    joint_detail::Anchors worked_out;
    const joint_detail::Anchors& anchors = anchors_at(tree_joint, &worked_out);
    const Vec3 force_on_b = joint.linear_impulse / joint.impulse_time;
    for (const auto& [node, r, pull] :
         {std::tuple{node_a, anchors.ra, -force_on_b.dot(anchors.ra)},
          std::tuple{node_b, anchors.rb, force_on_b.dot(anchors.rb)}}) {
      if (node == kNone || !(pull > 0)) continue;
      TreeBody& body = tree_bodies_[node];
      const double squared_arm = r.squaredNorm();
      if (!(squared_arm > 1e-20)) {
        body.weighed = true;
        continue;
      }
      const Mat3& w = bodies[body.index].inverse_inertia;
      const double trace = squared_arm * w.trace() - r.dot(w * r);
      const double second = squared_arm * r.dot(body.inverse_inertia_adjugate * r);
      const double largest = 0.5 * (trace + std::sqrt(std::max(0.0, trace * trace - 4 * second)));
      body.rho_bound += h2 * pull / squared_arm * largest;
    }
  }
  for (TreeBody& body : tree_bodies_) {
    body.weighed =
        body.weighed || !(body.rho_bound < kResolvedTurn * kResolvedTurn * (1 - kMinorsShortfall) *
                                               (1 - kBoundShortfall));
    if (!body.weighed) continue;
    body.longest_lever.setZero();
    body.longest_arm = body.second_arm = 0;
  }
  // The bodies not passed: their stiffness in full.
  for (const TreeJoint& tree_joint : joints_) {
    const JointRow& row = rows[tree_joint.row];
    const Joint& joint = row.joint;
    if (!(joint.impulse_time > 0)) continue;
    const std::uint32_t node_a = node_of(row.a), node_b = node_of(row.b);
    if (!(node_a != kNone && tree_bodies_[node_a].weighed) &&
        !(node_b != kNone && tree_bodies_[node_b].weighed))
      continue;
    joint_detail::Anchors worked_out;
    const joint_detail::Anchors& anchors = anchors_at(tree_joint, &worked_out);
    // The force on b (a takes the opposite).
    Vec3 force_on_b = Vec3::Zero();
    Mat3 linear = Mat3::Zero();
    if (joint.kind == JointKind::kDistance) {
      const Vec3 d = anchors.pb - anchors.pa;
      const double length = d.norm();
      if (!(length > 1e-12)) continue;
      const Vec3 n = d / length;
      force_on_b = joint.axial_impulse / joint.impulse_time * n;
      // A rod in tension (pulling b towards a) resists its ends' shift across it.
      const double tension = std::max(0.0, -joint.axial_impulse / joint.impulse_time);
      linear = h2 * tension / length * (Mat3::Identity() - n * n.transpose());
    } else if (joint.kind != JointKind::kSlider) {
      force_on_b = joint.linear_impulse / joint.impulse_time;
    }
    for (const auto& [node, r, force] : {std::tuple{node_a, anchors.ra, Vec3(-force_on_b)},
                                         std::tuple{node_b, anchors.rb, force_on_b}}) {
      if (node == kNone || !tree_bodies_[node].weighed) continue;
      TreeBody& body_node = tree_bodies_[node];
      if (joint.kind == JointKind::kDistance) body_node.linear_stiffness += linear;
      const double arm = r.norm();
      if (arm > body_node.longest_arm) {
        body_node.second_arm = body_node.longest_arm;
        body_node.longest_arm = arm;
        body_node.longest_lever = r;
      } else {
        body_node.second_arm = std::max(body_node.second_arm, arm);
      }
      // Only the pull along the lever turns the body back into line (a chain's tension); a force
      // across it (a load held out sideways) has no stiffness of this kind to speak of.
      const double pull = arm > 1e-12 ? force.dot(r) / arm : 0.0;
      if (pull > 0)
        body_node.angular_stiffness +=
            h2 * pull / arm * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
    }
  }
  // Only the part beyond the reach: scaled by 1 - rho0 / rho, where rho = (omega h)^2 of the
  // body's stiffest turn or shift (and rho0 = kResolvedTurn^2 or kResolvedShift^2); continuous in
  // the load.
  bool any = false;
  // rho: the largest eigenvalue of W^1/2 K W^1/2 (W the inverse mass or inertia, M its inverse).
  // rho < r exactly when r M - K is positive definite (the same congruence): three leading minors,
  // a few dozen operations, where the eigenvalues cost a hundred times that. Tested with r a
  // millionth short, so that a body it passes is one whose rho the eigenvalues would find below
  // r too (their error is near rounding): the same stiffness, zero, and the same bits.
  auto keep_excess = [&](Mat3& stiffness, const Mat3& mass, auto inverse_of_mass, double reach) {
    const double resolved = reach * reach;
    const Mat3 margin = resolved * (1 - kMinorsShortfall) * mass - stiffness;
    const double minor2 = margin(0, 0) * margin(1, 1) - margin(0, 1) * margin(1, 0);
    if (margin(0, 0) > 0 && minor2 > 0 && margin.determinant() > 0) {
      stiffness.setZero();
      return;
    }
    const Mat3 inverse_mass = inverse_of_mass();
    // The trace of K W bounds rho from above (both are positive semidefinite).
    if ((stiffness * inverse_mass).trace() <= resolved) {
      stiffness.setZero();
      return;
    }
    const Mat3 root = Eigen::LLT<Mat3>(inverse_mass).matrixL();
    const Mat3 relative = root.transpose() * stiffness * root;
    const double rho =
        Eigen::SelfAdjointEigenSolver<Mat3>().computeDirect(relative).eigenvalues()[2];
    stiffness *= rho > resolved ? 1 - resolved / rho : 0.0;
    any = any || rho > resolved;
  };
  // A stiffness of nothing keeps nothing (its margin is the mass itself), without the test: most
  // bodies have no rod and many no pull (building their masses cost a tenth of the pass).
  for (TreeBody& node : tree_bodies_) {
    if (!node.weighed) continue;
    const SolverBody& body = bodies[node.index];
    if (!node.linear_stiffness.isZero(0))
      keep_excess(
          node.linear_stiffness, Mat3(Mat3::Identity() / body.inverse_mass),
          [&] { return Mat3(body.inverse_mass * Mat3::Identity()); }, kResolvedShift);
    if (node.angular_stiffness.isZero(0)) continue;
    // Held by one joint, a body turns about that joint's anchor, not its centre (a pendulum's bob;
    // the joint moves it with the anchor): inertia I + m (|r|^2 - r r^T), r its lever. Held by
    // two far anchors, it can turn about its centre, each anchor carrying a neighbour along (a
    // bead on a string between two others, turning against its neighbours in a zig-zag): inertia
    // I. Between the two, about a point along its longest lever as far out as the second-longest
    // lever falls short of it (a ball hinged at its centre to the next and by a long arm to the
    // last turns about the arm's anchor). A bead of 5 mm between anchors 5 cm away turns about its
    // centre with a 250th of the inertia about an anchor, 16 times as fast; taken about its
    // longest lever, its stiffness went unseen and chains of such beads tore within a second.
    const Vec3 r = node.longest_arm > 0
                       ? Vec3((1 - node.second_arm / node.longest_arm) * node.longest_lever)
                       : node.longest_lever;
    const Mat3 turning =
        node.inertia + (r.squaredNorm() * Mat3::Identity() - r * r.transpose()) / body.inverse_mass;
    keep_excess(
        node.angular_stiffness, turning, [&] { return Mat3(turning.inverse()); }, kResolvedTurn);
  }
  return any;
}

namespace {

// Calls f.template operator()<W>() with the fixed width W (3, 5 or 6) of a joint's rows; with
// `Every` (a tree whose joints all have that width: JointTree::every_width_), that one without
// asking.
template <int Every = 0, class F>
void with_width(int width, F&& f) {
  if constexpr (Every != 0)
    f.template operator()<Every>();
  else if (width == 3)
    f.template operator()<3>();
  else if (width == 5)
    f.template operator()<5>();
  else
    f.template operator()<6>();
}
template <int Every = 0, class F>
void with_widths(int first, int second, F&& f) {
  with_width<Every>(first, [&]<int A>() {
    with_width<Every>(second, [&]<int B>() { f.template operator()<A, B>(); });
  });
}

// Calls f.template operator()<Every>() with the tree's one width where it has one of 3 (a chain of
// balls: its solves' loops then ask no joint its width), else with 0 (each joint asked).
template <class F>
void with_every_width(int every_width, F&& f) {
  if (every_width == 3)
    f.template operator()<3>();
  else
    f.template operator()<0>();
}

// A joint's rows on one of its bodies times x (6 x n): the first A rows of J x, each value handed
// to put(i, col, value) as it is formed. Where the first three are a point's
// (JointEquations::point_rows: on a, [-I, [r_a]x]; on b, [I, -[r_b]x]), they are plus or minus
// x's linear half and a cross product with its angular half, half the dense rows' arithmetic; the
// rest are written out (Eigen's general product of these shapes was a call of its own, a tenth of
// a ragdoll pile's factoring). The values go straight where they are used: built as a matrix on
// the stack one at a time and then added or copied two at a time, they stalled on store
// forwarding (a tenth of the pivots' building in a chain).
template <int A, class X, class Put>
TUMBLE_INLINE void for_rows_times(const JointEquations& equations, bool side_b, const X& x,
                                  Put put) {
  const Eigen::Matrix<double, 6, 6>& rows = side_b ? equations.on_b : equations.on_a;
  int first = 0;
  if (equations.point_rows) {
    // The cross block [c]x holds c: ([c]x)(2,1) = c_x, (0,2) = c_y, (1,0) = c_z.
    const Vec3 c(rows(2, 4), rows(0, 5), rows(1, 3));
    for (int col = 0; col < x.cols(); ++col) {
      const Vec3 linear = x.col(col).template head<3>(), angular = x.col(col).template tail<3>();
      const Vec3 turn = c.cross(angular);
      for (int i = 0; i < 3; ++i)
        put(i, col, (side_b ? linear[i] : -linear[i]) + turn[i]);
    }
    first = 3;
  }
  // (Rows that only turn: their zero linear columns left out, the same sums but for a zero's sign.)
  if (equations.turning_rest) {
    for (int col = 0; col < x.cols(); ++col)
      for (int i = first; i < A; ++i)
        put(i, col, rows(i, 3) * x(3, col) + rows(i, 4) * x(4, col) + rows(i, 5) * x(5, col));
    return;
  }
  for (int col = 0; col < x.cols(); ++col)
    for (int i = first; i < A; ++i) {
      double sum = rows(i, 0) * x(0, col);
      for (int k = 1; k < 6; ++k)
        sum += rows(i, k) * x(k, col);
      put(i, col, sum);
    }
}

// Whether the equations' rows after the point's have no linear part (JointEquations::turning_rest).
bool turns_only_after_point(const JointEquations& equations) {
  const int first = equations.point_rows ? 3 : 0;
  for (int i = first; i < equations.rows; ++i)
    for (int k = 0; k < 3; ++k)
      if (equations.on_a(i, k) != 0 || equations.on_b(i, k) != 0) return false;
  return true;
}

}  // namespace

void JointTree::set_masses(std::span<const SolverBody> bodies, bool velocities) {
  for (TreeBody& body : tree_bodies_) {
    const SolverBody& solver_body = bodies[body.index];
    body.stiff =
        velocities && (!body.linear_stiffness.isZero() || !body.angular_stiffness.isZero());
    if (body.stiff) {
      body.linear_inverse =
          (Mat3(Mat3::Identity() / solver_body.inverse_mass) + body.linear_stiffness).inverse();
      body.angular_inverse = (body.inertia + body.angular_stiffness).inverse();
    } else {
      body.angular_inverse = solver_body.inverse_inertia;
    }
    body.inverse_mass = solver_body.inverse_mass;
  }
}

void JointTree::form_pivot(std::size_t k) {
  TreeJoint& joint = joints_[k];
  with_width(joint.width, [&]<int W>() {
    auto pivot = joint.pivot.template topLeftCorner<W, W>();
    pivot.setZero();
    for (const bool side_b : {false, true}) {
      const std::uint32_t b = side_b ? joint.body_b : joint.body_a;
      if (b == kNone) continue;
      const TreeBody& body = tree_bodies_[b];
      const auto rows_on_body = jacobian(k, side_b).template topRows<W>();
      Mat6& response = side_b ? joint.response_b : joint.response_a;
      if (body.stiff)
        response.template topLeftCorner<3, W>().noalias() =
            body.linear_inverse.lazyProduct(rows_on_body.template leftCols<3>().transpose());
      else
        response.template topLeftCorner<3, W>() =
            body.inverse_mass * rows_on_body.template leftCols<3>().transpose();
      response.template bottomLeftCorner<3, W>().noalias() =
          body.angular_inverse.lazyProduct(rows_on_body.template rightCols<3>().transpose());
      for_rows_times<W>(equations_[k], side_b, response.template leftCols<W>(),
                        [&](int i, int col, double value) { pivot(i, col) += value; });
    }
    for (int r = equations_[k].rows; r < W; ++r)
      pivot(r, r) = 1;
  });
}

template <class Equations>
void JointTree::factor(std::span<const SolverBody> bodies, bool velocities, Equations equations) {
  set_masses(bodies, velocities);
  // Each joint's rows, its response on each body (W J^T) and its diagonal block J W J^T.
  for (std::size_t k = 0; k < joints_.size(); ++k) {
    equations(k, &equations_[k]);
    equations_[k].turning_rest = turns_only_after_point(equations_[k]);
    joints_[k].width = equations_[k].rows <= 3 ? 3 : equations_[k].rows <= 5 ? 5 : 6;
    form_pivot(k);
  }
  every_width_ = std::all_of(joints_.begin(), joints_.end(),
                             [](const TreeJoint& joint) { return joint.width == 3; })
                     ? 3
                     : 0;
  with_every_width(every_width_, [&]<int Every>() { eliminate<Every, false>(); });
}

// The position pass's factors (its rows, the bodies' plain masses) differ from the stiffened
// velocity system's only where a joint holds a body that takes stiffness, and in what such a
// joint's elimination passes on: the joints of its parent's hub after it, and theirs in turn up
// to the root. Those alone are formed and eliminated again; every other joint's inverse pivot and
// reaches are what a whole factoring would give them, and so is the rest (the same sums in the
// same order), at a fraction of the cost: in a hanging chain the stiff links are the loaded ones
// near its top, and the joints below them keep their factors.
void JointTree::refactor_stiffened(std::span<const SolverBody> bodies) {
  set_masses(bodies, true);
  const int check = JointTreeRefactorCheck::mode.load(std::memory_order_relaxed);
  if (check != JointTreeRefactorCheck::kOff)
    JointTreeRefactorCheck::partial.fetch_add(1, std::memory_order_relaxed);
  if (check == JointTreeRefactorCheck::kWhole) {
    for (std::size_t k = 0; k < joints_.size(); ++k)
      form_pivot(k);
    with_every_width(every_width_, [&]<int Every>() { eliminate<Every, false>(); });
    return;
  }
  changed_.assign(joints_.size(), 0);
  for (std::size_t k = 0; k < joints_.size(); ++k) {
    const TreeJoint& joint = joints_[k];
    const bool holds_stiff = (joint.body_a != kNone && tree_bodies_[joint.body_a].stiff) ||
                             (joint.body_b != kNone && tree_bodies_[joint.body_b].stiff);
    if (holds_stiff) changed_[k] = 1;
    if (!changed_[k]) continue;
    form_pivot(k);
    if (joint.hub == kNone) continue;
    const Hub& hub = hubs_[joint.hub];
    for (std::uint32_t j = joint.place + 1; j < hub.members; ++j)
      changed_[hub_members_[hub.first_member + j]] = 1;
  }
  with_every_width(every_width_, [&]<int Every>() { eliminate<Every, true>(); });
}

template <int Every, bool OnlyChanged>
void JointTree::eliminate() {
  // The blocks between joints of a hub: through the hub's body alone. (A joint left as it was
  // keeps its blocks with the later ones: those of a changed one follow it, changed.)
  for (const Hub& hub : hubs_) {
    for (std::uint32_t i = 0; i + 1 < hub.members; ++i) {
      const std::uint32_t first = hub_members_[hub.first_member + i];
      if (OnlyChanged && !changed_[first]) continue;
      const bool first_b = member_side_b_[hub.first_member + i] != 0;
      for (std::uint32_t j = i + 1; j < hub.members; ++j) {
        const std::uint32_t second = hub_members_[hub.first_member + j];
        const bool second_b = member_side_b_[hub.first_member + j] != 0;
        const Mat6& response = second_b ? joints_[second].response_b : joints_[second].response_a;
        with_widths<Every>(joints_[first].width, joints_[second].width, [&]<int A, int B>() {
          auto block = pairs_[pair_index(hub, i, j)].block.template topLeftCorner<A, B>();
          for_rows_times<A>(equations_[first], first_b, response.template leftCols<B>(),
                            [&](int row, int col, double value) { block(row, col) = value; });
        });
      }
    }
  }
  // Each joint eliminated into its later neighbours (each pivot kept as its inverse).
  for (std::size_t k = 0; k < joints_.size(); ++k) {
    TreeJoint& joint = joints_[k];
    const bool changed = !OnlyChanged || changed_[k];
    if (changed) {
      with_width<Every>(joint.width, [&]<int W>() {
        if constexpr (W == 3)
          invert_in_place(joint.pivot.topLeftCorner<3, 3>());
        else if constexpr (W == 5)
          joint.pivot.topLeftCorner<5, 5>() = inverse_of_definite<5>(
              Eigen::Matrix<double, 5, 5>(joint.pivot.topLeftCorner<5, 5>()));
        else
          joint.pivot = inverse_of_definite<6>(joint.pivot);
      });
    }
    if (joint.hub == kNone) continue;
    const Hub& hub = hubs_[joint.hub];
    const std::uint32_t i = joint.place;
    // (An unchanged joint's reaches are the kept ones.)
    for (std::uint32_t j = i + 1; changed && j < hub.members; ++j) {
      HubPair& pair = pairs_[pair_index(hub, i, j)];
      with_widths<Every>(joint.width, joints_[hub_members_[hub.first_member + j]].width,
                         [&]<int A, int B>() {
                           if constexpr (A == 3 && B == 3)
                             multiply_into(pair.reach.topLeftCorner<3, 3>(),
                                           std::as_const(joint.pivot).topLeftCorner<3, 3>(),
                                           std::as_const(pair.block).topLeftCorner<3, 3>());
                           else
                             pair.reach.template topLeftCorner<A, B>().noalias() =
                                 joint.pivot.template topLeftCorner<A, A>().lazyProduct(
                                     pair.block.template topLeftCorner<A, B>());
                         });
    }
    for (std::uint32_t j = i + 1; j < hub.members; ++j) {
      const std::uint32_t later_index = hub_members_[hub.first_member + j];
      // (A changed joint after an unchanged one takes what it passes on again.)
      if (OnlyChanged && !changed_[later_index]) continue;
      const HubPair& with_j = pairs_[pair_index(hub, i, j)];
      TreeJoint& later = joints_[later_index];
      with_widths<Every>(joint.width, later.width, [&]<int A, int B>() {
        if constexpr (A == 3 && B == 3)
          subtract_transposed_product(later.pivot.topLeftCorner<3, 3>(),
                                      with_j.block.topLeftCorner<3, 3>(),
                                      with_j.reach.topLeftCorner<3, 3>());
        else
          later.pivot.template topLeftCorner<B, B>().noalias() -=
              with_j.block.template topLeftCorner<A, B>().transpose().lazyProduct(
                  with_j.reach.template topLeftCorner<A, B>());
      });
      for (std::uint32_t l = j + 1; l < hub.members; ++l) {
        const HubPair& with_l = pairs_[pair_index(hub, i, l)];
        HubPair& between = pairs_[pair_index(hub, j, l)];
        with_widths<Every>(
            later.width, joints_[hub_members_[hub.first_member + l]].width, [&]<int B, int C>() {
              with_width<Every>(joint.width, [&]<int A>() {
                between.block.template topLeftCorner<B, C>().noalias() -=
                    with_j.block.template topLeftCorner<A, B>().transpose().lazyProduct(
                        with_l.reach.template topLeftCorner<A, C>());
              });
            });
      }
    }
  }
}

void JointTree::set_velocity_base(std::span<const SolverBody> bodies) {
  for (TreeBody& body : tree_bodies_) {
    const SolverBody& solver_body = bodies[body.index];
    if (!body.stiff) {
      body.base << solver_body.v, solver_body.w;
      continue;
    }
    // (M + K)^-1 M v: the stiffness damps what moves against it.
    body.base << body.linear_inverse * (solver_body.v / solver_body.inverse_mass),
        body.angular_inverse * (body.inertia * solver_body.w);
  }
}

template <class Targets>
void JointTree::solve(bool from_base, Targets targets) {
  with_every_width(every_width_, [&]<int Every>() {
    for (std::size_t k = 0; k < joints_.size(); ++k) {
      TreeJoint& joint = joints_[k];
      joint.rhs = -targets(k);
      if (!from_base) continue;
      with_width<Every>(joint.width, [&]<int W>() {
        for (const bool side_b : {false, true}) {
          const std::uint32_t b = side_b ? joint.body_b : joint.body_a;
          if (b == kNone) continue;
          for_rows_times<W>(equations_[k], side_b, tree_bodies_[b].base,
                            [&](int i, int, double value) { joint.rhs[i] += value; });
        }
      });
    }
    substitute_with<Every>();
    for (TreeBody& body : tree_bodies_) {
      if (from_base)
        body.result = body.base;
      else
        body.result.setZero();
    }
    for (const TreeJoint& joint : joints_) {
      with_width<Every>(joint.width, [&]<int W>() {
        // Column by column: each a 6-vector multiply-add that the compiler keeps in registers.
        for (const auto& [b, response] : {std::pair{joint.body_a, &joint.response_a},
                                          std::pair{joint.body_b, &joint.response_b}}) {
          if (b == kNone) continue;
          Vec6& result = tree_bodies_[b].result;
          for (int c = 0; c < W; ++c)
            result -= response->col(c) * joint.rhs[c];
        }
      });
    }
  });
}

template <int Every>
void JointTree::substitute_with() {
  for (const TreeJoint& joint : joints_) {
    for (std::uint32_t n = 0; n < joint.laters; ++n) {
      TreeJoint& later = joints_[hub_members_[joint.first_later + n]];
      const HubPair& pair = pairs_[joint.first_later_pair + n];
      with_widths<Every>(joint.width, later.width, [&]<int A, int B>() {
        if constexpr (A == 3 && B == 3) {
          // Written out in the dot products' own order, ((r0 x0 + r1 x1) + r2 x2): the same bits.
          // The next joint of a chain reads these three values at once; stored one by one by
          // Eigen's dot products and loaded two at a time, they stalled on store forwarding.
          const double x0 = joint.rhs[0], x1 = joint.rhs[1], x2 = joint.rhs[2];
          for (int b = 0; b < 3; ++b)
            later.rhs[b] -= (pair.reach(0, b) * x0 + pair.reach(1, b) * x1) + pair.reach(2, b) * x2;
        } else {
          later.rhs.template head<B>().noalias() -=
              pair.reach.template topLeftCorner<A, B>().transpose().lazyProduct(
                  joint.rhs.template head<A>());
        }
      });
    }
  }
  for (std::size_t k = joints_.size(); k-- > 0;) {
    TreeJoint& joint = joints_[k];
    with_width<Every>(joint.width, [&]<int W>() {
      const Eigen::Matrix<double, W, 1> scaled =
          joint.pivot.template topLeftCorner<W, W>().lazyProduct(joint.rhs.template head<W>());
      joint.rhs.template head<W>() = scaled;
      for (std::uint32_t n = 0; n < joint.laters; ++n) {
        const TreeJoint& later = joints_[hub_members_[joint.first_later + n]];
        const HubPair& pair = pairs_[joint.first_later_pair + n];
        with_width<Every>(later.width, [&]<int B>() {
          joint.rhs.template head<W>().noalias() -=
              pair.reach.template topLeftCorner<W, B>().lazyProduct(later.rhs.template head<B>());
        });
      }
    });
  }
}

double JointTree::solve_velocities(std::span<JointRow> rows, std::span<SolverBody> bodies,
                                   std::span<const Pose> poses, const JointTarget& target,
                                   std::span<const JointPoseTerms> terms) {
  if (joints_.empty()) return 0;
  // The poses stay put between moves: one factoring serves every sweep until the next.
  if (!velocities_factored_) {
    const auto equations_of_row = [&](std::size_t k, JointEquations* equations) {
      JointTarget plain = target;
      plain.h = 0;
      const std::uint32_t row = joints_[k].row;
      velocity_equations(equations, rows[row], bodies, poses, plain, &terms[row].anchors);
    };
    if (loads_unknown_) {
      learn_loads(rows, bodies, equations_of_row);
      stiffness_kept_ = false;
    }
    const bool kept = stiffness_kept_;
    stiffened_ = kept || set_geometric_stiffness(rows, bodies, poses, target.substep, terms);
    stiffness_kept_ = false;
    if (kept && factors_kept_)
      refactor_stiffened(bodies);
    else
      factor(bodies, true, equations_of_row);
    velocities_factored_ = true;
  }
  // The targets of a move ahead (the turns' curvature) depend on the velocities: SHAKE's
  // iteration. Taken afresh in every sweep they fed on themselves (a chain with a 1000 times
  // heavier end gained kilojoules in a step), so they are taken a substep at a time, from
  // velocities that already hold every joint (a first solve without them), and kept for its other
  // sweeps. Taken once, they are a step behind the velocities they produce: a pendulum lost a
  // little energy every swing (at 170 degrees its half period shortened by 2e-4 of itself every
  // half swing). So they are taken a second time, from the velocities the first produce, where the
  // iteration converges (the second changes them by under kConvergedTakes of the first: a
  // pendulum's by 2e-4, a heavy chain's by about 0.36, a chain of beads' erratically by up to 20;
  // taken at a tenth, a falling chain at dt 1/30 opened 1.4e-6 m, at 0.03 1.3e-7 m as with one
  // take): else the first are kept. What the last take leaves unsettled the position passes
  // project out after the move, and a projection is not SHAKE's symplectic step: at one substep
  // of 1/60 s a pendulum released at 170 degrees drifted from its period by 1e-3 over 60 s (two
  // takes) where settled takes keep RATTLE's 2.4e-4. So an island whose energy is its joints'
  // alone (`conserving`) takes them again while each moves them less than the one before, until
  // one moves them by under kSettledTakeMove. The others' contacts and drives take energy anyway,
  // and they keep the first take: the second cost a pile of ragdolls 4.5% of its step at one
  // substep, and of the report's joint section (errors and verdicts) changed only the chaotic
  // falling chain's gap, either way (at dt 1/60 2.6e-5 m with it, 5.9e-6 without; at 1/120
  // 1.8e-8, 1.4e-7).
  // Without a move ahead the rows' rates are held at zero.
  auto rates_of = [&](std::size_t k, const std::vector<Vec6>& targets) {
    Vec6 rates = target.h > 0 ? targets[k] : Vec6(Vec6::Zero());
    const JointRow& row = rows[joints_[k].row];
    if (has_motors_ && motor_row(row, equations_[k])) rates[5] = row.joint.motor.speed;
    return rates;
  };
  bool solved = false;
  if (target.h > 0 && !targets_taken_) {
    JointTarget plain = target;
    plain.h = 0;
    solve_velocities(rows, bodies, poses, plain, terms);
    kept_targets_.resize(joints_.size());
    set_turns(rows, bodies, target.h);
    for (std::size_t k = 0; k < joints_.size(); ++k) {
      const std::uint32_t row = joints_[k].row;
      kept_targets_[k] = velocity_targets(rows[row], bodies, poses, target, index_->turns.data(),
                                          &terms[row].anchors);
    }
    // Where an iterate is not taken, the solve of the targets kept (from the same velocities) is
    // this sweep's.
    double last = kConvergedTakes;
    for (int take = 2; target.conserving; ++take) {
      const Retake retake = take_targets_again(rows, bodies, poses, target, rates_of, last, terms);
      if (!(retake.ratio <= last)) {
        // Not contracting: the takes so far stand (after the second, the bound is reported).
        if (take > 2) ++take_limit_hits_;
        solved = true;
        break;
      }
      kept_targets_.swap(second_targets_);
      solved = false;
      if (retake.move <= kSettledTakeMove) break;
      if (take == kMostTakes) {
        ++take_limit_hits_;
        break;
      }
      // Each take after the second must move them less than the one before.
      last = retake.ratio;
    }
    targets_taken_ = true;
  }
  if (!solved) {
    set_velocity_base(bodies);
    solve(true, [&](std::size_t k) { return rates_of(k, kept_targets_); });
  }
  // A degenerate joint (its rows dependent) leaves a pivot without an inverse: nothing is
  // applied, and the Gauss-Seidel position passes and next sweeps carry on.
  if (!solution_finite()) return 0;
  double change = take_solution(rows, bodies);
  // A motor past its force bound leaves the direct solve: its impulse is held at the bound (the
  // excess taken back from the bodies) and it goes on as a Gauss-Seidel row, the others solved
  // again without it.
  bool saturated = false;
  for (std::size_t k = 0; has_motors_ && k < joints_.size(); ++k) {
    JointRow& row = rows[joints_[k].row];
    if (!motor_row(row, equations_[k])) continue;
    const double most = row.joint.motor.max_force * target.substep;
    const double held = std::clamp(row.joint.motor_impulse, -most, most);
    if (held == row.joint.motor_impulse) continue;
    joint_detail::JointBodies j = joint_detail::bodies_of(row, bodies, poses);
    const bool world_b = row.b == kWorldAnchor;
    const joint_detail::FreeCoordinate c = joint_detail::free_coordinate(
        row.joint, poses[row.a], world_b ? Pose{} : poses[row.b], world_b);
    joint_detail::apply_row(j, c.row, held - row.joint.motor_impulse);
    row.joint.motor_impulse = held;
    row.motor_in_tree = false;
    row.motor_at_bound = true;
    saturated = true;
  }
  if (saturated) {
    velocities_factored_ = false;
    targets_taken_ = false;
    change = std::max(change, solve_velocities(rows, bodies, poses, target, terms));
  }
  return change;
}

// The geometric stiffness reads each joint's load from its impulse, and a joint not yet solved has
// none: a chain made taut under a heavy end, its links small beads (a bead's turn between its two
// anchors rings thousands of times faster than the chain swings), met its first substep with no
// stiffness, and a push on its end in that substep tore it (a 5 mm bead chain under a 10^4 times
// heavier end opened 1 m within three steps; pushed a step later, it held to 1e-12 m). So a tree
// with such a joint first solves without stiffness, holding every joint at rate zero: the
// impulses that hold the bodies as they are, the loads its stiffness is then worked out from.
template <class VelocityEquations>
void JointTree::learn_loads(std::span<JointRow> rows, std::span<SolverBody> bodies,
                            VelocityEquations velocity_equations) {
  loads_unknown_ = false;
  for (TreeBody& body : tree_bodies_) {
    body.linear_stiffness.setZero();
    body.angular_stiffness.setZero();
  }
  factor(bodies, true, velocity_equations);
  set_velocity_base(bodies);
  solve(true, [&](std::size_t k) {
    Vec6 rates = Vec6::Zero();
    const JointRow& row = rows[joints_[k].row];
    if (has_motors_ && motor_row(row, equations_[k])) rates[5] = row.joint.motor.speed;
    return rates;
  });
  if (solution_finite()) take_solution(rows, bodies);
}

double JointTree::take_solution(std::span<JointRow> rows, std::span<SolverBody> bodies) {
  double change = 0;
  for (std::size_t k = 0; k < joints_.size(); ++k)
    add_equation_impulses(rows[joints_[k].row], equations_[k], -joints_[k].rhs);
  for (const TreeBody& tree_body : tree_bodies_) {
    SolverBody& body = bodies[tree_body.index];
    const Vec3 v = tree_body.result.head<3>(), w = tree_body.result.tail<3>();
    change = std::max(
        {change, (v - body.v).lpNorm<Eigen::Infinity>(), (w - body.w).lpNorm<Eigen::Infinity>()});
    body.v = v;
    body.w = w;
  }
  return change;
}

template <class Rates>
JointTree::Retake JointTree::take_targets_again(std::span<const JointRow> rows,
                                                std::span<SolverBody> bodies,
                                                std::span<const Pose> poses,
                                                const JointTarget& target, Rates rates_of,
                                                double refused_above,
                                                std::span<const JointPoseTerms> terms) {
  const std::size_t joints = joints_.size(), tree_bodies = tree_bodies_.size();
  held_velocities_.resize(tree_bodies);
  second_targets_.resize(joints);
  set_velocity_base(bodies);
  solve(true, [&](std::size_t k) { return rates_of(k, kept_targets_); });
  for (std::size_t k = 0; k < tree_bodies; ++k) {
    if (!tree_bodies_[k].result.allFinite()) continue;
    SolverBody& body = bodies[tree_bodies_[k].index];
    held_velocities_[k] << body.v, body.w;
    body.v = tree_bodies_[k].result.head<3>();
    body.w = tree_bodies_[k].result.tail<3>();
  }
  // The turns only of the joints visited: a refused take visits a quarter of a chain's joints.
  start_turns();
  double first = 0, change = 0;
  for (std::size_t k = 0; k < joints; ++k)
    first = std::max(first, kept_targets_[k].lpNorm<Eigen::Infinity>());
  // (Relative to the targets it started from; none with none: nothing to iterate.)
  const auto relative = [&] {
    return first > 0 ? change / first : change == 0 ? 0.0 : std::numeric_limits<double>::infinity();
  };
  // The move only grows joint by joint, and a correctly rounded quotient with it: past the bound
  // part way, it is past it at the end, and the caller refuses the iterate either way. A chain of
  // 100 links refuses 96% of its second takes, and now visits a quarter of its joints a take.
  for (std::size_t k = 0; k < joints && !(relative() > refused_above); ++k) {
    const JointRow& row = rows[joints_[k].row];
    turn_bodies_of(row, bodies, target.h);
    second_targets_[k] = velocity_targets(row, bodies, poses, target, index_->turns.data(),
                                          &terms[joints_[k].row].anchors);
    change = std::max(change, (second_targets_[k] - kept_targets_[k]).lpNorm<Eigen::Infinity>());
  }
  for (std::size_t k = 0; k < tree_bodies; ++k) {
    if (!tree_bodies_[k].result.allFinite()) continue;
    SolverBody& body = bodies[tree_bodies_[k].index];
    body.v = held_velocities_[k].head<3>();
    body.w = held_velocities_[k].tail<3>();
  }
  return {relative(), change * target.h};
}

double JointTree::solve_positions(std::span<const JointRow> rows, std::span<SolverBody> bodies,
                                  std::span<Pose> poses, bool refactor, double velocity_substep,
                                  bool bounds, double bound_slack) {
  if (joints_.empty()) return 0;
  // A move came before: the next sweeps take their targets afresh, and factor again unless this
  // pass or one before it since the move factored for them.
  targets_taken_ = false;
  stiffness_kept_ = false;
  double largest = 0;
  const auto corrected = [&](const JointEquations::Vector& target) {
    largest = std::max(largest, target.lpNorm<Eigen::Infinity>());
    return target;
  };
  if (refactor) {
    bool bound_rows = false;
    factor(bodies, false, [&](std::size_t k, JointEquations* equations) {
      joints_[k].bounds = 0;
      position_equations(equations, rows[joints_[k].row], bodies, poses,
                         bounds ? &joints_[k].bounds : nullptr, bound_slack);
      bound_rows = bound_rows || joints_[k].bounds != 0;
    });
    // The velocity sweeps hold no bound as an equality: a factoring with bound rows is not theirs;
    // nor one where a body takes stiffness (settle_velocity_factors decides after the passes).
    velocities_factored_ = false;
    share_pending_ = velocity_substep > 0 && !has_motors_ && !bound_rows;
    solve(false, [&](std::size_t k) { return corrected(equations_[k].target); });
  } else {
    solve(false, [&](std::size_t k) {
      return corrected(position_targets(rows[joints_[k].row], bodies, poses, joints_[k].bounds));
    });
  }
  if (!solution_finite()) return std::numeric_limits<double>::infinity();
  if (refactor) factored_correction_ = largest;
  for (const TreeBody& body : tree_bodies_)
    joint_detail::move_body(&bodies[body.index], &poses[body.index], body.result.head<3>(),
                            body.result.tail<3>());
  return largest;
}

void JointTree::settle_velocity_factors(std::span<const JointRow> rows,
                                        std::span<const SolverBody> bodies,
                                        std::span<const Pose> poses, double h, bool keep_stiffness,
                                        std::span<const JointPoseTerms> terms) {
  if (!share_pending_) return;
  share_pending_ = false;
  // Shared only where no body takes stiffness: a light link's stiffness as mass in the position
  // passes shifted its corrections onto the heavy end, and a chain of beads under a million times
  // heavier end tore. Worked out where the sweeps' own factoring would work it out (the poses
  // after the last pass, the impulses of the sweeps before), so that it can keep it.
  if (!set_geometric_stiffness(rows, bodies, poses, h, terms)) {
    velocities_factored_ = true;
    stiffened_ = false;
    return;
  }
  stiffness_kept_ = keep_stiffness;
  factors_kept_ = keep_stiffness && factored_correction_ < kKeptRowsTurn;
}

void JointTree::set_turns(std::span<const JointRow> rows, std::span<const SolverBody> bodies,
                          double h) {
  start_turns();
  for (const TreeJoint& joint : joints_)
    turn_bodies_of(rows[joint.row], bodies, h);
}

void JointTree::start_turns() {
  std::vector<Quat>& turns = index_->turns;
  if (turns.size() < index_->node_of_body.size()) turns.resize(index_->node_of_body.size());
  turned_.assign(tree_bodies_.size(), 0);
}

void JointTree::turn_bodies_of(const JointRow& row, std::span<const SolverBody> bodies, double h) {
  // The tree's turn with its velocity; a static body identity; the world (kWorldAnchor) none.
  for (const std::uint32_t body : {row.a, row.b}) {
    if (body == kWorldAnchor) continue;
    const std::uint32_t node = index_->node_of_body[body];
    if (node == kNone) {
      index_->turns[body] = Quat::Identity();
    } else if (!turned_[node]) {
      turned_[node] = 1;
      index_->turns[body] = rotation_quaternion(h * bodies[body].w);
    }
  }
}

bool JointTree::solution_finite() const {
  // One sum: an infinity or NaN anywhere leaves it non-finite (inf - inf is NaN).
  double sum = 0;
  for (const TreeJoint& joint : joints_)
    sum += joint.rhs.sum();
  for (const TreeBody& body : tree_bodies_)
    sum += body.result.sum();
  return std::isfinite(sum);
}

bool JointTree::respond(std::span<const BodyImpulse> impulses) {
  for (TreeBody& body : tree_bodies_)
    body.base.setZero();
  for (const BodyImpulse& push : impulses) {
    TreeBody& body = tree_bodies_[index_->node_of_body[push.body]];
    body.base.head<3>() += push.impulse.head<3>();
    body.base.tail<3>() += push.impulse.tail<3>();
  }
  // The impulses as the bodies' velocity change, with the masses of the last factoring.
  for (TreeBody& body : tree_bodies_) {
    if (body.base.isZero()) continue;
    const Vec3 linear = body.base.head<3>(), angular = body.base.tail<3>();
    body.base.head<3>() =
        body.stiff ? Vec3(body.linear_inverse * linear) : Vec3(body.inverse_mass * linear);
    body.base.tail<3>() = body.angular_inverse * angular;
  }
  solve(true, [](std::size_t) { return Vec6(Vec6::Zero()); });
  return solution_finite();
}

void JointTree::apply_response(std::span<JointRow> rows, std::span<SolverBody> bodies,
                               bool pseudo) const {
  if (!pseudo)
    for (std::size_t k = 0; k < joints_.size(); ++k)
      add_equation_impulses(rows[joints_[k].row], equations_[k], -joints_[k].rhs);
  for (const TreeBody& tree_body : tree_bodies_) {
    SolverBody& body = bodies[tree_body.index];
    (pseudo ? body.push_v : body.v) += tree_body.result.head<3>();
    (pseudo ? body.push_w : body.w) += tree_body.result.tail<3>();
  }
}

}  // namespace tumble
