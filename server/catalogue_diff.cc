#include "catalogue_diff.h"

#include <algorithm>
#include <iterator>

#include "convert.h"

namespace tumble::server {

void CatalogueDiff::add_changes(const FrameData& data, const std::vector<std::uint64_t>& only,
                                v1::Frame* out) {
  // The host makes a new catalogue (and a new world a new epoch) whenever the set of bodies
  // changes, so a frame sharing the last one's catalogue has nothing to diff.
  if (data.catalogue == known_catalogue_) return;
  std::vector<std::uint64_t> current;
  if (only.empty()) {
    current = data.ids;
  } else {
    for (std::uint64_t id : data.ids)
      if (std::binary_search(only.begin(), only.end(), id)) current.push_back(id);
  }
  std::sort(current.begin(), current.end());
  // A new world (a scene loaded, a snapshot restored): every body it holds is described again,
  // whether or not its id was known (a restored snapshot gives bodies back their ids), and only
  // the ids it no longer has are removed. So no id is ever both removed and added in one frame,
  // and a reader may apply the two lists in either order.
  const bool new_world = data.epoch != epoch_;
  epoch_ = data.epoch;
  std::vector<std::uint64_t> added, removed;
  if (new_world)
    added = current;
  else
    std::set_difference(current.begin(), current.end(), known_.begin(), known_.end(),
                        std::back_inserter(added));
  std::set_difference(known_.begin(), known_.end(), current.begin(), current.end(),
                      std::back_inserter(removed));
  for (std::uint64_t wire : added) {
    const auto look = data.catalogue->find(wire);
    if (look != data.catalogue->end()) describe(wire, look->second, out->add_added());
  }
  for (std::uint64_t wire : removed)
    out->add_removed(wire);
  known_ = std::move(current);
  known_catalogue_ = data.catalogue;
}

}  // namespace tumble::server
