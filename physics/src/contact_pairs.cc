#include "contact_pairs.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tumble {
namespace {

// A shift plus a turn about the centre: the farthest a point within `radius` can move.
double moved_at_most(double shift, double angle, double radius) {
  return std::isinf(radius) ? std::numeric_limits<double>::infinity() : shift + angle * radius;
}

}  // namespace

void match_pair_records(std::span<const BodyPair> pairs, std::span<const ContactPairRecord> records,
                        std::span<std::uint32_t> out) {
  const auto before = [](const ContactPairRecord& r, const BodyPair& p) {
    return r.a.index != p.a ? r.a.index < p.a : r.b.index < p.b;
  };
  std::size_t r = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    while (r < records.size() && before(records[r], pairs[i]))
      ++r;
    const bool same =
        r < records.size() && records[r].a.index == pairs[i].a && records[r].b.index == pairs[i].b;
    out[i] = same ? static_cast<std::uint32_t>(r) : kNoRecord;
  }
}

double relative_motion(const ContactPairRecord& record, const Pose& pose_a, const Pose& pose_b,
                       double outer_radius_a, double outer_radius_b) {
  const Vec3 position = pose_a.inverse_transform(pose_b.position);
  const Quat orientation = pose_a.orientation.conjugate() * pose_b.orientation;
  const Quat turn = record.relative_orientation.conjugate() * orientation;
  const double angle = 2 * std::asin(std::min(1.0, turn.vec().norm()));
  const double shift_in_a = (position - record.relative_position).norm();
  // A's centre seen from B: -(B's orientation in A)^-1 times B's position in A.
  const double shift_in_b = (orientation.conjugate() * position -
                             record.relative_orientation.conjugate() * record.relative_position)
                                .norm();
  return std::min(moved_at_most(shift_in_a, angle, outer_radius_b),
                  moved_at_most(shift_in_b, angle, outer_radius_a));
}

PolytopeFeature recorded_feature(const ContactPairRecord& record) {
  return {static_cast<PolytopeFeature::Kind>(record.feature_kind), record.feature_first,
          record.feature_second, false};
}

void match_manifold_records(std::span<const ContactManifold> manifolds,
                            std::span<const ContactPairRecord> run, bool by_feature,
                            std::span<std::uint32_t> out) {
  static_assert(kMaxPairManifolds <= 64, "one bit per record below");
  if (!by_feature) {
    for (std::size_t c = 0; c < manifolds.size(); ++c)
      out[c] = c < run.size() ? static_cast<std::uint32_t>(c) : kNoRecord;
    return;
  }
  std::uint64_t taken = 0;
  const auto shares_a_point = [](const ContactManifold& m, const ContactPairRecord& r) {
    for (int i = 0; i < m.count; ++i)
      for (int k = 0; k < r.count; ++k)
        if (m.points[i].feature_id == r.points[k].feature) return true;
    return false;
  };
  for (std::size_t c = 0; c < manifolds.size(); ++c) {
    out[c] = kNoRecord;
    for (std::size_t k = 0; k < run.size() && k < kMaxPairManifolds; ++k)
      if ((taken >> k & 1) == 0 && shares_a_point(manifolds[c], run[k])) {
        out[c] = static_cast<std::uint32_t>(k);
        taken |= std::uint64_t{1} << k;
        break;
      }
  }
  for (std::size_t c = 0; c < manifolds.size(); ++c)
    if (out[c] == kNoRecord && c < run.size() && (taken >> c & 1) == 0) {
      out[c] = static_cast<std::uint32_t>(c);
      taken |= std::uint64_t{1} << c;
    }
}

void record_manifold(const ContactManifold& manifold, const PolytopeFeature& feature, BodyId a,
                     const Pose& pose_a, BodyId b, const Pose& pose_b, ContactPairRecord* out) {
  out->a = a;
  out->b = b;
  out->relative_position = pose_a.inverse_transform(pose_b.position);
  out->relative_orientation = pose_a.orientation.conjugate() * pose_b.orientation;
  out->feature_kind = feature.kind;
  out->feature_first = feature.first;
  out->feature_second = feature.second;
  out->count = manifold.count;
  // Given by the step's rows stage (prepare_contact_rows); written here too, so that a record
  // in the narrow phase's unwritten buffers (ScratchBuffer) holds nothing undefined that is read.
  out->colour = kNoContactColour;
  for (int i = 0; i < manifold.count; ++i) {
    const ContactPoint& point = manifold.points[i];
    out->points[i] = {point.feature_id, pose_a.inverse_transform(point.point_a), 0.0, Vec3::Zero()};
  }
}

}  // namespace tumble
