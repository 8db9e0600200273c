#include "client.h"

#include <grpcpp/grpcpp.h>

#include <fstream>
#include <sstream>

#include "grpc/health/v1/health.grpc.pb.h"

namespace tumble::client {
namespace {

// Snapshots of large worlds are tens of megabytes: past gRPC's 4 MB default.
constexpr int kMaxMessageBytes = 512 << 20;

}  // namespace

Status from_grpc(const grpc::Status& status) {
  if (status.ok()) return Status::ok();
  return Status::error(status.error_message().empty()
                           ? "rpc failed with code " + std::to_string(status.error_code())
                           : status.error_message());
}

FrameStream::FrameStream(std::unique_ptr<grpc::ClientContext> context,
                         std::unique_ptr<grpc::ClientReader<v1::Frame>> reader)
    : context_(std::move(context)), reader_(std::move(reader)) {}
FrameStream::FrameStream(FrameStream&&) noexcept = default;
FrameStream::~FrameStream() {
  if (reader_ != nullptr && !finished_) finish();
}

bool FrameStream::next(v1::Frame* frame) {
  if (ended_) return false;
  ended_ = !reader_->Read(frame);
  return !ended_;
}

Status FrameStream::finish() {
  finished_ = true;
  if (!ended_) {
    context_->TryCancel();
    v1::Frame rest;
    while (reader_->Read(&rest)) {
    }
    reader_->Finish();
    return Status::ok();  // we ended it
  }
  return from_grpc(reader_->Finish());
}

Result<Client> Client::connect(const Connection& connection) {
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
  if (!connection.tls_ca_file.empty()) {
    std::ifstream file(connection.tls_ca_file);
    if (!file) return Status::error(connection.tls_ca_file + ": cannot open");
    std::stringstream pem;
    pem << file.rdbuf();
    grpc::SslCredentialsOptions options;
    options.pem_root_certs = pem.str();
    credentials = grpc::SslCredentials(options);
  }
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(kMaxMessageBytes);
  arguments.SetMaxSendMessageSize(kMaxMessageBytes);
  return Client(connection, grpc::CreateCustomChannel(connection.address, credentials, arguments));
}

Client::Client(const Connection& connection, std::shared_ptr<grpc::Channel> channel)
    : connection_(connection), channel_(std::move(channel)), stub_(v1::World::NewStub(channel_)) {}

void Client::prepare(grpc::ClientContext* context) const {
  if (!connection_.token.empty())
    context->AddMetadata("authorization", "Bearer " + connection_.token);
}

Result<v1::GetInfoResponse> Client::info() {
  return call<v1::GetInfoResponse>(&v1::World::Stub::GetInfo, v1::GetInfoRequest());
}

Result<std::vector<std::uint64_t>> Client::spawn(const std::vector<v1::BodySpec>& bodies) {
  v1::SpawnBodiesRequest request;
  request.mutable_bodies()->Add(bodies.begin(), bodies.end());
  auto response = call<v1::SpawnBodiesResponse>(&v1::World::Stub::SpawnBodies, request);
  if (!response) return response.status();
  return std::vector<std::uint64_t>(response.value().ids().begin(), response.value().ids().end());
}

Status Client::remove(const std::vector<std::uint64_t>& ids) {
  v1::RemoveBodiesRequest request;
  request.mutable_ids()->Add(ids.begin(), ids.end());
  return call<v1::RemoveBodiesResponse>(&v1::World::Stub::RemoveBodies, request).status();
}

Result<v1::GetBodiesResponse> Client::bodies(const std::vector<std::uint64_t>& ids) {
  v1::GetBodiesRequest request;
  request.mutable_ids()->Add(ids.begin(), ids.end());
  return call<v1::GetBodiesResponse>(&v1::World::Stub::GetBodies, request);
}

Result<v1::QueryResponse> Client::query(const v1::QueryRequest& request) {
  return call<v1::QueryResponse>(&v1::World::Stub::Query, request);
}

Status Client::set_states(const std::vector<v1::BodyStateUpdate>& updates) {
  v1::SetBodyStateRequest request;
  request.mutable_updates()->Add(updates.begin(), updates.end());
  return call<v1::SetBodyStateResponse>(&v1::World::Stub::SetBodyState, request).status();
}

Status Client::apply_impulses(const std::vector<v1::Impulse>& impulses) {
  v1::ApplyImpulseRequest request;
  request.mutable_impulses()->Add(impulses.begin(), impulses.end());
  return call<v1::ApplyImpulseResponse>(&v1::World::Stub::ApplyImpulse, request).status();
}

Result<std::vector<std::uint64_t>> Client::create_joints(const std::vector<v1::JointSpec>& joints) {
  v1::CreateJointsRequest request;
  request.mutable_joints()->Add(joints.begin(), joints.end());
  Result<v1::CreateJointsResponse> made =
      call<v1::CreateJointsResponse>(&v1::World::Stub::CreateJoints, request);
  if (!made) return made.status();
  return std::vector<std::uint64_t>(made.value().ids().begin(), made.value().ids().end());
}

Status Client::remove_joints(const std::vector<std::uint64_t>& ids) {
  v1::RemoveJointsRequest request;
  request.mutable_ids()->Add(ids.begin(), ids.end());
  return call<v1::RemoveJointsResponse>(&v1::World::Stub::RemoveJoints, request).status();
}

Status Client::set_joint_drives(const std::vector<v1::JointDriveUpdate>& updates) {
  v1::SetJointDrivesRequest request;
  request.mutable_updates()->Add(updates.begin(), updates.end());
  return call<v1::SetJointDrivesResponse>(&v1::World::Stub::SetJointDrives, request).status();
}

Result<v1::GetJointsResponse> Client::joints(const std::vector<std::uint64_t>& ids) {
  v1::GetJointsRequest request;
  request.mutable_ids()->Add(ids.begin(), ids.end());
  return call<v1::GetJointsResponse>(&v1::World::Stub::GetJoints, request);
}

Result<v1::ControlResponse> Client::control(const v1::ControlRequest& request) {
  return call<v1::ControlResponse>(&v1::World::Stub::Control, request);
}

Result<v1::LoadSceneResponse> Client::load_scene(const v1::LoadSceneRequest& request) {
  return call<v1::LoadSceneResponse>(&v1::World::Stub::LoadScene, request);
}

Result<v1::SnapshotResponse> Client::snapshot() {
  return call<v1::SnapshotResponse>(&v1::World::Stub::Snapshot, v1::SnapshotRequest());
}

Result<v1::RestoreResponse> Client::restore(const std::string& state) {
  v1::RestoreRequest request;
  request.set_state(state);
  return call<v1::RestoreResponse>(&v1::World::Stub::Restore, request);
}

Result<bool> Client::healthy() {
  auto health = grpc::health::v1::Health::NewStub(channel_);
  grpc::ClientContext context;
  grpc::health::v1::HealthCheckResponse response;
  if (Status s = from_grpc(health->Check(&context, {}, &response)); !s) return s;
  return response.status() == grpc::health::v1::HealthCheckResponse::SERVING;
}

Status Client::stream(const v1::StreamFramesRequest& request,
                      const std::function<bool(const v1::Frame&)>& on_frame) {
  FrameStream frames = subscribe(request);
  v1::Frame frame;
  while (frames.next(&frame))
    if (!on_frame(frame)) break;
  return frames.finish();
}

FrameStream Client::subscribe(const v1::StreamFramesRequest& request) {
  auto context = std::make_unique<grpc::ClientContext>();
  prepare(context.get());
  auto reader = stub_->StreamFrames(context.get(), request);
  return FrameStream(std::move(context), std::move(reader));
}

}  // namespace tumble::client
