// The gRPC World service over a WorldHost. Every RPC that changes the world runs as one host
// command, so it is applied between two steps, all or nothing; refusals carry the status code
// and a message naming the field.
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <string>

#include <mutex>

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
};

// StreamFrames uses gRPC's callback API on raw bytes (frame_stream.h); the rest is synchronous.
class WorldService final
    : public v1::World::WithRawCallbackMethod_StreamFrames<v1::World::Service> {
 public:
  // `scene`: what the host's world was made from, and what Control's reset goes back to.
  WorldService(WorldHost& host, ServiceLimits limits, SceneDef scene);

  grpc::Status SpawnBodies(grpc::ServerContext*, const v1::SpawnBodiesRequest*,
                           v1::SpawnBodiesResponse*) override;
  grpc::Status RemoveBodies(grpc::ServerContext*, const v1::RemoveBodiesRequest*,
                            v1::RemoveBodiesResponse*) override;
  grpc::Status GetBodies(grpc::ServerContext*, const v1::GetBodiesRequest*,
                         v1::GetBodiesResponse*) override;
  grpc::Status SetBodyState(grpc::ServerContext*, const v1::SetBodyStateRequest*,
                            v1::SetBodyStateResponse*) override;
  grpc::Status ApplyImpulse(grpc::ServerContext*, const v1::ApplyImpulseRequest*,
                            v1::ApplyImpulseResponse*) override;
  grpc::Status LoadScene(grpc::ServerContext*, const v1::LoadSceneRequest*,
                         v1::LoadSceneResponse*) override;
  grpc::Status Control(grpc::ServerContext*, const v1::ControlRequest*,
                       v1::ControlResponse*) override;
  grpc::Status GetInfo(grpc::ServerContext*, const v1::GetInfoRequest*,
                       v1::GetInfoResponse*) override;
  grpc::Status Snapshot(grpc::ServerContext*, const v1::SnapshotRequest*,
                        v1::SnapshotResponse*) override;
  grpc::Status Restore(grpc::ServerContext*, const v1::RestoreRequest*,
                       v1::RestoreResponse*) override;
  grpc::ServerWriteReactor<grpc::ByteBuffer>* StreamFrames(grpc::CallbackServerContext*,
                                                           const grpc::ByteBuffer*) override;

  // Ends every stream (they end with OK after the frame in flight).
  void shut_down() {
    shutting_down_ = true;
    streams_.end_all();
  }

 private:
  grpc::Status authorize(const grpc::ServerContextBase* context) const;
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
};

}  // namespace tumble::server
