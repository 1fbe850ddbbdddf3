// Static polygon objects as voxel sources: the object's mesh built into an
// LDC of cell size s / 16 on the landscape's lattice origin.
#pragma once

#include "ldc/world.h"
#include "voxelize/detail/block.h"
#include "voxelize/voxelize.h"

namespace ldc::detail {

inline constexpr int kObjectSupersampling = 16;

struct ObjectWorld {
  World world;
  VoxelBox voxels;  // the voxels (of size s) the object's bounds touch
  int material_offset = 0;  // added to the ids its points hold (material_base)
};

// The object's world-space bounds (transformed vertices).
WorldBox object_bounds(const StaticObject& object);
// Voxels of size s (on the lattice origin) that a world box touches.
VoxelBox voxels_of_box(const WorldBox& box, const glm::dvec3& origin, double voxel_size);

Result<ObjectWorld> build_object_world(const StaticObject& object, const glm::dvec3& origin, double voxel_size,
                                       Context* ctx);

// The voxel source reading an object world (m = 16).
VoxelSource object_source(const ObjectWorld& object, const MaterialTable& materials, int occ_axis);

}  // namespace ldc::detail
