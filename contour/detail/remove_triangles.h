// Removing triangles from a ContourMesh and the vertices they leave unused:
// what simplify_mesh and untangle_mesh (specks) finish with.
#pragma once

#include <cstdint>
#include <vector>

#include "contour/contour.h"

namespace ldc::detail {

// Removes the triangles whose `gone` is set (one flag per triangle), then
// every vertex no triangle uses. Triangles and vertices left keep their
// order; triangle materials, normals and vertex materials follow (those
// arrays that have one entry per triangle or vertex).
void remove_triangles(ContourMesh& mesh, const std::vector<uint8_t>& gone);

}  // namespace ldc::detail
