// Touching pairs kept from step to step (ContactPairRecord, contact_record.h): matching this step's
// pairs to last step's records, how far the pair has moved since, and recording a manifold.
#pragma once

#include <cstdint>
#include <span>

#include "contact_record.h"
#include "narrow_phase.h"
#include "physics/world.h"

namespace tumble {

constexpr std::uint32_t kNoRecord = UINT32_MAX;

// Each pair's record of the last step, found by walking both lists once (both are sorted by body
// pair, so no pair is looked up): out[i] is the index in `records` of the record of pairs[i]'s
// slots, or kNoRecord. The caller compares generations (a slot may have been given to a new body).
void match_pair_records(std::span<const BodyPair> pairs, std::span<const ContactPairRecord> records,
                        std::span<std::uint32_t> out);

// How far a point where the bodies can touch (inside both outer spheres) can have moved relative
// to the other body since the record's pose (m): B's centre's shift in A's axes plus the turn
// times B's outer radius, or the same from B's side, whichever is smaller (the two coincident
// points of A and B move apart by the same amount seen from either; a half-space's radius is
// infinite).
double relative_motion(const ContactPairRecord& record, const Pose& pose_a, const Pose& pose_b,
                       double outer_radius_a, double outer_radius_b);

PolytopeFeature recorded_feature(const ContactPairRecord& record);

// For a pair that keeps several manifolds (terrain, compounds), which of its last step's records
// `run` (the pair's, in order) each of this step's `manifolds` continues; out[c] is an index into
// `run` or kNoRecord. At most kMaxPairManifolds of each. `by_feature` (compounds, whose list of
// touching parts changes as they roll): the record sharing a point's feature id, or else the one
// in the same place in the order that no other took. Otherwise (terrain, whose few manifolds keep
// their order): the one in the same place.
void match_manifold_records(std::span<const ContactManifold> manifolds,
                            std::span<const ContactPairRecord> run, bool by_feature,
                            std::span<std::uint32_t> out);

// A record of `manifold`, from `feature`, with the bodies at these poses; impulses zero.
void record_manifold(const ContactManifold& manifold, const PolytopeFeature& feature, BodyId a,
                     const Pose& pose_a, BodyId b, const Pose& pose_b, ContactPairRecord* out);

}  // namespace tumble
