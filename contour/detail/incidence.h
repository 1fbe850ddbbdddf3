// Triangles around each vertex, built with a counting sort (linear): what
// mesh_quality reads topology from and untangle_mesh moves vertices by.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "contour/contour.h"

namespace ldc::detail {

// Triangles around each vertex: triangle[offset[v] .. offset[v + 1]).
// Triangles with an index out of range or a repeated index are left out.
struct Incidence {
  std::vector<size_t> offset;
  std::vector<uint32_t> triangle;
};

Incidence incidence(const ContourMesh& mesh);

}  // namespace ldc::detail
