// What the dense voxelizer and the cascades share: the prepared sources
// (landscape and static objects), per-thread scratch and the block loop.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "voxelize/detail/block.h"
#include "voxelize/detail/objects.h"
#include "voxelize/voxelize.h"

namespace ldc::detail {

struct PreparedSources {
  VoxelSource land;
  std::vector<std::unique_ptr<ObjectWorld>> objects;
};

// Checks the config and materials and builds the objects' LDCs at the voxel size.
Result<PreparedSources> prepare_sources(const World& world, const VoxelConfig& config, const MaterialTable& materials,
                                        std::span<const StaticObject> objects, Context* ctx);

struct ObjectRef {
  VoxelSource source;
  VoxelBox voxels;
};
std::vector<ObjectRef> object_refs(const PreparedSources& p, const MaterialTable& materials, int occ_axis);

// Scratch for one thread: the landscape's block and an object's.
struct BlockPair {
  BlockScratch land;
  BlockScratch object;
};

// The landscape and every object overlapping the block, combined into scratch->land.
void voxelize_sources(const VoxelSource& land, const std::vector<ObjectRef>& objects, const VoxelBox& block,
                      bool faces, BlockPair* scratch, BlockCounters* counters);

// Runs fn(i) for every block in parallel, with progress (stage) and cancel.
Status for_each_block(const std::vector<VoxelBox>& blocks, Context* ctx, const char* stage,
                      const std::function<void(size_t)>& fn);

}  // namespace ldc::detail
