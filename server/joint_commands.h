// The service's joint requests (proto/tumble/v1/world.proto, "Joints") applied to a hosted world,
// as world_commands.h does for bodies: all or nothing, refusals naming the entry and field
// ("joints[2].axis: must not be zero"), unknown ids kNotFound, too many joints
// kResourceExhausted.
#pragma once

#include <cstdint>
#include <vector>

#include "hosted_world.h"
#include "tumble/v1/world.pb.h"

namespace tumble::server {

// The definition a JointSpec gives, bodies aside (checked with the world by create_joints).
Result<JointDef> joint_from_proto(const v1::JointSpec& spec);
void joint_to_proto(const JointDef& def, const HostedWorld& hosted, v1::JointSpec* out);

// Creates the request's joints unless one is refused or the world would then hold more than
// `max_joints`; their ids into `ids`.
Status create_joints(HostedWorld& hosted, const v1::CreateJointsRequest& request,
                     std::size_t max_joints, std::vector<std::uint64_t>* ids);
Status remove_joints(HostedWorld& hosted, const v1::RemoveJointsRequest& request);
Status set_joint_drives(HostedWorld& hosted, const v1::SetJointDrivesRequest& request);
Status get_joints(const HostedWorld& hosted, const v1::GetJointsRequest& request,
                  v1::GetJointsResponse* response);

}  // namespace tumble::server
