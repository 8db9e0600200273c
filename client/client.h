// A small C++ client of the tumble.v1 World service: connect, change the world, control the run,
// save and restore it, and receive frames with a callback or by pulling them one at a time.
// Errors come back as Status with the server's message.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tumble/v1/world.grpc.pb.h"
#include "tumble/wire_status.h"

namespace tumble::client {

struct Connection {
  std::string address = "127.0.0.1:50051";
  std::string token;  // sent as "authorization: Bearer <token>" when set
  // PEM file of the certificate authority that signed the server's certificate; when set, the
  // connection uses TLS.
  std::string tls_ca_file;
};

// A failed call's status with the server's message.
Status from_grpc(const grpc::Status& status);

// Frames pulled one at a time: `while (stream.next(&frame)) ...; stream.finish()`.
class FrameStream {
 public:
  FrameStream(std::unique_ptr<grpc::ClientContext> context,
              std::unique_ptr<grpc::ClientReader<v1::Frame>> reader);
  ~FrameStream();  // cancels the stream if it is still open
  FrameStream(FrameStream&&) noexcept;
  bool next(v1::Frame* frame);
  // Ends a next() waiting on another thread (it returns false); safe from any thread.
  void cancel() { context_->TryCancel(); }
  // Cancels the stream if frames are still coming; the stream's final status.
  Status finish();

 private:
  std::unique_ptr<grpc::ClientContext> context_;
  std::unique_ptr<grpc::ClientReader<v1::Frame>> reader_;
  bool ended_ = false, finished_ = false;
};

class Client {
 public:
  // Fails only for a TLS authority file that cannot be read; the server is first contacted by
  // the first call.
  static Result<Client> connect(const Connection& connection);

  Result<v1::GetInfoResponse> info();
  Result<std::vector<std::uint64_t>> spawn(const std::vector<v1::BodySpec>& bodies);
  Status remove(const std::vector<std::uint64_t>& ids);
  Result<v1::GetBodiesResponse> bodies(const std::vector<std::uint64_t>& ids = {});
  // Ray casts between two steps (QueryRequest: flat arrays of origins and directions).
  Result<v1::QueryResponse> query(const v1::QueryRequest& request);
  // All or nothing: one refused update or impulse leaves every body as it was.
  Status set_states(const std::vector<v1::BodyStateUpdate>& updates);
  Status apply_impulses(const std::vector<v1::Impulse>& impulses);
  // Joints (docs/SERVICE.md, "Joints"), all or nothing.
  Result<std::vector<std::uint64_t>> create_joints(const std::vector<v1::JointSpec>& joints);
  Status remove_joints(const std::vector<std::uint64_t>& ids);
  Status set_joint_drives(const std::vector<v1::JointDriveUpdate>& updates);
  Result<v1::GetJointsResponse> joints(const std::vector<std::uint64_t>& ids = {});
  Result<v1::ControlResponse> control(const v1::ControlRequest& request);
  Result<v1::LoadSceneResponse> load_scene(const v1::LoadSceneRequest& request);
  Result<v1::SnapshotResponse> snapshot();
  Result<v1::RestoreResponse> restore(const std::string& state);
  // The standard health check: true when the server says SERVING.
  Result<bool> healthy();
  // Calls `on_frame` for each frame until it returns false or the stream ends.
  Status stream(const v1::StreamFramesRequest& request,
                const std::function<bool(const v1::Frame&)>& on_frame);
  FrameStream subscribe(const v1::StreamFramesRequest& request);

 private:
  Client(const Connection& connection, std::shared_ptr<grpc::Channel> channel);
  void prepare(grpc::ClientContext* context) const;
  // One unary call with a fresh context carrying the token; the server's refusal as a Status.
  template <class Response, class Request, class Method>
  Result<Response> call(Method method, const Request& request) {
    grpc::ClientContext context;
    prepare(&context);
    Response response;
    if (Status s = from_grpc(((*stub_).*method)(&context, request, &response)); !s) return s;
    return response;
  }
  Connection connection_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::World::Stub> stub_;
};

}  // namespace tumble::client
