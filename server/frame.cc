#include "frame.h"

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

std::shared_ptr<const FrameData> make_frame(const HostedWorld& hosted, double dt,
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
  const std::size_t n = world.body_count();
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
  // impulse of a step of dt.
  auto add_contacts = [&](std::span<const Contact> contacts, std::span<const double> impulses,
                          double scale) {
    std::size_t row = 0;
    for (const Contact& contact : contacts) {
      for (int i = 0; i < contact.manifold.count; ++i, ++row) {
        const ContactPoint& point = contact.manifold.points[i];
        frame->contact_a.push_back(hosted.ids.wire(contact.a));
        frame->contact_b.push_back(hosted.ids.wire(contact.b));
        frame->contact_points.insert(frame->contact_points.end(), point.point_b.data(),
                                     point.point_b.data() + 3);
        frame->contact_normals.insert(frame->contact_normals.end(), contact.manifold.normal.data(),
                                      contact.manifold.normal.data() + 3);
        frame->contact_depths.push_back(point.depth);
        frame->contact_impulses.push_back(row < impulses.size() ? scale * impulses[row] : 0.0);
      }
    }
  };
  add_contacts(world.contacts(), world.contact_impulses(), 1.0);
  add_contacts(world.resting_contacts(), world.resting_contact_forces(), dt);
  return frame;
}

}  // namespace tumble::server
