// The cell of a uniform grid that holds a point, clamped into the grid: the
// one mapping the self-intersection grids of mesh_quality and simplify_mesh
// share. Monotone in each coordinate, so a point inside a box falls in one of
// the box's cells.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

namespace ldc::detail {

inline glm::ivec3 clamped_grid_cell(const glm::dvec3& p, const glm::dvec3& origin, double size,
                                    const glm::ivec3& dims) {
  glm::ivec3 c;
  for (int k = 0; k < 3; ++k) {
    const double x = std::floor((p[k] - origin[k]) / size);
    c[k] = x <= 0.0 ? 0 : x >= dims[k] - 1 ? dims[k] - 1 : static_cast<int>(x);
  }
  return c;
}

}  // namespace ldc::detail
