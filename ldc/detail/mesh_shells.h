// The surface reading of build_from_mesh (BuildConfig, ldc/build.h): which
// connected components are solids, and thin closed prisms for the rest.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "ldc/build.h"

namespace ldc::detail {

struct MeshComponents {
  std::vector<uint32_t> of_triangle;  // component of each triangle; kNone for degenerate ones
  std::vector<uint8_t> closed;        // per component: every edge balanced
  std::vector<double> volume;         // per component: signed volume [m^3]
  std::vector<double> area;           // per component [m^2]
  size_t boundary_edges = 0;          // edges used once, over the whole mesh
  static constexpr uint32_t kNone = UINT32_MAX;
  size_t count() const { return closed.size(); }
};

// Components joined by shared welded vertices; welded_id maps each input
// vertex to its welded vertex (equal snapped positions).
MeshComponents mesh_components(const TriangleMesh& mesh, const std::vector<uint32_t>& welded_id,
                               size_t welded_count);

// Whether component c is read as a solid under `mode` with shells of
// `thickness` m: closed, outward-facing and more than half a shell thick
// (a slab of thickness w has volume area * w / 2).
bool reads_as_solid(const MeshComponents& components, size_t c, BuildMode mode, double thickness);

// The mesh the rasterizer reads: solid components' triangles as they are,
// every other non-degenerate triangle as a closed prism of `thickness` below
// it (away from `up_axis`). Counts go into the report.
TriangleMesh shelled_mesh(const TriangleMesh& mesh, const MeshComponents& components,
                          BuildMode mode, double thickness, int up_axis, BuildReport& report);

}  // namespace ldc::detail
