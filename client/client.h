// A small C++ client of the tumble.v1 World service: connect, change the world, control the run,
// and receive frames with a callback. Errors come back as Status with the server's message.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "physics/status.h"
#include "tumble/v1/world.grpc.pb.h"

namespace tumble::client {

struct Connection {
  std::string address = "127.0.0.1:50051";
  std::string token;  // sent as "authorization: Bearer <token>" when set
};

class Client {
 public:
  explicit Client(const Connection& connection);

  Result<v1::GetInfoResponse> info();
  Result<std::vector<std::uint64_t>> spawn(const std::vector<v1::BodySpec>& bodies);
  Status remove(const std::vector<std::uint64_t>& ids);
  Result<v1::ControlResponse> control(const v1::ControlRequest& request);
  Result<v1::LoadSceneResponse> load_scene(const v1::LoadSceneRequest& request);
  // Calls `on_frame` for each frame until it returns false or the stream ends.
  Status stream(const v1::StreamFramesRequest& request,
                const std::function<bool(const v1::Frame&)>& on_frame);

 private:
  void prepare(grpc::ClientContext* context) const;
  Connection connection_;
  std::unique_ptr<v1::World::Stub> stub_;
};

}  // namespace tumble::client
