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
  for (int i = 0; i < manifold.count; ++i) {
    const ContactPoint& point = manifold.points[i];
    out->points[i] = {point.feature_id, pose_a.inverse_transform(point.point_a), 0.0, Vec3::Zero()};
  }
}

}  // namespace tumble
