// Recoverable failures (a bad definition, a missing body) come back as a Status or Result that
// names what is wrong; programmer misuse is an assert (TUMBLE_ASSERT).
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <utility>

#define TUMBLE_ASSERT(condition) assert(condition)

namespace tumble {

class Status {
 public:
  static Status ok() { return Status(); }
  static Status error(std::string message) { return Status(std::move(message)); }

  bool is_ok() const { return !failed_; }
  explicit operator bool() const { return is_ok(); }
  const std::string& message() const { return message_; }

  // Prefixes the message with the path of the field that failed, e.g. "bodies[3]." + "size".
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
  Result(Status error) : status_(std::move(error)) { TUMBLE_ASSERT(!status_.is_ok()); }

  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  const Status& status() const { return status_; }
  const std::string& error() const { return status_.message(); }
  const T& value() const& {
    TUMBLE_ASSERT(ok());
    return *value_;
  }
  T& value() & {
    TUMBLE_ASSERT(ok());
    return *value_;
  }
  T&& value() && {
    TUMBLE_ASSERT(ok());
    return std::move(*value_);
  }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace tumble
