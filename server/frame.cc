#include "frame.h"

#include <algorithm>
#include <chrono>

namespace tumble::server {

BodyLook look_of(BodyView body, std::uint32_t colour) {
  return {body.shape(), body.type(), body.is_static() ? 0 : body.mass(), colour};
}

std::shared_ptr<const Catalogue> updated_catalogue(HostedWorld& hosted,
                                                   std::shared_ptr<const Catalogue> current,
                                                   std::uint64_t current_epoch) {
  const World& world = hosted.world;
  hosted.colours.resize(world.slot_count(), 0);
  bool same =
      current != nullptr && current_epoch == hosted.epoch && current->size() == world.body_count();
  for (std::uint32_t slot = 0; same && slot < world.slot_count(); ++slot) {
    const BodyId id = world.id_at(slot);
    same = !id.is_valid() || current->contains(hosted.ids.wire(id));
  }
  if (same) return current;
  auto fresh = std::make_shared<Catalogue>();
  fresh->reserve(world.body_count());
  for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot) {
    const BodyId id = world.id_at(slot);
    const BodyView body = world.body(id);
    if (!body) {
      hosted.colours[slot] = 0;  // a later body in this slot starts with the viewer's choice
      continue;
    }
    fresh->emplace(hosted.ids.wire(id), look_of(body, hosted.colours[slot]));
  }
  return fresh;
}

void note_changes(HostedWorld& hosted) {
  World& world = hosted.world;
  const std::uint64_t tick = ++hosted.change_clock;
  hosted.changed_at.resize(world.slot_count(), tick);  // new slots hold new bodies
  if (!world.body_events_complete()) {
    std::fill(hosted.changed_at.begin(), hosted.changed_at.end(), tick);
  } else {
    for (const BodyEvent& event : world.body_events())
      if (event.body.index < hosted.changed_at.size()) hosted.changed_at[event.body.index] = tick;
  }
  world.clear_body_events();
}

namespace {

// The joints' states into `frame`, and their catalogue: the one before while the same joints
// live in the same world. A world without joints pays one comparison.
void add_joints(HostedWorld& hosted, FrameData* frame) {
  const World& world = hosted.world;
  static const auto none = std::make_shared<const JointCatalogue>();
  if (world.joint_count() == 0 &&
      (hosted.joint_catalogue == nullptr || hosted.joint_catalogue->ids.empty())) {
    frame->joint_catalogue = none;
    return;
  }
  JointTable& table = frame->joints;
  std::vector<JointId> live;
  live.reserve(world.joint_count());
  for (std::uint32_t slot = 0; slot < world.joint_slot_count(); ++slot) {
    const JointId id = world.joint_at(slot);
    const std::uint64_t wire = hosted.joint_ids.wire(id);
    if (!id.is_valid() || wire == 0) continue;  // gone, or not yet given an id
    live.push_back(id);
    const JointReading reading = world.joint_reading(id).value();
    table.ids.push_back(wire);
    table.positions.push_back(reading.position);
    table.speeds.push_back(reading.speed);
    table.efforts.push_back(reading.effort);
    table.forces.insert(table.forces.end(),
                        {reading.force.x(), reading.force.y(), reading.force.z()});
    table.torques.insert(table.torques.end(),
                         {reading.torque.x(), reading.torque.y(), reading.torque.z()});
    const JointDef def = world.joint_def(id).value();
    Vec3 axis = def.axis;
    if (def.kind == JointKind::kDistance) {
      const Vec3 rod = def.anchor_b - def.anchor;
      if (rod.norm() > 0) axis = rod.normalized();
    }
    table.anchors.insert(table.anchors.end(), {def.anchor.x(), def.anchor.y(), def.anchor.z()});
    table.axes.insert(table.axes.end(), {axis.x(), axis.y(), axis.z()});
  }
  std::vector<std::size_t> order(live.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t x, std::size_t y) { return table.ids[x] < table.ids[y]; });
  const std::shared_ptr<const JointCatalogue>& known = hosted.joint_catalogue;
  bool same = known != nullptr && hosted.joint_catalogue_epoch == hosted.epoch &&
              known->ids.size() == order.size();
  for (std::size_t i = 0; same && i < order.size(); ++i)
    same = known->ids[i] == table.ids[order[i]];
  if (!same) {
    auto fresh = std::make_shared<JointCatalogue>();
    for (std::size_t i : order) {
      const JointDef def = world.joint_def(live[i]).value();
      fresh->ids.push_back(table.ids[i]);
      fresh->body_a.push_back(hosted.ids.wire(def.a));
      fresh->body_b.push_back(def.b.is_valid() ? hosted.ids.wire(def.b) : 0);
      fresh->defs.push_back(def);
    }
    hosted.joint_catalogue = std::move(fresh);
    hosted.joint_catalogue_epoch = hosted.epoch;
  }
  frame->joint_catalogue = hosted.joint_catalogue;
}

}  // namespace

std::shared_ptr<const FrameData> make_frame(HostedWorld& hosted, double dt,
                                            std::shared_ptr<const Catalogue> catalogue) {
  const World& world = hosted.world;
  auto frame = std::make_shared<FrameData>();
  frame->stepped_at_unix_ns =
      static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     std::chrono::system_clock::now().time_since_epoch())
                                     .count());
  frame->epoch = hosted.epoch;
  frame->catalogue = std::move(catalogue);
  frame->step = world.step_count();
  frame->time = world.time();
  frame->stats = world.last_step();
  frame->change_clock = hosted.change_clock;
  const std::size_t n = world.body_count();
  frame->changed_at.reserve(n);
  frame->ids.reserve(n);
  frame->positions.reserve(3 * n);
  frame->orientations.reserve(4 * n);
  frame->linear_velocities.reserve(3 * n);
  frame->angular_velocities.reserve(3 * n);
  for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot) {
    const BodyId id = world.id_at(slot);
    const BodyView body = world.body(id);
    if (!body) continue;
    frame->ids.push_back(hosted.ids.wire(id));
    frame->changed_at.push_back(slot < hosted.changed_at.size() ? hosted.changed_at[slot]
                                                                : hosted.change_clock);
    auto append = [](const Vec3& v, std::vector<double>& out) {
      out.insert(out.end(), {v.x(), v.y(), v.z()});
    };
    append(body.position(), frame->positions);
    const Quat q = body.orientation();
    frame->orientations.insert(frame->orientations.end(), {q.w(), q.x(), q.y(), q.z()});
    append(body.linear_velocity(), frame->linear_velocities);
    append(body.angular_velocity(), frame->angular_velocities);
  }
  // The step's contacts, then those of sleeping islands: they still carry their weight, as the
  // impulse of a step of dt. The sleepers' are shared from frame to frame while they stay put.
  auto add_contacts = [&](std::span<const Contact> contacts, std::span<const double> impulses,
                          double scale, ContactTable& out) {
    std::size_t row = 0;
    for (const Contact& contact : contacts) {
      for (int i = 0; i < contact.manifold.count; ++i, ++row) {
        const ContactPoint& point = contact.manifold.points[i];
        out.a.push_back(hosted.ids.wire(contact.a));
        out.b.push_back(hosted.ids.wire(contact.b));
        out.points.insert(out.points.end(), point.point_b.data(), point.point_b.data() + 3);
        out.normals.insert(out.normals.end(), contact.manifold.normal.data(),
                           contact.manifold.normal.data() + 3);
        out.depths.push_back(point.depth);
        out.impulses.push_back(row < impulses.size() ? scale * impulses[row] : 0.0);
      }
    }
  };
  add_contacts(world.contacts(), world.contact_impulses(), 1.0, frame->contacts);
  if (hosted.resting_table == nullptr ||
      hosted.resting_table_version != world.resting_contacts_version() ||
      hosted.resting_table_epoch != hosted.epoch || hosted.resting_table_dt != dt) {
    auto resting = std::make_shared<ContactTable>();
    add_contacts(world.resting_contacts(), world.resting_contact_forces(), dt, *resting);
    hosted.resting_table = resting;
    hosted.resting_table_version = world.resting_contacts_version();
    hosted.resting_table_epoch = hosted.epoch;
    hosted.resting_table_dt = dt;
  }
  frame->resting_contacts = hosted.resting_table;
  add_joints(hosted, frame.get());
  return frame;
}

}  // namespace tumble::server
