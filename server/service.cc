#include "service.h"

#include "log.h"

#include <algorithm>
#include <chrono>
#include <unordered_set>

#include "convert.h"
#include "scenes/scene.h"
#include "scenes/standard.h"
#include "snapshot.h"
#include "tumble/v1/snapshot.pb.h"

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

grpc::Status too_many(const std::string& message) {
  return to_grpc(Status::error(message, StatusCode::kResourceExhausted));
}

// The bodies named by `wire_ids`, or the first unknown one's position in the list.
Status find_bodies(const HostedWorld& hosted,
                   const google::protobuf::RepeatedField<std::uint64_t>& wire_ids,
                   std::vector<BodyId>* ids) {
  for (int i = 0; i < wire_ids.size(); ++i) {
    const BodyId id = hosted.ids.find(wire_ids[i]);
    if (!hosted.world.contains(id))
      return Status::not_found("ids[" + std::to_string(i) + "]: no body " +
                               std::to_string(wire_ids[i]));
    ids->push_back(id);
  }
  return Status::ok();
}

// The first id listed a second time, named.
grpc::Status refuse_repeats(const google::protobuf::RepeatedField<std::uint64_t>& ids) {
  std::unordered_set<std::uint64_t> seen;
  seen.reserve(static_cast<std::size_t>(ids.size()));
  for (int i = 0; i < ids.size(); ++i)
    if (!seen.insert(ids[i]).second) return invalid("ids[" + std::to_string(i) + "]: listed twice");
  return grpc::Status::OK;
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
  scene.world.limits = limits_.world;
  if (Status t = check_time_step(scene.dt, limits_.world); !t)
    return invalid("scene: " + t.message());
  if (scene.bodies.size() > limits_.max_bodies)
    return too_many("scene: " + std::to_string(scene.bodies.size()) + " bodies, more than the " +
                    std::to_string(limits_.max_bodies) + " allowed");
  // Built before the world is touched: a scene that cannot be made changes nothing.
  Result<World> made = make_world(scene);
  if (!made) return invalid("scene: " + made.error());
  const Status replaced = host_.apply([&](HostedWorld& hosted) {
    World& world = made.value();
    WorldSettings settings = world.settings();
    settings.threads = hosted.world.settings().threads;  // the server's choice, not the scene's
    if (Status s = world.set_settings(settings); !s) return s;
    hosted.replace(std::move(world), scene.dt, {});
    for (std::uint32_t slot = 0; slot < hosted.world.slot_count(); ++slot)
      if (const BodyId id = hosted.world.id_at(slot); id.is_valid())
        ids->push_back(hosted.ids.wire(id));
    return Status::ok();
  });
  return to_grpc(replaced);
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
  std::vector<BodyDef> defs;
  defs.reserve(request.bodies_size());
  for (int i = 0; i < request.bodies_size(); ++i) {
    Result<BodyDef> def = body_from_proto(request.bodies(i));
    if (!def) return invalid("bodies[" + std::to_string(i) + "]." + def.error());
    defs.push_back(std::move(def).value());
  }
  std::vector<std::uint64_t> ids;
  const Status applied = host_.apply([&](HostedWorld& hosted) {
    World& world = hosted.world;
    if (world.body_count() + defs.size() > limits_.max_bodies)
      return Status::error("bodies: " + std::to_string(defs.size()) + " more would exceed the " +
                               std::to_string(limits_.max_bodies) + " bodies allowed",
                           StatusCode::kResourceExhausted);
    Result<std::vector<BodyId>> made = world.create_bodies(defs);
    if (!made) return made.status();
    hosted.ids.sync(world);
    for (std::size_t i = 0; i < made.value().size(); ++i) {
      hosted.set_colour(made.value()[i], request.bodies(static_cast<int>(i)).color());
      ids.push_back(hosted.ids.wire(made.value()[i]));
    }
    return Status::ok();
  });
  if (!applied) return to_grpc(applied);
  for (std::uint64_t id : ids)
    response->add_ids(id);
  return grpc::Status::OK;
}

grpc::Status WorldService::remove_bodies(const v1::RemoveBodiesRequest& request,
                                         v1::RemoveBodiesResponse*) {
  if (grpc::Status twice = refuse_repeats(request.ids()); !twice.ok()) return twice;
  return to_grpc(host_.apply([&](HostedWorld& hosted) {
    // Every id is checked before anything is removed: all or nothing.
    std::vector<BodyId> ids;
    if (Status found = find_bodies(hosted, request.ids(), &ids); !found) return found;
    for (BodyId id : ids)
      hosted.world.remove_body(id);
    return Status::ok();
  }));
}

grpc::Status WorldService::get_bodies(const v1::GetBodiesRequest& request,
                                      v1::GetBodiesResponse* response) {
  // An id asked for twice would be answered twice: the reply could grow past any bound.
  if (grpc::Status twice = refuse_repeats(request.ids()); !twice.ok()) return twice;
  Status read = Status::ok();
  host_.inspect([&](const HostedWorld& hosted) {
    const World& world = hosted.world;
    std::vector<BodyId> ids;
    if (request.ids_size() == 0) {
      for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot)
        if (world.id_at(slot).is_valid()) ids.push_back(world.id_at(slot));
    } else if (Status found = find_bodies(hosted, request.ids(), &ids); !found) {
      read = found;
      return;
    }
    response->set_step(world.step_count());
    for (BodyId id : ids) {
      const BodyView body = world.body(id);
      describe(hosted.ids.wire(id), look_of(body, hosted.colours[id.index]),
               response->add_descriptions());
      v1::BodyState* state = response->add_states();
      state->set_id(hosted.ids.wire(id));
      auto set = [](const Vec3& v, v1::Vec3* out) {
        out->set_x(v.x());
        out->set_y(v.y());
        out->set_z(v.z());
      };
      set(body.position(), state->mutable_position());
      const Quat q = body.orientation();
      state->mutable_orientation()->set_w(q.w());
      state->mutable_orientation()->set_x(q.x());
      state->mutable_orientation()->set_y(q.y());
      state->mutable_orientation()->set_z(q.z());
      set(body.linear_velocity(), state->mutable_linear_velocity());
      set(body.angular_velocity(), state->mutable_angular_velocity());
      state->set_asleep(body.asleep());
    }
  });
  return to_grpc(read);
}

namespace {

Vec3 vec(const v1::Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

// Checks every entry with `check`, then applies every entry with `apply`, in one host command:
// all or nothing. An unknown id is NOT_FOUND, any other refusal INVALID_ARGUMENT; the message
// starts with the entry ("updates[2].orientation: ...").
template <class Entries, class Check, class Apply>
grpc::Status apply_batch(WorldHost& host, const char* name, const Entries& entries, Check check,
                         Apply apply) {
  return to_grpc(host.apply([&](HostedWorld& hosted) {
    World& world = hosted.world;
    std::vector<BodyId> ids;
    ids.reserve(entries.size());
    for (int i = 0; i < entries.size(); ++i) {
      const BodyId id = hosted.ids.find(entries[i].id());
      if (!world.contains(id))
        return Status::not_found(std::string(name) + "[" + std::to_string(i) + "].id: no body " +
                                 std::to_string(entries[i].id()));
      if (Status s = check(world, id, entries[i]); !s)
        return s.within(std::string(name) + "[" + std::to_string(i) + "].");
      ids.push_back(id);
    }
    for (int i = 0; i < entries.size(); ++i)
      apply(world, ids[i], entries[i]);
    return Status::ok();
  }));
}

BodyMotion motion_from_proto(const v1::BodyStateUpdate& update) {
  BodyMotion motion;
  if (update.has_position()) motion.position = vec(update.position());
  if (update.has_orientation()) {
    const v1::Quat& q = update.orientation();
    motion.orientation = Quat(q.w(), q.x(), q.y(), q.z());
  }
  if (update.has_linear_velocity()) motion.linear_velocity = vec(update.linear_velocity());
  if (update.has_angular_velocity()) motion.angular_velocity = vec(update.angular_velocity());
  return motion;
}

}  // namespace

grpc::Status WorldService::set_body_state(const v1::SetBodyStateRequest& request,
                                          v1::SetBodyStateResponse*) {
  return apply_batch(
      host_, "updates", request.updates(),
      [](const World& world, BodyId id, const v1::BodyStateUpdate& u) {
        return world.check_motion(id, motion_from_proto(u));
      },
      [](World& world, BodyId id, const v1::BodyStateUpdate& u) {
        world.set_motion(id, motion_from_proto(u));
      });
}

grpc::Status WorldService::apply_impulse(const v1::ApplyImpulseRequest& request,
                                         v1::ApplyImpulseResponse*) {
  return to_grpc(host_.apply([&](HostedWorld& hosted) {
    std::vector<ImpulseAt> impulses;
    impulses.reserve(request.impulses_size());
    for (int i = 0; i < request.impulses_size(); ++i) {
      const v1::Impulse& impulse = request.impulses(i);
      const BodyId id = hosted.ids.find(impulse.id());
      if (!hosted.world.contains(id))
        return Status::not_found("impulses[" + std::to_string(i) + "].id: no body " +
                                 std::to_string(impulse.id()));
      impulses.push_back(
          {id, vec(impulse.impulse()),
           impulse.has_point() ? std::optional<Vec3>(vec(impulse.point())) : std::nullopt});
    }
    // Several impulses on one body add up, and are checked as their sum: all or nothing.
    if (Status s = hosted.world.apply_impulses(impulses); !s) return s.within("impulses");
    return Status::ok();
  }));
}

grpc::Status WorldService::load_scene(const v1::LoadSceneRequest& request,
                                      v1::LoadSceneResponse* response) {
  Result<SceneDef> scene = Status::error("source: required (scene_json or builtin)");
  if (request.has_scene_json())
    scene = parse_scene(request.scene_json(), limits_.max_bodies);
  else if (request.has_builtin())
    scene = standard_scene(request.builtin(), limits_.max_bodies);
  if (!scene) {
    const char* field = request.has_scene_json() ? "scene_json: "
                        : request.has_builtin()  ? "builtin: "
                                                 : "";
    return to_grpc(scene.status().within(field));
  }
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
    acceptable = validate(change.value().applied_to(hosted.world.settings()));
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
  host_.inspect([&](const HostedWorld& hosted) {
    saved = {hosted.world.settings(), hosted.world.save_state(), hosted.dt,
             hosted.colours,          hosted.ids.by_slot(),      hosted.ids.next(),
             hosted.server_instance};
  });
  // Encoded off the stepping thread: the copy above is all the world waits for.
  response->set_step(saved.state.step);
  response->set_state(encode_snapshot(saved));
  return grpc::Status::OK;
}

grpc::Status WorldService::restore(const v1::RestoreRequest& request,
                                   v1::RestoreResponse* response) {
  // The snapshot's slots (live or free) are counted, and what decoding it would take is
  // bounded, before it is decoded: every slot costs memory and every step's time.
  const Result<WireScan> scan =
      scan_wire(request.state(), *v1::snapshot::WorldSnapshot::descriptor(),
                parsed_bound(request.state().size()), limits_.max_bodies);
  if (!scan) {
    const std::string what = "state: " + scan.error();
    return scan.status().code() == StatusCode::kResourceExhausted
               ? too_many(what + " (slots, live or free, count against the " +
                          std::to_string(limits_.max_bodies) + " bodies allowed)")
               : invalid("state: not a snapshot (" + scan.error() + ")");
  }
  Result<SavedWorld> saved = decode_snapshot(request.state());
  if (!saved) return invalid("state." + saved.error());
  SavedWorld& s = saved.value();
  const std::uint64_t step = s.state.step;
  s.settings.limits = limits_.world;
  if (Status t = check_time_step(s.dt, limits_.world); !t) return invalid("state." + t.message());
  // Checked whole before the running world is touched.
  Result<World> restored = World::from_state(s.settings, std::move(s.state));
  if (!restored) return invalid("state." + restored.error());
  const Status replaced = host_.apply([&](HostedWorld& hosted) {
    World& world = restored.value();
    WorldSettings settings = world.settings();
    settings.threads = hosted.world.settings().threads;  // the server's choice
    if (Status t = world.set_settings(settings); !t) return t;
    if (s.server_instance == hosted.server_instance) {
      // Ids this server gave to these very bodies: they keep them.
      hosted.restore(std::move(world), s.dt, std::move(s.colours), s.ids, s.next_id);
      return Status::ok();
    }
    // Another server's ids could name bodies of ours: every body gets a new one.
    hosted.replace(std::move(world), s.dt, std::move(s.colours));
    for (std::uint32_t slot = 0; slot < s.ids.size(); ++slot)
      if (const BodyId id = hosted.world.id_at(slot); id.is_valid() && s.ids[slot] != 0)
        (*response->mutable_new_ids())[s.ids[slot]] = hosted.ids.wire(id);
    return Status::ok();
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
  options->ids.assign(request.ids().begin(), request.ids().end());
  std::sort(options->ids.begin(), options->ids.end());
  *max_rate = request.max_rate();
  return grpc::Status::OK;
}

}  // namespace tumble::server
