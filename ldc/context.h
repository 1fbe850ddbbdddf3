// Context: progress, cancellation and per-stage timers for long calls.
//
// Pass a Context* to any long-running call (nullptr is always allowed). The
// command-line tool draws its progress bar from it and reports its stage
// timers (`--json`: seconds.stages). The progress callback may be called
// from worker threads, but never concurrently with itself for one Context.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <string_view>

namespace ldc {

class Context {
 public:
  // fraction in [0, 1] of the named stage.
  using ProgressFn = std::function<void(std::string_view stage, double fraction)>;

  void set_progress(ProgressFn fn) { progress_ = std::move(fn); }

  // Request that the running call stops at its next checkpoint; it then
  // returns ErrorCode::kCancelled and leaves its outputs untouched.
  void cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }

  void report_progress(std::string_view stage, double fraction);

  // Seconds accumulated per stage name since construction or clear_timers():
  // "build.rasterize", "build.votes", "contour", "edit", "voxelize", ...
  std::map<std::string, double> timers() const;
  void add_time(const std::string& stage, double seconds);
  void clear_timers();

 private:
  ProgressFn progress_;
  std::atomic<bool> cancelled_{false};
  mutable std::mutex mutex_;
  std::map<std::string, double> timers_;
};

// Adds the wall time of a scope to ctx's timer `stage` (no-op for nullptr).
class ScopedTimer {
 public:
  ScopedTimer(Context* ctx, std::string stage)
      : ctx_(ctx), stage_(std::move(stage)), start_(std::chrono::steady_clock::now()) {}
  ~ScopedTimer() {
    if (ctx_) ctx_->add_time(stage_, seconds());
  }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  Context* ctx_;
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace ldc
