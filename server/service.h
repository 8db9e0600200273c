// The gRPC World service over a WorldHost. Every RPC that changes the world runs as one host
// command, so it is applied between two steps, all or nothing; refusals carry the status code
// and a message naming the field.
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <string>

#include <mutex>

#include "call_gate.h"
#include "frame_stream.h"
#include "scenes/scene.h"
#include "tumble/v1/world.grpc.pb.h"
#include "world_host.h"

namespace tumble::server {

struct ServiceLimits {
  std::size_t max_bodies = 100000;  // spawning past this is RESOURCE_EXHAUSTED
  // When set, every call must carry the metadata "authorization: Bearer <token>" or is
  // UNAUTHENTICATED.
  std::string token;
  // What every world this server holds accepts (docs/SCENES.md, "Limits"): imposed on scenes
  // loaded and snapshots restored, whatever limits they carry, so a client cannot widen them.
  WorldLimits world;
  // The largest request (--max-message-mb): the bound of Restore and LoadScene, and the cap of
  // every other method's bound (request_bounds.h).
  std::size_t max_message_bytes = 64u << 20;
};

// Every method is generic: the CallGate (call_gate.h) receives the calls, checks the token before
// reading a request, bounds and scans it, and hands it to the methods below. The typed service
// is registered too, for its name (reflection lists it).
using GatedWorldService = v1::World::WithGenericMethod_SpawnBodies<
    v1::World::WithGenericMethod_RemoveBodies<v1::World::WithGenericMethod_SetBodyState<
        v1::World::WithGenericMethod_ApplyImpulse<v1::World::WithGenericMethod_GetBodies<
            v1::World::WithGenericMethod_Query<
            v1::World::WithGenericMethod_CreateJoints<v1::World::WithGenericMethod_RemoveJoints<
                v1::World::WithGenericMethod_SetJointDrives<
                    v1::World::WithGenericMethod_GetJoints<v1::World::WithGenericMethod_LoadScene<
                        v1::World::WithGenericMethod_Control<v1::World::WithGenericMethod_GetInfo<
                            v1::World::WithGenericMethod_StreamFrames<
                                v1::World::WithGenericMethod_Snapshot<
                                    v1::World::WithGenericMethod_Restore<
                                        v1::World::Service>>>>>>>>>>>>>>>>;

class WorldService final : public GatedWorldService {
 public:
  // `scene`: what the host's world was made from, and what Control's reset goes back to.
  WorldService(WorldHost& host, ServiceLimits limits, SceneDef scene);

  // Registers the service and its gate on `builder`, and tells gRPC the largest request.
  void register_on(grpc::ServerBuilder& builder);

  // Ends every stream (they end with OK after the frame in flight).
  void shut_down() {
    shutting_down_ = true;
    streams_.end_all();
  }

 private:
  grpc::Status spawn_bodies(const v1::SpawnBodiesRequest&, v1::SpawnBodiesResponse*);
  grpc::Status remove_bodies(const v1::RemoveBodiesRequest&, v1::RemoveBodiesResponse*);
  grpc::Status get_bodies(const v1::GetBodiesRequest&, v1::GetBodiesResponse*);
  grpc::Status query(const v1::QueryRequest&, v1::QueryResponse*);
  grpc::Status create_joints(const v1::CreateJointsRequest&, v1::CreateJointsResponse*);
  grpc::Status remove_joints(const v1::RemoveJointsRequest&, v1::RemoveJointsResponse*);
  grpc::Status set_joint_drives(const v1::SetJointDrivesRequest&, v1::SetJointDrivesResponse*);
  grpc::Status get_joints(const v1::GetJointsRequest&, v1::GetJointsResponse*);
  grpc::Status set_body_state(const v1::SetBodyStateRequest&, v1::SetBodyStateResponse*);
  grpc::Status apply_impulse(const v1::ApplyImpulseRequest&, v1::ApplyImpulseResponse*);
  grpc::Status load_scene(const v1::LoadSceneRequest&, v1::LoadSceneResponse*);
  grpc::Status control(const v1::ControlRequest&, v1::ControlResponse*);
  grpc::Status get_info(const v1::GetInfoRequest&, v1::GetInfoResponse*);
  grpc::Status snapshot(const v1::SnapshotRequest&, v1::SnapshotResponse*);
  grpc::Status restore(const v1::RestoreRequest&, v1::RestoreResponse*);
  // A StreamFrames request's options, or why they are refused.
  grpc::Status read_stream_request(const std::string& bytes, FrameOptions* options,
                                   double* max_rate) const;
  grpc::Status authorize(const grpc::ServerContextBase& context) const;
  // One unary method for the gate: parses the request the gate checked, serves it, encodes.
  template <class Request, class Response>
  CallGate::Unary unary(grpc::Status (WorldService::*serve)(const Request&, Response*));
  CallGate make_gate();
  StreamHub streams_;
  WorldHost& host_;
  ServiceLimits limits_;
  // Builds `scene`'s world and swaps it in between two steps; its body ids into `ids`.
  grpc::Status replace_world(SceneDef scene, std::vector<std::uint64_t>* ids);
  // Back to the scene last loaded.
  grpc::Status reset_world();
  std::mutex scene_mutex_;
  SceneDef scene_;  // the last scene loaded
  std::atomic<bool> shutting_down_{false};
  FrameStream::ReadRequest read_stream_;
  CallGate gate_;  // last: its workers stop first
};

}  // namespace tumble::server
