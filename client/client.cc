#include "client.h"

#include <grpcpp/grpcpp.h>

namespace tumble::client {
namespace {

Status from_grpc(const grpc::Status& status) {
  if (status.ok()) return Status::ok();
  return Status::error(status.error_message().empty()
                           ? "rpc failed with code " + std::to_string(status.error_code())
                           : status.error_message());
}

}  // namespace

Client::Client(const Connection& connection)
    : connection_(connection),
      stub_(v1::World::NewStub(
          grpc::CreateChannel(connection.address, grpc::InsecureChannelCredentials()))) {}

void Client::prepare(grpc::ClientContext* context) const {
  if (!connection_.token.empty())
    context->AddMetadata("authorization", "Bearer " + connection_.token);
}

Result<v1::GetInfoResponse> Client::info() {
  grpc::ClientContext context;
  prepare(&context);
  v1::GetInfoResponse response;
  if (Status s = from_grpc(stub_->GetInfo(&context, {}, &response)); !s) return s;
  return response;
}

Result<std::vector<std::uint64_t>> Client::spawn(const std::vector<v1::BodySpec>& bodies) {
  grpc::ClientContext context;
  prepare(&context);
  v1::SpawnBodiesRequest request;
  for (const v1::BodySpec& body : bodies)
    *request.add_bodies() = body;
  v1::SpawnBodiesResponse response;
  if (Status s = from_grpc(stub_->SpawnBodies(&context, request, &response)); !s) return s;
  return std::vector<std::uint64_t>(response.ids().begin(), response.ids().end());
}

Status Client::remove(const std::vector<std::uint64_t>& ids) {
  grpc::ClientContext context;
  prepare(&context);
  v1::RemoveBodiesRequest request;
  for (std::uint64_t id : ids)
    request.add_ids(id);
  v1::RemoveBodiesResponse response;
  return from_grpc(stub_->RemoveBodies(&context, request, &response));
}

Result<v1::ControlResponse> Client::control(const v1::ControlRequest& request) {
  grpc::ClientContext context;
  prepare(&context);
  v1::ControlResponse response;
  if (Status s = from_grpc(stub_->Control(&context, request, &response)); !s) return s;
  return response;
}

Result<v1::LoadSceneResponse> Client::load_scene(const v1::LoadSceneRequest& request) {
  grpc::ClientContext context;
  prepare(&context);
  v1::LoadSceneResponse response;
  if (Status s = from_grpc(stub_->LoadScene(&context, request, &response)); !s) return s;
  return response;
}

Status Client::stream(const v1::StreamFramesRequest& request,
                      const std::function<bool(const v1::Frame&)>& on_frame) {
  grpc::ClientContext context;
  prepare(&context);
  auto reader = stub_->StreamFrames(&context, request);
  v1::Frame frame;
  while (reader->Read(&frame)) {
    if (!on_frame(frame)) {
      context.TryCancel();
      reader->Finish();
      return Status::ok();
    }
  }
  return from_grpc(reader->Finish());
}

}  // namespace tumble::client
