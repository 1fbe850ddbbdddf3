// Checks and messages for 3-vectors that every module's input checks share.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include <glm/glm.hpp>

namespace ldc::detail {

inline bool is_finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// A number with %g, for error messages.
inline std::string number_g(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", x);
  return buffer;
}

// "(x, y, z)" with %g, for error messages.
inline std::string vec_text(const glm::dvec3& v) {
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), "(%g, %g, %g)", v.x, v.y, v.z);
  return buffer;
}

// "(x, y, z)" for chunk coordinates in messages. snprintf: GCC 12 warns
// (-Wrestrict, a false positive) on "(" + std::to_string(...).
inline std::string chunk_text(const glm::ivec3& c) {
  char buffer[48];
  std::snprintf(buffer, sizeof(buffer), "(%d, %d, %d)", c.x, c.y, c.z);
  return buffer;
}

// A map key for the chunk coordinates of a checked source layout: they lie
// within +-2^17 (C >= 8, nodes within +-2^20), so 21 bits per axis with a
// bias of 2^20 hold them.
inline uint64_t source_chunk_key(const glm::ivec3& c) {
  constexpr int64_t kBias = int64_t{1} << 20;
  return uint64_t(c.x + kBias) | uint64_t(c.y + kBias) << 21 | uint64_t(c.z + kBias) << 42;
}

}  // namespace ldc::detail
