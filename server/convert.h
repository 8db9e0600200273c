// Between the API's messages and the engine's types. Every refusal names the field at fault,
// relative to the message given ("shape.box.size.x: must be > 0").
#pragma once

#include "frame.h"
#include "physics/world.h"
#include "tumble/v1/world.pb.h"

namespace tumble::server {

Result<BodyDef> body_from_proto(const v1::BodySpec& spec);

// What a viewer needs to draw the body with wire id `id`.
void describe(std::uint64_t id, const BodyLook& look, v1::BodyDescription* out);

struct FrameOptions {
  bool velocities = false, contacts = false, stats = false;
  std::vector<std::uint64_t> ids;  // sorted; empty: every body
};

// The frame's bodies (and, when asked, velocities, contacts and statistics) into `out`.
void frame_to_proto(const FrameData& frame, const FrameOptions& options, v1::Frame* out);

void stats_to_proto(const StepStats& stats, v1::StepStats* out);

}  // namespace tumble::server
