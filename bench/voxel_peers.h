// OpenVDB's solid voxelization (the peer of bench_voxelize), behind a plain
// interface so that OpenVDB's headers stay in voxel_peers.cpp (built with
// NDEBUG, as shared/PEERS.md measured it).
#pragma once

#include <cstddef>

#include <glm/glm.hpp>

#include "ldc/mesh.h"

namespace ldc::bench {

struct VdbSolidResult {
  size_t occupied = 0;       // inside voxels of the dense grid
  size_t level_set_voxels = 0;
  double level_set_ms = 0.0, mask_ms = 0.0, dense_ms = 0.0;
  double total_ms() const { return level_set_ms + mask_ms + dense_ms; }
};

// meshToLevelSet (half width 3) + sdfInteriorMask + copyToDense into a dense
// uint8 array of `dims` voxels of size s whose voxel (0,0,0) has its low corner at lo.
VdbSolidResult vdb_solid_occupancy(const TriangleMesh& mesh, double s, const glm::dvec3& lo, const glm::ivec3& dims);

}  // namespace ldc::bench
