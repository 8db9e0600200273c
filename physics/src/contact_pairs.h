// Touching pairs kept from step to step (ContactPairRecord, world_state.h): finding last step's
// record of a pair, how far the pair has moved since, and recording a manifold.
#pragma once

#include <cstdint>
#include <span>

#include "narrow_phase.h"
#include "physics/world_state.h"

namespace tumble {

constexpr std::uint32_t kNoRecord = UINT32_MAX;

// The record of the pair (a, b), same generations, in `records` sorted by body pair; kNoRecord
// when there is none.
std::uint32_t find_pair_record(std::span<const ContactPairRecord> records, BodyId a, BodyId b);

// How far a point where the bodies can touch (inside both outer spheres) can have moved relative
// to the other body since the record's pose (m): B's centre's shift in A's axes plus the turn
// times B's outer radius, or the same from B's side, whichever is smaller (the two coincident
// points of A and B move apart by the same amount seen from either; a half-space's radius is
// infinite).
double relative_motion(const ContactPairRecord& record, const Pose& pose_a, const Pose& pose_b,
                       double outer_radius_a, double outer_radius_b);

PolytopeFeature recorded_feature(const ContactPairRecord& record);

// A record of `manifold`, from `feature`, with the bodies at these poses; impulses zero.
void record_manifold(const ContactManifold& manifold, const PolytopeFeature& feature, BodyId a,
                     const Pose& pose_a, BodyId b, const Pose& pose_b, ContactPairRecord* out);

}  // namespace tumble
