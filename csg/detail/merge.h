// Chunk-level merges behind booleans, brush edits and painting.
#pragma once

#include <climits>
#include <cstdint>
#include <memory>

#include "csg/csg.h"

namespace ldc::detail {

// A chunk slot as a boolean reads it: its kind, and its data when mixed
// (shared, to hand back unchanged chunks without copying).
struct ChunkView {
  ChunkKind kind = ChunkKind::kEmpty;
  std::shared_ptr<const Chunk> data;
};

ChunkView view_chunk(const World& w, const glm::ivec3& chunk);

// Chunk-local lattice nodes around the points a merge changed: both nodes of
// every cell edge whose crossings changed (so hi may reach C + 1).
struct ChangeBox {
  glm::ivec3 lo{INT32_MAX};
  glm::ivec3 hi{INT32_MIN};  // exclusive
  bool empty() const { return lo.x >= hi.x; }
  void add(const glm::ivec3& node_lo, const glm::ivec3& node_hi) {
    lo = glm::min(lo, node_lo);
    hi = glm::max(hi, node_hi);
  }
};

struct MergedChunk {
  ChunkKind kind = ChunkKind::kEmpty;
  std::shared_ptr<const Chunk> data;  // set when kind is kMixed
  bool changed_from_a = true;         // differs from the first input
  ChangeBox changed;                  // where, when changed_from_a and tracked
};

// a op b for one chunk slot. With track_changes, `changed` holds the nodes
// whose crossings changed and an unchanged result is a's own chunk; without
// (whole-world booleans, which need no dirty boxes), the rays are not
// compared and only families b leaves alone count as unchanged.
MergedChunk merge_chunk(const ChunkView& a, const ChunkView& b, BooleanOp op, const BooleanConfig& config,
                        int chunk_size, bool track_changes);

// a with the material of its surface points inside b replaced by `material`.
MergedChunk paint_chunk(const ChunkView& a, const ChunkView& b, uint16_t material, int chunk_size);

// Stores a merged chunk into w (which must contain it).
void store_chunk(World& w, const glm::ivec3& chunk, const MergedChunk& m);

}  // namespace ldc::detail
