// The world as the wire sees it: one step's frame (poses, velocities, contacts, statistics) and
// the catalogue of what each body is, read from the hosted world in this one place. The gRPC
// streams (convert.h, frame_stream.h) and the DDS publisher (dds_publisher.h) encode the same
// frame; neither reads the world itself.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "hosted_world.h"

namespace tumble::server {

// What a viewer needs to draw a body, kept while the body lives.
struct BodyLook {
  Shape shape;  // in the body's frame (origin at the centre of mass)
  BodyType type = BodyType::kDynamic;
  double mass = 0;           // kg; 0 for static bodies
  std::uint32_t colour = 0;  // 0xRRGGBBAA; 0 lets the viewer choose
};
// Every live body's look by wire id. Shared by frames until the set of bodies changes.
using Catalogue = std::unordered_map<std::uint64_t, BodyLook>;

// Contact points, one entry per point, as parallel arrays.
struct ContactTable {
  std::vector<std::uint64_t> a, b;       // wire ids
  std::vector<double> points, normals;   // m, x y z per point; unit, from a to b
  std::vector<double> depths, impulses;  // m; N s over one step
  std::size_t size() const { return a.size(); }
};

// Every joint's state at a step, as parallel arrays (empty in a world without joints).
struct JointTable {
  std::vector<std::uint64_t> ids;                  // wire ids, slot order
  std::vector<double> positions, speeds, efforts;  // along the free coordinate (physics/joint.h)
  std::vector<double> forces, torques;             // x y z per joint: on b, N and N m, world
  std::vector<double> anchors, axes;  // x y z per joint: its anchor on a (m) and axis, world
  std::size_t size() const { return ids.size(); }
};

// Each live joint's definition, sorted by wire id: shared by frames until the set of joints
// changes (its drives as they were then: GetJoints has them as they are).
struct JointCatalogue {
  std::vector<std::uint64_t> ids;
  std::vector<JointDef> defs;
  std::vector<std::uint64_t> body_a, body_b;  // wire ids of each joint's bodies (b: 0, the world)
};

// One step of the world, shared read-only by every subscriber.
struct FrameData {
  // Encodings of this frame made for one subscriber and kept for the others that asked for the
  // same fields (the gRPC streams fill it; see frame_stream.h).
  struct Encodings {
    std::mutex mutex;
    std::vector<std::pair<std::uint32_t, std::shared_ptr<const std::string>>> by_fields;
  };
  mutable Encodings encodings;

  std::uint64_t epoch = 0;  // HostedWorld::epoch
  std::uint64_t stepped_at_unix_ns = 0;
  std::shared_ptr<const Catalogue> catalogue;
  std::uint64_t step = 0;
  double time = 0;                                            // s, simulated
  std::vector<std::uint64_t> ids;                             // live bodies, slot order
  std::vector<double> positions;                              // x y z per body, m
  std::vector<double> orientations;                           // w x y z per body
  std::vector<double> linear_velocities, angular_velocities;  // x y z per body
  // Per body, the tick of HostedWorld::change_clock at which it last changed, and the tick of
  // this frame: a subscriber that last got the frame of tick t needs only the bodies above t.
  std::vector<std::uint64_t> changed_at;
  std::uint64_t change_clock = 0;
  // The step's contacts, then those sleeping islands rest on (shared by every frame until
  // islands fall asleep or wake: a sleeping world's 400,000 resting points are not copied each
  // step). Read both, in that order: contact_tables().
  ContactTable contacts;
  std::shared_ptr<const ContactTable> resting_contacts;
  std::array<const ContactTable*, 2> contact_tables() const {
    return {&contacts, resting_contacts != nullptr ? resting_contacts.get() : &contacts_none()};
  }
  static const ContactTable& contacts_none() {
    static const ContactTable none;
    return none;
  }
  StepStats stats;
  JointTable joints;
  std::shared_ptr<const JointCatalogue> joint_catalogue;  // never null
};

BodyLook look_of(BodyView body, std::uint32_t colour);

// The catalogue of `hosted`'s bodies: `current` itself while the set of bodies is the same (so a
// steady world's frames share one), else a new one. Forgets the colours of empty slots.
std::shared_ptr<const Catalogue> updated_catalogue(HostedWorld& hosted,
                                                   std::shared_ptr<const Catalogue> current,
                                                   std::uint64_t current_epoch);

// Takes the world's body events into hosted.changed_at at a new tick of its change clock, and
// clears them: the cost is the bodies that changed, not the bodies there are.
void note_changes(HostedWorld& hosted);

// The frame of `hosted` as it is now. `dt`: the step's, which turns the resting contacts' forces
// into the impulses of a step (passed in: the host changes hosted.dt under its lock, and the
// stepping thread builds frames without it).
std::shared_ptr<const FrameData> make_frame(HostedWorld& hosted, double dt,
                                            std::shared_ptr<const Catalogue> catalogue);

}  // namespace tumble::server
