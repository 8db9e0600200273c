// Failures on the clients' side of the wire (the client library, recordings, the CLI, the viewer):
// a Status or Result that names what is wrong. Their own type, header-only, so that a program that
// only talks to a server or reads recordings does not link the engine; the engine and the server
// keep physics/status.h, and the server converts where the two meet (its recorder).
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <utility>

namespace tumble::wire {

class Status {
 public:
  static Status ok() { return Status(); }
  static Status error(std::string message) { return Status(std::move(message)); }

  bool is_ok() const { return !failed_; }
  explicit operator bool() const { return is_ok(); }
  const std::string& message() const { return message_; }
  // Prefixes the message with where it happened ("recording.mcap: ").
  Status within(const std::string& prefix) const {
    return is_ok() ? *this : Status(prefix + message_);
  }

 private:
  Status() = default;
  explicit Status(std::string message) : failed_(true), message_(std::move(message)) {}
  bool failed_ = false;
  std::string message_;
};

template <class T>
class Result {
 public:
  Result(T value) : value_(std::move(value)), status_(Status::ok()) {}
  Result(Status error) : status_(std::move(error)) { assert(!status_.is_ok()); }

  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  const Status& status() const { return status_; }
  const std::string& error() const { return status_.message(); }
  const T& value() const& { return checked(), *value_; }
  T& value() & { return checked(), *value_; }
  T&& value() && { return checked(), std::move(*value_); }

 private:
  void checked() const { assert(ok() && "the value of a failed Result"); }
  std::optional<T> value_;
  Status status_;
};

}  // namespace tumble::wire

namespace tumble::client {
using wire::Result;
using wire::Status;
}  // namespace tumble::client
