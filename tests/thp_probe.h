// What the kernel says of transparent huge pages, for the tests of the
// tool's operator new and of the library's huge-page advice.
#pragma once

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

namespace ldc::test {

// The THPeligible field of the /proc/self/smaps mapping holding p, or -1.
inline int thp_eligible(const void* p) {
  std::ifstream smaps("/proc/self/smaps");
  const auto addr = reinterpret_cast<std::uintptr_t>(p);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
      inside = lo <= addr && addr < hi;
      continue;
    }
    if (inside && line.rfind("THPeligible:", 0) == 0) return std::stoi(line.substr(12));
  }
  return -1;
}

// The line of /sys/kernel/mm/transparent_hugepage/enabled ("always [madvise] never"), or "".
inline std::string thp_mode() {
  std::ifstream f("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string s;
  std::getline(f, s);
  return s;
}

}  // namespace ldc::test
