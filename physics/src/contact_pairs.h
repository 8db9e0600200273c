// Touching pairs kept from step to step (ContactPairRecord, world_state.h): finding last step's
// record of a pair, taking its manifold again while the pair has barely moved, and recording a
// manifold the narrow phase found.
#pragma once

#include <cstdint>
#include <span>

#include "physics/collision.h"
#include "physics/world_state.h"

namespace tumble {

constexpr std::uint32_t kNoRecord = UINT32_MAX;

// The record of the pair (a, b), same generations, in `records` sorted by body pair; kNoRecord
// when there is none.
std::uint32_t find_pair_record(std::span<const ContactPairRecord> records, BodyId a, BodyId b);

// How far any point of either body can have moved relative to the other since the record was
// made (m): B's motion in A's axes bounded by its centre's shift plus the turn times its outer
// radius, or the same from B's side, whichever is smaller (a half-space's radius is infinite).
double relative_motion(const ContactPairRecord& record, const Pose& pose_a, const Pose& pose_b,
                       double outer_radius_a, double outer_radius_b);

// Whether the record's manifold still stands for the pair: nothing moved by more than
// `tolerance`, and no feature the record left out can have come within `margin` (the margin it
// was found with covers today's plus the motion).
bool may_reuse(const ContactPairRecord& record, double motion, double tolerance, double margin);

// The record's manifold at the bodies' present poses: its points move with the bodies, each
// depth measured along the normal, which turns with A.
void manifold_from_record(const ContactPairRecord& record, const Pose& pose_a, const Pose& pose_b,
                          ContactManifold* out);

// A record of `manifold`, found at these poses with this margin; impulses zero.
void record_manifold(const ContactManifold& manifold, BodyId a, const Pose& pose_a, BodyId b,
                     const Pose& pose_b, double margin, ContactPairRecord* out);

}  // namespace tumble
