#include "contact_solver.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>

#include "rotation.h"
#include "wide.h"

namespace tumble {
namespace {

// Relative tangential speeds below this leave the friction basis fixed to the normal, so resting
// contacts keep one basis from step to step.
constexpr double kSlidingSpeed = 1e-3;

// A unit vector perpendicular to `n`, chosen the same way every time.
Vec3 any_perpendicular(const Vec3& n) {
  const Vec3 axis = std::abs(n.x()) < 0.57735 ? Vec3::UnitX() : Vec3::UnitY();
  return n.cross(axis).normalized();
}

// Eigen's 3-vector arithmetic on four vectors at once, operation for operation (checked bit for
// bit by the pinned hashes), always inlined into the AVX2 clone of prepare_rows (wide.h): the cross
// product's formula, and Matrix3d * Vector3d's sums, whose first two rows Eigen adds as (a0 + a1) +
// a2 in SIMD pairs and whose last as a0 + (a1 + a2).
TUMBLE_INLINE WideVec3 cross(const WideVec3& a, const WideVec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
TUMBLE_INLINE WideVec3 times(const Mat3& m, const WideVec3& v) {
  return {(m(0, 0) * v.x + m(0, 1) * v.y) + m(0, 2) * v.z,
          (m(1, 0) * v.x + m(1, 1) * v.y) + m(1, 2) * v.z,
          m(2, 0) * v.x + (m(2, 1) * v.y + m(2, 2) * v.z)};
}
TUMBLE_INLINE WideVec3 scaled(Wide s, const WideVec3& v) {
  return {s * v.x, s * v.y, s * v.z};
}

// J M^-1 J^T of a row from its angular parts, r x d and I^-1 (r x d): the velocity change a unit
// impulse gives the contact.
TUMBLE_INLINE Wide velocity_response(const Body& a, const Body& b, const WideVec3& ra_cross,
                                     const WideVec3& angular_a, const WideVec3& rb_cross,
                                     const WideVec3& angular_b) {
  return ((wide(a.inverse_mass) + b.inverse_mass) + dot(ra_cross, angular_a)) +
         dot(rb_cross, angular_b);
}

// Its inverse, the row's effective mass (none for a row that nothing can move).
TUMBLE_INLINE Wide mass_of(Wide response) {
  return select(response > 0, 1.0 / response, wide(0));
}

// The inverse of the leading count x count block of the symmetric `k` (of which it reads the
// lower triangle and the diagonal) through its Cholesky factor L (k = L L^T, inverse =
// L^-T L^-1), written out for at most four rows: Eigen's LLT of a fixed 4x4 goes through its
// general blocked kernels, which cost more than the arithmetic (3% of an awake pile's step).
// Leaves `inverse` zero when k is not positive definite.
void invert_positive_definite(const Eigen::Matrix4d& k, int count, Eigen::Matrix4d* inverse) {
  double l[4][4] = {};
  for (int j = 0; j < count; ++j) {
    double pivot = k(j, j);
    for (int p = 0; p < j; ++p)
      pivot -= l[j][p] * l[j][p];
    if (!(pivot > 0)) return;  // also NaN
    l[j][j] = std::sqrt(pivot);
    for (int i = j + 1; i < count; ++i) {
      double sum = k(i, j);
      for (int p = 0; p < j; ++p)
        sum -= l[i][p] * l[j][p];
      l[i][j] = sum / l[j][j];
    }
  }
  // L^-1, lower triangular, column by column by forward substitution.
  double m[4][4] = {};
  for (int j = 0; j < count; ++j) {
    m[j][j] = 1 / l[j][j];
    for (int i = j + 1; i < count; ++i) {
      double sum = 0;
      for (int p = j; p < i; ++p)
        sum -= l[i][p] * m[p][j];
      m[i][j] = sum / l[i][i];
    }
  }
  for (int i = 0; i < count; ++i) {
    for (int j = 0; j <= i; ++j) {
      double sum = 0;
      for (int p = i; p < count; ++p)
        sum += m[p][i] * m[p][j];
      (*inverse)(i, j) = sum;
      (*inverse)(j, i) = sum;
    }
  }
}

}  // namespace

TUMBLE_PER_CPU
void prepare_rows(const ContactManifold& manifold, std::uint32_t solver_a, const Body& a,
                  std::uint32_t solver_b, const Body& b, const ContactPairRecord* previous,
                  std::uint32_t block_index, ContactRow* rows, ContactRowCold* cold,
                  NormalBlock* block) {
  TUMBLE_ASSERT(manifold.count >= 1 && manifold.count <= 4);
  const int count = manifold.count;
  const Vec3& n = manifold.normal;
  const double friction = std::sqrt(a.friction * b.friction);
  const double restitution = std::max(a.restitution, b.restitution);
  const Mat3 ra_to_local = a.orientation.conjugate().toRotationMatrix();
  const Mat3 rb_to_local = b.orientation.conjugate().toRotationMatrix();
  const double match_distance = 0.05 * std::min(a.shape.size(), b.shape.size());
  // The friction basis of a point that does not slide (one per manifold: it depends on n alone).
  const Vec3 resting_tangent = any_perpendicular(n);

  // The manifold's points side by side, one a lane (lanes past the count repeat the last point,
  // and are not written): each lane computes Eigen's expressions for its point operation for
  // operation (wide.h), so the rows are what a loop over the points would write.
  WideVec3 point_a, point_b;
  for (int k = 0; k < kWideLanes; ++k) {
    const ContactPoint& point = manifold.points[std::min(k, count - 1)];
    set_lane(&point_a, k, point.point_a);
    set_lane(&point_b, k, point.point_b);
  }
  const WideVec3 normal = broadcast(n);
  const WideVec3 ra = point_a - broadcast(a.position);
  const WideVec3 rb = point_b - broadcast(b.position);
  const WideVec3 local_a = times(ra_to_local, ra);
  const WideVec3 local_b = times(rb_to_local, rb);
  const WideVec3 dv = ((broadcast(b.linear_velocity) + cross(broadcast(b.angular_velocity), rb)) -
                       broadcast(a.linear_velocity)) -
                      cross(broadcast(a.angular_velocity), ra);
  const Wide relative_velocity = dot(dv, normal);
  // Friction along the sliding direction when sliding: a sliding body then feels exactly the
  // Coulomb force, whatever its direction (no bias from the basis).
  const WideVec3 slip = dv - scaled(relative_velocity, normal);
  const Wide slip_squared = dot(slip, slip);
  Wide slip_speed;
  for (int k = 0; k < kWideLanes; ++k)
    slip_speed[k] = std::sqrt(slip_squared[k]);
  const WideVec3 tangent1 =
      select(slip_speed > kSlidingSpeed,
             WideVec3{slip.x / slip_speed, slip.y / slip_speed, slip.z / slip_speed},
             broadcast(resting_tangent));
  const WideVec3 tangent2 = cross(normal, tangent1);
  const WideVec3 ra_cross_n = cross(ra, normal), rb_cross_n = cross(rb, normal);
  const WideVec3 ra_cross_t1 = cross(ra, tangent1), rb_cross_t1 = cross(rb, tangent1);
  const WideVec3 ra_cross_t2 = cross(ra, tangent2), rb_cross_t2 = cross(rb, tangent2);
  const Mat3& inertia_a = a.inverse_inertia_world;
  const Mat3& inertia_b = b.inverse_inertia_world;
  const WideVec3 angular_a = times(inertia_a, ra_cross_n), angular_b = times(inertia_b, rb_cross_n);
  const WideVec3 angular_a_t1 = times(inertia_a, ra_cross_t1);
  const WideVec3 angular_b_t1 = times(inertia_b, rb_cross_t1);
  const WideVec3 angular_a_t2 = times(inertia_a, ra_cross_t2);
  const WideVec3 angular_b_t2 = times(inertia_b, rb_cross_t2);
  const Wide normal_response =
      velocity_response(a, b, ra_cross_n, angular_a, rb_cross_n, angular_b);
  const Wide tangent_response1 =
      velocity_response(a, b, ra_cross_t1, angular_a_t1, rb_cross_t1, angular_b_t1);
  const Wide tangent_response2 =
      velocity_response(a, b, ra_cross_t2, angular_a_t2, rb_cross_t2, angular_b_t2);
  const Wide normal_mass = mass_of(normal_response);
  const Wide tangent_mass1 = mass_of(tangent_response1);
  const Wide tangent_mass2 = mass_of(tangent_response2);

  for (int i = 0; i < count; ++i) {
    const ContactPoint& point = manifold.points[i];
    ContactRow row;
    ContactRowCold far;
    row.a = solver_a;
    row.b = solver_b;
    row.normal = n;
    far.ra = lane_of(ra, i);
    far.rb = lane_of(rb, i);
    far.local_a = lane_of(local_a, i);
    far.local_b = lane_of(local_b, i);
    row.separation = -point.depth;
    row.friction = friction;
    far.restitution = restitution;
    far.feature = point.feature_id;
    row.manifold = block_index;
    row.block_index = static_cast<std::uint8_t>(i);
    row.block_size = static_cast<std::uint8_t>(count);
    far.relative_velocity = relative_velocity[i];
    row.tangent1 = lane_of(tangent1, i);
    row.tangent2 = lane_of(tangent2, i);
    row.ra_cross_n = lane_of(ra_cross_n, i);
    row.rb_cross_n = lane_of(rb_cross_n, i);
    row.angular_a = lane_of(angular_a, i);
    row.angular_b = lane_of(angular_b, i);
    row.ra_cross_t1 = lane_of(ra_cross_t1, i);
    row.rb_cross_t1 = lane_of(rb_cross_t1, i);
    row.ra_cross_t2 = lane_of(ra_cross_t2, i);
    row.rb_cross_t2 = lane_of(rb_cross_t2, i);
    row.angular_a_t1 = lane_of(angular_a_t1, i);
    row.angular_b_t1 = lane_of(angular_b_t1, i);
    row.angular_a_t2 = lane_of(angular_a_t2, i);
    row.angular_b_t2 = lane_of(angular_b_t2, i);
    row.normal_response = normal_response[i];
    row.tangent_response1 = tangent_response1[i];
    row.tangent_response2 = tangent_response2[i];
    row.normal_mass = normal_mass[i];
    row.tangent_mass1 = tangent_mass1[i];
    row.tangent_mass2 = tangent_mass2[i];

    // Feature ids change when a vertex of a face resting on an equal face moves across the
    // other's edge by a nanometre; the point has not moved, so its impulse still applies (Jolt
    // matches all points this way).
    const ContactPointRecord* match = nullptr;
    if (previous != nullptr) {
      double nearest = match_distance * match_distance;
      for (int k = 0; k < previous->count; ++k) {
        const ContactPointRecord& kept = previous->points[k];
        if (kept.feature == far.feature) {
          match = &kept;
          break;
        }
        const double d2 = (kept.local_a - far.local_a).squaredNorm();
        if (d2 < nearest) {
          nearest = d2;
          match = &kept;
        }
      }
    }
    if (match != nullptr) {
      row.normal_impulse = match->normal_impulse;
      row.tangent_impulse1 = match->friction_impulse.dot(row.tangent1);
      row.tangent_impulse2 = match->friction_impulse.dot(row.tangent2);
    }
    rows[i] = row;
    cold[i] = far;
  }

  NormalBlock normal_block;
  if (count > 1) {
    // The lower triangle and diagonal: all that the factorisation reads (K is symmetric).
    Eigen::Matrix4d k = Eigen::Matrix4d::Zero();
    for (int i = 0; i < count; ++i) {
      const ContactRow& ri = rows[i];
      for (int j = 0; j <= i; ++j) {
        const ContactRow& rj = rows[j];
        k(i, j) = a.inverse_mass + b.inverse_mass + rj.ra_cross_n.dot(ri.angular_a) +
                  rj.rb_cross_n.dot(ri.angular_b);
      }
    }
    // K is singular for coplanar points (a face has three degrees of freedom, not four). A
    // compliance of 1e-6 of the mean diagonal gives a well-posed inverse that, for velocity
    // errors a rigid face can produce, is the pseudo-inverse to that accuracy: the load spreads
    // evenly over the face.
    const double compliance = 1e-6 * k.trace() / count;
    for (int i = 0; i < count; ++i)
      k(i, i) += compliance;
    invert_positive_definite(k, count, &normal_block.inverse);
  }
  *block = normal_block;
}

Softness contact_softness(double hertz, double damping_ratio, double h) {
  if (hertz <= 0) return {};
  const double omega = 2 * std::numbers::pi * hertz;
  const double a1 = 2 * damping_ratio + h * omega;
  const double a2 = h * omega * a1;
  const double a3 = 1 / (1 + a2);
  return {omega / a1, a2 * a3, a3};
}

void update_separations(std::span<ContactRow> rows, std::span<const std::uint32_t> ids,
                        std::span<const SolverBody> bodies, double kinematic_elapsed) {
  if (kinematic_elapsed != 0) {
    for (std::uint32_t id : ids)
      rows[id].substep_separation = current_separation(rows[id], bodies, kinematic_elapsed);
    return;
  }
  for (std::uint32_t id : ids)
    rows[id].substep_separation = current_separation(rows[id], bodies);
}

void warm_start(std::span<ContactRow> rows, std::span<ContactRowCold> cold,
                std::span<const std::uint32_t> ids, std::span<SolverBody> bodies,
                bool keep_last_substep, double kinematic_elapsed) {
  for (std::uint32_t id : ids) {
    ContactRow& row = rows[id];
    row.substep_separation = current_separation(row, bodies);
    if (keep_last_substep) cold[id].earlier_substeps_impulse += row.normal_impulse;
    apply_normal_impulse(row, row.normal_impulse, bodies);
    if (row.tangent_impulse1 != 0 || row.tangent_impulse2 != 0)
      apply_tangent_impulses(row, row.tangent_impulse1, row.tangent_impulse2, bodies);
  }
  // The separations again with kinematic bodies' motion (the impulses moved no body).
  if (kinematic_elapsed != 0) update_separations(rows, ids, bodies, kinematic_elapsed);
}

namespace {

struct NormalTarget {
  double bias = 0, mass_scale = 1, impulse_scale = 0;
};

TUMBLE_INLINE NormalTarget normal_target(const ContactRow& row, const SolverSettings& settings,
                                         const Softness* soft, double inverse_h) {
  const double separation = row.substep_separation;
  if (separation > 0) return {separation * inverse_h, 1, 0};  // may close the gap, no more
  if (soft != nullptr && separation + settings.slop < 0)
    return {std::max(soft->bias_rate * (separation + settings.slop), -settings.max_push_velocity),
            soft->mass_scale, soft->impulse_scale};
  return {};
}

// The velocities of a manifold's two bodies, held in registers while its rows are solved and
// written back once: the rows of one manifold share both bodies, so going through memory for
// every row would reload them (the compiler cannot tell a row from a body). Statics are read,
// never written (islands and colours solved in parallel share them).
struct PairVelocities {
  Vec3 va, wa, vb, wb;
  double inverse_mass_a = 0, inverse_mass_b = 0;

  PairVelocities() = default;
  PairVelocities(const SolverBody& a, const SolverBody& b)
      : va(a.v),
        wa(a.w),
        vb(b.v),
        wb(b.w),
        inverse_mass_a(a.inverse_mass),
        inverse_mass_b(b.inverse_mass) {}

  void store(SolverBody& a, SolverBody& b) const {
    if (inverse_mass_a > 0) {
      a.v = va;
      a.w = wa;
    }
    if (inverse_mass_b > 0) {
      b.v = vb;
      b.w = wb;
    }
  }
  TUMBLE_INLINE double normal_velocity(const ContactRow& row) const {
    return row.normal.dot(vb - va) + wb.dot(row.rb_cross_n) - wa.dot(row.ra_cross_n);
  }
  // Impulses delta[i] along `normal` at four points with angular parts angular_a/b[i], at once.
  TUMBLE_INLINE void apply_normals(const Vec3& normal, const double (&delta)[4],
                                   const Vec3 (&angular_a)[4], const Vec3 (&angular_b)[4]) {
    const double total = ((delta[0] + delta[1]) + delta[2]) + delta[3];
    if (inverse_mass_a > 0) {
      va -= (inverse_mass_a * total) * normal;
      wa -= ((delta[0] * angular_a[0] + delta[1] * angular_a[1]) + delta[2] * angular_a[2]) +
            delta[3] * angular_a[3];
    }
    if (inverse_mass_b > 0) {
      vb += (inverse_mass_b * total) * normal;
      wb += ((delta[0] * angular_b[0] + delta[1] * angular_b[1]) + delta[2] * angular_b[2]) +
            delta[3] * angular_b[3];
    }
  }
  TUMBLE_INLINE void apply_normal(const ContactRow& row, double impulse) {
    if (inverse_mass_a > 0) {
      va -= (inverse_mass_a * impulse) * row.normal;
      wa -= impulse * row.angular_a;
    }
    if (inverse_mass_b > 0) {
      vb += (inverse_mass_b * impulse) * row.normal;
      wb += impulse * row.angular_b;
    }
  }
};

TUMBLE_INLINE double solve_friction(ContactRow& row, PairVelocities& pair) {
  if (row.friction <= 0) return 0;
  // A point that carries no load and held no friction has none to give (a speculative point
  // short of touching): the cone clamps it to nothing.
  if (row.normal_impulse == 0 && row.tangent_impulse1 == 0 && row.tangent_impulse2 == 0) return 0;
  const Vec3 dv = pair.vb - pair.va;
  const double v1 =
      row.tangent1.dot(dv) + pair.wb.dot(row.rb_cross_t1) - pair.wa.dot(row.ra_cross_t1);
  const double v2 =
      row.tangent2.dot(dv) + pair.wb.dot(row.rb_cross_t2) - pair.wa.dot(row.ra_cross_t2);
  const double limit = row.friction * row.normal_impulse;
  const double old1 = row.tangent_impulse1, old2 = row.tangent_impulse2;
  double new1 = old1 - row.tangent_mass1 * v1;
  double new2 = old2 - row.tangent_mass2 * v2;
  // The circular cone: no direction of sliding is preferred.
  const double squared = new1 * new1 + new2 * new2;
  if (squared > limit * limit) {
    const double scale = limit / std::sqrt(squared);
    new1 *= scale;
    new2 *= scale;
  }
  row.tangent_impulse1 = new1;
  row.tangent_impulse2 = new2;
  const double d1 = new1 - old1, d2 = new2 - old2;
  const Vec3 linear = d1 * row.tangent1 + d2 * row.tangent2;
  if (pair.inverse_mass_a > 0) {
    pair.va -= pair.inverse_mass_a * linear;
    pair.wa -= d1 * row.angular_a_t1 + d2 * row.angular_a_t2;
  }
  if (pair.inverse_mass_b > 0) {
    pair.vb += pair.inverse_mass_b * linear;
    pair.wb += d1 * row.angular_b_t1 + d2 * row.angular_b_t2;
  }
  // The velocity change this gave the contact, m/s.
  return std::max(std::abs(d1) * row.tangent_response1, std::abs(d2) * row.tangent_response2);
}

TUMBLE_INLINE double solve_normal(ContactRow& row, PairVelocities& pair,
                                  const NormalTarget& target) {
  const double vn = pair.normal_velocity(row);
  const double delta = -row.normal_mass * target.mass_scale * (vn + target.bias) -
                       target.impulse_scale * row.normal_impulse;
  const double updated = std::max(row.normal_impulse + delta, 0.0);
  const double change = std::abs(updated - row.normal_impulse) * row.normal_response;
  pair.apply_normal(row, updated - row.normal_impulse);
  row.normal_impulse = updated;
  row.max_normal_impulse = std::max(row.max_normal_impulse, updated);
  return change;
}

// The normals of one manifold as a block when the block solution keeps every impulse
// non-negative, else point by point. Returns the largest velocity change it gave a contact.
TUMBLE_INLINE double solve_normals(std::span<ContactRow> rows, const ManifoldRows& manifold,
                                   std::span<const NormalBlock> blocks, PairVelocities& pair,
                                   const NormalTarget* targets) {
  const std::uint32_t* ids = manifold.ids;
  const int count = manifold.count;
  if (count == 1) return solve_normal(rows[ids[0]], pair, targets[0]);
  Eigen::Vector4d error = Eigen::Vector4d::Zero();
  for (int i = 0; i < count; ++i)
    error[i] = pair.normal_velocity(rows[ids[i]]) + targets[i].bias;
  const Eigen::Matrix4d& inverse = blocks[rows[ids[0]].manifold].inverse;
  const Eigen::Vector4d step = inverse * error;
  double updated[4];
  bool feasible = true;
  for (int i = 0; i < count; ++i) {
    const ContactRow& row = rows[ids[i]];
    updated[i] = row.normal_impulse - targets[i].mass_scale * step[i] -
                 targets[i].impulse_scale * row.normal_impulse;
    feasible &= updated[i] >= 0;
  }
  double change = 0;
  if (!feasible) {
    for (int i = 0; i < count; ++i)
      change = std::max(change, solve_normal(rows[ids[i]], pair, targets[i]));
    return change;
  }
  // The block's impulses share the normal, so the bodies take their sum once (four points
  // applied one by one cost twice the arithmetic). Summed over four points, the missing ones as
  // zeros, in the order the packs sum their lanes (contact_packs.cc), so both give the same bits.
  double delta[4] = {};
  Vec3 angular_a[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  Vec3 angular_b[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  for (int i = 0; i < count; ++i) {
    ContactRow& row = rows[ids[i]];
    delta[i] = updated[i] - row.normal_impulse;
    angular_a[i] = row.angular_a;
    angular_b[i] = row.angular_b;
    change = std::max(change, std::abs(delta[i]) * row.normal_response);
    row.normal_impulse = updated[i];
    row.max_normal_impulse = std::max(row.max_normal_impulse, updated[i]);
  }
  pair.apply_normals(rows[ids[0]].normal, delta, angular_a, angular_b);
  return change;
}

// A manifold's rows form one chain of dependent arithmetic (each row reads the velocities the
// last one wrote); its bodies' velocities stay in registers across them (PairVelocities).
double solve_one_manifold(std::span<ContactRow> rows, const ManifoldRows& manifold,
                          std::span<const NormalBlock> blocks, std::span<SolverBody> bodies,
                          const SolverSettings& settings, const Softness* soft, double inverse_h) {
  const ContactRow& first = rows[manifold.ids[0]];
  SolverBody& body_a = bodies[first.a];
  SolverBody& body_b = bodies[first.b];
  PairVelocities pair(body_a, body_b);
  double change = 0;
  for (int i = 0; i < manifold.count; ++i)
    change = std::max(change, solve_friction(rows[manifold.ids[i]], pair));
  NormalTarget targets[4];
  for (int i = 0; i < manifold.count; ++i)
    targets[i] = normal_target(rows[manifold.ids[i]], settings, soft, inverse_h);
  change = std::max(change, solve_normals(rows, manifold, blocks, pair, targets));
  pair.store(body_a, body_b);
  return change;
}

}  // namespace

double solve_contacts(std::span<ContactRow> rows, std::span<const std::uint32_t> ids,
                      std::span<const NormalBlock> blocks, std::span<SolverBody> bodies,
                      const SolverSettings& settings, const Softness* soft, double h,
                      bool backward) {
  const double inverse_h = 1 / h;
  double change = 0;
  const std::size_t count = ids.size();
  // A manifold's rows are consecutive in `ids`; visit manifolds forwards or backwards.
  if (!backward) {
    for (std::size_t k = 0; k < count;) {
      const ManifoldRows manifold{&ids[k], rows[ids[k]].block_size};
      change = std::max(
          change, solve_one_manifold(rows, manifold, blocks, bodies, settings, soft, inverse_h));
      k += manifold.count;
    }
  } else {
    for (std::size_t end = count; end > 0;) {
      const ContactRow& last = rows[ids[end - 1]];
      const std::size_t start = end - 1 - last.block_index;
      const ManifoldRows manifold{&ids[start], last.block_size};
      change = std::max(
          change, solve_one_manifold(rows, manifold, blocks, bodies, settings, soft, inverse_h));
      end = start;
    }
  }
  return change;
}

double solve_manifold(std::span<ContactRow> rows, const ManifoldRows& manifold,
                      std::span<const NormalBlock> blocks, std::span<SolverBody> bodies,
                      const SolverSettings& settings, const Softness* soft, double h) {
  return solve_one_manifold(rows, manifold, blocks, bodies, settings, soft, 1 / h);
}

void apply_restitution(std::span<ContactRow> rows, std::span<const ContactRowCold> cold,
                       std::span<const std::uint32_t> ids, std::span<const NormalBlock> blocks,
                       std::span<SolverBody> bodies, const SolverSettings& settings) {
  auto bounces = [&](std::uint32_t id) {
    return cold[id].restitution > 0 &&
           cold[id].relative_velocity < -settings.restitution_threshold &&
           rows[id].max_normal_impulse > 0;
  };
  // The normal velocity restitution asks of a row: e times the approach velocity.
  auto rebound = [&](std::uint32_t id) {
    return cold[id].restitution * cold[id].relative_velocity;
  };
  for (std::size_t k = 0; k < ids.size();) {
    const int count = rows[ids[k]].block_size;
    const std::uint32_t* block = &ids[k];
    k += count;
    int bouncing = 0;
    for (int i = 0; i < count; ++i)
      bouncing += bounces(block[i]) ? 1 : 0;
    if (bouncing == 0) continue;
    // A face landing flat bounces as one: the block solve gives every corner its target at
    // once, where single points would each undo part of the others' work.
    if (bouncing == count && count > 1) {
      Eigen::Vector4d error = Eigen::Vector4d::Zero();
      for (int i = 0; i < count; ++i) {
        error[i] = normal_velocity(rows[block[i]], bodies) + rebound(block[i]);
      }
      const Eigen::Vector4d step = blocks[rows[block[0]].manifold].inverse * error;
      bool feasible = true;
      for (int i = 0; i < count; ++i)
        feasible &= rows[block[i]].normal_impulse - step[i] >= 0;
      if (feasible) {
        for (int i = 0; i < count; ++i) {
          ContactRow& row = rows[block[i]];
          apply_normal_impulse(row, -step[i], bodies);
          row.normal_impulse -= step[i];
        }
        continue;
      }
    }
    for (int i = 0; i < count; ++i) {
      if (!bounces(block[i])) continue;
      ContactRow& row = rows[block[i]];
      const double vn = normal_velocity(row, bodies);
      const double delta = -row.normal_mass * (vn + rebound(block[i]));
      const double updated = std::max(row.normal_impulse + delta, 0.0);
      apply_normal_impulse(row, updated - row.normal_impulse, bodies);
      row.normal_impulse = updated;
    }
  }
}

int impact_manifolds(std::span<const ContactRow> rows, std::span<const ContactRowCold> cold,
                     std::span<const std::uint32_t> ids, const SolverSettings& settings) {
  int elastic_manifolds = 0, manifolds = 0;
  bool bouncing = false;
  for (std::size_t k = 0; k < ids.size(); k += rows[ids[k]].block_size) {
    ++manifolds;
    if (cold[ids[k]].restitution <= 0) continue;
    ++elastic_manifolds;
    for (int i = 0; i < rows[ids[k]].block_size; ++i)
      bouncing |= cold[ids[k + i]].relative_velocity < -settings.restitution_threshold;
  }
  return bouncing && elastic_manifolds >= 2 ? manifolds : 0;
}

bool pass_impacts(std::span<const ContactRow> rows, std::span<ContactRowCold> cold,
                  std::span<const std::uint32_t> ids, std::span<const NormalBlock> blocks,
                  std::span<SolverBody> bodies, const SolverSettings& settings, double reach) {
  const double threshold = settings.restitution_threshold;
  const int manifolds = impact_manifolds(rows, cold, ids, settings);
  if (manifolds == 0) return false;
  // The approach speed of a contact that meets within `reach`, else 0.
  const auto approach = [&](std::uint32_t id) {
    const ContactRow& row = rows[id];
    if (cold[id].restitution <= 0) return 0.0;
    const double vn = normal_velocity(row, bodies);
    return vn < -threshold && row.separation + vn * reach <= 0 ? -vn : 0.0;
  };
  const int most_sweeps = std::min(kMostImpactSweeps, 2 * manifolds + 8);
  bool settled = false;
  for (int sweep = 0; sweep < most_sweeps && !settled; ++sweep) {
    settled = true;
    for (std::size_t k = 0; k < ids.size();) {
      const int count = rows[ids[k]].block_size;
      const std::uint32_t* block = &ids[k];
      k += count;
      double speeds[4] = {};
      int approaching = 0;
      for (int i = 0; i < count; ++i) {
        speeds[i] = approach(block[i]);
        approaching += speeds[i] > 0 ? 1 : 0;
      }
      if (approaching == 0) continue;
      settled = false;
      // A face landing flat bounces as one (as in apply_restitution), where its impulses all push.
      if (approaching == count && count > 1) {
        Eigen::Vector4d error = Eigen::Vector4d::Zero();
        for (int i = 0; i < count; ++i)
          error[i] = -(1 + cold[block[i]].restitution) * speeds[i];
        const Eigen::Vector4d impulse = -(blocks[rows[block[0]].manifold].inverse * error);
        if ((impulse.head(count).array() >= 0).all()) {
          for (int i = 0; i < count; ++i) {
            apply_normal_impulse(rows[block[i]], impulse[i], bodies);
            cold[block[i]].earlier_substeps_impulse += impulse[i];
          }
          continue;
        }
      }
      for (int i = 0; i < count; ++i) {
        const double speed = i == 0 ? speeds[0] : approach(block[i]);
        if (speed <= 0) continue;
        const ContactRow& row = rows[block[i]];
        const double impulse = (1 + cold[block[i]].restitution) * row.normal_mass * speed;
        apply_normal_impulse(row, impulse, bodies);
        cold[block[i]].earlier_substeps_impulse += impulse;
      }
    }
  }
  if (!settled) return true;
  for (std::uint32_t id : ids)
    cold[id].relative_velocity = 0;
  return false;
}

void correct_positions(std::span<const ContactRow> rows, std::span<const ContactRowCold> cold,
                       std::span<const std::uint32_t> ids, std::span<const SolverBody> bodies,
                       std::span<Pose> poses, const SolverSettings& settings, bool backward) {
  for (std::size_t n = 0; n < ids.size(); ++n) {
    const std::uint32_t id = backward ? ids[ids.size() - 1 - n] : ids[n];
    const ContactRow& row = rows[id];
    Pose& pa = poses[row.a];
    Pose& pb = poses[row.b];
    const Vec3 ra = pa.orientation * cold[id].local_a;
    const Vec3 rb = pb.orientation * cold[id].local_b;
    const double separation = (pb.position + rb - pa.position - ra).dot(row.normal);
    const double error = std::clamp(settings.baumgarte * (separation + settings.slop),
                                    -settings.max_correction, 0.0);
    if (error == 0) continue;
    const SolverBody& a = bodies[row.a];
    const SolverBody& b = bodies[row.b];
    const Vec3 ca = ra.cross(row.normal);
    const Vec3 cb = rb.cross(row.normal);
    const double k = a.inverse_mass + b.inverse_mass + ca.dot(a.inverse_inertia * ca) +
                     cb.dot(b.inverse_inertia * cb);
    if (k <= 0) continue;
    const Vec3 push = (-error / k) * row.normal;
    if (a.inverse_mass > 0) {
      pa.position -= a.inverse_mass * push;
      pa.orientation = rotated(pa.orientation, -(a.inverse_inertia * ra.cross(push)));
    }
    if (b.inverse_mass > 0) {
      pb.position += b.inverse_mass * push;
      pb.orientation = rotated(pb.orientation, b.inverse_inertia * rb.cross(push));
    }
  }
}

double normal_residual(std::span<const ContactRow> rows, std::span<const std::uint32_t> ids,
                       std::span<const SolverBody> bodies, double h, double kinematic_elapsed) {
  double residual = 0;
  for (std::uint32_t id : ids) {
    const ContactRow& row = rows[id];
    if (row.normal_mass <= 0) continue;
    const double separation = current_separation(row, bodies, kinematic_elapsed);
    const double target = separation > 0 ? -separation / h : 0;
    const double gap_velocity = normal_velocity(row, bodies) - target;
    const double impulse_velocity = row.normal_impulse / row.normal_mass;
    residual = std::max(residual, std::abs(std::min(impulse_velocity, gap_velocity)));
  }
  return residual;
}

}  // namespace tumble
