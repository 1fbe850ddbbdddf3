// Index arithmetic and bit tricks shared by the world, builders and validate().
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "ldc/world.h"

namespace ldc::detail {

constexpr int floor_div(int a, int b) {
  int q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}
constexpr int64_t floor_div64(int64_t a, int64_t b) {
  int64_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}
constexpr int floor_mod(int a, int b) { return a - floor_div(a, b) * b; }

// Index of the ray of `axis` through `node` within its chunk's family.
inline int ray_index(const glm::ivec3& node, int axis, int chunk_size) {
  int u = floor_mod(node[axis_u(axis)], chunk_size);
  int v = floor_mod(node[axis_v(axis)], chunk_size);
  return v * chunk_size + u;
}

// Lattice position of a point stored in chunk `chunk`, family `axis`, ray `ray`.
inline glm::dvec3 point_lattice_position(const glm::ivec3& chunk, int axis, int ray,
                                         uint16_t depth, int chunk_size) {
  glm::dvec3 q;
  q[axis] = double(chunk[axis]) * chunk_size + double(depth) / depth_steps_per_cell(chunk_size);
  q[axis_u(axis)] = double(chunk[axis_u(axis)]) * chunk_size + (ray % chunk_size);
  q[axis_v(axis)] = double(chunk[axis_v(axis)]) * chunk_size + (ray / chunk_size);
  return q;
}

// Bit n of the result = XOR of bits 0..n of x.
inline uint64_t prefix_xor(uint64_t x) {
  x ^= x << 1;
  x ^= x << 2;
  x ^= x << 4;
  x ^= x << 8;
  x ^= x << 16;
  x ^= x << 32;
  return x;
}

// Node-inside word of one ray segment: bit n is set when node n (local) is
// inside. Points are never on nodes, so node n follows the points with
// depth < n*Q.
template <class PointRange>
uint64_t node_word(bool starts_inside, const PointRange& points, int chunk_size) {
  const uint32_t q = depth_steps_per_cell(chunk_size);
  uint64_t toggles = 0;
  for (const auto& p : points) {
    uint32_t next_node = p.depth / q + 1;  // first node after the point
    if (next_node < static_cast<uint32_t>(chunk_size)) toggles ^= uint64_t{1} << next_node;
  }
  uint64_t word = prefix_xor(toggles);
  if (starts_inside) word = ~word;
  return chunk_size == 64 ? word : word & ((uint64_t{1} << chunk_size) - 1);
}

// In-place transpose of a 64x64 bit matrix: bit c of row r <-> bit r of row c.
inline void transpose64(uint64_t* m) {
  uint64_t mask = 0x00000000FFFFFFFFull;
  for (int j = 32; j != 0; j >>= 1, mask ^= (mask << j)) {
    for (int k = 0; k < 64; k = ((k | j) + 1) & ~j) {
      uint64_t t = ((m[k] >> j) ^ m[k | j]) & mask;
      m[k] ^= t << j;
      m[k | j] ^= t;
    }
  }
}

// In-place transpose of a 32x32 bit matrix (rows in the low 32 bits).
inline void transpose32(uint32_t* m) {
  uint32_t mask = 0x0000FFFFu;
  for (int j = 16; j != 0; j >>= 1, mask ^= (mask << j)) {
    for (int k = 0; k < 32; k = ((k | j) + 1) & ~j) {
      uint32_t t = ((m[k] >> j) ^ m[k | j]) & mask;
      m[k] ^= t << j;
      m[k | j] ^= t;
    }
  }
}

// Transposes the c x c bit matrix in m[0..c) (c <= 64), zero-padded.
inline void transpose_bits(uint64_t* m, int c) {
  if (c > 32) return transpose64(m);
  uint32_t s[32] = {};
  for (int i = 0; i < c; ++i) s[i] = uint32_t(m[i]);
  transpose32(s);
  for (int i = 0; i < c; ++i) m[i] = s[i];
}

// Node words of a family: family[v*c + u] has bit n for node n along the axis.
// The X layout xl[z*64 + y] has bit x. Converts family -> X layout
// (to_family = false) or back (true); the other array must hold c*64 words.
inline void convert_layout(int axis, int c, const uint64_t* in, uint64_t* out, bool to_family) {
  if (axis == 0) {  // X rays are (y, z): the layouts differ only in row stride
    for (int z = 0; z < c; ++z)
      for (int y = 0; y < c; ++y) {
        if (to_family) out[size_t(z) * c + y] = in[size_t(z) * 64 + y];
        else out[size_t(z) * 64 + y] = in[size_t(z) * c + y];
      }
    return;
  }
  // Y rays (z, x): fam[x*c + z]; for fixed z the rows x transpose into rows y.
  // Z rays (x, y): fam[y*c + x]; for fixed y the rows x transpose into rows z.
  const size_t fam_stride = axis == 1 ? size_t(c) : 1, fam_fixed = axis == 1 ? 1 : size_t(c);
  const size_t xl_stride = axis == 1 ? 1 : 64, xl_fixed = axis == 1 ? 64 : 1;
  uint64_t m[64];
  for (int fixed = 0; fixed < c; ++fixed) {
    const size_t fam0 = fixed * fam_fixed, xl0 = fixed * xl_fixed;
    if (to_family) {
      for (int i = 0; i < c; ++i) m[i] = in[xl0 + i * xl_stride];
      transpose_bits(m, c);
      for (int i = 0; i < c; ++i) out[fam0 + i * fam_stride] = m[i];
    } else {
      for (int i = 0; i < c; ++i) m[i] = in[fam0 + i * fam_stride];
      transpose_bits(m, c);
      for (int i = 0; i < c; ++i) out[xl0 + i * xl_stride] = m[i];
    }
  }
}
}  // namespace ldc::detail
