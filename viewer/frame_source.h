// Where the viewer's frames come from: a running server (a stream, reopened after the server is
// lost; the world can be played, paused and stepped), or a recording (tumble record, or
// tumble-server --record), played at its recorded pace and then held on its last frame.
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "client.h"
#include "recording.h"

namespace tumble::viewer {

using wire::Result;
using wire::Status;

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Starts over: the next frames describe every body again.
  virtual void open() = 0;
  // The next frame; false when there is none (the server was lost, the recording ended, or
  // cancel() was called).
  virtual bool next(v1::Frame* frame) = 0;
  // Ends a next() waiting on another thread; safe from any thread.
  virtual void cancel() = 0;
  // Why the frames stopped (OK: the stream or the file ended).
  virtual Status finish() = 0;
  // A recording ends for good; a server may come back.
  virtual bool reopens() const = 0;
  // Play, pause or step the world, where there is one to control.
  virtual void control(const v1::ControlRequest& request) = 0;
};

class ServerSource final : public FrameSource {
 public:
  ServerSource(client::Client& client, bool contacts, bool joints)
      : client_(client), contacts_(contacts), joints_(joints) {}
  void open() override;
  bool next(v1::Frame* frame) override;
  void cancel() override;
  Status finish() override;
  bool reopens() const override { return true; }
  void control(const v1::ControlRequest& request) override { client_.control(request); }

 private:
  client::Client& client_;
  bool contacts_, joints_;
  std::mutex mutex_;
  std::optional<client::FrameStream> stream_;
  bool cancelled_ = false;
};

class RecordingSource final : public FrameSource {
 public:
  // `paced`: at the recorded simulated-time pace (a window), or as fast as read (pictures).
  static Result<std::unique_ptr<RecordingSource>> open_file(const std::string& path, bool paced);
  void open() override;
  bool next(v1::Frame* frame) override;
  void cancel() override;
  Status finish() override;
  bool reopens() const override { return false; }
  void control(const v1::ControlRequest&) override {}  // a recording is what it is

 private:
  RecordingSource(std::string path, bool paced) : path_(std::move(path)), paced_(paced) {}
  std::string path_;
  bool paced_;
  std::optional<client::RecordingReader> reader_;
  Status status_ = Status::ok();
  double first_time_ = -1;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  bool cancelled_ = false;
};

}  // namespace tumble::viewer
