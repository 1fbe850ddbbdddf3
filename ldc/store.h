// Worlds larger than memory: chunk sources and a paged world under a memory budget.
//
// A ChunkSource (ldc/chunk_source.h) hands out the chunks of a box that may
// be far larger than one World (kMaxSourceChunkSlots against kMaxChunkSlots).
// This header gives two sources and the pager:
//
//   ImplicitSource  builds each chunk from an implicit solid when it is read
//                   (make_terrain_source: the procedural landscape), equal
//                   chunk for chunk to build_from_implicit / build_terrain of
//                   the whole world;
//   OverlaySource   edited chunks held in memory over a base source, with an
//                   optional lower layer (e.g. an on-disk log) between them;
//   PagedWorld      pages chunks in from a source through an LRU cache under
//                   a memory budget and hands out Worlds (windows) over the
//                   part of the box the game needs now; takes edited chunks
//                   back and keeps them until they are saved.
//
// Memory: nothing here allocates in proportion to a source's box; sources
// hold their parameters, and the pager holds the window it makes plus its
// cache (bounded by PagingOptions::memory_budget_bytes, see PagedWorld).
//
// Thread safety: sources' read() is const and safe from many threads at
// once (OverlaySource::set may run beside reads). A PagedWorld has one owner
// thread that calls window(), put() and take_dirty(); stats() may be called
// from any thread. The Worlds it hands out are independent snapshots: they
// share immutable chunks with the cache and with each other, and later calls
// never change them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <span>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/build.h"
#include "ldc/chunk_log.h"
#include "ldc/chunk_source.h"
#include "ldc/context.h"
#include "ldc/status.h"
#include "ldc/terrain.h"
#include "ldc/world.h"

namespace ldc {

// --- Procedural sources -------------------------------------------------------

// The layout build_from_implicit would give `solid` for this cell size, chunk
// size and padding (GridConfig::cell_size, chunk_size, padding): the same
// lattice origin and chunk box, but without the build's limits on chunk slots
// and memory (a source's box may hold up to kMaxSourceChunkSlots).
// Errors (kInvalidArgument, kTooLarge) name the field and value.
Result<SourceLayout> implicit_source_layout(const ImplicitSolid& solid, double cell_size,
                                            int chunk_size, int padding = 2);

// Builds each chunk from an implicit solid on read(), deterministically:
// with the layout of implicit_source_layout, every chunk equals the chunk of
// build_from_implicit's whole world (same kind, families bit for bit).
// Cost per read: a chunk the solid cannot classify samples up to (C+1)^3
// nodes and finds a root per crossing (the terrain at C = 32: about 14 ms for
// a mixed chunk, 1 ms for one that turns out uniform, on a 2-core VM);
// chunks the solid classifies as outside or inside cost a box test. Holds
// only the solid and the layout; read() allocates one chunk's samples.
class ImplicitSource final : public ChunkSource {
 public:
  // Checks the layout (check_source_layout) and the solid's bounds.
  static Result<std::shared_ptr<const ImplicitSource>> create(
      std::shared_ptr<const ImplicitSolid> solid, const SourceLayout& layout);

  const SourceLayout& layout() const override { return layout_; }
  // Never fails for chunks in or out of the box (outside: kEmpty).
  Result<StoredChunk> read(const glm::ivec3& chunk) const override;
  const ImplicitSolid& solid() const { return *solid_; }

 private:
  ImplicitSource(std::shared_ptr<const ImplicitSolid> solid, const SourceLayout& layout);
  std::shared_ptr<const ImplicitSolid> solid_;
  WorldBox bounds_;  // solid_->bounds(), read once
  SourceLayout layout_;
};

// The landscape of build_terrain(config, cell_size, chunk_size) as a source:
// its chunks equal that build's, and its box may be kilometres wide
// (make_terrain_solid holds a few noise tables and at most 64 arches,
// whatever the size). Note for kilometre worlds: the noise tables repeat
// every 256 noise cells, so the hills repeat every 4.1 km, the tunnels every
// 2.8 km and the overhang warp every 1.5 km. Errors: those of check_terrain
// and implicit_source_layout.
Result<std::shared_ptr<const ImplicitSource>> make_terrain_source(const TerrainConfig& config,
                                                                  double cell_size = 0.2,
                                                                  int chunk_size = 32);

// --- Overlay ------------------------------------------------------------------

// A lower overlay layer: the chunk if the layer holds one, nullopt if not,
// or an error. An on-disk log's find() fits here. Must be safe to call from
// many threads at once.
using ChunkFinder = std::function<Result<std::optional<StoredChunk>>(const glm::ivec3& chunk)>;

// Edited chunks over a base source. read() looks, in order, in the chunks
// set() here, in the lower layer (if given), then in the base. The layout is
// the base's; chunks outside its box cannot be set.
// Memory: the chunks set here (shared, not copied).
class OverlaySource final : public ChunkSource {
 public:
  explicit OverlaySource(std::shared_ptr<const ChunkSource> base, ChunkFinder lower = {});

  const SourceLayout& layout() const override { return base_->layout(); }
  Result<StoredChunk> read(const glm::ivec3& chunk) const override;

  // Lays `data` over the chunk. Errors (kInvalidArgument): the chunk is
  // outside the box, or `data` is inconsistent (mixed without data, data of
  // another chunk size, a uniform chunk passed as kMixed).
  Status set(const glm::ivec3& chunk, StoredChunk data);
  // Chunks set here.
  size_t size() const;

 private:
  std::shared_ptr<const ChunkSource> base_;
  ChunkFinder lower_;
  mutable std::shared_mutex mutex_;  // set() beside concurrent read()s
  std::unordered_map<uint64_t, StoredChunk> chunks_;
};

// --- Paged world --------------------------------------------------------------

struct PagingOptions {
  // Bytes of chunk data the cache keeps resident. Mixed chunks count
  // Chunk::memory_bytes() plus kPagingEntryBytes; uniform ones only
  // kPagingEntryBytes. Over it, least recently used clean chunks are evicted,
  // except those of the latest window and dirty ones.
  // [Units: bytes] [Default: 512 MiB] [Limit: any; 0 keeps only pinned chunks]
  size_t memory_budget_bytes = size_t{512} << 20;
};

// What the cache costs per entry besides the chunk data (map node, LRU link).
inline constexpr size_t kPagingEntryBytes = 64;

struct PagingStats {
  size_t resident_chunks = 0;       // entries in the cache, uniform ones included
  size_t resident_mixed = 0;        // of which mixed (holding chunk data)
  size_t resident_bytes = 0;        // as counted against the budget
  size_t peak_resident_bytes = 0;   // highest resident_bytes seen (before evictions)
  size_t page_ins = 0;              // chunks read from the source
  size_t hits = 0;                  // window chunks found in the cache
  size_t evictions = 0;
  size_t dirty = 0;                 // chunks put() and not yet taken
  size_t windows = 0;               // windows made
  size_t windows_over_budget = 0;   // windows whose own chunks exceeded the budget
  size_t prefetched = 0;            // chunks prefetch() looked for that were not cached
};

// A chunk put() back and not yet saved.
struct DirtyStoredChunk {
  glm::ivec3 chunk{0};
  StoredChunk data;
};

// Pages chunks from a source through an LRU cache and hands out windows.
//
// Budget: after each window the cache is trimmed to the budget by evicting
// least recently used clean chunks that are not in that window. A window
// whose own chunks exceed the budget is still made (the game needs it, and
// its chunks stay in memory through the World anyway); the cache then stays
// over budget until the next window, and stats().windows_over_budget counts
// it. Dirty chunks count against the budget too (clean ones make room for
// them). After each call resident bytes are therefore within max(budget,
// latest window + dirty chunks); while a window is made, within that plus
// the chunks it pages in (stats().peak_resident_bytes).
//
// Edits: put() takes edited chunks back as dirty: pinned, served to every
// later window, never evicted, until take_dirty() hands them out for saving
// and marks them clean. A clean chunk may be evicted and is then read from
// the source again, so the caller must save what take_dirty() returns into
// the source (e.g. an OverlaySource or a store file it reads) first.
//
// Thread safety: one owner thread calls window(), put() and take_dirty();
// one other thread may call prefetch() meanwhile; every method holds an
// internal lock, so stats() is safe from any thread. window() reads missing
// chunks from the source in parallel (TBB) under the lock; prefetch() reads
// them outside it, so a worker can page ahead of the camera while the owner
// makes windows from what is cached.
class PagedWorld {
 public:
  // `source` must not be null; it is shared, and read from window() only.
  PagedWorld(std::shared_ptr<const ChunkSource> source, const PagingOptions& options = {});

  const SourceLayout& layout() const { return source_->layout(); }

  // A World over chunks [chunk_lo, chunk_hi) (exclusive) clipped to the
  // source's box, on the source's lattice and chunk size, every chunk shared
  // with the cache (no copy). Errors: kInvalidArgument when the clipped box
  // is empty; kTooLarge when it has more than kMaxChunkSlots slots; the
  // source's error for a chunk it cannot read (earlier chunks stay cached);
  // kCancelled through ctx (progress stage "page").
  Result<World> window(const glm::ivec3& chunk_lo, const glm::ivec3& chunk_hi, Context* ctx = nullptr);
  // The window of every chunk that meets the cube of half-size radius_m
  // around focus [Units: m]. Errors: a non-finite focus or a radius < 0 or
  // not finite (kInvalidArgument), then those of window().
  Result<World> window_around(const glm::dvec3& focus, double radius_m, Context* ctx = nullptr);

  // Reads the chunks of [chunk_lo, chunk_hi) (clipped to the source's box)
  // that are not cached into the cache, as clean chunks, without making a
  // window; the source is read outside the lock (see Thread safety). A chunk
  // a window or put() caches meanwhile is kept, not replaced. The cache is
  // then trimmed to the budget (the latest window's chunks stay). Errors:
  // kTooLarge for a box over kMaxChunkSlots, the source's first error (the
  // other chunks are cached), kCancelled through ctx.
  Status prefetch(const glm::ivec3& chunk_lo, const glm::ivec3& chunk_hi, Context* ctx = nullptr);

  // Takes the listed chunks of `edited` (a window after an edit; its
  // lattice and chunk size must be the source's) back as dirty. All or
  // nothing: kInvalidArgument names the first chunk outside `edited`'s box or
  // the source's box, or the lattice that differs.
  Status put(const World& edited, std::span<const glm::ivec3> chunks);
  // The dirty chunks, sorted by chunk_order_less, now clean (evictable).
  std::vector<DirtyStoredChunk> take_dirty();

  PagingStats stats() const;

 private:
  struct Entry {
    glm::ivec3 chunk{0};
    StoredChunk data;
    size_t bytes = 0;                   // counted against the budget
    bool dirty = false;                 // put() and not taken: out of the LRU list
    uint64_t window = 0;                // the last window that used it
    std::list<uint64_t>::iterator lru;  // valid while clean
  };
  using Cache = std::unordered_map<uint64_t, Entry>;

  Result<World> make_window(const glm::ivec3& lo, const glm::ivec3& hi, Context* ctx);
  std::vector<glm::ivec3> use_cached(const World& world);
  Status page_in(const std::vector<glm::ivec3>& missing, Context* ctx);
  std::vector<Result<StoredChunk>> read_chunks(const std::vector<glm::ivec3>& chunks, Context* ctx) const;
  Status cache_read(const std::vector<glm::ivec3>& chunks, std::vector<Result<StoredChunk>>& read);
  void fill(World& world);
  void insert(const glm::ivec3& chunk, StoredChunk data, bool dirty);
  void touch(Entry& entry);
  void trim_to_budget();
  Status check_put(const World& edited, std::span<const glm::ivec3> chunks) const;

  std::shared_ptr<const ChunkSource> source_;
  PagingOptions options_;
  mutable std::mutex mutex_;
  Cache cache_;
  std::list<uint64_t> lru_;  // clean entries, least recently used first
  PagingStats stats_;
  uint64_t window_ = 0;      // the latest window's number; its entries are pinned
};

// --- Stores: a chunk log over the base it describes -----------------------------

// The landscape a store is built on, named by one line of text that the
// chunk log's header carries (ChunkLog::base_description), e.g.
//   "ldc-terrain 1 seed=1 size_x=4000 size_y=4000 ... cell_size=0.2 chunk_size=32"
// Numbers are written with 17 significant digits, so the same chunks come
// back bit for bit on any machine.
struct TerrainSourceParams {
  TerrainConfig config;
  double cell_size = 0.2;  // [Units: m]
  int chunk_size = 32;
};
std::string terrain_source_description(const TerrainConfig& config, double cell_size, int chunk_size);
// Errors (kCorruptData): not a landscape description, a key missing, given
// twice or unknown, a value that is not a finite number or out of range.
Result<TerrainSourceParams> parse_terrain_source_description(const std::string& description);
// The source a base description names (today: the landscape, through
// make_terrain_source).
Result<std::shared_ptr<const ChunkSource>> source_from_description(const std::string& description);

// A large world on disk: a chunk log of its edited chunks over the base its
// header describes. `source` reads the log's committed chunks, else the
// base's: page windows from it with a PagedWorld, and save() what was put
// back into the log. Thread safety: as ChunkLog's (save() must not run
// beside reads of `source`, e.g. a prefetch: save between frames' paging).
struct Store {
  std::shared_ptr<ChunkLog> log;
  std::shared_ptr<const ChunkSource> base;
  std::shared_ptr<OverlaySource> source;  // log over base

  // Commits the pager's dirty chunks (take_dirty) as one commit; nothing
  // to commit writes nothing. On error the chunks are no longer dirty in
  // the pager: keep the Store and retry only after reopening.
  Status save(PagedWorld& paged);
  ChunkFinder log_finder() const;
};
// A new store of the landscape (refuses an existing file unless overwrite).
Result<Store> create_terrain_store(const std::string& path, const TerrainConfig& config, double cell_size = 0.2,
                                   int chunk_size = 32, bool overwrite = false);
// Opens a store in its last committed state; errors name the path, and a
// log whose layout is not its description's is refused (kCorruptData).
Result<Store> open_store(const std::string& path, const ChunkLogLimits& limits = {});

}  // namespace ldc
