// The self-intersecting triangle pairs mesh_quality counts, as a list, so
// that untangle_mesh can move the vertices that cause them
// (contour/quality.cpp).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "contour/contour.h"

namespace ldc::detail {

using TrianglePair = std::pair<uint32_t, uint32_t>;  // triangle indices, first < second

// Every pair of triangles that intersect by the rules of
// detail/triangle_intersection.h, sorted. With `hot` (one flag per
// triangle), only pairs with at least one hot triangle are tested, at a cost
// that grows with the hot triangles' neighbourhoods (plus a linear pass).
std::vector<TrianglePair> self_intersecting_pairs(const ContourMesh& mesh, const std::vector<uint8_t>* hot = nullptr);

}  // namespace ldc::detail
