// The snapped triangle mesh and the rasterizer that turns it into span lists.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/build.h"
#include "ldc/detail/exact.h"
#include "ldc/world.h"

namespace ldc::detail {

using Vec3i = std::array<int64_t, 3>;

// Vertices in fixed-point lattice coordinates, welded; non-degenerate triangles only.
struct SnappedMesh {
  std::vector<Vec3i> vertices;
  // The input positions of the welded vertices in the same fixed-point units,
  // before rounding: depths are computed from these (snapping moves a crossing
  // far along a ray that grazes the surface), decisions from `vertices`.
  std::vector<glm::dvec3> unsnapped;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<uint16_t> material;
  std::vector<uint32_t> normal_code;   // outward (as wound) normal, octahedral
  std::vector<uint8_t> normal_positive;  // bit a: normal component a > 0
  std::vector<std::array<int64_t, 6>> box;  // min x, y, z, max x, y, z of each triangle

  void resize(size_t n);
  // Sets triangle i; safe to call for different i from several threads.
  void set_triangle(size_t i, const std::array<uint32_t, 3>& t, const std::array<i128, 3>& n,
                    uint16_t mat);
};

// Stage 1 of build_from_mesh: vertices to the lattice's fixed point, welded
// where equal; welded_id maps input vertices to welded ones. Fills
// `vertices` and `unsnapped` of `out`.
Status snap_vertices(const TriangleMesh& mesh, const Lattice& lat, SnappedMesh& out,
                     std::vector<uint32_t>& welded_id);

// (B - A) x (C - A), exact.
std::array<i128, 3> triangle_normal(const std::vector<Vec3i>& v, const std::array<uint32_t, 3>& t);

// Stages 2-4 of build_from_mesh: fills every chunk of `world` (whose lattice the
// mesh was snapped to). Updates the report's crossing and repair counts.
Status rasterize_mesh_into(const SnappedMesh& mesh, World& world, Context* ctx,
                           BuildReport& report);

}  // namespace ldc::detail
