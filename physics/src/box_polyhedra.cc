#include "box_polyhedra.h"

#include <array>
#include <map>
#include <mutex>

#include "weak_table.h"

namespace tumble {

std::shared_ptr<const ConvexPolyhedron> shared_box_polyhedron(const Vec3& half_extents) {
  using Key = std::array<double, 3>;
  static std::mutex mutex;
  static std::map<Key, std::weak_ptr<const ConvexPolyhedron>> live;
  static std::size_t swept_at = kSweptAtLeast;
  const Key key{half_extents.x(), half_extents.y(), half_extents.z()};
  const std::lock_guard lock(mutex);
  std::weak_ptr<const ConvexPolyhedron>& entry = live[key];
  if (std::shared_ptr<const ConvexPolyhedron> kept = entry.lock()) return kept;
  auto made = std::make_shared<const ConvexPolyhedron>(make_box_polyhedron(half_extents));
  entry = made;
  sweep_when_doubled(live, swept_at, [](const auto& item) { return item.second.expired(); });
  return made;
}

}  // namespace tumble
