// Frames as text for other tools: one JSON object per line, or CSV rows (one per body).
#pragma once

#include <string>

#include "tumble/wire_status.h"
#include "tumble/v1/world.pb.h"

namespace tumble::client {

// Whether a frame's arrays agree with its ids (3 position and 4 orientation values per body,
// velocities for all bodies or none, contact arrays of one length) and its descriptions have
// shapes; the message names the field. A frame from a file or the network is checked before it
// is formatted: the formatters below index its arrays by its ids.
Status check_frame(const v1::Frame& frame);

// {"step", "time", "dropped", "bodies": [{"id", "p": [x,y,z], "q": [w,x,y,z], "v", "w"}],
//  "contacts": [{"a", "b", "p", "n", "depth", "impulse"}], "added": [...], "removed": [...],
//  "stats": {every field of tumble.v1.StepStats by name}}
// Velocities, contacts and statistics appear when the frame has them. Numbers round-trip exactly.
// The frame must pass check_frame.
std::string frame_to_json_line(const v1::Frame& frame);

// "step,time,id,x,y,z,qw,qx,qy,qz" (and ",vx,vy,vz,wx,wy,wz" with velocities): a row per body,
// so contacts and statistics have no place in it (the CLI refuses to ask for them with CSV). Rows
// have the header's columns: with `velocities`, a frame without them gives empty cells.
std::string csv_header(bool velocities);
std::string frame_to_csv_rows(const v1::Frame& frame, bool velocities);

}  // namespace tumble::client
