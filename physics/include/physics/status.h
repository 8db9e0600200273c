// Recoverable failures (a bad definition, a missing body) come back as a Status or Result that
// names what is wrong; programmer misuse is an assert (TUMBLE_ASSERT).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

namespace tumble {
// Prints what failed and where, then aborts.
[[noreturn]] void internal_check_failed(const char* condition, const char* file, int line);
}  // namespace tumble

// Programmer misuse and broken invariants. On in Debug and RelWithDebInfo, and so in the sanitizer
// builds, whatever NDEBUG says (CMake defines TUMBLE_ASSERTS=1 for those); off in Release, where
// the step's cost is measured. The condition is not evaluated when off.
#if TUMBLE_ASSERTS
#define TUMBLE_ASSERT(condition) \
  ((condition) ? void(0) : ::tumble::internal_check_failed(#condition, __FILE__, __LINE__))
#else
#define TUMBLE_ASSERT(condition) ((void)sizeof(!(condition)))
#endif

namespace tumble {

// What kind of failure, so that a caller (the server's one mapping to gRPC codes) can answer
// without reading the message.
enum class StatusCode : std::uint8_t {
  kOk,
  kInvalidArgument,    // a value is wrong: the message names the field
  kNotFound,           // an id that names nothing
  kResourceExhausted,  // more than a configured capacity allows
  kUnavailable,        // shutting down
  kInternal,           // a broken invariant: a bug of ours
};

class Status {
 public:
  static Status ok() { return Status(); }
  static Status error(std::string message, StatusCode code = StatusCode::kInvalidArgument) {
    return Status(std::move(message), code);
  }
  static Status not_found(std::string message) {
    return Status(std::move(message), StatusCode::kNotFound);
  }

  bool is_ok() const { return code_ == StatusCode::kOk; }
  explicit operator bool() const { return is_ok(); }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }

  // Prefixes the message with the path of the field that failed, e.g. "bodies[3]." + "size".
  Status within(const std::string& prefix) const {
    return is_ok() ? *this : Status(prefix + message_, code_);
  }

 private:
  Status() = default;
  Status(std::string message, StatusCode code) : code_(code), message_(std::move(message)) {
    TUMBLE_ASSERT(code != StatusCode::kOk);
  }
  StatusCode code_ = StatusCode::kOk;
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
