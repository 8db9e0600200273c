#include "service.h"

#include "log.h"

#include <algorithm>
#include <chrono>
#include <unordered_set>

#include "convert.h"
#include "joint_commands.h"
#include "scenes/scene.h"
#include "scenes/standard.h"
#include "snapshot.h"
#include "tumble/v1/snapshot.pb.h"
#include "world_commands.h"

namespace tumble::server {
namespace {

// The one mapping from the engine's and the host's failures to gRPC's codes.
grpc::Status to_grpc(const Status& status) {
  switch (status.code()) {
    case StatusCode::kOk:
      return grpc::Status::OK;
    case StatusCode::kInvalidArgument:
      return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, status.message());
    case StatusCode::kNotFound:
      return grpc::Status(grpc::StatusCode::NOT_FOUND, status.message());
    case StatusCode::kResourceExhausted:
      return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, status.message());
    case StatusCode::kUnavailable:
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, status.message());
    case StatusCode::kInternal:
      break;
  }
  return grpc::Status(grpc::StatusCode::INTERNAL, status.message());
}

grpc::Status invalid(const std::string& message) {
  return to_grpc(Status::error(message));
}

}  // namespace

WorldService::WorldService(WorldHost& host, ServiceLimits limits, SceneDef scene)
    : host_(host),
      limits_(limits),
      scene_(std::move(scene)),
      read_stream_([this](const std::string& bytes, FrameOptions* options, double* max_rate) {
        return read_stream_request(bytes, options, max_rate);
      }),
      gate_(make_gate()) {}

template <class Request, class Response>
CallGate::Unary WorldService::unary(grpc::Status (WorldService::*serve)(const Request&,
                                                                        Response*)) {
  return {Request::descriptor(), [this, serve](const std::string& bytes, std::string* out) {
            Request request;
            if (!request.ParseFromString(bytes))
              return invalid("request: not a " + Request::descriptor()->full_name());
            Response response;
            grpc::Status status = (this->*serve)(request, &response);
            if (status.ok()) response.SerializeToString(out);
            if (!status.ok() && logs(LogLevel::kDebug))
              log(LogLevel::kDebug, Request::descriptor()->name() + " refused (code " +
                                        std::to_string(status.error_code()) +
                                        "): " + status.error_message());
            return status;
          }};
}

CallGate WorldService::make_gate() {
  std::vector<std::pair<std::string, CallGate::Unary>> methods = {
      {"SpawnBodies", unary(&WorldService::spawn_bodies)},
      {"RemoveBodies", unary(&WorldService::remove_bodies)},
      {"SetBodyState", unary(&WorldService::set_body_state)},
      {"ApplyImpulse", unary(&WorldService::apply_impulse)},
      {"GetBodies", unary(&WorldService::get_bodies)},
      {"Query", unary(&WorldService::query)},
      {"CreateJoints", unary(&WorldService::create_joints)},
      {"RemoveJoints", unary(&WorldService::remove_joints)},
      {"SetJointDrives", unary(&WorldService::set_joint_drives)},
      {"GetJoints", unary(&WorldService::get_joints)},
      {"LoadScene", unary(&WorldService::load_scene)},
      {"Control", unary(&WorldService::control)},
      {"GetInfo", unary(&WorldService::get_info)},
      {"Snapshot", unary(&WorldService::snapshot)},
      {"Restore", unary(&WorldService::restore)}};
  std::vector<std::pair<std::string, CallGate::StartStream>> streams = {
      {"StreamFrames",
       [this](CallGate* gate, std::size_t max_bytes) -> grpc::ServerGenericBidiReactor* {
         if (shutting_down_) return new RefusedCall(grpc::Status::OK);
         return new FrameStream(streams_, host_, read_stream_, gate, max_bytes, "StreamFrames");
       }}};
  return CallGate(
      v1::World::service_full_name(),
      {.max_bodies = limits_.max_bodies, .max_message_bytes = limits_.max_message_bytes},
      [this](const grpc::ServerContextBase& context) { return authorize(context); },
      std::move(methods), std::move(streams));
}

void WorldService::register_on(grpc::ServerBuilder& builder) {
  builder.RegisterService(this);
  builder.RegisterCallbackGenericService(&gate_);
  builder.SetMaxReceiveMessageSize(static_cast<int>(gate_.bounds().largest()));
  // A stream's flow-control window stays at HTTP/2's 64 KiB until its request is read (gRPC's
  // bandwidth probe would grow it to megabytes): a client without the token can push no more
  // than that before it is refused. Reading a request opens the window to its whole size, so
  // large requests still arrive at full speed.
  builder.AddChannelArgument(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  // Bytes still arriving for a refused call are read off the socket and dropped 1 MiB at a time
  // (gRPC's default grows its reads to 4 MiB).
  builder.AddChannelArgument(GRPC_ARG_TCP_MAX_READ_CHUNK_SIZE, 1 << 20);
  // gRPC (1.51) inflates a compressed request whole before it checks the size: 190 KB of gzip
  // becomes 190 MB in memory. Compressed requests are refused (UNIMPLEMENTED, naming the
  // algorithm) when their headers arrive, before any of the message is read.
  builder.SetCompressionAlgorithmSupportStatus(GRPC_COMPRESS_DEFLATE, false);
  builder.SetCompressionAlgorithmSupportStatus(GRPC_COMPRESS_GZIP, false);
}

grpc::Status WorldService::authorize(const grpc::ServerContextBase& context) const {
  if (limits_.token.empty()) return grpc::Status::OK;
  const std::string expected = "Bearer " + limits_.token;
  const auto& metadata = context.client_metadata();
  const auto found = metadata.find("authorization");
  bool same = found != metadata.end() && found->second.size() == expected.size();
  if (same) {
    // Compared in full whatever the first difference, so timing tells nothing of the token.
    unsigned char difference = 0;
    for (std::size_t i = 0; i < expected.size(); ++i)
      difference |= static_cast<unsigned char>(found->second.data()[i] ^ expected[i]);
    same = difference == 0;
  }
  return same ? grpc::Status::OK
              : grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                             "authorization: missing or wrong bearer token");
}

grpc::Status WorldService::replace_world(SceneDef scene, std::vector<std::uint64_t>* ids) {
  // Built before the world is touched: a scene that cannot be made changes nothing.
  const double dt = scene.dt;
  Result<World> made = world_of_scene(std::move(scene), limits_.world, limits_.max_bodies);
  if (!made) return to_grpc(made.status());
  return to_grpc(host_.apply([&](HostedWorld& hosted) {
    return server::replace_world(hosted, std::move(made).value(), dt, ids);
  }));
}

grpc::Status WorldService::reset_world() {
  SceneDef scene;
  {
    std::lock_guard lock(scene_mutex_);
    scene = scene_;
  }
  std::vector<std::uint64_t> ids;
  return replace_world(scene, &ids);
}

grpc::Status WorldService::spawn_bodies(const v1::SpawnBodiesRequest& request,
                                        v1::SpawnBodiesResponse* response) {
  Result<std::vector<BodyDef>> defs = body_defs(request);
  if (!defs) return to_grpc(defs.status());
  std::vector<std::uint64_t> ids;
  const Status applied = host_.apply([&](HostedWorld& hosted) {
    return server::spawn_bodies(hosted, defs.value(), request, limits_.max_bodies, &ids);
  });
  if (!applied) return to_grpc(applied);
  for (std::uint64_t id : ids)
    response->add_ids(id);
  return grpc::Status::OK;
}

grpc::Status WorldService::remove_bodies(const v1::RemoveBodiesRequest& request,
                                         v1::RemoveBodiesResponse*) {
  return to_grpc(host_.apply(
      [&](HostedWorld& hosted) { return server::remove_bodies(hosted, request.ids()); }));
}

grpc::Status WorldService::get_bodies(const v1::GetBodiesRequest& request,
                                      v1::GetBodiesResponse* response) {
  Status read = Status::ok();
  host_.inspect(
      [&](const HostedWorld& hosted) { read = server::get_bodies(hosted, request, response); });
  return to_grpc(read);
}

grpc::Status WorldService::query(const v1::QueryRequest& request, v1::QueryResponse* response) {
  // Between two steps, on the world's thread: a query's cost is bounded by its size (at most
  // 262144 rays or hits; docs/SERVICE.md, "Queries").
  Status read = Status::ok();
  host_.inspect([&](const HostedWorld& hosted) { read = server::query(hosted, request, response); });
  return to_grpc(read);
}

grpc::Status WorldService::create_joints(const v1::CreateJointsRequest& request,
                                         v1::CreateJointsResponse* response) {
  std::vector<std::uint64_t> ids;
  const std::size_t max_joints = kJointsPerBody * limits_.max_bodies;
  const Status applied = host_.apply([&](HostedWorld& hosted) {
    return server::create_joints(hosted, request, max_joints, &ids);
  });
  if (!applied) return to_grpc(applied);
  for (std::uint64_t id : ids)
    response->add_ids(id);
  return grpc::Status::OK;
}

grpc::Status WorldService::remove_joints(const v1::RemoveJointsRequest& request,
                                         v1::RemoveJointsResponse*) {
  return to_grpc(
      host_.apply([&](HostedWorld& hosted) { return server::remove_joints(hosted, request); }));
}

grpc::Status WorldService::set_joint_drives(const v1::SetJointDrivesRequest& request,
                                            v1::SetJointDrivesResponse*) {
  return to_grpc(
      host_.apply([&](HostedWorld& hosted) { return server::set_joint_drives(hosted, request); }));
}

grpc::Status WorldService::get_joints(const v1::GetJointsRequest& request,
                                      v1::GetJointsResponse* response) {
  Status read = Status::ok();
  host_.inspect(
      [&](const HostedWorld& hosted) { read = server::get_joints(hosted, request, response); });
  return to_grpc(read);
}

grpc::Status WorldService::set_body_state(const v1::SetBodyStateRequest& request,
                                          v1::SetBodyStateResponse*) {
  return to_grpc(
      host_.apply([&](HostedWorld& hosted) { return server::set_body_states(hosted, request); }));
}

grpc::Status WorldService::apply_impulse(const v1::ApplyImpulseRequest& request,
                                         v1::ApplyImpulseResponse*) {
  return to_grpc(
      host_.apply([&](HostedWorld& hosted) { return server::apply_impulses(hosted, request); }));
}

grpc::Status WorldService::load_scene(const v1::LoadSceneRequest& request,
                                      v1::LoadSceneResponse* response) {
  Result<SceneDef> scene = scene_of(request, limits_.max_bodies);
  if (!scene) return to_grpc(scene.status());
  std::vector<std::uint64_t> ids;
  if (grpc::Status replaced = replace_world(scene.value(), &ids); !replaced.ok()) return replaced;
  {
    std::lock_guard lock(scene_mutex_);
    scene_ = scene.value();
  }
  for (std::uint64_t id : ids)
    response->add_ids(id);
  response->set_name(scene.value().name);
  return grpc::Status::OK;
}

grpc::Status WorldService::control(const v1::ControlRequest& request,
                                   v1::ControlResponse* response) {
  // Checked whole before anything changes, the world's settings against the world as it is.
  Result<RunChange> change = run_change_from_proto(request.settings(), limits_.world.max_time_step);
  if (!change) return invalid("settings." + change.error());
  Status acceptable = Status::ok();
  host_.inspect([&](const HostedWorld& hosted) {
    acceptable = change.value().check_against(hosted.world.settings());
  });
  if (!acceptable) return invalid("settings." + acceptable.message());
  if (request.action_case() == v1::ControlRequest::kReset && request.reset()) {
    host_.pause();
    if (grpc::Status reset = reset_world(); !reset.ok()) return reset;
  }
  // The world's own settings change in one command, all or nothing (World::set_settings).
  WorldSettings now;
  const Status changed = host_.apply([&](HostedWorld& hosted) {
    if (Status s = hosted.world.set_settings(change.value().applied_to(hosted.world.settings()));
        !s)
      return s;
    now = hosted.world.settings();
    return Status::ok();
  });
  if (!changed) return invalid("settings." + changed.message());
  if (change.value().dt) host_.set_dt(*change.value().dt);
  if (change.value().real_time_factor) host_.set_real_time_factor(*change.value().real_time_factor);
  switch (request.action_case()) {
    case v1::ControlRequest::kPlay:
      if (request.play()) host_.play();
      break;
    case v1::ControlRequest::kPause:
      if (request.pause()) host_.pause();
      break;
    case v1::ControlRequest::kStep:
      host_.step(request.step());
      break;
    default:
      break;
  }
  const HostStatus status = host_.status();
  response->set_running(status.running);
  response->set_step(status.step);
  run_settings_to_proto(status.dt, status.real_time_factor, now, response->mutable_settings());
  return grpc::Status::OK;
}

grpc::Status WorldService::get_info(const v1::GetInfoRequest&, v1::GetInfoResponse* response) {
  const HostStatus status = host_.status();
  response->set_version(TUMBLE_VERSION);
  response->set_step(status.step);
  response->set_time(status.time);
  response->set_body_count(static_cast<std::uint32_t>(status.bodies));
  response->set_joint_count(static_cast<std::uint32_t>(status.joints));
  response->set_running(status.running);
  // From the host's status, not the world: GetInfo answers while a long step runs.
  run_settings_to_proto(status.dt, status.real_time_factor, status.settings,
                        response->mutable_settings());
  stats_to_proto(status.last_step, response->mutable_last_step());
  response->set_subscribers(static_cast<std::uint32_t>(status.subscribers));
  response->set_achieved_real_time_factor(status.achieved_real_time_factor);
  response->set_behind(status.behind);
  response->set_times_behind(status.times_behind);
  return grpc::Status::OK;
}

grpc::Status WorldService::snapshot(const v1::SnapshotRequest&, v1::SnapshotResponse* response) {
  SavedWorld saved;
  host_.inspect([&](const HostedWorld& hosted) { saved = save_world(hosted); });
  // The server's wrapping is encoded off the stepping thread; the world waits for its own bytes.
  response->set_step(saved.step);
  response->set_state(encode_snapshot(saved));
  return grpc::Status::OK;
}

grpc::Status WorldService::restore(const v1::RestoreRequest& request,
                                   v1::RestoreResponse* response) {
  // Checked whole before the running world is touched.
  Result<RestoredWorld> restored =
      decode_restore(request.state(), limits_.world, limits_.max_bodies);
  if (!restored) return to_grpc(restored.status());
  const std::uint64_t step = restored.value().world.step_count();
  const Status replaced = host_.apply([&](HostedWorld& hosted) {
    return restore_world(hosted, std::move(restored).value(), response->mutable_new_ids());
  });
  if (!replaced) return to_grpc(replaced);
  response->set_step(step);
  return grpc::Status::OK;
}

grpc::Status WorldService::read_stream_request(const std::string& bytes, FrameOptions* options,
                                               double* max_rate) const {
  v1::StreamFramesRequest request;
  if (!request.ParseFromString(bytes)) return invalid("request: not a StreamFramesRequest");
  // A rate below one frame in about 17 minutes would never send even the first frame.
  if (!(request.max_rate() == 0 || request.max_rate() >= kMinStreamRate) ||
      !std::isfinite(request.max_rate()))
    return invalid("max_rate: must be 0 (every step) or finite and at least " +
                   std::to_string(kMinStreamRate) + " Hz");
  options->velocities = request.velocities();
  options->contacts = request.contacts();
  options->stats = request.stats();
  options->joints = request.joints();
  options->ids.assign(request.ids().begin(), request.ids().end());
  std::sort(options->ids.begin(), options->ids.end());
  if (!(request.full_frame_interval() >= 0) || !std::isfinite(request.full_frame_interval()))
    return invalid("full_frame_interval: must be finite and >= 0 (s; 0: only when needed)");
  options->changes_only = request.changes_only();
  options->full_frame_interval = request.full_frame_interval();
  *max_rate = request.max_rate();
  return grpc::Status::OK;
}

}  // namespace tumble::server
