#include "hull_polyhedra.h"

#include <array>
#include <bit>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <vector>

#include "weak_table.h"

namespace tumble {
namespace {

// Keys hold the coordinates' bits: 0.0 and -0.0 are different points to Qhull's output, and bits
// order totally where a NaN would break the map (build_convex_hull refuses it anyway).
std::uint64_t bits(double x) {
  return std::bit_cast<std::uint64_t>(x);
}

std::size_t bytes_of(const ConvexPolyhedron& p) {
  return p.vertices.size() * sizeof(Vec3) + p.faces.size() * sizeof(ConvexPolyhedron::Face) +
         p.face_vertices.size() * sizeof(std::uint32_t) +
         p.edges.size() * sizeof(ConvexPolyhedron::Edge);
}

}  // namespace

Result<std::shared_ptr<const ConvexPolyhedron>> shared_hull_polyhedron(
    std::span<const Vec3> points) {
  using Key = std::vector<std::uint64_t>;
  static std::mutex mutex;
  static std::map<Key, std::weak_ptr<const ConvexPolyhedron>> live;
  static std::size_t swept_at = kSweptAtLeast;
  // A body keeps only its copy moved to its centre of mass, so the hull it was built from dies
  // with the shape that made it; the last hulls built are held here so the next body made from the
  // same points finds its hull. Bounded in number and bytes: rocks that are all different cost
  // at most this much more than before.
  static std::deque<std::shared_ptr<const ConvexPolyhedron>> recent;
  static std::size_t recent_bytes = 0;
  Key key;
  key.reserve(3 * points.size());
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k)
      key.push_back(bits(p[k]));
  {
    const std::lock_guard lock(mutex);
    if (auto found = live.find(key); found != live.end())
      if (std::shared_ptr<const ConvexPolyhedron> kept = found->second.lock()) return kept;
  }
  // Qhull runs outside the lock, so threads making different rocks do not wait on each other;
  // two making the same one at once both build it, and the first to return is kept.
  Result<ConvexPolyhedron> built = build_convex_hull(points);
  if (!built) return built.status();
  auto made = std::make_shared<const ConvexPolyhedron>(std::move(built).value());
  const std::lock_guard lock(mutex);
  std::weak_ptr<const ConvexPolyhedron>& entry = live[std::move(key)];
  if (std::shared_ptr<const ConvexPolyhedron> kept = entry.lock()) return kept;
  entry = made;
  recent.push_back(made);
  recent_bytes += bytes_of(*made);
  while (recent.size() > kRecentHulls || recent_bytes > kRecentHullBytes) {
    recent_bytes -= bytes_of(*recent.front());
    recent.pop_front();
  }
  sweep_when_doubled(live, swept_at, [](const auto& item) { return item.second.expired(); });
  return made;
}

std::shared_ptr<const ConvexPolyhedron> shared_moved_polyhedron(
    const std::shared_ptr<const ConvexPolyhedron>& source, const Vec3& offset) {
  using Key = std::pair<const ConvexPolyhedron*, std::array<std::uint64_t, 3>>;
  // The source is held weakly and compared on lookup: a freed source's address may be reused by
  // another polyhedron, whose entry must not find this one's copy.
  struct Entry {
    std::weak_ptr<const ConvexPolyhedron> source;
    std::weak_ptr<const ConvexPolyhedron> moved;
  };
  static std::mutex mutex;
  static std::map<Key, Entry> live;
  static std::size_t swept_at = kSweptAtLeast;
  const Key key{source.get(), {bits(offset.x()), bits(offset.y()), bits(offset.z())}};
  const std::lock_guard lock(mutex);
  Entry& entry = live[key];
  if (entry.source.lock() == source)
    if (std::shared_ptr<const ConvexPolyhedron> kept = entry.moved.lock()) return kept;
  auto moved = std::make_shared<ConvexPolyhedron>(*source);
  for (Vec3& v : moved->vertices)
    v -= offset;
  for (auto& face : moved->faces)
    face.offset -= face.normal.dot(offset);
  moved->centroid -= offset;
  entry = {source, moved};
  sweep_when_doubled(live, swept_at, [](const auto& item) { return item.second.moved.expired(); });
  return moved;
}

}  // namespace tumble
