// The z-up frame rotated onto another up axis (render/render.h, "Up").
#pragma once

#include <glm/glm.hpp>

namespace ldc::detail {

// v given in a z-up world, in the world whose up is `axis` (0 x, 1 y, 2 z):
// the axes cycled (x -> y -> z -> x) until z lands on `axis`; a rotation,
// and exact (a permutation of the components).
template <typename T>
glm::vec<3, T> from_z_up(const glm::vec<3, T>& v, int axis) {
  glm::vec<3, T> out;
  for (int k = 0; k < 3; ++k) out[(axis + 1 + k) % 3] = v[k];
  return out;
}

// The inverse: v of the world whose up is `axis`, in the z-up world.
template <typename T>
glm::vec<3, T> to_z_up(const glm::vec<3, T>& v, int axis) {
  glm::vec<3, T> out;
  for (int k = 0; k < 3; ++k) out[k] = v[(axis + 1 + k) % 3];
  return out;
}

}  // namespace ldc::detail
