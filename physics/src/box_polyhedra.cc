#include "box_polyhedra.h"

#include <array>
#include <map>
#include <mutex>

namespace tumble {

std::shared_ptr<const ConvexPolyhedron> shared_box_polyhedron(const Vec3& half_extents) {
  using Key = std::array<double, 3>;
  static std::mutex mutex;
  static std::map<Key, std::weak_ptr<const ConvexPolyhedron>> live;
  // Entries of freed polyhedra are swept when the map has doubled since the last sweep: a client
  // making boxes of ever new sizes and removing them holds the map to twice the live sizes.
  static std::size_t swept_at = 64;
  const Key key{half_extents.x(), half_extents.y(), half_extents.z()};
  const std::lock_guard lock(mutex);
  std::weak_ptr<const ConvexPolyhedron>& entry = live[key];
  if (std::shared_ptr<const ConvexPolyhedron> kept = entry.lock()) return kept;
  auto made = std::make_shared<const ConvexPolyhedron>(make_box_polyhedron(half_extents));
  entry = made;
  if (live.size() >= 2 * swept_at) {
    std::erase_if(live, [](const auto& item) { return item.second.expired(); });
    swept_at = std::max<std::size_t>(64, live.size());
  }
  return made;
}

}  // namespace tumble
