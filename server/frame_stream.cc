#include "frame_stream.h"

#include <algorithm>
#include <iterator>
#include <string>

namespace tumble::server {
namespace {

// The fields a subscription asks for, as a key of FrameData::Encodings. Subscriptions that name
// ids encode privately (their bodies differ).
std::uint32_t fields_key(const FrameOptions& options) {
  return (options.velocities ? 1u : 0u) | (options.contacts ? 2u : 0u) | (options.stats ? 4u : 0u) |
         (options.joints ? 8u : 0u);
}

std::shared_ptr<const std::string> shared_encoding(const FrameData& frame,
                                                   const FrameOptions& options) {
  const auto encode = [&] {
    v1::Frame shared;
    frame_to_proto(frame, options, &shared);
    return std::make_shared<const std::string>(shared.SerializeAsString());
  };
  if (!options.ids.empty()) return encode();
  const std::uint32_t key = fields_key(options);
  std::lock_guard lock(frame.encodings.mutex);
  for (const auto& [fields, bytes] : frame.encodings.by_fields)
    if (fields == key) return bytes;
  frame.encodings.by_fields.emplace_back(key, encode());
  return frame.encodings.by_fields.back().second;
}

// A slice over shared bytes, without copying them: the slice holds a reference until gRPC is done.
grpc::Slice slice_of(std::shared_ptr<const std::string> bytes) {
  auto* holder = new std::shared_ptr<const std::string>(std::move(bytes));
  return grpc::Slice(
      const_cast<char*>((*holder)->data()), (*holder)->size(),
      [](void* user) { delete static_cast<std::shared_ptr<const std::string>*>(user); }, holder);
}

}  // namespace

void StreamLink::frame_arrived() {
  {
    std::lock_guard lock(mutex);
    if (stream == nullptr || scheduled) return;
    scheduled = true;
  }
  hub->schedule(shared_from_this());
}

void StreamLink::offer() {
  std::lock_guard lock(mutex);
  scheduled = false;
  if (stream != nullptr) stream->offer();
}

void StreamLink::end() {
  std::lock_guard lock(mutex);
  if (stream != nullptr) stream->end();
}

StreamHub::StreamHub() {
  thread_ = std::thread([this] {
    std::unique_lock lock(mutex_);
    while (true) {
      wake_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, nothing left
      auto link = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();
      link->offer();
      lock.lock();
    }
  });
}

StreamHub::~StreamHub() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void StreamHub::schedule(std::shared_ptr<StreamLink> link) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(link));
  }
  wake_.notify_one();
}

void StreamHub::add(const std::shared_ptr<StreamLink>& link) {
  std::lock_guard lock(mutex_);
  streams_.insert(link);
}

void StreamHub::remove(const std::shared_ptr<StreamLink>& link) {
  std::lock_guard lock(mutex_);
  streams_.erase(link);
}

void StreamHub::end_all() {
  std::vector<std::shared_ptr<StreamLink>> links;
  {
    std::lock_guard lock(mutex_);
    links.assign(streams_.begin(), streams_.end());
  }
  for (const auto& link : links)
    link->end();
}

FrameStream::FrameStream(StreamHub& hub, WorldHost& host, const ReadRequest& read, CallGate* gate,
                         std::size_t max_bytes, const std::string& method)
    : RequestReader(gate, max_bytes, method), hub_(hub), host_(host), read_(read) {}

void FrameStream::on_request(std::string bytes) {
  double max_rate = 0;
  const grpc::Status refused = read_(bytes, &options_, &max_rate);
  done_with_request();  // a stream holds its options, not its request
  if (!refused.ok()) {
    Finish(refused);
    return;
  }
  min_interval_ = std::chrono::duration<double>(max_rate > 0 ? 1 / max_rate : 0.0);
  {
    std::lock_guard lock(mutex_);
    started_ = true;
    mailbox_ = host_.subscribe();
    link_ = std::make_shared<StreamLink>();
    link_->hub = &hub_;
    link_->stream = this;
  }
  hub_.add(link_);
  mailbox_->set_listener(link_);
  link_->frame_arrived();  // the host's newest frame is already waiting
}

void FrameStream::offer() {
  std::lock_guard lock(mutex_);
  if (writing_ || finishing_) return;
  auto delivery = mailbox_->take(std::chrono::milliseconds(0));
  if (!delivery) return;
  dropped_ += delivery->dropped;
  const auto now = std::chrono::steady_clock::now();
  if (sent_any_ && now - last_sent_ < min_interval_) {
    ++dropped_;  // over this subscriber's rate; the next step brings a newer frame
    return;
  }
  encode(*delivery->frame, dropped_);
  dropped_ = 0;
  last_sent_ = now;
  sent_any_ = true;
  writing_ = true;
  StartWrite(&buffer_);
}

void FrameStream::encode(const FrameData& data, std::uint64_t dropped) {
  v1::Frame own;
  own.set_dropped(dropped);
  // Bodies new to this subscriber get their descriptions; vanished ones are listed.
  catalogue_.add_changes(data, options_.ids, &own);
  if (options_.joints) catalogue_.add_joint_changes(data, &own);
  // Changes only: the bodies changed since the tick of this subscriber's previous frame (frames
  // dropped between are covered: a body keeps the tick of its last change). Every body when it
  // joins, when the world was replaced, and at the interval it asked for.
  const auto now = std::chrono::steady_clock::now();
  const bool full =
      !options_.changes_only || !sent_any_ || data.epoch != sent_epoch_ ||
      (options_.full_frame_interval > 0 &&
       now - last_full_ >= std::chrono::duration<double>(options_.full_frame_interval));
  std::shared_ptr<const std::string> bodies;
  if (full) {
    bodies = shared_encoding(data, options_);
    last_full_ = now;
  } else {
    v1::Frame changed;
    frame_to_proto(data, options_, &changed, sent_tick_);
    bodies = std::make_shared<const std::string>(changed.SerializeAsString());
  }
  sent_tick_ = data.change_clock;
  sent_epoch_ = data.epoch;
  grpc::Slice parts[2] = {slice_of(std::move(bodies)), grpc::Slice(own.SerializeAsString())};
  buffer_ = grpc::ByteBuffer(parts, 2);
}

void FrameStream::OnWriteDone(bool ok) {
  {
    std::lock_guard lock(mutex_);
    writing_ = false;
    if (!ok) finishing_ = true;  // the client went away
    if (finishing_) {
      finish_locked(ok ? final_status_ : grpc::Status::OK);
      return;
    }
  }
  offer();
}

void FrameStream::end() {
  std::lock_guard lock(mutex_);
  // Before the request is read, the read itself ends the call (a cancelled read fails).
  if (!started_) return;
  finishing_ = true;
  final_status_ = grpc::Status::OK;
  if (!writing_) finish_locked(final_status_);
}

void FrameStream::on_cancel() {
  end();
}

void FrameStream::finish_locked(const grpc::Status& status) {
  if (finished_) return;
  finished_ = true;
  Finish(status);
}

void FrameStream::OnDone() {
  if (link_ != nullptr) {
    {
      std::lock_guard lock(link_->mutex);
      link_->stream = nullptr;
    }
    host_.unsubscribe(mailbox_);
    hub_.remove(link_);
  }
  delete this;
}

}  // namespace tumble::server
