// The service's requests applied to a hosted world: what the gRPC service runs on its stepping
// thread, and what Python's in-process world (server/python/) runs directly, so that both
// accept, refuse and answer alike. Each is all or nothing: a refusal changes nothing and names the
// field at fault, with the engine's code (an unknown id is kNotFound, too many bodies
// kResourceExhausted, anything else kInvalidArgument).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "hosted_world.h"
#include "scenes/scene.h"
#include "snapshot.h"
#include "tumble/v1/world.pb.h"

namespace tumble::server {

using WireIds = google::protobuf::RepeatedField<std::uint64_t>;

// The bodies named by `wire_ids`, refusing the first unknown one ("ids[2]: no body 7").
Status find_bodies(const HostedWorld& hosted, const WireIds& wire_ids, std::vector<BodyId>* ids);
// Refuses the first id listed a second time ("ids[3]: listed twice").
Status refuse_repeats(const WireIds& ids);

// The definitions of a SpawnBodiesRequest, checked before the world is touched.
Result<std::vector<BodyDef>> body_defs(const v1::SpawnBodiesRequest& request);
// Creates `defs` (from `request`, whose colours they take) unless the world would then hold more
// than `max_bodies`; their ids into `ids`.
Status spawn_bodies(HostedWorld& hosted, const std::vector<BodyDef>& defs,
                    const v1::SpawnBodiesRequest& request, std::size_t max_bodies,
                    std::vector<std::uint64_t>* ids);
Status remove_bodies(HostedWorld& hosted, const WireIds& wire_ids);
Status get_bodies(const HostedWorld& hosted, const v1::GetBodiesRequest& request,
                  v1::GetBodiesResponse* response);
// A batch of ray casts (QueryRequest, bounded by request_bounds.h's kMaxQueryRays), refused
// whole naming the field.
Status query(const HostedWorld& hosted, const v1::QueryRequest& request,
             v1::QueryResponse* response);
Status set_body_states(HostedWorld& hosted, const v1::SetBodyStateRequest& request);
Status apply_impulses(HostedWorld& hosted, const v1::ApplyImpulseRequest& request);

// The scene a LoadSceneRequest names, at most `max_bodies` bodies ("builtin: ...").
Result<SceneDef> scene_of(const v1::LoadSceneRequest& request, std::size_t max_bodies);
// A scene's world under `limits` (whatever limits the scene carries), checked whole: its time
// step, its number of bodies, every body.
Result<World> world_of_scene(SceneDef scene, const WorldLimits& limits, std::size_t max_bodies);
// Replaces the hosted world (keeping its thread count); the new bodies' ids into `ids`.
Status replace_world(HostedWorld& hosted, World world, double dt, std::vector<std::uint64_t>* ids);

// The hosted world's snapshot bytes (proto/tumble/v1/snapshot.proto).
SavedWorld save_world(const HostedWorld& hosted);
// A snapshot decoded and checked whole, under `limits`, before any world is touched.
struct RestoredWorld {
  World world;
  SavedWorld saved;  // its state moved into `world`
};
Result<RestoredWorld> decode_restore(std::string_view bytes, const WorldLimits& limits,
                                     std::size_t max_bodies);
// Puts a restored world in place. Bodies keep their ids when the snapshot was made by this
// server (hosted.server_instance); otherwise each gets a new one, listed in `new_ids`.
Status restore_world(HostedWorld& hosted, RestoredWorld restored,
                     google::protobuf::Map<std::uint64_t, std::uint64_t>* new_ids);

}  // namespace tumble::server
