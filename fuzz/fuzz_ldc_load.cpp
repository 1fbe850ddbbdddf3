// libFuzzer target: .ldc bytes -> deserialize_world. A file the loader accepts
// must be a valid world; one it refuses must say why. Never a crash.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "ldc/io.h"
#include "ldc/world.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ldc::LoadLimits limits;
  limits.max_chunk_raw_bytes = size_t{4} << 20;  // keep the fuzzer within memory
  limits.max_total_raw_bytes = size_t{64} << 20;
  std::string_view bytes(reinterpret_cast<const char*>(data), size);
  ldc::Result<ldc::World> w = ldc::deserialize_world(bytes, "fuzz", limits);
  if (w.ok()) {
    ldc::ValidationReport r = ldc::validate(w.value());
    if (!r.ok) {
      std::fprintf(stderr, "accepted an invalid world: %s\n", r.summary().c_str());
      std::abort();
    }
  } else if (w.status().message().empty()) {
    std::abort();
  }
  return 0;
}
