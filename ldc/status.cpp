#include "ldc/status.h"

#include <cstdio>
#include <cstdlib>

namespace ldc {

const char* error_code_name(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk: return "ok";
    case ErrorCode::kInvalidArgument: return "invalid argument";
    case ErrorCode::kParseError: return "parse error";
    case ErrorCode::kIoError: return "i/o error";
    case ErrorCode::kCorruptData: return "corrupt data";
    case ErrorCode::kTooLarge: return "too large";
    case ErrorCode::kUnsupported: return "unsupported";
    case ErrorCode::kCancelled: return "cancelled";
    case ErrorCode::kInternal: return "internal error";
  }
  return "unknown error";
}

std::string Status::to_string() const {
  if (ok()) return "ok";
  return std::string(error_code_name(code_)) + ": " + message_;
}

namespace detail {

void abort_on_error_result(const Status& status, const char* what) {
  std::fprintf(stderr, "ldc: %s on an error Result: %s\n", what, status.to_string().c_str());
  std::fflush(stderr);
  std::abort();
}

}  // namespace detail

}  // namespace ldc
