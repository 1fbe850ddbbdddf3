// OpenVDB export of voxel grids (library ldc::voxelize_vdb, linked by the
// tests and the benchmarks; the tool loads it through the plugin ldc-vdb.so,
// vdb_plugin.cpp, only to write a .vdb file). OpenVDB's headers stay in vdb.cpp.
//
// Each grid becomes three OpenVDB grids that DCC tools (Houdini, Blender)
// open: "occupancy" (FloatGrid, fog volume: the volume fraction, active where
// > 0), "normal" (Vec3SGrid: the surface voxels' mean face normal, weighted by
// the faces' surface weights) and "albedo" (Vec3SGrid: the same mean of the
// face albedos). Index (i, j, k) is global voxel (i, j, k); the transform maps
// it to the voxel's centre: origin + voxel_size * (i + 1/2, j + 1/2, k + 1/2).
// Grid metadata: "voxel_size", "ldc_source".
#pragma once

#include <string>
#include <vector>

#include "ldc/status.h"
#include "voxelize/voxelize.h"

namespace ldc {

struct VdbGridSet {
  const VoxelGrid* grid = nullptr;
  std::string suffix;  // appended to the grid names ("_L0" for cascade level 0)
};

// Writes the grids (normal and albedo only for grids with faces) into one
// .vdb file. Errors name the file; no exception leaves.
Status save_vdb(const std::vector<VdbGridSet>& grids, const std::string& path, const std::string& source = "");
Status save_vdb(const VoxelGrid& grid, const std::string& path, const std::string& source = "");
// Every valid level as occupancy_L<k>, normal_L<k>, albedo_L<k>.
Status save_vdb(const Cascades& cascades, const std::string& path, const std::string& source = "");

}  // namespace ldc
