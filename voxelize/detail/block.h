// The walk over voxel blocks: one LDC sampled into a block of voxels, ray
// family by ray family, into a scratch that holds the block's accumulated
// occupancy and face sums; then resolved to FaceSamples. Sinks (dense grid,
// G-buffer, cascade texture) copy the resolved block out.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "voxelize/voxelize.h"

namespace ldc::detail {

// One LDC as a voxel source: voxel g is its nodes [m*g, m*g + m].
struct VoxelSource {
  const World* world = nullptr;
  int m = 1;          // cells per voxel
  int stride = 1;     // sampled ray spacing [Units: nodes]; divides m
  int occ_axis = 2;   // family integrated for the volume
  const MaterialTable* materials = nullptr;
  // Added to the material ids read from the points (a static object's material_base).
  int material_offset = 0;
};

// stride for m cells per voxel and at most `supersampling` intervals per edge.
int sample_stride(int m, int supersampling);

// Face sums while accumulating; means after the resolve (weight then the
// fraction of the face's rays that saw a surface point).
struct FaceAccum {
  float weight;
  glm::vec3 albedo;
  glm::vec3 normal;
  glm::vec3 emission;
};

// What one block accumulates. Face sums are not zeroed (a block holds far
// more voxels than surface faces): `touched` says which are set.
struct BlockScratch {
  VoxelBox box;
  bool faces = false;
  int full_n = 1;                      // n = m / stride: ray intervals per voxel edge
  std::vector<int64_t> volume;         // per voxel: weighted inside steps
  std::vector<int64_t> volume_diff;    // (bins + 1) x columns of the occupancy axis, bin-major: run starts/ends
  std::vector<int64_t> volume_run;     // per column: the running sum of volume_diff (resolve scratch)
  std::vector<int32_t> coverage_diff;  // per column of the current axis: (bins + 1)
  std::vector<uint8_t> surface;        // per voxel: holds a surface point
  std::vector<uint8_t> touched;        // per voxel: bit f set when face f holds a surface point
  std::vector<FaceAccum> face;         // face f of voxel i at i * kFaces + f (valid where touched)
  std::vector<float> coverage;         // faces: per axis a and voxel i at a * V + i
  std::vector<float> occupancy;        // per voxel, after the resolve
  // Set when every chunk the block's rays touch is empty (kEmpty) or solid
  // (kSolid): the arrays are then filled without reading a ray.
  ChunkKind uniform = ChunkKind::kMixed;

  void reset(const VoxelBox& b, bool with_faces);
  size_t voxels() const { return box.count(); }
};

struct BlockCounters {
  size_t closed = 0;
  size_t walked = 0;
  size_t rays = 0;
};

// Accumulates the source into the scratch (reset it first) and resolves:
// occupancy, face means and fractions. With scratch.faces all three axes
// are walked, else only the occupancy axis.
void voxelize_block(const VoxelSource& source, BlockScratch* scratch, BlockCounters* counters);

// Combines `other` (another source resolved on the same box) into `into`.
void combine_blocks(BlockScratch* into, const BlockScratch& other);

// Blocks of at most `edge` voxels per axis, aligned to multiples of `edge`
// in global voxel coordinates, covering the box.
std::vector<VoxelBox> split_blocks(const VoxelBox& box, int edge);

// The FaceSample of face f of voxel i of a resolved block (flags kFaceOwn
// where it saw a surface).
FaceSample face_sample(const BlockScratch& block, size_t i, int f);

}  // namespace ldc::detail
