// Chunk sources: where the chunks of a world larger than memory come from.
//
// A World holds every chunk of its box in memory, and its box is limited to
// kMaxChunkSlots. A large world is instead described by a ChunkSource (a
// store file, the procedural generator, or edits laid over a generator),
// whose box may hold far more chunk slots than one World; a PagedWorld
// (ldc/store.h) pages chunks in from it under a memory budget and hands out
// Worlds over the part of the box the game needs now.
//
// Thread safety: read() is const and may be called from many threads at
// once; it returns the same chunk for the same coordinates every time
// (until the source's owner changes it, e.g. by a commit to a store file).
#pragma once

#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {

// Chunk slots one source may cover (2^40): a 4 km x 4 km x 512 m world at
// h = 0.2 m and C = 32 has about 3.1e7.
inline constexpr int64_t kMaxSourceChunkSlots = int64_t{1} << 40;

// A chunk as a source hands it out: its kind, and the data of a mixed chunk.
struct StoredChunk {
  ChunkKind kind = ChunkKind::kEmpty;
  std::shared_ptr<const Chunk> data;  // non-null iff kind == kMixed
};

// The chunks a source covers: [chunk_origin, chunk_origin + chunk_dims).
struct SourceBox {
  glm::ivec3 chunk_origin{0};  // [Units: chunks]
  glm::ivec3 chunk_dims{1};    // [Limit: >= 1 each, product <= kMaxSourceChunkSlots] [Units: chunks]

  bool contains(const glm::ivec3& chunk) const {
    const glm::ivec3 d = chunk - chunk_origin;
    return d.x >= 0 && d.y >= 0 && d.z >= 0 && d.x < chunk_dims.x && d.y < chunk_dims.y && d.z < chunk_dims.z;
  }
  int64_t slots() const { return int64_t(chunk_dims.x) * chunk_dims.y * chunk_dims.z; }
};

// The shape every chunk of a source shares.
struct SourceLayout {
  Lattice lattice;
  int chunk_size = 32;  // C [Limit: 8, 16, 32 or 64]
  SourceBox box;
};
// Checks a layout; an error names the bad field and value.
Status check_source_layout(const SourceLayout& layout);

class ChunkSource {
 public:
  virtual ~ChunkSource() = default;
  virtual const SourceLayout& layout() const = 0;
  // The chunk at `chunk`: kEmpty (no data) outside the box. An error
  // (kIoError, kCorruptData) names the chunk and what went wrong; the source
  // stays usable.
  virtual Result<StoredChunk> read(const glm::ivec3& chunk) const = 0;
};

}  // namespace ldc
