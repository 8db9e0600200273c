#include "local_world.h"

#include <random>

#include "joint_commands.h"
#include "world_commands.h"

namespace tumble::python {
namespace {

template <class Message>
Result<Message> parsed(std::string_view bytes) {
  Message message;
  if (!message.ParseFromArray(bytes.data(), static_cast<int>(bytes.size())))
    return Status::error("request: not a " + Message::descriptor()->full_name());
  return message;
}

std::string serialized(const google::protobuf::Message& message) {
  return message.SerializeAsString();
}

// Runs `serve` on the request `bytes` parse into; the response's bytes.
template <class Request, class Response, class Serve>
Result<std::string> served(std::string_view bytes, Serve serve) {
  Result<Request> request = parsed<Request>(bytes);
  if (!request) return request.status();
  Response response;
  if (Status s = serve(request.value(), &response); !s) return s;
  return serialized(response);
}

}  // namespace

LocalWorld::LocalWorld(int threads, const LocalLimits& limits) : limits_(limits) {
  scene_.name = "empty";
  scene_.world.threads = threads;
  scene_.world.limits = limits.world;
  hosted_.world = World(scene_.world);
  hosted_.dt = scene_.dt;
  // A snapshot of another world (or of a server) gives its bodies new ids here.
  hosted_.server_instance = std::random_device{}() | (std::uint64_t{std::random_device{}()} << 32);
  refresh_catalogue();
}

Result<std::string> LocalWorld::call(std::string_view method, std::string_view bytes) {
  using namespace server;
  Result<std::string> answer = Status::error("method: unknown (" + std::string(method) + ")");
  if (method == "SpawnBodies") {
    answer = served<v1::SpawnBodiesRequest, v1::SpawnBodiesResponse>(bytes, [&](auto& r, auto* a) {
      Result<std::vector<BodyDef>> defs = body_defs(r);
      if (!defs) return defs.status();
      std::vector<std::uint64_t> ids;
      if (Status s = spawn_bodies(hosted_, defs.value(), r, limits_.max_bodies, &ids); !s) return s;
      a->mutable_ids()->Add(ids.begin(), ids.end());
      return Status::ok();
    });
  } else if (method == "RemoveBodies") {
    answer = served<v1::RemoveBodiesRequest, v1::RemoveBodiesResponse>(
        bytes, [&](auto& r, auto*) { return remove_bodies(hosted_, r.ids()); });
  } else if (method == "GetBodies") {
    answer = served<v1::GetBodiesRequest, v1::GetBodiesResponse>(
        bytes, [&](auto& r, auto* a) { return get_bodies(hosted_, r, a); });
  } else if (method == "Query") {
    answer = served<v1::QueryRequest, v1::QueryResponse>(
        bytes, [&](auto& r, auto* a) { return query(hosted_, r, a); });
  } else if (method == "SetBodyState") {
    answer = served<v1::SetBodyStateRequest, v1::SetBodyStateResponse>(
        bytes, [&](auto& r, auto*) { return set_body_states(hosted_, r); });
  } else if (method == "ApplyImpulse") {
    answer = served<v1::ApplyImpulseRequest, v1::ApplyImpulseResponse>(
        bytes, [&](auto& r, auto*) { return apply_impulses(hosted_, r); });
  } else if (method == "CreateJoints") {
    answer =
        served<v1::CreateJointsRequest, v1::CreateJointsResponse>(bytes, [&](auto& r, auto* a) {
          std::vector<std::uint64_t> ids;
          if (Status s = create_joints(hosted_, r, kJointsPerBody * limits_.max_bodies, &ids); !s)
            return s;
          a->mutable_ids()->Add(ids.begin(), ids.end());
          return Status::ok();
        });
  } else if (method == "RemoveJoints") {
    answer = served<v1::RemoveJointsRequest, v1::RemoveJointsResponse>(
        bytes, [&](auto& r, auto*) { return remove_joints(hosted_, r); });
  } else if (method == "SetJointDrives") {
    answer = served<v1::SetJointDrivesRequest, v1::SetJointDrivesResponse>(
        bytes, [&](auto& r, auto*) { return set_joint_drives(hosted_, r); });
  } else if (method == "GetJoints") {
    answer = served<v1::GetJointsRequest, v1::GetJointsResponse>(
        bytes, [&](auto& r, auto* a) { return get_joints(hosted_, r, a); });
  } else if (method == "LoadScene") {
    answer = served<v1::LoadSceneRequest, v1::LoadSceneResponse>(bytes, [&](auto& r, auto* a) {
      Result<SceneDef> scene = scene_of(r, limits_.max_bodies);
      if (!scene) return scene.status();
      Result<World> made = world_of_scene(scene.value(), limits_.world, limits_.max_bodies);
      if (!made) return made.status();
      std::vector<std::uint64_t> ids;
      if (Status s = replace_world(hosted_, std::move(made).value(), scene.value().dt, &ids); !s)
        return s;
      scene_ = std::move(scene).value();
      a->mutable_ids()->Add(ids.begin(), ids.end());
      a->set_name(scene_.name);
      return Status::ok();
    });
  } else if (method == "Control") {
    answer = control(bytes);
  } else if (method == "GetInfo") {
    answer = info();
  } else if (method == "Snapshot") {
    v1::SnapshotResponse response;
    const SavedWorld saved = save_world(hosted_);
    response.set_step(saved.step);
    response.set_state(encode_snapshot(saved));
    answer = serialized(response);
  } else if (method == "Restore") {
    answer = served<v1::RestoreRequest, v1::RestoreResponse>(bytes, [&](auto& r, auto* a) {
      Result<RestoredWorld> restored = decode_restore(r.state(), limits_.world, limits_.max_bodies);
      if (!restored) return restored.status();
      a->set_step(restored.value().world.step_count());
      return restore_world(hosted_, std::move(restored).value(), a->mutable_new_ids());
    });
  }
  // The ids and the catalogue follow the bodies: only these calls add or remove any.
  if (method == "SpawnBodies" || method == "RemoveBodies" || method == "LoadScene" ||
      method == "Restore" || method == "Control")
    refresh_catalogue();
  return answer;
}

Result<std::string> LocalWorld::control(std::string_view bytes) {
  Result<v1::ControlRequest> request = parsed<v1::ControlRequest>(bytes);
  if (!request) return request.status();
  const v1::ControlRequest& r = request.value();
  // Checked whole before anything changes, as the server does.
  Result<server::RunChange> change =
      server::run_change_from_proto(r.settings(), limits_.world.max_time_step);
  if (!change) return change.status().within("settings.");
  if (Status s = change.value().check_against(hosted_.world.settings()); !s)
    return s.within("settings.");
  if (r.action_case() == v1::ControlRequest::kReset && r.reset()) {
    running_ = false;
    Result<World> made = server::world_of_scene(scene_, limits_.world, limits_.max_bodies);
    if (!made) return made.status();
    std::vector<std::uint64_t> ids;
    if (Status s = server::replace_world(hosted_, std::move(made).value(), scene_.dt, &ids); !s)
      return s;
  }
  if (Status s = hosted_.world.set_settings(change.value().applied_to(hosted_.world.settings()));
      !s)
    return s.within("settings.");
  if (change.value().dt) hosted_.dt = *change.value().dt;
  if (change.value().real_time_factor) real_time_factor_ = *change.value().real_time_factor;
  if (r.action_case() == v1::ControlRequest::kPlay && r.play()) running_ = true;
  if (r.action_case() == v1::ControlRequest::kPause && r.pause()) running_ = false;
  if (r.action_case() == v1::ControlRequest::kStep) {
    running_ = false;
    if (Status s = step(r.step()); !s) return s;
  }
  v1::ControlResponse response;
  response.set_running(running_);
  response.set_step(hosted_.world.step_count());
  server::run_settings_to_proto(hosted_.dt, real_time_factor_, hosted_.world.settings(),
                                response.mutable_settings());
  return serialized(response);
}

Result<std::string> LocalWorld::info() const {
  v1::GetInfoResponse response;
  response.set_version(TUMBLE_VERSION);
  response.set_step(hosted_.world.step_count());
  response.set_time(hosted_.world.time());
  response.set_body_count(static_cast<std::uint32_t>(hosted_.world.body_count()));
  response.set_joint_count(static_cast<std::uint32_t>(hosted_.world.joint_count()));
  response.set_running(running_);
  server::run_settings_to_proto(hosted_.dt, real_time_factor_, hosted_.world.settings(),
                                response.mutable_settings());
  server::stats_to_proto(hosted_.world.last_step(), response.mutable_last_step());
  return serialized(response);
}

Status LocalWorld::step(std::uint64_t n) {
  for (std::uint64_t i = 0; i < n; ++i)
    if (Status s = hosted_.world.step(hosted_.dt); !s) return s;
  return Status::ok();
}

void LocalWorld::refresh_catalogue() {
  hosted_.ids.sync(hosted_.world);
  catalogue_ = server::updated_catalogue(hosted_, catalogue_, catalogue_epoch_);
  catalogue_epoch_ = hosted_.epoch;
}

std::shared_ptr<const server::FrameData> LocalWorld::frame_data() {
  refresh_catalogue();
  server::note_changes(hosted_);
  return server::make_frame(hosted_, hosted_.dt, catalogue_);
}

std::string LocalWorld::frame(const server::FrameOptions& options, server::CatalogueDiff& diff) {
  const std::shared_ptr<const server::FrameData> data = frame_data();
  v1::Frame frame;
  server::frame_to_proto(*data, options, &frame);
  diff.add_changes(*data, options.ids, &frame);
  if (options.joints) diff.add_joint_changes(*data, &frame);
  return frame.SerializeAsString();
}

}  // namespace tumble::python
