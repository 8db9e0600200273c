// One subscriber's StreamFrames, written with gRPC's callback API: no thread waits per stream; a
// frame arriving in the subscriber's mailbox starts a write when none is in flight (on the hub's
// thread: the stepping thread that delivered the frame never encodes), and the end of a write
// takes the newest frame waiting. Each step's frame is encoded once per distinct set
// of fields asked for (kept in the FrameData, shared by every subscriber that asked for the same)
// and sent as those bytes followed by this subscriber's own small part (frames dropped, bodies
// added and removed since its previous frame): protobuf reads two encoded messages one after the
// other as their merge, so the subscriber receives one Frame.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "call_gate.h"
#include "catalogue_diff.h"
#include "convert.h"
#include "world_host.h"

namespace tumble::server {

class FrameStream;
class StreamHub;

// Hz: the lowest max_rate a subscription may ask for (0 asks for every step).
inline constexpr double kMinStreamRate = 1e-3;

// Between a stream and those who call it from other threads (the mailbox on the stepping thread,
// the hub): it outlives the stream, and forgets it under its lock when the stream is done.
struct StreamLink final : MailboxListener, std::enable_shared_from_this<StreamLink> {
  StreamHub* hub = nullptr;
  std::mutex mutex;
  FrameStream* stream = nullptr;  // null once the stream is done
  bool scheduled = false;
  // On the stepping thread: asks the hub to run the stream's offer(), once however many frames
  // arrive before the hub gets to it.
  void frame_arrived() override;
  void offer();  // on the hub's thread
  void end();
};

// The streams of one service: the thread that starts their writes when frames arrive, and the
// live streams, so that shutting down can end them all.
class StreamHub {
 public:
  StreamHub();
  ~StreamHub();  // every stream must be done (the gRPC server shut down) before
  void schedule(std::shared_ptr<StreamLink> link);
  void add(const std::shared_ptr<StreamLink>& link);
  void remove(const std::shared_ptr<StreamLink>& link);
  // Ends every stream with OK after its write in flight.
  void end_all();

 private:
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<StreamLink>> queue_;
  std::set<std::shared_ptr<StreamLink>> streams_;
  bool stopping_ = false;
  std::thread thread_;
};

class FrameStream final : public RequestReader {
 public:
  // What a request asks for, or why it is refused.
  using ReadRequest =
      std::function<grpc::Status(const std::string& bytes, FrameOptions*, double* max_rate)>;
  // Reads the request (at most `max_bytes`), then subscribes to `host`.
  FrameStream(StreamHub& hub, WorldHost& host, const ReadRequest& read, CallGate* gate,
              std::size_t max_bytes, const std::string& method);
  // Ends the stream with OK after the write in flight (the server is shutting down).
  void end();

  void OnWriteDone(bool ok) override;
  void on_cancel() override;
  void OnDone() override;

 private:
  void on_request(std::string bytes) override;
  // Starts a write of the newest frame when none is in flight.
  void offer();
  void finish_locked(const grpc::Status& status);
  // The bytes this subscriber gets for `frame` (the shared encoding, then its own part).
  void encode(const FrameData& frame, std::uint64_t dropped);

  friend struct StreamLink;
  StreamHub& hub_;
  WorldHost& host_;
  const ReadRequest& read_;
  bool started_ = false;  // the request was read and the subscription made
  FrameOptions options_;
  std::chrono::duration<double> min_interval_;
  std::shared_ptr<FrameMailbox> mailbox_;
  std::shared_ptr<StreamLink> link_;
  std::mutex mutex_;
  bool writing_ = false, finishing_ = false, finished_ = false;
  grpc::Status final_status_;
  grpc::ByteBuffer buffer_;  // the write in flight
  std::uint64_t dropped_ = 0;
  CatalogueDiff catalogue_;  // what this subscriber was told about the bodies
  std::chrono::steady_clock::time_point last_sent_{};
  bool sent_any_ = false;  // the first frame (describing every body) goes whatever the rate
  // Changes only: the change clock's tick and the world's epoch of the previous frame sent, and
  // when the last full frame went.
  std::uint64_t sent_tick_ = 0, sent_epoch_ = 0;
  std::chrono::steady_clock::time_point last_full_{};
};

}  // namespace tumble::server
