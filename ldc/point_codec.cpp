// Octahedral normal encoding (Cigolle et al. 2014, "A Survey of Efficient
// Representations for Independent Unit Vectors"), 15 bits per component.
#include <algorithm>
#include <cmath>

#include "ldc/world.h"

namespace ldc {
namespace {

constexpr int kOctBits = kNormalOctBits;
constexpr uint32_t kOctMax = (1u << kOctBits) - 1;  // 32767 (decode_normal, world.h, reads the same)

double sign_not_zero(double v) { return v >= 0.0 ? 1.0 : -1.0; }

// Unit vector -> octahedral square [-1, 1]^2.
glm::dvec2 to_oct(const glm::dvec3& n) {
  double l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  glm::dvec2 p(n.x / l1, n.y / l1);
  if (n.z < 0.0) {
    p = glm::dvec2((1.0 - std::abs(p.y)) * sign_not_zero(p.x),
                   (1.0 - std::abs(p.x)) * sign_not_zero(p.y));
  }
  return p;
}

}  // namespace

uint32_t encode_normal(const glm::dvec3& unit_normal) {
  glm::dvec3 n = unit_normal;
  double l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  if (!(l1 > 0.0) || !std::isfinite(l1)) n = glm::dvec3(0, 0, 1);
  glm::dvec2 p = to_oct(n);
  // Rounding to the nearest code: at 15 bits the error stays below 0.02 degrees
  // (tests/test_world.cpp measures it), so no search among neighbours.
  auto quantize = [](double v) {
    return static_cast<uint32_t>(std::lround(std::clamp((v + 1.0) * 0.5 * kOctMax, 0.0, double(kOctMax))));
  };
  return quantize(p.x) | (quantize(p.y) << kOctBits);
}

SurfacePoint decode_point(const PackedPoint& p, int chunk_size, int segment_start) {
  SurfacePoint out;
  out.depth = segment_start + static_cast<double>(p.depth) / depth_steps_per_cell(chunk_size);
  out.normal = decode_normal(p.normal);
  out.material = p.material;
  out.enter = p.enters();
  return out;
}

}  // namespace ldc
