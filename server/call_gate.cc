#include "call_gate.h"

#include "log.h"

#include <malloc.h>

#include <algorithm>

namespace tumble::server {

WorkerPool::WorkerPool(int threads) {
  for (int i = 0; i < threads; ++i)
    threads_.emplace_back([this] {
      std::unique_lock lock(mutex_);
      while (true) {
        wake_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
        if (jobs_.empty()) return;  // stopping, nothing left
        std::function<void()> job = std::move(jobs_.front());
        jobs_.pop_front();
        lock.unlock();
        job();
        lock.lock();
      }
    });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& thread : threads_)
    thread.join();
}

void WorkerPool::post(std::function<void()> job) {
  {
    std::lock_guard lock(mutex_);
    jobs_.push_back(std::move(job));
  }
  wake_.notify_one();
}

void release_memory_after(std::size_t bytes) {
  // glibc keeps freed memory in its arenas for reuse; a refused 60 MB request would otherwise
  // stay part of the server's resident size for good.
  if (bytes >= (1u << 20)) malloc_trim(0);
}

RequestReader::RequestReader(CallGate* gate, std::size_t max_bytes, std::string method)
    : gate_(gate), max_bytes_(max_bytes), method_(std::move(method)) {
  if (gate_ == nullptr || gate_->admit(this)) StartRead(&request_);
}

RequestReader::~RequestReader() {
  done_with_request();
}

void RequestReader::done_with_request() {
  if (gate_ != nullptr) gate_->release(max_bytes_);
  gate_ = nullptr;
}

void RequestReader::OnCancel() {
  if (gate_ != nullptr && gate_->forget(this)) {
    Finish(grpc::Status(grpc::StatusCode::CANCELLED, "cancelled before its request was read"));
    return;
  }
  on_cancel();
}

void RequestReader::OnReadDone(bool ok) {
  if (!ok) {
    Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        "request: the call ended before its request message"));
    return;
  }
  const std::size_t length = request_.Length();
  if (length > max_bytes_) {
    request_.Clear();
    done_with_request();
    release_memory_after(length);
    Finish(grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                        "request: " + std::to_string(length) + " bytes, more than the " +
                            std::to_string(max_bytes_) + " " + method_ +
                            " accepts (docs/SERVICE.md, \"Bounds\")"));
    return;
  }
  std::string bytes;
  bytes.reserve(length);
  std::vector<grpc::Slice> slices;
  if (request_.Dump(&slices).ok())
    for (const grpc::Slice& slice : slices)
      bytes.append(reinterpret_cast<const char*>(slice.begin()), slice.size());
  slices.clear();
  request_.Clear();
  on_request(std::move(bytes));
}

CallGate* charged(CallGate& gate, std::size_t max_bytes) {
  return max_bytes >= (1u << 20) ? &gate : nullptr;
}

// One unary call: its request read, then scanned, parsed and served on a worker.
class CallGate::UnaryCall final : public RequestReader {
 public:
  UnaryCall(CallGate& gate, const std::string& method, const Unary& unary, MethodBounds bounds)
      : RequestReader(charged(gate, bounds.bytes), bounds.bytes, method),
        gate_(gate),
        unary_(unary),
        bounds_(bounds) {}

  void OnDone() override {
    gate_.unary_in_flight_.fetch_sub(1);
    delete this;
  }

 private:
  void on_request(std::string bytes) override {
    gate_.workers_.post([this, bytes = std::move(bytes)]() mutable { serve(std::move(bytes)); });
  }

  void serve(std::string bytes) {
    const std::size_t length = bytes.size();
    grpc::Status status = check(bytes);
    std::string answer;
    if (status.ok()) status = unary_.serve(bytes, &answer);
    bytes.clear();
    bytes.shrink_to_fit();
    done_with_request();
    release_memory_after(length);
    if (!status.ok()) {
      Finish(status);
      return;
    }
    grpc::Slice slice(std::move(answer));
    response_ = grpc::ByteBuffer(&slice, 1);
    StartWriteAndFinish(&response_, grpc::WriteOptions(), grpc::Status::OK);
  }

  grpc::Status check(const std::string& bytes) const {
    Result<WireScan> scan =
        scan_wire(bytes, *unary_.request, parsed_bound(bounds_.bytes), bounds_.entries);
    if (scan) return grpc::Status::OK;
    const bool too_big = scan.status().code() == StatusCode::kResourceExhausted;
    return grpc::Status(
        too_big ? grpc::StatusCode::RESOURCE_EXHAUSTED : grpc::StatusCode::INVALID_ARGUMENT,
        "request: " + scan.error() +
            (too_big ? " (the bound of " + method() + ", docs/SERVICE.md \"Bounds\")" : ""));
  }

  CallGate& gate_;
  const Unary& unary_;
  MethodBounds bounds_;
  grpc::ByteBuffer response_;
};

bool CallGate::admit(RequestReader* reader) {
  std::lock_guard lock(budget_mutex_);
  // Alone, a call always goes (no bound exceeds the budget, but a call must never wait forever).
  if (waiting_.empty() &&
      (reserved_ == 0 || reserved_ + reader->max_bytes_ <= bounds_.in_flight_budget())) {
    reserved_ += reader->max_bytes_;
    return true;
  }
  waiting_.push_back(reader);
  return false;
}

void CallGate::release(std::size_t bytes) {
  std::vector<RequestReader*> admitted;
  {
    std::lock_guard lock(budget_mutex_);
    reserved_ -= bytes;
    while (!waiting_.empty() && (reserved_ == 0 || reserved_ + waiting_.front()->max_bytes_ <=
                                                       bounds_.in_flight_budget())) {
      reserved_ += waiting_.front()->max_bytes_;
      admitted.push_back(waiting_.front());
      waiting_.pop_front();
    }
  }
  for (RequestReader* reader : admitted)
    reader->StartRead(&reader->request_);
}

bool CallGate::forget(RequestReader* reader) {
  std::lock_guard lock(budget_mutex_);
  const auto found = std::find(waiting_.begin(), waiting_.end(), reader);
  if (found == waiting_.end()) return false;
  waiting_.erase(found);
  // It never held any of the budget: its destructor gives back nothing.
  reader->gate_ = nullptr;
  return true;
}

CallGate::CallGate(std::string service, RequestBounds bounds, Authorize authorize,
                   std::vector<std::pair<std::string, Unary>> unary,
                   std::vector<std::pair<std::string, StartStream>> streams, int workers)
    : prefix_("/" + service + "/"),
      bounds_(bounds),
      authorize_(std::move(authorize)),
      unary_(std::move(unary)),
      streams_(std::move(streams)),
      workers_(workers) {}

grpc::ServerGenericBidiReactor* CallGate::CreateReactor(
    grpc::GenericCallbackServerContext* context) {
  const std::string& method = context->method();
  const std::string name =
      method.rfind(prefix_, 0) == 0 ? method.substr(prefix_.size()) : std::string();
  const auto unary = std::find_if(unary_.begin(), unary_.end(),
                                  [&](const auto& entry) { return entry.first == name; });
  const auto stream = std::find_if(streams_.begin(), streams_.end(),
                                   [&](const auto& entry) { return entry.first == name; });
  if (name.empty() || (unary == unary_.end() && stream == streams_.end()))
    return new RefusedCall(
        grpc::Status(grpc::StatusCode::UNIMPLEMENTED, "no method " + method.substr(0, 200)));
  if (grpc::Status denied = authorize_(*context); !denied.ok()) {
    log(LogLevel::kDebug,
        name + " from " + context->peer() + " refused: " + denied.error_message());
    return new RefusedCall(denied);
  }
  const MethodBounds bounds = bounds_.of(name);
  if (stream != streams_.end()) return stream->second(charged(*this, bounds.bytes), bounds.bytes);
  if (unary_in_flight_.fetch_add(1) >= kMaxUnaryInFlight) {
    unary_in_flight_.fetch_sub(1);
    return new RefusedCall(grpc::Status(
        grpc::StatusCode::RESOURCE_EXHAUSTED,
        "busy: " + std::to_string(kMaxUnaryInFlight) + " calls in flight; retry later"));
  }
  return new UnaryCall(*this, method, unary->second, bounds);
}

}  // namespace tumble::server
