// Helpers shared by the tests.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "contour/contour.h"
#include "ldc/build.h"
#include "ldc/mesh.h"
#include "ldc/world.h"

namespace ldc::test {

// Absolute path of a file in tests/data.
std::string data_path(const std::string& name);

// Loads tests/data/<name>; fails the calling test (ADD_FAILURE) and returns an
// empty mesh when it cannot.
TriangleMesh load_test_mesh(const std::string& name);

// Axis-aligned box [lo, hi] as 12 outward triangles.
TriangleMesh box_mesh(const glm::dvec3& lo, const glm::dvec3& hi);

// Icosphere with `subdivisions` levels (0 = icosahedron), outward.
TriangleMesh sphere_mesh(const glm::dvec3& centre, double radius, int subdivisions);

// A grid whose origin is (0,0,0) and cell size h, so lattice planes sit at
// multiples of h; chunks of 16 cells.
GridConfig lattice_at_origin(double h);

// Appends b's triangles (and positions) to a.
void append_mesh(TriangleMesh& a, const TriangleMesh& b);

// Fails the test with the report's messages unless validate() passes.
::testing::AssertionResult is_valid(const World& world);

// Chunk meshes equal: the same chunks, own vertices (in order), vertex data
// per cell, and triangles by their cells (the order of copies and triangles
// may differ: an incremental update and a fresh build agree up to that).
::testing::AssertionResult same_chunk_meshes(const ChunkedMesh& a, const ChunkedMesh& b);

// A mesh's triangles as their corners' positions, each turned to start at its
// smallest corner, sorted: equal for two meshes with the same triangles
// whatever their vertex numbering and order.
using TrianglePositions = std::array<glm::dvec3, 3>;
std::vector<TrianglePositions> sorted_triangle_positions(const ContourMesh& mesh);
// Their order: by corners, each by x, y, z.
bool triangle_positions_less(const TrianglePositions& a, const TrianglePositions& b);

}  // namespace ldc::test
