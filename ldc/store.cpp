// PagedWorld: windows over a chunk source through an LRU cache under a memory budget (see store.h).
#include "ldc/store.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <new>
#include <string>
#include <utility>

#include <tbb/parallel_for.h>

#include "ldc/internal/build_common.h"
#include "ldc/internal/vec_text.h"

namespace ldc {
namespace {



size_t entry_bytes(const StoredChunk& data) {
  return kPagingEntryBytes + (data.data ? data.data->memory_bytes() : 0);
}

// Calls fn(chunk) for every chunk of a world's box, in slot order.
template <class Fn>
void for_each_slot(const World& world, Fn&& fn) {
  const glm::ivec3 lo = world.chunk_origin(), hi = lo + world.chunk_dims();
  for (int z = lo.z; z < hi.z; ++z)
    for (int y = lo.y; y < hi.y; ++y)
      for (int x = lo.x; x < hi.x; ++x) fn(glm::ivec3(x, y, z));
}

// Lattice coordinate -> chunk index, clamped to [lo - 1, hi + 1] before the
// integer conversion so that far-off foci cannot overflow.
int chunk_index(double lattice_coord, int c, int lo, int hi) {
  const double chunk = std::floor(lattice_coord / c);
  return int(std::clamp(chunk, double(lo) - 1.0, double(hi) + 1.0));
}

}  // namespace

PagedWorld::PagedWorld(std::shared_ptr<const ChunkSource> source, const PagingOptions& options)
    : source_(std::move(source)), options_(options) {}

Result<World> PagedWorld::window(const glm::ivec3& chunk_lo, const glm::ivec3& chunk_hi, Context* ctx) {
  const SourceBox& box = layout().box;
  const glm::ivec3 lo = glm::max(chunk_lo, box.chunk_origin);
  const glm::ivec3 hi = glm::min(chunk_hi, box.chunk_origin + box.chunk_dims);
  if (glm::any(glm::lessThanEqual(hi, lo))) {
    return Status(ErrorCode::kInvalidArgument,
                  "paged world: window " + detail::chunk_text(chunk_lo) + " .. " + detail::chunk_text(chunk_hi) +
                      " misses the source's box " + detail::chunk_text(box.chunk_origin) + " .. " +
                      detail::chunk_text(box.chunk_origin + box.chunk_dims));
  }
  std::lock_guard lock(mutex_);
  try {
    return make_window(lo, hi, ctx);
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, "paged world: out of memory paging the window " +
                                            detail::chunk_text(lo) + " .. " + detail::chunk_text(hi));
  }
}

Result<World> PagedWorld::window_around(const glm::dvec3& focus, double radius_m, Context* ctx) {
  if (!detail::is_finite(focus)) {
    return Status(ErrorCode::kInvalidArgument, "paged world: focus " + detail::vec_text(focus) + " is not finite");
  }
  if (!(radius_m >= 0.0) || !std::isfinite(radius_m)) {
    return Status(ErrorCode::kInvalidArgument,
                  "paged world: radius_m = " + detail::number_g(radius_m) + " must be finite and >= 0");
  }
  const SourceLayout& lay = layout();
  const glm::dvec3 a = lay.lattice.to_lattice(focus - radius_m), b = lay.lattice.to_lattice(focus + radius_m);
  glm::ivec3 lo, hi;
  for (int k = 0; k < 3; ++k) {
    const int first = lay.box.chunk_origin[k], end = first + lay.box.chunk_dims[k];
    lo[k] = chunk_index(a[k], lay.chunk_size, first, end);
    hi[k] = chunk_index(b[k], lay.chunk_size, first, end) + 1;
  }
  return window(lo, hi, ctx);
}

// Holds the lock. Pins the window's cached chunks, pages in the rest, fills
// the World, then trims the cache.
Result<World> PagedWorld::make_window(const glm::ivec3& lo, const glm::ivec3& hi, Context* ctx) {
  WorldConfig config;
  config.lattice = layout().lattice;
  config.chunk_size = layout().chunk_size;
  config.chunk_origin = lo;
  config.chunk_dims = hi - lo;
  Result<World> made = World::create(config);
  if (!made.ok()) return made.status();
  World world = std::move(made).value();
  ++window_;
  ++stats_.windows;
  const std::vector<glm::ivec3> missing = use_cached(world);
  Status paged = page_in(missing, ctx);
  if (!paged.ok()) {
    trim_to_budget();
    return paged;
  }
  fill(world);
  trim_to_budget();
  world.set_metadata("source", "paged");
  return world;
}

// Marks the window's cached chunks as used by this window (pinned, most
// recent) and returns the chunks that are not cached.
std::vector<glm::ivec3> PagedWorld::use_cached(const World& world) {
  std::vector<glm::ivec3> missing;
  for_each_slot(world, [&](const glm::ivec3& chunk) {
    const uint64_t key = detail::source_chunk_key(chunk);
    auto it = cache_.find(key);
    if (it == cache_.end()) {
      missing.push_back(chunk);
      return;
    }
    it->second.window = window_;
    touch(it->second);
    ++stats_.hits;
  });
  return missing;
}

// Reads the missing chunks in parallel and caches those read; returns the
// first error in chunk order, or kCancelled.
Status PagedWorld::page_in(const std::vector<glm::ivec3>& missing, Context* ctx) {
  std::vector<Result<StoredChunk>> read = read_chunks(missing, ctx);
  return cache_read(missing, read);
}

// Reads the chunks from the source in parallel (no lock needed: the source
// is thread-safe and nothing of the cache is touched).
std::vector<Result<StoredChunk>> PagedWorld::read_chunks(const std::vector<glm::ivec3>& chunks, Context* ctx) const {
  std::vector<Result<StoredChunk>> read(chunks.size(), detail::cancelled_status("paged world"));
  detail::ProgressCounter progress(ctx, "page", chunks.size());
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t i) {
    if (progress.cancelled()) return;
    read[i] = source_->read(chunks[i]);
    progress.step();
  });
  return read;
}

// Holds the lock. Caches the chunks read that are not cached yet (a
// prefetch may find chunks a window or put() cached meanwhile: those stay);
// returns the first error in chunk order.
Status PagedWorld::cache_read(const std::vector<glm::ivec3>& chunks, std::vector<Result<StoredChunk>>& read) {
  Status first_error;
  for (size_t i = 0; i < chunks.size(); ++i) {
    if (!read[i].ok()) {
      if (first_error.ok()) first_error = read[i].status();
      continue;
    }
    if (cache_.count(detail::source_chunk_key(chunks[i])) != 0) continue;
    insert(chunks[i], std::move(read[i]).value(), false);
    ++stats_.page_ins;
  }
  stats_.peak_resident_bytes = std::max(stats_.peak_resident_bytes, stats_.resident_bytes);
  return first_error;
}

Status PagedWorld::prefetch(const glm::ivec3& chunk_lo, const glm::ivec3& chunk_hi, Context* ctx) {
  const SourceBox& box = layout().box;
  const glm::ivec3 lo = glm::max(chunk_lo, box.chunk_origin);
  const glm::ivec3 hi = glm::min(chunk_hi, box.chunk_origin + box.chunk_dims);
  if (glm::any(glm::lessThanEqual(hi, lo))) return {};
  const glm::i64vec3 dims = glm::i64vec3(hi - lo);
  if (dims.x * dims.y * dims.z > kMaxChunkSlots) {
    return {ErrorCode::kTooLarge, "paged world: prefetch of " + detail::chunk_text(lo) + " .. " +
                                      detail::chunk_text(hi) + " is larger than a window may be"};
  }
  std::vector<glm::ivec3> missing;
  {
    std::lock_guard lock(mutex_);
    for (int z = lo.z; z < hi.z; ++z)
      for (int y = lo.y; y < hi.y; ++y)
        for (int x = lo.x; x < hi.x; ++x)
          if (cache_.count(detail::source_chunk_key({x, y, z})) == 0) missing.emplace_back(x, y, z);
  }
  std::vector<Result<StoredChunk>> read = read_chunks(missing, ctx);
  std::lock_guard lock(mutex_);
  Status s = cache_read(missing, read);
  stats_.prefetched += missing.size();
  trim_to_budget();
  return s;
}

// Sets every chunk of the world from the cache (all present after page_in)
// and counts windows larger than the budget.
void PagedWorld::fill(World& world) {
  size_t bytes = 0;
  for_each_slot(world, [&](const glm::ivec3& chunk) {
    const Entry& e = cache_.at(detail::source_chunk_key(chunk));
    bytes += e.bytes;
    if (e.data.kind == ChunkKind::kMixed) {
      world.set_chunk(chunk, e.data.data);
    } else if (e.data.kind == ChunkKind::kSolid) {
      world.set_uniform_chunk(chunk, true);
    }
  });
  if (bytes > options_.memory_budget_bytes) ++stats_.windows_over_budget;
}

void PagedWorld::insert(const glm::ivec3& chunk, StoredChunk data, bool dirty) {
  const uint64_t key = detail::source_chunk_key(chunk);
  auto [it, fresh] = cache_.try_emplace(key);
  Entry& e = it->second;
  if (!fresh) {  // replaced: take the old entry out of the counts
    stats_.resident_bytes -= e.bytes;
    stats_.resident_mixed -= e.data.kind == ChunkKind::kMixed;
    stats_.dirty -= e.dirty;
    if (!e.dirty) lru_.erase(e.lru);
  }
  if (fresh) ++stats_.resident_chunks;
  e.chunk = chunk;
  e.bytes = entry_bytes(data);
  e.data = std::move(data);
  e.dirty = dirty;
  e.window = window_;
  stats_.resident_bytes += e.bytes;
  stats_.resident_mixed += e.data.kind == ChunkKind::kMixed;
  stats_.dirty += dirty;
  if (!dirty) e.lru = lru_.insert(lru_.end(), key);
}

void PagedWorld::touch(Entry& entry) {
  if (!entry.dirty) lru_.splice(lru_.end(), lru_, entry.lru);
}

// Evicts least recently used clean chunks outside the latest window until
// the cache fits the budget (or only pinned chunks are left).
void PagedWorld::trim_to_budget() {
  auto it = lru_.begin();
  while (stats_.resident_bytes > options_.memory_budget_bytes && it != lru_.end()) {
    auto found = cache_.find(*it);
    if (found->second.window == window_) {
      ++it;  // pinned by the latest window
      continue;
    }
    stats_.resident_bytes -= found->second.bytes;
    stats_.resident_mixed -= found->second.data.kind == ChunkKind::kMixed;
    --stats_.resident_chunks;
    ++stats_.evictions;
    it = lru_.erase(it);
    cache_.erase(found);
  }
}

Status PagedWorld::check_put(const World& edited, std::span<const glm::ivec3> chunks) const {
  const SourceLayout& lay = layout();
  if (edited.chunk_size() != lay.chunk_size || edited.lattice().cell_size != lay.lattice.cell_size ||
      edited.lattice().origin != lay.lattice.origin) {
    return {ErrorCode::kInvalidArgument,
            "paged world: put: the edited world's lattice (origin " + detail::vec_text(edited.lattice().origin) +
                ", cell size " + detail::number_g(edited.lattice().cell_size) + ", chunk size " +
                std::to_string(edited.chunk_size()) + ") is not the source's"};
  }
  for (const glm::ivec3& c : chunks) {
    if (!edited.contains_chunk(c)) {
      return {ErrorCode::kInvalidArgument, "paged world: put: chunk " + detail::chunk_text(c) +
                                               " is outside the edited world's box"};
    }
    if (!lay.box.contains(c)) {
      return {ErrorCode::kInvalidArgument,
              "paged world: put: chunk " + detail::chunk_text(c) + " is outside the source's box"};
    }
  }
  return {};
}

Status PagedWorld::put(const World& edited, std::span<const glm::ivec3> chunks) {
  if (Status s = check_put(edited, chunks); !s.ok()) return s;
  std::lock_guard lock(mutex_);
  for (const glm::ivec3& c : chunks) {
    insert(c, StoredChunk{edited.chunk_kind(c), edited.chunk_shared(c)}, true);
  }
  stats_.peak_resident_bytes = std::max(stats_.peak_resident_bytes, stats_.resident_bytes);
  trim_to_budget();
  return {};
}

std::vector<DirtyStoredChunk> PagedWorld::take_dirty() {
  std::lock_guard lock(mutex_);
  std::vector<DirtyStoredChunk> out;
  for (auto& [key, e] : cache_) {
    if (!e.dirty) continue;
    out.push_back({e.chunk, e.data});
    e.dirty = false;
    e.lru = lru_.insert(lru_.end(), key);  // clean now: evictable, most recent
  }
  stats_.dirty = 0;
  std::sort(out.begin(), out.end(), [](const DirtyStoredChunk& a, const DirtyStoredChunk& b) {
    return chunk_order_less(a.chunk, b.chunk);
  });
  return out;
}

PagingStats PagedWorld::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace ldc
