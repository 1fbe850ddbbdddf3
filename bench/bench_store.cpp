// Large worlds (issue 21): what paging and saving cost per chunk.
//
// - Generation: chunks of the procedural landscape (make_terrain_source,
//   4 km x 4 km, h = 0.2 m, C = 32) read one by one from a fresh source,
//   mixed and uniform apart; and chunks per second on 1 and 2 threads.
// - Page-in from disk: the mixed chunks committed to a chunk log
//   (ChunkLog::commit), the log opened again, each chunk read back with
//   ChunkLog::find (pread, CRC-32, decompression, validation): once with the
//   file in the OS page cache, once with its pages dropped before each read
//   (posix_fadvise DONTNEED; they are clean after the commit's fsync), so
//   that the read comes from the disk.
// - Save: a 2 m sphere dug into a window of the landscape (WorldEditor),
//   its changed chunks committed (appended with CRC-32, two fsyncs), per dig
//   and per chunk; 20 digs along a line.
// Targets (issue 21): page-in of a mixed chunk <= 0.5 ms from disk; an
// incremental save of one dig <= 2 ms.
//
// Usage: bench_store [--quick] [DIR]   (DIR: where the log goes; default /tmp)
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "bench_common.h"
#include "csg/csg.h"
#include "ldc/chunk_log.h"
#include "ldc/query.h"
#include "ldc/store.h"
#include "ldc/terrain.h"

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(p * double(v.size() - 1) + 0.5))];
}

void row(const char* what, const std::vector<double>& ms) {
  std::printf("| %s | %zu | %.3f | %.3f | %.3f | %.3f |\n", what, ms.size(), percentile(ms, 0.0), percentile(ms, 0.5),
              percentile(ms, 0.95), percentile(ms, 1.0));
}

ldc::TerrainConfig world_config() {
  ldc::TerrainConfig t;
  t.size_x = t.size_y = 4000.0;
  t.arches = 64;
  return t;
}

// The chunks of a block of columns near the world's middle, every layer.
std::vector<glm::ivec3> block(const ldc::SourceLayout& layout, int columns) {
  std::vector<glm::ivec3> out;
  const glm::ivec3 o = layout.box.chunk_origin + layout.box.chunk_dims / 2;
  for (int y = 0; y < columns; ++y)
    for (int x = 0; x < columns; ++x)
      for (int z = 0; z < layout.box.chunk_dims.z; ++z)
        out.emplace_back(o.x + x, o.y + y, layout.box.chunk_origin.z + z);
  return out;
}

struct Generated {
  std::vector<std::pair<glm::ivec3, ldc::StoredChunk>> mixed;
  std::vector<double> mixed_ms, uniform_ms;
};

Generated generate_one_by_one(const std::vector<glm::ivec3>& chunks) {
  Generated g;
  auto source = ldc::make_terrain_source(world_config(), 0.2, 32).value();
  for (const glm::ivec3& c : chunks) {
    const Clock::time_point t = Clock::now();
    ldc::StoredChunk s = source->read(c).value();
    const double ms = ms_since(t);
    if (s.kind == ldc::ChunkKind::kMixed) {
      g.mixed_ms.push_back(ms);
      g.mixed.emplace_back(c, std::move(s));
    } else {
      g.uniform_ms.push_back(ms);
    }
  }
  return g;
}

double chunks_per_second(const std::vector<glm::ivec3>& chunks, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  auto source = ldc::make_terrain_source(world_config(), 0.2, 32).value();
  const Clock::time_point t = Clock::now();
  std::atomic<size_t> failed{0};
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t i) { failed += !source->read(chunks[i]).ok(); });
  const double s = ms_since(t) / 1000.0;
  if (failed) std::abort();
  return double(chunks.size()) / s;
}

// Drops the file's pages from the OS page cache (they are clean after the
// commit's fsync), so that the next read comes from the disk.
void evict_from_page_cache(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) std::abort();
  (void)::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
  ::close(fd);
}

// Each mixed chunk read back from the log: warm (the file in the page cache)
// or cold (its pages dropped before each read).
std::vector<double> page_in_from_log(const std::string& path, const Generated& g, bool cold) {
  auto source = ldc::make_terrain_source(world_config(), 0.2, 32).value();
  ldc::ChunkLogCreateOptions create;
  create.overwrite = true;
  {
    ldc::ChunkLog log = ldc::ChunkLog::create(path, source->layout(),
                                              ldc::terrain_source_description(world_config(), 0.2, 32), create)
                            .value();
    if (!log.commit(g.mixed).ok()) std::abort();
  }
  const ldc::ChunkLog log = ldc::ChunkLog::open(path).value();
  std::vector<double> ms;
  for (const auto& [c, s] : g.mixed) {
    if (cold) evict_from_page_cache(path);
    const Clock::time_point t = Clock::now();
    std::optional<ldc::StoredChunk> read = log.find(c).value();
    ms.push_back(ms_since(t));
    if (!read || read->kind != ldc::ChunkKind::kMixed) std::abort();
  }
  return ms;
}

struct Saves {
  std::vector<double> per_dig_ms, per_chunk_ms;
  size_t chunks = 0;
};

Saves dig_and_save(const std::string& path, int digs) {
  auto base = ldc::make_terrain_source(world_config(), 0.2, 32).value();
  auto overlay = std::make_shared<ldc::OverlaySource>(base);
  ldc::PagedWorld paged(overlay);
  ldc::ChunkLogCreateOptions create;
  create.overwrite = true;
  ldc::ChunkLog log =
      ldc::ChunkLog::create(path, base->layout(), ldc::terrain_source_description(world_config(), 0.2, 32), create)
          .value();
  Saves out;
  const glm::dvec3 start(2000.0, 2000.0, 0.0);
  for (int i = 0; i < digs; ++i) {
    const glm::dvec3 at = start + glm::dvec3(3.0 * i, 1.0 * i, 0.0);
    ldc::World window = paged.window_around(at, 8.0).value();
    ldc::Queries q(window);
    ldc::Result<ldc::RayHit> hit = q.ray_cast({{at.x, at.y, window.box().max.z + 1.0}, {0.0, 0.0, -1.0}});
    if (!hit.ok() || !hit->hit) continue;
    ldc::WorldEditor editor(std::move(window));
    if (!editor.apply(ldc::Brush::sphere(hit->point, 2.0), ldc::EditOp::kSubtract).ok()) std::abort();
    std::vector<glm::ivec3> changed;
    for (const ldc::DirtyChunk& d : editor.take_dirty()) changed.push_back(d.chunk);
    if (!paged.put(editor.world(), changed).ok()) std::abort();
    std::vector<std::pair<glm::ivec3, ldc::StoredChunk>> chunks;
    for (const ldc::DirtyStoredChunk& d : paged.take_dirty()) {
      if (!overlay->set(d.chunk, d.data).ok()) std::abort();
      chunks.emplace_back(d.chunk, d.data);
    }
    const Clock::time_point t = Clock::now();
    if (!log.commit(chunks).ok()) std::abort();
    const double ms = ms_since(t);
    out.per_dig_ms.push_back(ms);
    out.per_chunk_ms.push_back(ms / double(std::max<size_t>(1, chunks.size())));
    out.chunks += chunks.size();
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string dir = "/tmp";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) quick = true;
    else dir = argv[i];
  }
  const std::string path = (std::filesystem::path(dir) / "bench_store.ldcs").string();
  std::printf("# Large worlds: paging and saving per chunk (issue 21)\n\n");
  ldc::bench::print_machine();
  const int columns = quick ? 3 : 6;
  auto layout = ldc::make_terrain_source(world_config(), 0.2, 32).value()->layout();
  const std::vector<glm::ivec3> chunks = block(layout, columns);
  std::printf("\nThe 4 km x 4 km landscape (h = 0.2 m, C = 32, 64 arches), %d x %d columns of %d chunks near its "
              "middle (%zu chunks). Log at %s. Times in ms.\n\n",
              columns, columns, layout.box.chunk_dims.z, chunks.size(), path.c_str());
  const Generated g = generate_one_by_one(chunks);
  const std::vector<double> from_log = page_in_from_log(path, g, false);
  const std::vector<double> from_disk = page_in_from_log(path, g, true);
  const Saves saves = dig_and_save(path, quick ? 5 : 20);
  std::printf("| what | count | min | median | p95 | max |\n|---|---|---|---|---|---|\n");
  row("page-in of a mixed chunk from the generator", g.mixed_ms);
  row("page-in of a uniform chunk from the generator", g.uniform_ms);
  row("page-in of a mixed chunk from the chunk log, in the page cache", from_log);
  row("page-in of a mixed chunk from the chunk log, from the disk (target <= 0.5)", from_disk);
  row("save of one 2 m dig (commit, two fsyncs; target <= 2)", saves.per_dig_ms);
  row("save per changed chunk (commit time / chunks)", saves.per_chunk_ms);
  std::printf("\n%zu chunks saved in %zu digs. Generation throughput: %.0f chunks/s on 1 thread, %.0f on 2.\n",
              saves.chunks, saves.per_dig_ms.size(), chunks_per_second(chunks, 1), chunks_per_second(chunks, 2));
  std::filesystem::remove(path);
  return 0;
}
