// The world as the server holds it, with what the server keeps beside it: the step, colours,
// the ids clients see, and the count of wholesale replacements.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "body_ids.h"
#include "physics/world.h"

namespace tumble::server {

struct ContactTable;
struct JointCatalogue;

// The world and what the server keeps beside it. Only the stepping thread touches it: commands
// run there.
struct HostedWorld {
  World world;
  double dt = 1.0 / 60;                // s per step
  std::vector<std::uint32_t> colours;  // by slot, 0xRRGGBBAA
  // The ids clients see. The host follows every command's changes (a body created gets a new
  // id, a removed one loses its id for good); a command that needs a new body's id at once
  // calls ids.sync(world) itself.
  BodyIds ids;
  // The joints' ids, as the bodies' (a joint removed with its body loses its id at the next
  // sync). A snapshot of this server gives its joints back their ids, as its bodies.
  JointIds joint_ids;
  // Chosen at random when the server starts, and written into snapshots: a snapshot made here
  // gives its bodies back their ids; one from elsewhere gets new ones, which cannot collide with
  // ids this server has handed out.
  std::uint64_t server_instance = 0;
  // Counts wholesale replacements (a scene loaded, a snapshot restored), so that a subscriber
  // forgets every body it knew.
  std::uint64_t epoch = 0;
  // Which bodies changed when, for subscribers that ask for changes only: by slot, the tick of
  // change_clock at which the body was last made, moved, woken or put to sleep (from the
  // world's body events, note_changes in frame.h).
  std::vector<std::uint64_t> changed_at;
  std::uint64_t change_clock = 0;
  // The resting contacts as frames carry them (ContactTable, frame.h), kept while the world's
  // resting contacts, its ids (epoch) and the step are the same.
  std::shared_ptr<const ContactTable> resting_table;
  std::uint64_t resting_table_version = 0, resting_table_epoch = 0;
  double resting_table_dt = 0;
  // The joints' catalogue of the frames, kept while the set of joints (and the epoch) is the same.
  std::shared_ptr<const JointCatalogue> joint_catalogue;
  std::uint64_t joint_catalogue_epoch = 0;

  // A new world whose bodies all get new ids.
  void replace(World replacement, double new_dt, std::vector<std::uint32_t> new_colours) {
    world = std::move(replacement);
    dt = new_dt;
    colours = std::move(new_colours);
    ids.clear();
    ids.sync(world);
    joint_ids.clear();
    joint_ids.sync(world);
    ++epoch;
  }
  // A restored world whose bodies and joints keep the ids they had (by slot; see
  // SlotIds::adopt).
  void restore(World replacement, double new_dt, std::vector<std::uint32_t> new_colours,
               std::span<const std::uint64_t> wire_ids, std::uint64_t next_id,
               std::span<const std::uint64_t> joint_wire_ids, std::uint64_t next_joint_id) {
    world = std::move(replacement);
    dt = new_dt;
    colours = std::move(new_colours);
    ids.adopt(world, wire_ids, next_id);
    joint_ids.adopt(world, joint_wire_ids, next_joint_id);
    ++epoch;
  }
  void set_colour(BodyId id, std::uint32_t colour) {
    if (colours.size() <= id.index) colours.resize(id.index + 1, 0);
    colours[id.index] = colour;
  }
};

}  // namespace tumble::server
