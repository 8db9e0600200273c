// The door of the World service: every call of tumble.v1.World comes in here (a generic callback
// service, so gRPC reads no request on its own). A call is checked in this order, and each check
// costs nothing the one before it has not allowed:
//   1. the method is one of the service's, and the call carries the token (before any byte of
//      the request is read: a client without the token makes the server hold nothing);
//   2. the request, once read, is within its method's bound (request_bounds.h);
//   3. its wire bytes are scanned: its entries and the memory its parsed form would take are
//      within the bounds, before it is parsed;
//   4. it is parsed and served on one of a few worker threads (the callback threads of gRPC must
//      not wait for the world's next step), and the answer is written.
// Memory a large request took is handed back to the system once it has been served or refused.
#pragma once

#include <grpcpp/generic/async_generic_service.h>
#include <grpcpp/grpcpp.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "request_bounds.h"

namespace tumble::server {

// A fixed set of threads running posted jobs in order.
class WorkerPool {
 public:
  explicit WorkerPool(int threads);
  ~WorkerPool();  // runs what was posted, then joins
  void post(std::function<void()> job);

 private:
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> jobs_;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

class CallGate;

// Reads a call's one request message, refusing one past `max_bytes`, then hands its bytes to
// on_request(). The base of every call the gate lets in. With a `gate`, the call holds
// `max_bytes` of the gate's in-flight budget until it is done, and waits, unread, for room.
class RequestReader : public grpc::ServerGenericBidiReactor {
 public:
  ~RequestReader() override;
  void OnCancel() final;

 protected:
  RequestReader(CallGate* gate, std::size_t max_bytes, std::string method);
  // Once, with the request's bytes; the reactor then writes and finishes as it sees fit.
  virtual void on_request(std::string bytes) = 0;
  // The client cancelled, or the server is shutting down, after the read began.
  virtual void on_cancel() {}
  void OnReadDone(bool ok) override;
  const std::string& method() const { return method_; }
  // The request's bytes are gone: its share of the budget goes back (once; the destructor does
  // it when this was not called).
  void done_with_request();

 private:
  friend class CallGate;
  CallGate* gate_;
  std::size_t max_bytes_;
  std::string method_;
  grpc::ByteBuffer request_;
};

// A call refused before anything was read.
class RefusedCall final : public grpc::ServerGenericBidiReactor {
 public:
  explicit RefusedCall(const grpc::Status& status) { Finish(status); }
  void OnDone() override { delete this; }
};

class CallGate final : public grpc::CallbackGenericService {
 public:
  // Serves one parsed-and-checked request: its bytes in, the response's bytes out.
  using Serve = std::function<grpc::Status(const std::string& request, std::string* response)>;
  // Starts a streaming call whose request the reactor reads itself (a RequestReader charged to
  // `gate`'s budget when it is not null).
  using StartStream =
      std::function<grpc::ServerGenericBidiReactor*(CallGate* gate, std::size_t max_bytes)>;
  struct Unary {
    const google::protobuf::Descriptor* request;
    Serve serve;
  };
  using Authorize = std::function<grpc::Status(const grpc::ServerContextBase&)>;

  // `service`: the full name of the service ("tumble.v1.World"); `unary`: its unary methods by
  // short name; `streams`: its streaming ones.
  CallGate(std::string service, RequestBounds bounds, Authorize authorize,
           std::vector<std::pair<std::string, Unary>> unary,
           std::vector<std::pair<std::string, StartStream>> streams, int workers = 8);

  grpc::ServerGenericBidiReactor* CreateReactor(
      grpc::GenericCallbackServerContext* context) override;

  const RequestBounds& bounds() const { return bounds_; }

  // The in-flight budget (RequestBounds::in_flight_budget): true when `reader`'s bytes fit now;
  // otherwise it waits, and its read starts when calls before it are done.
  bool admit(RequestReader* reader);
  void release(std::size_t bytes);
  // Takes back a waiting reader (cancelled before its read began); false if it was not waiting.
  bool forget(RequestReader* reader);
  // Unary calls read and not yet answered, beyond which new ones are refused as busy.
  static constexpr int kMaxUnaryInFlight = 1024;

 private:
  class UnaryCall;
  std::string prefix_;  // "/tumble.v1.World/"
  RequestBounds bounds_;
  Authorize authorize_;
  std::vector<std::pair<std::string, Unary>> unary_;
  std::vector<std::pair<std::string, StartStream>> streams_;
  std::atomic<int> unary_in_flight_{0};
  std::mutex budget_mutex_;
  std::size_t reserved_ = 0;
  std::deque<RequestReader*> waiting_;
  WorkerPool workers_;
};

// The gate whose budget a request of `max_bytes` is charged to: requests of a megabyte or more;
// small ones (GetInfo, Control) never wait behind large ones.
CallGate* charged(CallGate& gate, std::size_t max_bytes);

// Gives freed memory back to the system after a request of `bytes` (large ones only: the walk
// over the heap is not free).
void release_memory_after(std::size_t bytes);

}  // namespace tumble::server
