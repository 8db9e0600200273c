// One unary call of `method` ("/tumble.v1.World/GetInfo") with `bytes` as its request, whatever
// they hold: how the hostile-request tests send what no typed stub would.
#pragma once

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>

namespace tumble::testing {

inline grpc::Status generic_unary_call(const std::shared_ptr<grpc::Channel>& channel,
                                       grpc::ClientContext* context, const std::string& method,
                                       const std::string& bytes) {
  grpc::GenericStub generic(channel);
  grpc::Slice slice(bytes);
  grpc::ByteBuffer request(&slice, 1), response;
  grpc::Status status;
  bool done = false;
  std::mutex mutex;
  std::condition_variable finished;
  generic.UnaryCall(context, method, grpc::StubOptions(), &request, &response, [&](grpc::Status s) {
    std::lock_guard lock(mutex);
    status = std::move(s);
    done = true;
    finished.notify_one();
  });
  std::unique_lock lock(mutex);
  finished.wait(lock, [&] { return done; });
  return status;
}

}  // namespace tumble::testing
