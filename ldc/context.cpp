#include "ldc/context.h"

namespace ldc {

void Context::report_progress(std::string_view stage, double fraction) {
  if (!progress_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  progress_(stage, fraction < 0.0 ? 0.0 : (fraction > 1.0 ? 1.0 : fraction));
}

std::map<std::string, double> Context::timers() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return timers_;
}

void Context::add_time(const std::string& stage, double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  timers_[stage] += seconds;
}

void Context::clear_timers() {
  std::lock_guard<std::mutex> lock(mutex_);
  timers_.clear();
}

}  // namespace ldc
