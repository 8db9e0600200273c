// What a request may cost before it is paid for: the bytes each method of tumble.v1.World accepts
// (from the server's --max-bodies and --max-message-mb), and a scan of a request's wire bytes
// that counts its entries and the memory its parsed form would take, without parsing it. A
// message of a million empty entries is a few megabytes on the wire and gigabytes parsed; the
// scan sees that first.
#pragma once

#include <google/protobuf/descriptor.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "physics/status.h"

namespace tumble::server {

// A query casts at most this many rays and answers at most this many hits (a ray's nearest, or
// up to kMaxHitsPerRay each): its cost and its answer's size are bounded before it runs.
inline constexpr std::size_t kMaxQueryRays = 262144, kMaxQueryHits = 262144, kMaxHitsPerRay = 64;
// Overlap queries a request may hold; their bodies count against kMaxQueryHits.
inline constexpr std::size_t kMaxQueryOverlaps = 256;
// Closest-point queries a request may hold.
inline constexpr std::size_t kMaxQueryClosest = 65536;
// Shape casts a request may hold, and the bodies their swept bounds may reach in all (each is met
// by up to kShapeCastIterations narrow-phase calls): refused before any is tested.
inline constexpr std::size_t kMaxQueryShapeCasts = 1024, kMaxCastCandidates = 65536;

// The largest request of each method, in bytes on the wire (after decompression).
struct MethodBounds {
  std::size_t bytes = 0;
  // The most entries a top-level repeated field may hold (bodies, ids, updates, impulses);
  // 0: no repeated field is expected.
  std::size_t entries = 0;
};

// `max_bodies`: the server's --max-bodies; `max_message_bytes`: --max-message-mb in bytes, the
// bound of the requests that carry whole worlds (Restore, LoadScene) and the cap of every other.
struct RequestBounds {
  std::size_t max_bodies = 100000;
  std::size_t max_message_bytes = 64u << 20;

  // For "/tumble.v1.World/SpawnBodies" and the other methods, by their short name
  // ("SpawnBodies"); an unknown name gets the bound of an empty request.
  MethodBounds of(std::string_view method) const;
  // The largest bound of any method: what gRPC itself is told to accept.
  std::size_t largest() const;
  // The request bytes all calls being read or served may hold together: four of the largest.
  // A call whose bound does not fit waits, unread, until calls before it are done.
  std::size_t in_flight_budget() const { return 4 * largest(); }
};

// What a scan of a message's wire bytes found.
struct WireScan {
  std::size_t parsed_bytes = 0;  // about what the parsed message takes in memory, an upper bound
  std::size_t top_entries = 0;   // entries of the largest top-level repeated field
};

// Scans `bytes` as a `type` message without building it. Refuses bytes that are not such a
// message, and stops (refusing) as soon as the parsed form would exceed `max_parsed_bytes` or a
// top-level repeated field would hold more than `max_top_entries` (0: no bound), naming the
// field, so the scan's own cost is linear in the bytes.
Result<WireScan> scan_wire(std::string_view bytes, const google::protobuf::Descriptor& type,
                           std::size_t max_parsed_bytes, std::size_t max_top_entries);

// The memory a request of `wire_bytes` may take once parsed: a well-formed request takes a few
// times its wire size; only runs of empty entries take more, and those are refused.
inline std::size_t parsed_bound(std::size_t wire_bytes) {
  return 16 * wire_bytes + (1u << 20);
}

}  // namespace tumble::server
