// Status and Result: how every fallible ldc call reports failure.
//
// No exceptions cross the public API. A call that can fail returns a Status
// (or a Result<T> holding either a value or a Status). The message names what
// was wrong in terms a user can act on: the file, the line, the value.
// Status and Result are plain values (copyable, movable, thread-compatible).
// The C API (capi/ldc.h) maps ErrorCode n to ldc_status n.
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace ldc {

enum class ErrorCode {
  kOk = 0,
  kInvalidArgument,  // a config value or argument out of its documented range
  kParseError,       // a text or binary file does not follow its format
  kIoError,          // a file could not be opened, read or written
  kCorruptData,      // checksum mismatch, inconsistent counts, hostile input
  kTooLarge,         // the request would not fit in the configured limits
  kUnsupported,      // a valid request the library does not handle (yet)
  kCancelled,        // stopped through Context::cancel
  kInternal,         // a broken invariant inside ldc: a bug, please report
};

const char* error_code_name(ErrorCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status ok_status() { return {}; }

  bool ok() const { return code_ == ErrorCode::kOk; }
  ErrorCode code() const { return code_; }
  const std::string& message() const { return message_; }
  // "parse error: bunny.obj:12: face index 40000 out of range (file has 35947 vertices)"
  std::string to_string() const;

 private:
  ErrorCode code_ = ErrorCode::kOk;
  std::string message_;
};

// Either a value or an error Status. Access to value() on an error is a bug (asserts).
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  Result(Status status) : status_(std::move(status)) {}  // NOLINT

  bool ok() const { return value_.has_value(); }
  const Status& status() const { return status_; }
  T& value() & { return *value_; }
  const T& value() const& { return *value_; }
  T&& value() && { return std::move(*value_); }
  T* operator->() { return &*value_; }
  const T* operator->() const { return &*value_; }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace ldc
