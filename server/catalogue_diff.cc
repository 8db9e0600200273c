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

void CatalogueDiff::add_joint_changes(const FrameData& data, v1::Frame* out) {
  // As for bodies: a new catalogue whenever the set of joints changes; a new world describes
  // every joint again and removes only the ids it no longer has.
  if (data.joint_catalogue == known_joints_) return;
  const JointCatalogue& current = *data.joint_catalogue;
  static const JointCatalogue none;
  const JointCatalogue& known = known_joints_ != nullptr ? *known_joints_ : none;
  const bool new_world = data.epoch != joints_epoch_;
  for (std::size_t i = 0; i < current.ids.size(); ++i) {
    if (new_world || !std::binary_search(known.ids.begin(), known.ids.end(), current.ids[i])) {
      v1::JointDescription* added = out->add_joints_added();
      added->set_id(current.ids[i]);
      joint_spec_to_proto(current.defs[i], current.body_a[i], current.body_b[i],
                          added->mutable_spec());
    }
  }
  for (std::uint64_t id : known.ids)
    if (!std::binary_search(current.ids.begin(), current.ids.end(), id))
      out->add_joints_removed(id);
  joints_epoch_ = data.epoch;
  known_joints_ = data.joint_catalogue;
}

}  // namespace tumble::server
