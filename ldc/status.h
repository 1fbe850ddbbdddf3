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

namespace detail {
// Prints "ldc: <what> on an error Result: <status>" to stderr and aborts, in
// every build (NDEBUG or not): reading the value of a failed call is a bug in
// the caller, and undefined behaviour would hide it.
[[noreturn]] void abort_on_error_result(const Status& status, const char* what);
}  // namespace detail

// Either a value or an error Status.
//
//   Result<World> w = load_world("a.ldc");
//   if (!w) return w.status();      // explicit operator bool: ok()
//   use(*w); w->chunk_size();       // the value, as with std::optional
//
// Reading the value of an error (value(), *, ->) aborts with the status
// message in every build; value_or() gives a fallback instead. A Result made
// from an ok Status (a bug in the callee) holds the error kInternal.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  Result(Status status) : status_(std::move(status)) {  // NOLINT
    if (status_.ok()) status_ = Status(ErrorCode::kInternal, "a Result was made from an ok Status without a value");
  }

  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  const Status& status() const { return status_; }

  T& value() & { return checked("value()"); }
  const T& value() const& { return checked("value()"); }
  T&& value() && { return std::move(checked("value()")); }
  T& operator*() & { return checked("operator*"); }
  const T& operator*() const& { return checked("operator*"); }
  T&& operator*() && { return std::move(checked("operator*")); }
  T* operator->() { return &checked("operator->"); }
  const T* operator->() const { return &checked("operator->"); }

  // The value, or `fallback` when this holds an error.
  template <class U>
  T value_or(U&& fallback) const& {
    return ok() ? *value_ : static_cast<T>(std::forward<U>(fallback));
  }
  template <class U>
  T value_or(U&& fallback) && {
    return ok() ? std::move(*value_) : static_cast<T>(std::forward<U>(fallback));
  }

 private:
  T& checked(const char* what) {
    if (!value_) detail::abort_on_error_result(status_, what);
    return *value_;
  }
  const T& checked(const char* what) const {
    if (!value_) detail::abort_on_error_result(status_, what);
    return *value_;
  }

  std::optional<T> value_;
  Status status_;
};

}  // namespace ldc
