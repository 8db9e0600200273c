#include "contact_packs.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace tumble {
namespace {

// Which lanes `on` selects, as a mask. (Every helper that takes or returns a vector is inlined
// into the AVX2 clones: called out of line it would pass the vector by another convention than
// the clone expects, wide.h.)
TUMBLE_INLINE WideMask mask_of(const bool (&on)[kWideLanes]) {
  return WideMask{on[0] ? -1 : 0, on[1] ? -1 : 0, on[2] ? -1 : 0, on[3] ? -1 : 0};
}

// Where entry (i, j) of a block's inverse is kept (ContactPack::block_inverse): its lower triangle.
constexpr int triangle_index(int i, int j) {
  return i >= j ? i * (i + 1) / 2 + j : j * (j + 1) / 2 + i;
}
TUMBLE_INLINE const Wide& block_entry(const ContactPack& pack, int i, int j) {
  return pack.block_inverse[triangle_index(i, j)];
}

// A row of zeros, which lanes without a point p copy: they compute on zeros and write nothing.
ContactRow zero_row() {
  ContactRow row;
  for (Vec3* v :
       {&row.normal, &row.tangent1, &row.tangent2, &row.ra_cross_n, &row.rb_cross_n, &row.angular_a,
        &row.angular_b, &row.ra_cross_t1, &row.rb_cross_t1, &row.ra_cross_t2, &row.rb_cross_t2,
        &row.angular_a_t1, &row.angular_b_t1, &row.angular_a_t2, &row.angular_b_t2})
    v->setZero();
  return row;
}
const ContactRow kZeroRow = zero_row();

using LaneRows = const ContactRow* [kWideLanes];

// A field of four rows, one a lane: whole vectors are stored, four times fewer stores than lane
// by lane.
TUMBLE_INLINE Wide lanes_of(const LaneRows& rows, double ContactRow::*field) {
  return Wide{rows[0]->*field, rows[1]->*field, rows[2]->*field, rows[3]->*field};
}
TUMBLE_INLINE WideVec3 lanes_of(const LaneRows& rows, Vec3 ContactRow::*field) {
  return {Wide{(rows[0]->*field).x(), (rows[1]->*field).x(), (rows[2]->*field).x(),
               (rows[3]->*field).x()},
          Wide{(rows[0]->*field).y(), (rows[1]->*field).y(), (rows[2]->*field).y(),
               (rows[3]->*field).y()},
          Wide{(rows[0]->*field).z(), (rows[1]->*field).z(), (rows[2]->*field).z(),
               (rows[3]->*field).z()}};
}

// Point p of every lane from its row (kZeroRow where the lane has none), its friction from
// `friction_rows` (kZeroRow also where the point has no friction: solve_friction relies on it).
TUMBLE_INLINE void pack_point(const LaneRows& rows, const LaneRows& friction_rows, PackPoint* p) {
  p->tangent1 = lanes_of(friction_rows, &ContactRow::tangent1);
  p->tangent2 = lanes_of(friction_rows, &ContactRow::tangent2);
  p->ra_cross_n = lanes_of(rows, &ContactRow::ra_cross_n);
  p->rb_cross_n = lanes_of(rows, &ContactRow::rb_cross_n);
  p->angular_a = lanes_of(rows, &ContactRow::angular_a);
  p->angular_b = lanes_of(rows, &ContactRow::angular_b);
  p->ra_cross_t1 = lanes_of(friction_rows, &ContactRow::ra_cross_t1);
  p->rb_cross_t1 = lanes_of(friction_rows, &ContactRow::rb_cross_t1);
  p->ra_cross_t2 = lanes_of(friction_rows, &ContactRow::ra_cross_t2);
  p->rb_cross_t2 = lanes_of(friction_rows, &ContactRow::rb_cross_t2);
  p->angular_a_t1 = lanes_of(friction_rows, &ContactRow::angular_a_t1);
  p->angular_b_t1 = lanes_of(friction_rows, &ContactRow::angular_b_t1);
  p->angular_a_t2 = lanes_of(friction_rows, &ContactRow::angular_a_t2);
  p->angular_b_t2 = lanes_of(friction_rows, &ContactRow::angular_b_t2);
  p->separation = lanes_of(rows, &ContactRow::separation);
  p->substep_separation = lanes_of(rows, &ContactRow::substep_separation);
  p->earlier_substeps_impulse = wide(0);
  p->normal_mass = lanes_of(rows, &ContactRow::normal_mass);
  p->tangent_mass1 = lanes_of(friction_rows, &ContactRow::tangent_mass1);
  p->tangent_mass2 = lanes_of(friction_rows, &ContactRow::tangent_mass2);
  p->normal_response = lanes_of(rows, &ContactRow::normal_response);
  p->tangent_response1 = lanes_of(rows, &ContactRow::tangent_response1);
  p->tangent_response2 = lanes_of(rows, &ContactRow::tangent_response2);
  p->normal_impulse = lanes_of(rows, &ContactRow::normal_impulse);
  p->tangent_impulse1 = lanes_of(rows, &ContactRow::tangent_impulse1);
  p->tangent_impulse2 = lanes_of(rows, &ContactRow::tangent_impulse2);
  p->max_normal_impulse = lanes_of(rows, &ContactRow::max_normal_impulse);
}

}  // namespace

TUMBLE_PER_CPU
void pack_manifolds(const std::uint32_t (&manifolds)[kWideLanes],
                    std::span<const std::uint32_t> row_begin, std::span<const ContactRow> rows,
                    std::span<const NormalBlock> blocks, std::span<const SolverBody> bodies,
                    ContactPack* pack) {
  const std::uint32_t* any_manifold = std::find_if(
      std::begin(manifolds), std::end(manifolds), [](std::uint32_t m) { return m != kNoManifold; });
  TUMBLE_ASSERT(any_manifold != std::end(manifolds));
  bool moves_a[kWideLanes] = {}, moves_b[kWideLanes] = {};
  bool alone[kWideLanes] = {}, in_block[kWideLanes] = {};
  bool present[4][kWideLanes] = {}, rubs[4][kWideLanes] = {};
  LaneRows first_rows;
  pack->most_points = 0;
  for (int k = 0; k < kWideLanes; ++k) {
    // Lanes without a manifold read another lane's bodies (any valid memory), never write.
    const std::uint32_t m = manifolds[k] != kNoManifold ? manifolds[k] : *any_manifold;
    const ContactRow& first = rows[row_begin[m]];
    pack->a[k] = first.a;
    pack->b[k] = first.b;
    pack->first_row[k] = 0;
    pack->points[k] = 0;
    first_rows[k] = &kZeroRow;
    for (Wide& entry : pack->block_inverse)
      entry[k] = 0;
    if (manifolds[k] == kNoManifold) continue;
    first_rows[k] = &first;
    const int count = static_cast<int>(row_begin[m + 1] - row_begin[m]);
    pack->first_row[k] = row_begin[m];
    pack->points[k] = static_cast<std::uint8_t>(count);
    pack->most_points = std::max(pack->most_points, pack->points[k]);
    moves_a[k] = bodies[first.a].inverse_mass > 0;
    moves_b[k] = bodies[first.b].inverse_mass > 0;
    alone[k] = count == 1;
    in_block[k] = count > 1;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j <= i; ++j)
        pack->block_inverse[triangle_index(i, j)][k] = blocks[m].inverse(i, j);
    for (int p = 0; p < count; ++p) {
      present[p][k] = true;
      rubs[p][k] = rows[row_begin[m] + p].friction > 0;
    }
  }
  pack->normal = lanes_of(first_rows, &ContactRow::normal);
  pack->friction = lanes_of(first_rows, &ContactRow::friction);
  for (int k = 0; k < kWideLanes; ++k) {
    pack->inverse_mass_a[k] = first_rows[k] == &kZeroRow ? 0 : bodies[pack->a[k]].inverse_mass;
    pack->inverse_mass_b[k] = first_rows[k] == &kZeroRow ? 0 : bodies[pack->b[k]].inverse_mass;
  }
  pack->moves_a = mask_of(moves_a);
  pack->moves_b = mask_of(moves_b);
  pack->alone = mask_of(alone);
  pack->in_block = mask_of(in_block);
  // Every point, also past the most any lane has: the block solve reads all four (as zeros).
  for (int p = 0; p < 4; ++p) {
    LaneRows point_rows, friction_rows;
    for (int k = 0; k < kWideLanes; ++k) {
      point_rows[k] = present[p][k] ? &rows[row_begin[manifolds[k]] + p] : &kZeroRow;
      friction_rows[k] = rubs[p][k] ? point_rows[k] : &kZeroRow;
    }
    pack_point(point_rows, friction_rows, &pack->point[p]);
    pack->point[p].present = mask_of(present[p]);
    pack->point[p].rubs = mask_of(rubs[p]);
  }
}

void store_impulses(const ContactPack& pack, std::span<ContactRow> rows,
                    std::span<ContactRowCold> cold) {
  for (int k = 0; k < kWideLanes; ++k) {
    for (int p = 0; p < pack.points[k]; ++p) {
      const PackPoint& point = pack.point[p];
      const std::uint32_t id = pack.first_row[k] + p;
      ContactRow& row = rows[id];
      row.normal_impulse = point.normal_impulse[k];
      row.tangent_impulse1 = point.tangent_impulse1[k];
      row.tangent_impulse2 = point.tangent_impulse2[k];
      row.max_normal_impulse = point.max_normal_impulse[k];
      row.substep_separation = point.substep_separation[k];
      cold[id].earlier_substeps_impulse = point.earlier_substeps_impulse[k];
    }
  }
}

namespace {

// A vector of each lane's two bodies, twice: their velocities, held while the pack is solved
// (PairVelocities, four at a time), or their motion since the step start.
struct WidePair {
  WideVec3 va, wa, vb, wb;
};

// Two vectors of each lane's two bodies: their velocities (v, w), or their motion since the step
// start (delta_position, delta_angle) for the separations of moving anchors.
template <Vec3 SolverBody::*Linear, Vec3 SolverBody::*Angular>
TUMBLE_INLINE WidePair gather(const ContactPack& pack, std::span<const SolverBody> bodies) {
  WidePair pair;
  for (int k = 0; k < kWideLanes; ++k) {
    const SolverBody& a = bodies[pack.a[k]];
    const SolverBody& b = bodies[pack.b[k]];
    set_lane(&pair.va, k, a.*Linear);
    set_lane(&pair.wa, k, a.*Angular);
    set_lane(&pair.vb, k, b.*Linear);
    set_lane(&pair.wb, k, b.*Angular);
  }
  return pair;
}

// Adds to the lanes' motion since the step start (gather's delta_position and delta_angle) a
// kinematic body's, its velocity times `kinematic_elapsed` (SolverBody::kinematic). Out of line:
// a world without kinematic bodies never calls it, and its sweeps' code stays as it was.
[[gnu::noinline]] void add_kinematic_motion(const ContactPack& pack,
                                            std::span<const SolverBody> bodies,
                                            double kinematic_elapsed, WidePair* motion) {
  for (int k = 0; k < kWideLanes; ++k) {
    const SolverBody& a = bodies[pack.a[k]];
    const SolverBody& b = bodies[pack.b[k]];
    if (a.kinematic) {
      set_lane(&motion->va, k, lane_of(motion->va, k) + kinematic_elapsed * a.v);
      set_lane(&motion->wa, k, lane_of(motion->wa, k) + kinematic_elapsed * a.w);
    }
    if (b.kinematic) {
      set_lane(&motion->vb, k, lane_of(motion->vb, k) + kinematic_elapsed * b.v);
      set_lane(&motion->wb, k, lane_of(motion->wb, k) + kinematic_elapsed * b.w);
    }
  }
}

TUMBLE_INLINE void scatter(const ContactPack& pack, WideMask lanes, const WidePair& pair,
                           std::span<SolverBody> bodies) {
  const WideMask moves_a = lanes & pack.moves_a, moves_b = lanes & pack.moves_b;
  for (int k = 0; k < kWideLanes; ++k) {
    if (moves_a[k]) {
      bodies[pack.a[k]].v = lane_of(pair.va, k);
      bodies[pack.a[k]].w = lane_of(pair.wa, k);
    }
    if (moves_b[k]) {
      bodies[pack.b[k]].v = lane_of(pair.vb, k);
      bodies[pack.b[k]].w = lane_of(pair.wb, k);
    }
  }
}

// current_separation, lane by lane.
TUMBLE_INLINE Wide current_separation(const ContactPack& pack, const WidePair& motion,
                                      const PackPoint& point) {
  return point.separation + dot(pack.normal, motion.vb - motion.va) +
         dot(motion.wb, point.rb_cross_n) - dot(motion.wa, point.ra_cross_n);
}

// The same, set in the lanes where the point is present.
TUMBLE_INLINE void set_substep_separation(const ContactPack& pack, const WidePair& motion,
                                          PackPoint& point) {
  point.substep_separation =
      select(point.present, current_separation(pack, motion, point), point.substep_separation);
}

// normal_target's bias, mass scale and impulse scale, lane by lane.
struct WideTarget {
  Wide bias, mass_scale, impulse_scale;
};

TUMBLE_INLINE WideTarget wide_target(const PackPoint& point, const SolverSettings& settings,
                                     const Softness* soft, double inverse_h) {
  const Wide separation = point.substep_separation;
  const WideMask gap = separation > 0;
  WideTarget target{select(gap, separation * inverse_h, wide(0)), wide(1), wide(0)};
  if (soft != nullptr) {
    const Wide beyond_slop = separation + settings.slop;
    const WideMask pushes = ~gap & (beyond_slop < 0);
    target.bias =
        select(pushes, wide_max(soft->bias_rate * beyond_slop, wide(-settings.max_push_velocity)),
               target.bias);
    target.mass_scale = select(pushes, wide(soft->mass_scale), target.mass_scale);
    target.impulse_scale = select(pushes, wide(soft->impulse_scale), target.impulse_scale);
  }
  return target;
}

TUMBLE_INLINE Wide normal_velocity(const ContactPack& pack, const PackPoint& point,
                                   const WidePair& pair) {
  return dot(pack.normal, pair.vb - pair.va) + dot(pair.wb, point.rb_cross_n) -
         dot(pair.wa, point.ra_cross_n);
}

// Applies a normal impulse change in the lanes of `mask` (PairVelocities::apply_normal).
TUMBLE_INLINE void apply_normal(const ContactPack& pack, const PackPoint& point, WideMask mask,
                                Wide impulse, WidePair& pair) {
  const WideMask on_a = mask & pack.moves_a, on_b = mask & pack.moves_b;
  pair.va =
      select(on_a, minus_scaled(pair.va, pack.inverse_mass_a * impulse, pack.normal), pair.va);
  pair.wa = select(on_a, minus_scaled(pair.wa, impulse, point.angular_a), pair.wa);
  pair.vb = select(on_b, plus_scaled(pair.vb, pack.inverse_mass_b * impulse, pack.normal), pair.vb);
  pair.wb = select(on_b, plus_scaled(pair.wb, impulse, point.angular_b), pair.wb);
}

// delta[i] times point i's angular part, summed over the four points in the rows' order.
TUMBLE_INLINE WideVec3 summed_angular(const PackPoint* p, const Wide (&delta)[4],
                                      WideVec3 PackPoint::*angular) {
  WideVec3 term[4];
  for (int i = 0; i < 4; ++i)
    term[i] = {delta[i] * (p[i].*angular).x, delta[i] * (p[i].*angular).y,
               delta[i] * (p[i].*angular).z};
  return ((term[0] + term[1]) + term[2]) + term[3];
}

// Applies a block's impulse changes delta[i] at its four points at once in the lanes of `mask`
// (PairVelocities::apply_normals). Points past most_points are zeros in every lane.
TUMBLE_INLINE void apply_normals(const ContactPack& pack, WideMask mask, const Wide (&delta)[4],
                                 WidePair& pair) {
  const PackPoint* p = pack.point;
  const Wide total = ((delta[0] + delta[1]) + delta[2]) + delta[3];
  const WideVec3 sum_a = summed_angular(p, delta, &PackPoint::angular_a);
  const WideVec3 sum_b = summed_angular(p, delta, &PackPoint::angular_b);
  const WideMask on_a = mask & pack.moves_a, on_b = mask & pack.moves_b;
  pair.va = select(on_a, minus_scaled(pair.va, pack.inverse_mass_a * total, pack.normal), pair.va);
  pair.wa = select(on_a, pair.wa - sum_a, pair.wa);
  pair.vb = select(on_b, plus_scaled(pair.vb, pack.inverse_mass_b * total, pack.normal), pair.vb);
  pair.wb = select(on_b, pair.wb + sum_b, pair.wb);
}

// Applies impulses d1 and d2 along a point's tangents in the lanes of `mask`
// (apply_tangent_impulses).
TUMBLE_INLINE void apply_tangents(const ContactPack& pack, const PackPoint& point, WideMask mask,
                                  Wide d1, Wide d2, WidePair& pair) {
  const WideVec3 linear = {d1 * point.tangent1.x + d2 * point.tangent2.x,
                           d1 * point.tangent1.y + d2 * point.tangent2.y,
                           d1 * point.tangent1.z + d2 * point.tangent2.z};
  const WideVec3 angular_a = {d1 * point.angular_a_t1.x + d2 * point.angular_a_t2.x,
                              d1 * point.angular_a_t1.y + d2 * point.angular_a_t2.y,
                              d1 * point.angular_a_t1.z + d2 * point.angular_a_t2.z};
  const WideVec3 angular_b = {d1 * point.angular_b_t1.x + d2 * point.angular_b_t2.x,
                              d1 * point.angular_b_t1.y + d2 * point.angular_b_t2.y,
                              d1 * point.angular_b_t1.z + d2 * point.angular_b_t2.z};
  const WideMask on_a = mask & pack.moves_a, on_b = mask & pack.moves_b;
  pair.va = select(on_a, minus_scaled(pair.va, pack.inverse_mass_a, linear), pair.va);
  pair.wa = select(on_a, pair.wa - angular_a, pair.wa);
  pair.vb = select(on_b, plus_scaled(pair.vb, pack.inverse_mass_b, linear), pair.vb);
  pair.wb = select(on_b, pair.wb + angular_b, pair.wb);
}

// apply_tangents in every lane (solve_friction says when that is the same).
TUMBLE_INLINE void add_tangents(const ContactPack& pack, const PackPoint& point, Wide d1, Wide d2,
                                WidePair& pair) {
  const WideVec3 linear = {d1 * point.tangent1.x + d2 * point.tangent2.x,
                           d1 * point.tangent1.y + d2 * point.tangent2.y,
                           d1 * point.tangent1.z + d2 * point.tangent2.z};
  pair.va = minus_scaled(pair.va, pack.inverse_mass_a, linear);
  pair.wa = pair.wa - WideVec3{d1 * point.angular_a_t1.x + d2 * point.angular_a_t2.x,
                               d1 * point.angular_a_t1.y + d2 * point.angular_a_t2.y,
                               d1 * point.angular_a_t1.z + d2 * point.angular_a_t2.z};
  pair.vb = plus_scaled(pair.vb, pack.inverse_mass_b, linear);
  pair.wb = pair.wb + WideVec3{d1 * point.angular_b_t1.x + d2 * point.angular_b_t2.x,
                               d1 * point.angular_b_t1.y + d2 * point.angular_b_t2.y,
                               d1 * point.angular_b_t1.z + d2 * point.angular_b_t2.z};
}

// solve_friction for a point in the lanes of `mask`. Returns the velocity change per lane.
TUMBLE_INLINE Wide solve_friction(const ContactPack& pack, PackPoint& point, WideMask mask,
                                  WidePair& pair) {
  const WideVec3 dv = pair.vb - pair.va;
  const Wide v1 =
      dot(point.tangent1, dv) + dot(pair.wb, point.rb_cross_t1) - dot(pair.wa, point.ra_cross_t1);
  const Wide v2 =
      dot(point.tangent2, dv) + dot(pair.wb, point.rb_cross_t2) - dot(pair.wa, point.ra_cross_t2);
  const Wide limit = pack.friction * point.normal_impulse;
  const Wide old1 = point.tangent_impulse1, old2 = point.tangent_impulse2;
  Wide new1 = old1 - point.tangent_mass1 * v1;
  Wide new2 = old2 - point.tangent_mass2 * v2;
  const Wide squared = new1 * new1 + new2 * new2;
  const WideMask outside_cone = mask & (squared > limit * limit);
  if (any(outside_cone)) {
    // Every lane's root and quotient at once (correctly rounded, so each lane's are the scalar
    // solver's), kept where the lane is outside the cone: branching lane by lane cost more.
    Wide root;
    for (int k = 0; k < kWideLanes; ++k)
      root[k] = std::sqrt(squared[k]);
    const Wide scale = limit / root;
    new1 = select(outside_cone, new1 * scale, new1);
    new2 = select(outside_cone, new2 * scale, new2);
  }
  point.tangent_impulse1 = select(mask, new1, old1);
  point.tangent_impulse2 = select(mask, new2, old2);
  // Applied in every lane, without the selects: a lane outside `mask` either has no friction at
  // this point (its friction data are zeros, pack_manifolds, so body a's velocity loses +0, which
  // leaves every value as it was, and body b's gains +0, which leaves every value but a -0, made
  // +0 where the rows would keep it: a velocity component holds -0 only while every change made to
  // it was -0 too, which no scene of the tests has shown) or is not swept now (solve_pack writes
  // back only the swept lanes), and a static body adds 0 times its zero inverse mass and inertia to
  // its own zero velocity, which stays +0. The rows' bits, in fewer operations.
  const Wide d1 = new1 - old1, d2 = new2 - old2;
  add_tangents(pack, point, d1, d2, pair);
  return wide_max(wide_abs(d1) * point.tangent_response1, wide_abs(d2) * point.tangent_response2);
}

// solve_normal for point p in the lanes of `mask`.
TUMBLE_INLINE Wide solve_normal(const ContactPack& pack, PackPoint& point, WideMask mask,
                                const WideTarget& target, WidePair& pair) {
  const Wide vn = normal_velocity(pack, point, pair);
  const Wide delta = -point.normal_mass * target.mass_scale * (vn + target.bias) -
                     target.impulse_scale * point.normal_impulse;
  const Wide updated = wide_max(point.normal_impulse + delta, wide(0));
  const Wide change = wide_abs(updated - point.normal_impulse) * point.normal_response;
  apply_normal(pack, point, mask, updated - point.normal_impulse, pair);
  point.normal_impulse = select(mask, updated, point.normal_impulse);
  point.max_normal_impulse =
      select(mask, wide_max(point.max_normal_impulse, updated), point.max_normal_impulse);
  return select(mask, change, wide(0));
}

}  // namespace

namespace {

bool machine_has_wide_vectors() {
#if defined(__x86_64__)
  // This runs as a static initialiser, possibly before libgcc's own has read the CPU's features.
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

std::atomic<bool> sweep_packs{machine_has_wide_vectors()};

}  // namespace

bool packed_sweeps() {
  return sweep_packs.load(std::memory_order_relaxed);
}

void set_packed_sweeps(bool on) {
  sweep_packs.store(on, std::memory_order_relaxed);
}

TUMBLE_PER_CPU
void warm_start(ContactPack& pack, std::span<SolverBody> bodies, bool keep_last_substep,
                double kinematic_elapsed) {
  WidePair pair = gather<&SolverBody::v, &SolverBody::w>(pack, bodies);
  const WidePair motion =
      gather<&SolverBody::delta_position, &SolverBody::delta_angle>(pack, bodies);
  for (int p = 0; p < pack.most_points; ++p) {
    PackPoint& point = pack.point[p];
    set_substep_separation(pack, motion, point);
    if (keep_last_substep)
      point.earlier_substeps_impulse =
          select(point.present, point.earlier_substeps_impulse + point.normal_impulse,
                 point.earlier_substeps_impulse);
    apply_normal(pack, point, point.present, point.normal_impulse, pair);
    const WideMask rubbing =
        point.present & ((point.tangent_impulse1 != 0) | (point.tangent_impulse2 != 0));
    apply_tangents(pack, point, rubbing, point.tangent_impulse1, point.tangent_impulse2, pair);
  }
  scatter(pack, kAllLanes, pair, bodies);
  // The separations again with kinematic bodies' motion (the impulses moved no body).
  if (kinematic_elapsed != 0) update_separations(pack, bodies, kinematic_elapsed);
}

// update_separations with kinematic bodies' motion.
[[gnu::noinline]] void update_kinematic_separations(ContactPack& pack,
                                                    std::span<const SolverBody> bodies,
                                                    double kinematic_elapsed) {
  WidePair motion = gather<&SolverBody::delta_position, &SolverBody::delta_angle>(pack, bodies);
  add_kinematic_motion(pack, bodies, kinematic_elapsed, &motion);
  for (int p = 0; p < pack.most_points; ++p)
    set_substep_separation(pack, motion, pack.point[p]);
}

TUMBLE_PER_CPU
void update_separations(ContactPack& pack, std::span<const SolverBody> bodies,
                        double kinematic_elapsed) {
  if (kinematic_elapsed != 0) return update_kinematic_separations(pack, bodies, kinematic_elapsed);
  const WidePair motion =
      gather<&SolverBody::delta_position, &SolverBody::delta_angle>(pack, bodies);
  for (int p = 0; p < pack.most_points; ++p)
    set_substep_separation(pack, motion, pack.point[p]);
}

template <bool kKinematic>
TUMBLE_INLINE void residuals_of(const ContactPack& pack, std::span<const SolverBody> bodies,
                               double h, double (&lane_residuals)[kWideLanes],
                               double kinematic_elapsed) {
  const WidePair pair = gather<&SolverBody::v, &SolverBody::w>(pack, bodies);
  WidePair motion = gather<&SolverBody::delta_position, &SolverBody::delta_angle>(pack, bodies);
  if constexpr (kKinematic) add_kinematic_motion(pack, bodies, kinematic_elapsed, &motion);
  Wide residual = wide(0);
  for (int p = 0; p < pack.most_points; ++p) {
    const PackPoint& point = pack.point[p];
    // Rows that nothing can move are left out, as normal_residual leaves them.
    const WideMask measured = point.present & (point.normal_mass > 0);
    const Wide separation = current_separation(pack, motion, point);
    const Wide target = select(separation > 0, -separation / h, wide(0));
    const Wide gap_velocity = normal_velocity(pack, point, pair) - target;
    const Wide impulse_velocity = point.normal_impulse / point.normal_mass;
    // std::min's choice, then std::max's.
    const Wide smaller = select(gap_velocity < impulse_velocity, gap_velocity, impulse_velocity);
    residual = select(measured, wide_max(residual, wide_abs(smaller)), residual);
  }
  for (int k = 0; k < kWideLanes; ++k)
    lane_residuals[k] = residual[k];
}

[[gnu::noinline]] void kinematic_residuals(const ContactPack& pack,
                                           std::span<const SolverBody> bodies, double h,
                                           double (&lane_residuals)[kWideLanes],
                                           double kinematic_elapsed) {
  residuals_of<true>(pack, bodies, h, lane_residuals, kinematic_elapsed);
}

TUMBLE_PER_CPU
void pack_residuals(const ContactPack& pack, std::span<const SolverBody> bodies, double h,
                    double (&lane_residuals)[kWideLanes], double kinematic_elapsed) {
  if (kinematic_elapsed != 0)
    return kinematic_residuals(pack, bodies, h, lane_residuals, kinematic_elapsed);
  residuals_of<false>(pack, bodies, h, lane_residuals, 0);
}

// Compiled twice, for AVX2 (one register a vector) and for any x86-64 (two), and chosen when the
// program loads: the same operations lane by lane, so the same bits on either.
// (Vectors cross its boundary by reference: GCC gives the clones one calling convention only
// that way.)
TUMBLE_PER_CPU
double solve_pack(ContactPack& pack, const WideMask& lanes, std::span<SolverBody> bodies,
                  const SolverSettings& settings, const Softness* soft, double h,
                  double* lane_changes) {
  const double inverse_h = 1 / h;
  const int most = pack.most_points;
  WidePair pair = gather<&SolverBody::v, &SolverBody::w>(pack, bodies);
  Wide change = wide(0);
  for (int p = 0; p < most; ++p)
    change =
        wide_max(change, solve_friction(pack, pack.point[p], pack.point[p].rubs & lanes, pair));

  WideTarget targets[4];
  for (int p = 0; p < most; ++p)
    targets[p] = wide_target(pack.point[p], settings, soft, inverse_h);

  // The block solve of manifolds with several points, taken where it keeps every impulse
  // non-negative (solve_normals); elsewhere, and for single points, point by point.
  WideMask one_by_one = pack.alone & lanes;
  const WideMask in_block = pack.in_block & lanes;
  if (any(in_block)) {
    Wide error[4];
    for (int p = 0; p < 4; ++p) {
      error[p] = p < most
                     ? select(pack.point[p].present,
                              normal_velocity(pack, pack.point[p], pair) + targets[p].bias, wide(0))
                     : wide(0);
    }
    Wide updated[4];
    WideMask feasible = in_block;
    for (int i = 0; i < most; ++i) {
      const PackPoint& point = pack.point[i];
      const Wide step = block_entry(pack, i, 0) * error[0] + block_entry(pack, i, 1) * error[1] +
                        block_entry(pack, i, 2) * error[2] + block_entry(pack, i, 3) * error[3];
      updated[i] = point.normal_impulse - targets[i].mass_scale * step -
                   targets[i].impulse_scale * point.normal_impulse;
      feasible &= ~point.present | (updated[i] >= 0);
    }
    // The points a lane lacks are zeros (an impulse change of +0 at a zero lever), as the scalar
    // solver pads them: the sums below are its sums, lane by lane.
    Wide delta[4] = {wide(0), wide(0), wide(0), wide(0)};
    for (int i = 0; i < most; ++i) {
      PackPoint& point = pack.point[i];
      const WideMask mask = feasible & point.present;
      delta[i] = updated[i] - point.normal_impulse;
      change = wide_max(change, select(mask, wide_abs(delta[i]) * point.normal_response, wide(0)));
      point.normal_impulse = select(mask, updated[i], point.normal_impulse);
      point.max_normal_impulse =
          select(mask, wide_max(point.max_normal_impulse, updated[i]), point.max_normal_impulse);
    }
    apply_normals(pack, feasible, delta, pair);
    one_by_one |= in_block & ~feasible;
  }
  if (any(one_by_one)) {
    // Only as many points as those lanes have (single points are the usual reason).
    int points = 0;
    // (A lane's mask is all ones or zeros: the points of the lanes in it, without a branch on
    // which lanes they are, which a pile's packs made a coin toss.)
    for (int k = 0; k < kWideLanes; ++k)
      points = std::max(points, static_cast<int>(pack.points[k]) & static_cast<int>(one_by_one[k]));
    for (int p = 0; p < points; ++p)
      change = wide_max(change, solve_normal(pack, pack.point[p],
                                             one_by_one & pack.point[p].present, targets[p], pair));
  }
  scatter(pack, lanes, pair, bodies);
  if (lane_changes != nullptr)
    for (int k = 0; k < kWideLanes; ++k)
      lane_changes[k] = change[k];
  return largest_lane(change);
}

}  // namespace tumble
