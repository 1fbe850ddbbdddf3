// The GPU texel formats of the volumetric G-buffer.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "voxelize/voxelize.h"

namespace ldc {
namespace {

// Round to nearest (halves away from zero); NaN gives 0.
uint32_t unorm8(float x) { return x > 0.0f ? uint32_t(std::min(x, 1.0f) * 255.0f + 0.5f) : 0u; }
uint32_t snorm8(float x) {
  const float c = x > 0.0f ? std::min(x, 1.0f) : x < 0.0f ? std::max(x, -1.0f) : 0.0f;
  return uint32_t(uint8_t(int8_t(int(c * 127.0f + (c >= 0.0f ? 0.5f : -0.5f)))));
}
float snorm8_value(uint32_t b) { return std::max(-1.0f, float(int8_t(uint8_t(b))) / 127.0f); }

// An unsigned float of 5 exponent bits (bias 15) and `mb` mantissa bits,
// rounded to nearest; 0 for negative and NaN, the largest finite past it.
uint32_t pack_ufloat(float value, int mb) {
  const uint32_t max_code = (30u << mb) | ((1u << mb) - 1u);
  if (!(value > 0.0f)) return 0;
  int e = 0;
  const double f = std::frexp(double(value), &e);  // value = f * 2^e, f in [0.5, 1)
  int exponent = e - 1 + 15;
  if (exponent <= 0) {  // denormal: value = mantissa * 2^(-14 - mb)
    const double mant = std::round(std::ldexp(double(value), 14 + mb));
    return std::min(uint32_t(mant), max_code);  // rounding up to 2^mb is exponent 1, mantissa 0
  }
  uint32_t mant = uint32_t(std::lround((2.0 * f - 1.0) * double(1u << mb)));
  if (mant == (1u << mb)) {
    mant = 0;
    ++exponent;
  }
  if (exponent >= 31) return max_code;
  return std::min((uint32_t(exponent) << mb) | mant, max_code);
}

float unpack_ufloat(uint32_t code, int mb) {
  const uint32_t exponent = code >> mb, mant = code & ((1u << mb) - 1u);
  if (exponent == 0) return float(std::ldexp(double(mant), -14 - mb));
  return float(std::ldexp(1.0 + double(mant) / double(1u << mb), int(exponent) - 15));
}

}  // namespace

uint32_t pack_unorm8x4(const glm::vec4& v) {
  return unorm8(v.x) | unorm8(v.y) << 8 | unorm8(v.z) << 16 | unorm8(v.w) << 24;
}

glm::vec4 unpack_unorm8x4(uint32_t b) {
  return glm::vec4(float(b & 255u), float((b >> 8) & 255u), float((b >> 16) & 255u), float(b >> 24)) / 255.0f;
}

uint32_t pack_snorm8x4(const glm::vec4& v) {
  return snorm8(v.x) | snorm8(v.y) << 8 | snorm8(v.z) << 16 | snorm8(v.w) << 24;
}

glm::vec4 unpack_snorm8x4(uint32_t b) {
  return {snorm8_value(b), snorm8_value(b >> 8), snorm8_value(b >> 16), snorm8_value(b >> 24)};
}

uint32_t pack_r11g11b10f(const glm::vec3& v) {
  return pack_ufloat(v.x, 6) | pack_ufloat(v.y, 6) << 11 | pack_ufloat(v.z, 5) << 22;
}

glm::vec3 unpack_r11g11b10f(uint32_t b) {
  return {unpack_ufloat(b & 0x7ffu, 6), unpack_ufloat((b >> 11) & 0x7ffu, 6), unpack_ufloat(b >> 22, 5)};
}

void PackedGBuffer::resize(int n, int k) {
  resolution = n;
  levels = k;
  const size_t count = texel_count();
  albedo.assign(count, 0);
  normal.assign(count, 0);
  occupancy.assign(count, 0);
  emission.assign(count, 0);
}

FaceSample PackedGBuffer::sample(int face, int level, const glm::ivec3& local) const {
  const size_t t = texel(face, level, local);
  FaceSample out;
  out.albedo = unpack_unorm8x4(albedo[t]);
  const glm::vec4 n = unpack_snorm8x4(normal[t]);
  out.normal = glm::vec3(n);
  const uint32_t flag = normal[t] >> 24;
  out.flags = flag == 127 ? kFaceOwn : flag == 64 ? kFacePropagated : 0;
  out.occupancy = float(occupancy[t]) / 255.0f;
  out.emission = unpack_r11g11b10f(emission[t]);
  return out;
}

}  // namespace ldc
