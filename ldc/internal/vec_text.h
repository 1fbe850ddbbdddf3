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

}  // namespace ldc::detail
