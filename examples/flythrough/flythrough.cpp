// A streaming fly-through of a procedural world far larger than memory: the
// large-world proof for engine programmers (ldc/store.h, ldc/chunk_log.h).
//
// The landscape of build_terrain, 4 km x 4 km by default (about 1.2 million
// chunk slots at h = 0.2 m), is never built whole: chunks are generated on
// first touch (make_terrain_source) under a memory budget (PagedWorld).
// Every frame, as a game would:
//   1. page    the camera moves; a worker thread prefetches the chunks a
//              second ahead of it (PagedWorld::prefetch), and the frame
//              takes a window of the chunks around it from the cache;
//   2. edit    once a second the player digs a sphere into the ground under
//              the camera (WorldEditor on the window); the edited chunks go
//              back to the pager as dirty (PagedWorld::put);
//   3. save    right after, the edits are saved incrementally: appended to a
//              crash-safe chunk log (ChunkLog::commit) and laid over the
//              generator (OverlaySource), so they survive eviction;
//   4. mesh    each chunk has a level of detail by its distance to the
//              camera (lod_level, with hysteresis: level 1 from 12 m,
//              level 2 from 24 m); a mesh worker thread meshes, nearest
//              first, the chunks that came into view, were edited, or have a
//              neighbour whose level changed (contour_chunk_levels: seams
//              between levels closed); the frame collects what it finished
//              and drops meshes of chunks that left the window;
//   5. ray     a ground ray is cast under the camera (Queries);
//   6. nav     a nav worker thread rebuilds the nav mesh of the window
//              around the player when it has moved 8 m or dug, and plans a
//              path 12 m ahead on it.
// It prints the median, p95 and max of each stage and of the frame, the
// peak resident memory, the pager's and the log's figures, and with --png
// renders a few frames (render/render.h): the world ray-traced, and the
// chunk meshes drawn as they are (render_mesh), tinted by level.
//
// Usage: flythrough [--frames N] [--budget-mb M] [--size-km K] [--speed V]
//                   [--store PATH] [--png DIR] [--quiet]
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/chunk_log.h"
#include "ldc/lod.h"
#include "ldc/query.h"
#include "ldc/store.h"
#include "ldc/terrain.h"
#include "nav/nav.h"
#include "render/render.h"

namespace {

using Clock = std::chrono::steady_clock;
using ldc::Result;
using ldc::Status;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Options {
  int frames = 600;
  double budget_mb = 512.0;
  double size_km = 4.0;
  double speed = 10.0;  // m/s, at 60 frames per second
  std::string store = "out/flythrough.ldcs";
  std::string png_dir;
  bool quiet = false;
};

bool parse_options(int argc, char** argv, Options* o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    const auto number = [&](double lo, double hi, double* out) {
      char* end = nullptr;
      const double v = std::strtod(argv[++i], &end);
      if (*end != '\0' || !(v >= lo && v <= hi)) {
        std::fprintf(stderr, "%s %s: must be a number in %g .. %g\n", a.c_str(), argv[i], lo, hi);
        return false;
      }
      *out = v;
      return true;
    };
    double v = 0;
    if (a == "--frames" && has_value) {
      if (!number(1, 100000, &v)) return false;
      o->frames = int(v);
    } else if (a == "--budget-mb" && has_value) {
      if (!number(16, 65536, &o->budget_mb)) return false;
    } else if (a == "--size-km" && has_value) {
      if (!number(0.1, 100, &o->size_km)) return false;
    } else if (a == "--speed" && has_value) {
      if (!number(0, 1000, &o->speed)) return false;
    } else if (a == "--store" && has_value) {
      o->store = argv[++i];
    } else if (a == "--png" && has_value) {
      o->png_dir = argv[++i];
    } else if (a == "--quiet") {
      o->quiet = true;
    } else {
      std::fprintf(stderr,
                   "usage: flythrough [--frames N] [--budget-mb M] [--size-km K] [--speed V] [--store PATH] "
                   "[--png DIR] [--quiet]\n");
      return false;
    }
  }
  return true;
}

constexpr int kFps = 60;
constexpr double kViewRadius = 40.0;  // m: the window around the camera
constexpr double kNavRadius = 20.0;   // m: the window the nav mesh covers
constexpr double kNavRebuildDistance = 8.0;  // m
// Chunk levels by distance from the camera: 1 from 12 m, 2 from 24 m.
const ldc::LodBands kLodBands{.start = {12.0, 24.0}, .hysteresis = 1.5};

using ChunkKey = std::tuple<int, int, int>;
using LevelMap = std::map<ChunkKey, int>;

ChunkKey key(const glm::ivec3& c) { return {c.x, c.y, c.z}; }

// A chunk mesh and the level it was meshed at.
struct LevelMesh {
  ldc::ChunkMesh mesh;
  int level = 0;
};

// One frame's measurements [ms].
struct Frame {
  double page = 0, edit = 0, save = 0, mesh = 0, ray = 0, nav = 0;
  double total() const { return page + edit + save + mesh + ray + nav; }
};

// The camera's ground track: a straight line across the world from near its
// south-west corner, 8 m above the ground.
glm::dvec2 track(const ldc::SourceLayout& layout, double size_m, double t_seconds, double speed) {
  const glm::dvec2 start = glm::dvec2(layout.lattice.origin) + glm::dvec2(0.1 * size_m, 0.12 * size_m);
  const glm::dvec2 dir = glm::normalize(glm::dvec2(1.0, 0.35));
  return start + dir * (speed * t_seconds);
}

// Runs `work` on its own thread for the newest job posted to it: a job not
// yet started when a newer one comes is dropped (only the newest window
// matters), as for a game's background paging or nav rebuild.
template <class Job>
class LatestJobWorker {
 public:
  explicit LatestJobWorker(std::function<void(const Job&)> work)
      : work_(std::move(work)), thread_([this] { loop(); }) {}
  ~LatestJobWorker() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  void post(Job job) {
    {
      std::lock_guard lock(mutex_);
      job_ = std::move(job);
    }
    wake_.notify_one();
  }

 private:
  void loop() {
    std::unique_lock lock(mutex_);
    while (true) {
      wake_.wait(lock, [this] { return stop_ || job_.has_value(); });
      if (stop_) return;
      const Job job = std::move(*job_);
      job_.reset();
      lock.unlock();
      work_(job);
      lock.lock();
    }
  }

  std::function<void(const Job&)> work_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Job> job_;
  bool stop_ = false;
  std::thread thread_;
};

struct ChunkBox {
  glm::ivec3 lo{0}, hi{0};
};

// Prefetches on its own thread the box a second ahead of the camera.
class Prefetcher {
 public:
  explicit Prefetcher(ldc::PagedWorld& paged)
      : worker_([&paged](const ChunkBox& box) {
          const Status s = paged.prefetch(box.lo, box.hi);
          if (!s.ok()) std::fprintf(stderr, "prefetch: %s\n", s.to_string().c_str());
        }) {}
  void want(const glm::ivec3& lo, const glm::ivec3& hi) { worker_.post({lo, hi}); }

 private:
  LatestJobWorker<ChunkBox> worker_;
};

// Nav around the player, on its own thread: a nav mesh of the window around
// the player (rebuilt when the player has moved kNavRebuildDistance or dug)
// and a path from the player to a point ahead of it on that mesh.
struct NavJob {
  std::shared_ptr<const ldc::World> window;
  glm::dvec3 from{0.0}, to{0.0};
};
struct NavResults {
  std::mutex mutex;
  std::vector<double> build_ms;
  size_t paths = 0, complete = 0;
  double path_length = 0.0;
};

class NavWorker {
 public:
  explicit NavWorker(NavResults& results) : worker_([&results](const NavJob& job) { run(job, results); }) {}
  void post(NavJob job) { worker_.post(std::move(job)); }

 private:
  static void run(const NavJob& job, NavResults& results) {
    const Clock::time_point start = Clock::now();
    Result<ldc::NavMesh> nav = ldc::NavMesh::build(*job.window, ldc::NavConfig{});
    const double ms = ms_since(start);
    if (!nav.ok()) {
      std::fprintf(stderr, "nav: %s\n", nav.status().to_string().c_str());
      return;
    }
    ldc::NavQuery query(nav.value());
    Result<ldc::NavPath> path = query.find_path(job.from, job.to);
    std::lock_guard lock(results.mutex);
    results.build_ms.push_back(ms);
    ++results.paths;
    if (path.ok() && path->status == ldc::PathStatus::kComplete) {
      ++results.complete;
      results.path_length += path->length;
    }
  }

  LatestJobWorker<NavJob> worker_;
};

// A level map as the frame hands it out: shared, never changed, and named
// by an id that the meshes made from it carry back.
struct Levels {
  uint64_t id = 0;
  LevelMap map;  // every chunk of the window
  int at(const glm::ivec3& c) const {
    auto it = map.find(key(c));
    return it == map.end() ? 0 : it->second;
  }
};
using LevelsPtr = std::shared_ptr<const Levels>;

struct MeshJob {
  glm::ivec3 chunk;
  LevelsPtr levels;
};

// A chunk mesh, its level, and the id of the level map it was made from.
struct MadeMesh {
  LevelMesh mesh;
  uint64_t levels_id = 0;
};

// Meshes chunks on its own thread, as an engine's job system would: the
// frame hands it the current window (a snapshot: chunks are shared) and the
// jobs (a chunk and the level map to mesh it from), nearest first, and
// collects finished meshes next frame.
class MeshWorker {
 public:
  // `threads` meshing threads share the queue (contour_chunk_levels may run concurrently).
  MeshWorker(const ldc::ContourConfig& config, int threads) : config_(config) {
    for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { loop(); });
  }
  ~MeshWorker() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }
  // Replaces the queue: these jobs on this window, in this order.
  void request(const ldc::World& window, std::vector<MeshJob> jobs) {
    {
      std::lock_guard lock(mutex_);
      window_ = std::make_shared<const ldc::World>(window);
      queue_ = std::move(jobs);
    }
    wake_.notify_all();
  }
  // The meshes finished since the last call.
  std::vector<MadeMesh> take() {
    std::lock_guard lock(mutex_);
    return std::exchange(done_, {});
  }
  size_t queued() {
    std::lock_guard lock(mutex_);
    return queue_.size() + running_;
  }
  double busy_ms() {
    std::lock_guard lock(mutex_);
    return busy_ms_;
  }

 private:
  void loop() {
    std::unique_lock lock(mutex_);
    while (true) {
      wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      const MeshJob job = queue_.front();
      queue_.erase(queue_.begin());
      std::shared_ptr<const ldc::World> window = window_;
      ++running_;
      lock.unlock();
      const Clock::time_point start = Clock::now();
      // Every chunk of the window has a level; the mesher asks only for those.
      auto level_of = [&](const glm::ivec3& c) { return job.levels->at(c); };
      Result<ldc::ChunkMesh> m = ldc::contour_chunk_levels(*window, job.chunk, level_of, config_);
      const double took = ms_since(start);
      lock.lock();
      --running_;
      busy_ms_ += took;
      if (m.ok()) {
        done_.push_back({{std::move(m).value(), level_of(job.chunk)}, job.levels->id});
      } else {
        std::fprintf(stderr, "mesh: %s\n", m.status().to_string().c_str());
      }
    }
  }

  ldc::ContourConfig config_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::shared_ptr<const ldc::World> window_;
  std::vector<MeshJob> queue_;
  std::vector<MadeMesh> done_;
  int running_ = 0;
  double busy_ms_ = 0.0;  // over all threads
  bool stop_ = false;
  std::vector<std::thread> threads_;
};

// The chunk box of the window of `radius` m around a ground point.
void chunk_box(const ldc::SourceLayout& layout, const glm::dvec2& xy, double radius, glm::ivec3* lo,
               glm::ivec3* hi) {
  const double c = layout.lattice.cell_size * layout.chunk_size;
  const glm::dvec2 o = glm::dvec2(layout.lattice.origin);
  *lo = glm::ivec3(glm::floor((xy - radius - o) / c), layout.box.chunk_origin.z);
  *hi = glm::ivec3(glm::floor((xy + radius - o) / c) + 1.0, layout.box.chunk_origin.z + layout.box.chunk_dims.z);
}

// Changes to meshes already shown (a chunk's level, a dig) are made as one
// batch: its chunks are meshed from one level map and shown together when
// the last is done, so that a shown chunk mesh never meets a neighbour's
// made from other levels or other rays (no crack while the worker catches
// up). One batch at a time: level changes wait for it; a dig joins it.
struct Batch {
  LevelsPtr levels;                       // what its chunks are meshed from
  std::set<ChunkKey> chunks;              // to show together
  std::map<ChunkKey, LevelMesh> staged;   // made, not yet shown
  std::set<ChunkKey> changed;             // chunks whose level or rays changed
};

struct Session {
  std::shared_ptr<ldc::OverlaySource> overlay;
  std::unique_ptr<ldc::PagedWorld> paged;
  std::optional<ldc::ChunkLog> log;
  ldc::World window;
  glm::ivec3 window_lo{0}, window_hi{0};
  bool window_stale = true;
  std::map<ChunkKey, LevelMesh> meshes;  // shown
  LevelsPtr levels = std::make_shared<const Levels>();  // the shown meshes' levels
  uint64_t next_levels_id = 1;
  std::optional<Batch> batch;
  std::set<ChunkKey> fresh;  // chunks come into view, to mesh from the shown levels and show when made
  bool queue_stale = true;   // the worker's queue is to be handed out again
  size_t level_changes = 0, batches = 0;
  size_t triangles = 0, meshed = 0, digs = 0, saved_chunks = 0;
  std::optional<double> ground_z;
  std::optional<glm::dvec2> nav_centre;  // where the nav worker's last window is centred
};

glm::ivec3 chunk_of(const ChunkKey& k) { return {std::get<0>(k), std::get<1>(k), std::get<2>(k)}; }

// Chunks whose neighbours across the window's sides are in the window: their
// meshes are whole. The window spans the world's height, whose faces are in
// the air and under the ground's floor (outside), so every layer is meshed.
bool meshable(const Session& s, const glm::ivec3& c, const ldc::SourceLayout& layout) {
  glm::ivec3 lo = glm::max(s.window_lo + 1, layout.box.chunk_origin);
  glm::ivec3 hi = glm::min(s.window_hi - 1, layout.box.chunk_origin + layout.box.chunk_dims);
  lo.z = s.window_lo.z;
  hi.z = s.window_hi.z;
  return glm::all(glm::greaterThanEqual(c, lo)) && glm::all(glm::lessThan(c, hi));
}

bool wants_mesh(const Session& s, const glm::ivec3& c) {
  return meshable(s, c, s.paged->layout()) && !ldc::chunk_is_quiet(s.window, c);
}

// Whether c is within one chunk of a chunk the batch changed: a chunk's mesh
// reads the rays and levels of its 26 neighbours (contour_chunk_levels).
bool near_change(const Batch& b, const glm::ivec3& c) {
  for (const glm::ivec3& n : ldc::LevelChunkedMesh::chunks_a_change_reaches(std::span(&c, 1)))
    if (b.changed.count(key(n))) return true;
  return false;
}

// Adds chunk c's change to the batch (starting one from `levels` if none):
// c and its neighbours are meshed again.
void add_change(Session& s, const glm::ivec3& c, const LevelsPtr& levels) {
  if (!s.batch) s.batch = Batch{levels, {}, {}, {}};
  s.batch->changed.insert(key(c));
  for (const glm::ivec3& n : ldc::LevelChunkedMesh::chunks_a_change_reaches(std::span(&c, 1))) {
    if (!wants_mesh(s, n)) continue;
    s.batch->chunks.insert(key(n));
    s.batch->staged.erase(key(n));  // made before this change
  }
  s.queue_stale = true;
}

// The level of a chunk at distance d, its level before being `previous`.
int level_at(double d, const std::optional<int>& previous) { return ldc::lod_level(kLodBands, d, previous.value_or(0)); }

// The window's chunks' levels by distance to the camera, with hysteresis.
// When no batch is under way and some chunk's level changed, starts one
// with the new levels. When the window moved, new chunks get their level in
// the shown map (and the batch's): no shown mesh reads them yet.
void set_levels(Session& s, const glm::dvec3& camera, bool window_changed) {
  const ldc::SourceLayout& layout = s.paged->layout();
  auto distance = [&](const glm::ivec3& c) { return ldc::chunk_distance(layout.lattice, layout.chunk_size, c, camera); };
  // The window's chunks, each at its level in `from` or (new) by distance;
  // chunks that left the window are dropped.
  auto with_new_chunks = [&](const LevelsPtr& from) {
    auto next = std::make_shared<Levels>();
    next->id = from->id;
    s.window.for_each_chunk([&](const glm::ivec3& c, ldc::ChunkKind, const ldc::Chunk*) {
      auto it = from->map.find(key(c));
      next->map[key(c)] = it != from->map.end() ? it->second : level_at(distance(c), std::nullopt);
    });
    return LevelsPtr(std::move(next));
  };
  if (window_changed) {  // new maps only when the window moved
    s.levels = with_new_chunks(s.levels);
    if (s.batch) s.batch->levels = with_new_chunks(s.batch->levels);
  }
  if (s.batch) return;
  std::vector<std::pair<glm::ivec3, int>> changed;
  for (const auto& [k, level] : s.levels->map) {
    const int now = level_at(distance(chunk_of(k)), level);
    if (now != level) changed.emplace_back(chunk_of(k), now);
  }
  if (changed.empty()) return;
  auto next = std::make_shared<Levels>(*s.levels);
  next->id = s.next_levels_id++;
  for (const auto& [c, level] : changed) next->map[key(c)] = level;
  const LevelsPtr levels(std::move(next));
  for (const auto& [c, level] : changed) add_change(s, c, levels);
  s.level_changes += changed.size();
}

// Sets *changed when the frame's window is a new one.
Status page(Session& s, Prefetcher& prefetcher, const ldc::SourceLayout& layout, const glm::dvec2& xy,
            const glm::dvec2& ahead, bool* changed) {
  glm::ivec3 lo, hi;
  chunk_box(layout, ahead, kViewRadius, &lo, &hi);
  prefetcher.want(lo, hi);
  chunk_box(layout, xy, kViewRadius, &lo, &hi);
  *changed = s.window_stale || lo != s.window_lo || hi != s.window_hi;
  if (!*changed) return {};
  Result<ldc::World> w = s.paged->window(lo, hi);
  if (!w.ok()) return w.status();
  s.window = std::move(w).value();
  s.window_lo = s.window.chunk_origin();
  s.window_hi = s.window_lo + s.window.chunk_dims();
  s.window_stale = false;
  // Drop what left the window; the chunks that came in are meshed fresh (and
  // join the batch under way where a change is beside them).
  auto gone = [&](const ChunkKey& k) { return !meshable(s, chunk_of(k), layout); };
  std::erase_if(s.meshes, [&](const auto& e) { return gone(e.first); });
  std::erase_if(s.fresh, gone);
  if (s.batch) {
    std::erase_if(s.batch->chunks, gone);
    std::erase_if(s.batch->staged, [&](const auto& e) { return gone(e.first); });
  }
  s.window.for_each_chunk([&](const glm::ivec3& c, ldc::ChunkKind, const ldc::Chunk*) {
    if (s.meshes.count(key(c)) || !wants_mesh(s, c)) return;
    s.fresh.insert(key(c));
    if (s.batch && near_change(*s.batch, c)) s.batch->chunks.insert(key(c));
  });
  s.queue_stale = true;
  return {};
}

Status dig(Session& s, const glm::dvec2& xy) {
  if (!s.ground_z) return {};
  ldc::WorldEditor editor(s.window);
  Result<ldc::EditReceipt> r = editor.apply(ldc::Brush::sphere({xy.x, xy.y, *s.ground_z}, 2.0), ldc::EditOp::kSubtract);
  if (!r.ok()) return r.status();
  const std::vector<ldc::DirtyChunk> dirty = editor.take_dirty();
  std::vector<glm::ivec3> chunks;
  for (const ldc::DirtyChunk& d : dirty) chunks.push_back(d.chunk);
  s.window = editor.world();
  if (Status p = s.paged->put(s.window, chunks); !p.ok()) return p;
  LevelsPtr levels = s.levels;
  if (!s.batch) {  // the shown levels, under a new id: meshes made before the dig are not the batch's
    auto copy = std::make_shared<Levels>(*s.levels);
    copy->id = s.next_levels_id++;
    levels = std::move(copy);
  }
  for (const glm::ivec3& c : chunks) add_change(s, c, levels);
  // Fresh chunks beside the dig are meshed from the new rays: drop what was made before.
  ++s.digs;
  return {};
}

Status save(Session& s) {
  std::vector<ldc::DirtyStoredChunk> dirty = s.paged->take_dirty();
  if (dirty.empty()) return {};
  std::vector<std::pair<glm::ivec3, ldc::StoredChunk>> chunks;
  for (const ldc::DirtyStoredChunk& d : dirty) {
    if (Status st = s.overlay->set(d.chunk, d.data); !st.ok()) return st;
    chunks.emplace_back(d.chunk, d.data);
  }
  s.saved_chunks += chunks.size();
  return s.log->commit(chunks);
}

// A finished mesh: shown (fresh, from the shown levels), staged (the
// batch's), or, made from levels since replaced, meshed again if still wanted.
void collect(Session& s, MadeMesh&& m) {
  const glm::ivec3 c = m.mesh.mesh.chunk;
  const ChunkKey k = key(c);
  ++s.meshed;
  if (s.batch && m.levels_id == s.batch->levels->id) {
    if (s.batch->chunks.count(k)) s.batch->staged[k] = std::move(m.mesh);
    return;
  }
  if (m.levels_id == s.levels->id && s.fresh.count(k)) {
    s.meshes[k] = std::move(m.mesh);
    s.fresh.erase(k);
    return;
  }
  s.queue_stale = true;  // stale: it is still in `fresh` or the batch, and will be asked for again
}

// Shows the batch when every chunk of it is made.
void finish_batch(Session& s) {
  if (!s.batch || s.batch->staged.size() < s.batch->chunks.size()) return;
  for (auto& [k, m] : s.batch->staged) s.meshes[k] = std::move(m);
  s.levels = s.batch->levels;
  for (const ChunkKey& k : s.batch->chunks) s.fresh.erase(k);
  s.batch.reset();
  ++s.batches;
  s.queue_stale = true;  // fresh chunks made from the old levels are made again
}

size_t waiting(const Session& s) {
  return s.fresh.size() + (s.batch ? s.batch->chunks.size() - s.batch->staged.size() : 0);
}

// Collects the meshes the worker finished, then hands it what is still to
// mesh, nearest first: the batch's chunks from its levels, fresh ones from
// the shown levels.
void mesh(Session& s, MeshWorker& worker, const glm::dvec2& xy) {
  for (MadeMesh& m : worker.take()) collect(s, std::move(m));
  finish_batch(s);
  if (s.queue_stale) {
    std::vector<MeshJob> jobs;
    if (s.batch) {
      for (const ChunkKey& k : s.batch->chunks)
        if (!s.batch->staged.count(k)) jobs.push_back({chunk_of(k), s.batch->levels});
    }
    for (const ChunkKey& k : s.fresh)
      if (!s.batch || !s.batch->chunks.count(k)) jobs.push_back({chunk_of(k), s.levels});
    const double c = s.window.lattice().cell_size * s.window.chunk_size();
    const glm::dvec2 o = glm::dvec2(s.window.lattice().origin);
    auto distance = [&](const MeshJob& j) { return glm::length(o + (glm::dvec2(j.chunk) + 0.5) * c - xy); };
    std::stable_sort(jobs.begin(), jobs.end(), [&](const MeshJob& a, const MeshJob& b) { return distance(a) < distance(b); });
    worker.request(s.window, std::move(jobs));
    s.queue_stale = false;
  }
  s.triangles = 0;
  for (const auto& [k, m] : s.meshes) s.triangles += m.mesh.mesh.triangle_count();
}

// The ground under (x, y): a ray cast straight down through the window.
std::optional<double> ground_at(const ldc::Queries& q, const ldc::World& window, const glm::dvec2& xy) {
  Result<ldc::RayHit> hit = q.ray_cast({{xy.x, xy.y, window.box().max.z + 1.0}, {0.0, 0.0, -1.0}});
  return hit.ok() && hit->hit ? std::optional<double>(hit->point.z) : std::nullopt;
}

void ground_ray(Session& s, const glm::dvec2& xy) {
  ldc::Queries q(s.window);
  s.ground_z = ground_at(q, s.window, xy);
}

// The chunks of `window` within [lo, hi) as a World of their own (shared,
// not copied): what the nav worker builds on.
Result<ldc::World> sub_window(const ldc::World& window, glm::ivec3 lo, glm::ivec3 hi) {
  lo = glm::max(lo, window.chunk_origin());
  hi = glm::min(hi, window.chunk_origin() + window.chunk_dims());
  ldc::WorldConfig config = window.config();
  config.chunk_origin = lo;
  config.chunk_dims = hi - lo;
  Result<ldc::World> made = ldc::World::create(config);
  if (!made.ok()) return made.status();
  for (int z = lo.z; z < hi.z; ++z)
    for (int y = lo.y; y < hi.y; ++y)
      for (int x = lo.x; x < hi.x; ++x) {
        const glm::ivec3 c(x, y, z);
        if (window.chunk_kind(c) == ldc::ChunkKind::kMixed) {
          made->set_chunk(c, window.chunk_shared(c));
        } else if (window.chunk_kind(c) == ldc::ChunkKind::kSolid) {
          made->set_uniform_chunk(c, true);
        }
      }
  return made;
}

// Hands the nav worker the window around the player when the player has
// moved far enough since the last one, or dug: it rebuilds the nav mesh
// there and plans a path 12 m ahead.
void nav(Session& s, NavWorker& worker, const glm::dvec2& xy, const glm::dvec2& dir, bool dug) {
  if (!s.ground_z) return;
  if (!dug && s.nav_centre && glm::length(*s.nav_centre - xy) < kNavRebuildDistance) return;
  glm::ivec3 lo, hi;
  chunk_box(s.paged->layout(), xy, kNavRadius, &lo, &hi);
  Result<ldc::World> w = sub_window(s.window, lo, hi);
  if (!w.ok()) return;
  ldc::Queries q(s.window);
  const glm::dvec2 goal = xy + 12.0 * dir;
  const std::optional<double> goal_z = ground_at(q, s.window, goal);
  if (!goal_z) return;
  worker.post({std::make_shared<const ldc::World>(std::move(w).value()), glm::dvec3(xy, *s.ground_z),
               glm::dvec3(goal, *goal_z)});
  s.nav_centre = xy;
}

// The render camera: 12 m behind the player and 9 m above the ground,
// looking 20 m ahead (the levels of detail follow it too).
ldc::CameraConfig view_of(const Session& s, const glm::dvec2& xy, const glm::dvec2& dir) {
  ldc::CameraConfig view;
  const double z = s.ground_z.value_or(10.0);
  view.position = glm::dvec3(xy - 12.0 * dir, z + 9.0);
  view.target = glm::dvec3(xy + 20.0 * dir, z - 2.0);
  view.fov_degrees = 70.0;
  view.width = 640;
  view.height = 360;
  return view;
}

// The chunk meshes in view as one mesh, tinted by level (0 grey, 1 blue, 2 orange).
ldc::TriangleMesh meshes_in_view(const Session& s, std::vector<glm::vec3>* colours) {
  static const glm::vec3 kTint[3] = {{0.75f, 0.75f, 0.70f}, {0.50f, 0.68f, 0.92f}, {0.95f, 0.66f, 0.40f}};
  ldc::TriangleMesh all;
  for (const auto& [k, m] : s.meshes) {
    const uint32_t base = uint32_t(all.positions.size());
    all.positions.insert(all.positions.end(), m.mesh.mesh.positions.begin(), m.mesh.mesh.positions.end());
    for (const glm::uvec3& t : m.mesh.mesh.triangles) all.triangles.push_back(t + base);
    colours->insert(colours->end(), m.mesh.mesh.triangles.size(), kTint[std::clamp(m.level, 0, 2)]);
  }
  return all;
}

bool write_image(const Result<ldc::Image>& image, const std::string& path) {
  const Status st = image.ok() ? ldc::write_png(*image, path) : image.status();
  if (!st.ok()) {
    std::fprintf(stderr, "render failed: %s\n", st.to_string().c_str());
    return false;
  }
  std::printf("wrote %s\n", path.c_str());
  return true;
}

// Cracks in the chunk meshes in view: edges with one triangle, in meshes of
// chunks whose 26 neighbours are all meshed too (or have nothing to mesh).
// Chunk meshes share their seam vertices bit for bit, so vertices are welded
// by position. A chunk's triangles meet only its neighbours', so with every
// neighbour meshed from one level map there are none; a neighbourhood still
// being re-meshed after a level change can show some for a while.
size_t count_cracks(const Session& s) {
  std::map<std::tuple<double, double, double>, uint32_t> ids;
  auto id = [&](const glm::dvec3& p) { return ids.try_emplace({p.x, p.y, p.z}, uint32_t(ids.size())).first->second; };
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  std::map<ChunkKey, std::vector<std::pair<uint32_t, uint32_t>>> edges_of;
  for (const auto& [k, m] : s.meshes) {
    const ldc::ContourMesh& mesh = m.mesh.mesh;
    for (const glm::uvec3& t : mesh.triangles) {
      const uint32_t v[3] = {id(mesh.positions[t.x]), id(mesh.positions[t.y]), id(mesh.positions[t.z])};
      for (int i = 0; i < 3; ++i) {
        const std::pair<uint32_t, uint32_t> e = std::minmax(v[i], v[(i + 1) % 3]);
        ++uses[e];
        edges_of[k].push_back(e);
      }
    }
  }
  auto covered = [&](const glm::ivec3& c) { return s.meshes.count(key(c)) > 0 || ldc::chunk_is_quiet(s.window, c); };
  size_t cracks = 0;
  for (const auto& [k, edges] : edges_of) {
    const glm::ivec3 c(std::get<0>(k), std::get<1>(k), std::get<2>(k));
    bool inner = true;
    for (int dz = -1; dz <= 1 && inner; ++dz)
      for (int dy = -1; dy <= 1 && inner; ++dy)
        for (int dx = -1; dx <= 1 && inner; ++dx) inner = covered(c + glm::ivec3(dx, dy, dz));
    if (!inner) continue;
    for (const auto& e : edges) cracks += uses[e] == 1;
  }
  return cracks;
}

// Two pictures of the frame: the world ray-traced (flythrough_N.png), and
// the chunk meshes as they are, tinted by level (flythrough_lod_N.png).
bool render_frame(const Session& s, const Options& o, int frame, const glm::dvec2& xy, const glm::dvec2& dir) {
  char name[64], lod_name[64];
  std::snprintf(name, sizeof name, "flythrough_%04d.png", frame);
  std::snprintf(lod_name, sizeof lod_name, "flythrough_lod_%04d.png", frame);
  ldc::RenderOptions options;
  options.shadows = true;
  ldc::Queries q(s.window);
  Result<ldc::Camera> camera = ldc::Camera::make(view_of(s, xy, dir));
  if (!write_image(camera.ok() ? ldc::render(q, *camera, options) : camera.status(),
                   (std::filesystem::path(o.png_dir) / name).string()))
    return false;
  ldc::MeshRenderOptions mesh_options;
  const ldc::TriangleMesh meshes = meshes_in_view(s, &mesh_options.triangle_colour);
  const ldc::SourceLayout& layout = s.paged->layout();
  size_t at_level = 0;  // shown at the level the camera's distance now asks (with no hysteresis)
  for (const auto& [k, m] : s.meshes) {
    const double d = ldc::chunk_distance(layout.lattice, layout.chunk_size, chunk_of(k), *view_of(s, xy, dir).position);
    at_level += ldc::lod_level({kLodBands.start, 0.0}, d, 0) == m.level;
  }
  std::printf("frame %d: %zu chunk meshes drawn (%zu at the level their distance asks now), %zu cracks (one-triangle "
              "edges between meshed neighbourhoods), %zu chunks waiting to be meshed\n",
              frame, s.meshes.size(), at_level, count_cracks(s), waiting(s));
  return write_image(camera.ok() ? ldc::render_mesh(meshes, *camera, mesh_options) : camera.status(),
                     (std::filesystem::path(o.png_dir) / lod_name).string());
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(p * double(v.size() - 1) + 0.5))];
}

void print_summary(const std::vector<Frame>& frames) {
  std::printf("| stage | median ms | p95 ms | max ms |\n|---|---|---|---|\n");
  const std::pair<const char*, double Frame::*> stages[] = {
      {"page", &Frame::page}, {"edit", &Frame::edit}, {"save", &Frame::save}, {"mesh", &Frame::mesh},
      {"ray", &Frame::ray}, {"nav", &Frame::nav}};
  for (const auto& [name, field] : stages) {
    std::vector<double> v;
    for (const Frame& f : frames) v.push_back(f.*field);
    std::printf("| %s | %.3f | %.3f | %.3f |\n", name, percentile(v, 0.5), percentile(v, 0.95), percentile(v, 1.0));
  }
  std::vector<double> total;
  for (const Frame& f : frames) total.push_back(f.total());
  std::printf("| **frame** | %.3f | %.3f | %.3f |\n", percentile(total, 0.5), percentile(total, 0.95),
              percentile(total, 1.0));
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse_options(argc, argv, &o)) return 2;
  if (!o.png_dir.empty()) std::filesystem::create_directories(o.png_dir);
  const std::filesystem::path store_dir = std::filesystem::path(o.store).parent_path();
  if (!store_dir.empty()) std::filesystem::create_directories(store_dir);

  ldc::TerrainConfig terrain;
  terrain.size_x = terrain.size_y = 1000.0 * o.size_km;
  terrain.arches = 64;
  Result<std::shared_ptr<const ldc::ImplicitSource>> base = ldc::make_terrain_source(terrain, 0.2, 32);
  if (!base.ok()) return std::fprintf(stderr, "%s\n", base.status().to_string().c_str()), 1;
  const ldc::SourceLayout layout = (*base)->layout();
  Session s;
  s.overlay = std::make_shared<ldc::OverlaySource>(*base);
  ldc::PagingOptions paging;
  paging.memory_budget_bytes = size_t(o.budget_mb * 1024 * 1024);
  s.paged = std::make_unique<ldc::PagedWorld>(s.overlay, paging);
  ldc::ChunkLogCreateOptions create;
  create.overwrite = true;
  const std::string description = ldc::terrain_source_description(terrain, 0.2, 32);
  Result<ldc::ChunkLog> log = ldc::ChunkLog::create(o.store, layout, description, create);
  if (!log.ok()) return std::fprintf(stderr, "%s\n", log.status().to_string().c_str()), 1;
  s.log.emplace(std::move(log).value());

  std::printf("# flythrough: %.1f x %.1f km landscape (h = 0.2 m, %lld chunk slots), budget %.0f MB, %d frames at "
              "%.0f m/s\n\n",
              o.size_km, o.size_km, static_cast<long long>(layout.box.slots()), o.budget_mb, o.frames, o.speed);
  ldc::ContourConfig contour;
  std::vector<Frame> frames;
  const int render_every = std::max(1, o.frames / 3);
  double setup_ms = 0.0, worker_ms = 0.0;
  NavResults nav_results;
  {
    Prefetcher prefetcher(*s.paged);
    MeshWorker worker(contour, 1);  // one thread: a second one (tried) slows the frame on two cores
    NavWorker nav_worker(nav_results);
    // The first window and its meshes: what a game does behind its loading screen.
    Clock::time_point start = Clock::now();
    bool changed = false;
    const glm::dvec2 first = track(layout, 1000.0 * o.size_km, 0.0, o.speed);
    Status st = page(s, prefetcher, layout, first, track(layout, 1000.0 * o.size_km, 1.0, o.speed), &changed);
    if (st.ok()) ground_ray(s, first);
    const glm::dvec2 first_dir = glm::normalize(track(layout, 1000.0 * o.size_km, 1.0, o.speed) - first);
    set_levels(s, *view_of(s, first, first_dir).position, true);
    mesh(s, worker, first);
    while (st.ok() && waiting(s) > 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      mesh(s, worker, first);
    }
    setup_ms = ms_since(start);
    if (!st.ok()) return std::fprintf(stderr, "setup: %s\n", st.to_string().c_str()), 1;
    std::printf("setup (first window, %zu chunk meshes): %.0f ms\n\n", s.meshes.size(), setup_ms);
    // Frames start every 1/60 s, as with vsync: the worker threads run in
    // the time a frame leaves, as they would in a game.
    const Clock::time_point loop_start = Clock::now();
    for (int i = 0; i < o.frames; ++i) {
      std::this_thread::sleep_until(loop_start + std::chrono::microseconds(int64_t(i) * 1000000 / kFps));
      const double t = double(i) / kFps;
      const glm::dvec2 xy = track(layout, 1000.0 * o.size_km, t, o.speed);
      const glm::dvec2 ahead = track(layout, 1000.0 * o.size_km, t + 1.0, o.speed);
      const glm::dvec2 dir = glm::normalize(ahead - xy);
      Frame f;
      start = Clock::now();
      st = page(s, prefetcher, layout, xy, ahead, &changed);
      f.page = ms_since(start);
      if (st.ok() && i % kFps == kFps / 2) {
        start = Clock::now();
        st = dig(s, xy);
        f.edit = ms_since(start);
        start = Clock::now();
        if (st.ok()) st = save(s);
        f.save = ms_since(start);
      }
      start = Clock::now();
      if (st.ok()) set_levels(s, *view_of(s, xy, dir).position, changed);
      if (st.ok()) mesh(s, worker, xy);
      f.mesh = ms_since(start);
      start = Clock::now();
      if (st.ok()) ground_ray(s, xy);
      f.ray = ms_since(start);
      start = Clock::now();
      if (st.ok()) nav(s, nav_worker, xy, dir, f.edit > 0.0);
      f.nav = ms_since(start);
      if (!st.ok()) return std::fprintf(stderr, "frame %d: %s\n", i, st.to_string().c_str()), 1;
      frames.push_back(f);
      if (!o.quiet && (i % kFps == 0)) {
        std::printf("frame %4d: at (%.0f, %.0f) %.2f ms, %zu chunk meshes (%zu triangles), resident %.1f MB\n", i,
                    xy.x, xy.y, f.total(), s.meshes.size(), s.triangles,
                    double(s.paged->stats().resident_bytes) / 1048576.0);
      }
      if (!o.png_dir.empty() && (i % render_every == 0 || i == o.frames - 1) && !render_frame(s, o, i, xy, dir))
        return 1;
    }
    worker_ms = worker.busy_ms();
  }
  std::printf("\n");
  print_summary(frames);
  const ldc::PagingStats ps = s.paged->stats();
  const ldc::ChunkLogStats ls = s.log->stats();
  std::printf("\npager: %zu page-ins (%zu by the prefetcher's requests), %zu hits, %zu evictions, resident %.1f MB "
              "(peak %.1f MB) of %.0f MB\n",
              ps.page_ins, ps.prefetched, ps.hits, ps.evictions, double(ps.resident_bytes) / 1048576.0,
              double(ps.peak_resident_bytes) / 1048576.0, o.budget_mb);
  std::printf("edits: %zu digs, %zu chunks saved in %llu commits, log %s %.1f KB\n", s.digs, s.saved_chunks,
              static_cast<unsigned long long>(ls.commits), o.store.c_str(), double(ls.file_bytes) / 1024.0);
  std::printf("meshes: %zu chunk meshes made on the mesh worker (%.0f ms of its time, %.1f ms each), %zu in view "
              "(%zu triangles), %zu waiting\n",
              s.meshed, worker_ms, s.meshed ? worker_ms / double(s.meshed) : 0.0, s.meshes.size(), s.triangles,
              waiting(s));
  size_t per_level[3] = {0, 0, 0}, tris_per_level[3] = {0, 0, 0};
  for (const auto& [k, m] : s.meshes) {
    ++per_level[std::clamp(m.level, 0, 2)];
    tris_per_level[std::clamp(m.level, 0, 2)] += m.mesh.mesh.triangle_count();
  }
  std::printf("levels of detail (1 from 12 m, 2 from 24 m): chunk meshes in view at level 0 / 1 / 2: %zu / %zu / %zu "
              "(%zu / %zu / %zu triangles); %zu level changes, %zu batches of re-meshed chunks shown\n",
              per_level[0], per_level[1], per_level[2], tris_per_level[0], tris_per_level[1], tris_per_level[2],
              s.level_changes, s.batches);
  {
    std::lock_guard lock(nav_results.mutex);
    const std::vector<double>& b = nav_results.build_ms;
    std::printf("nav: %zu nav meshes built on the nav worker around the player (median %.0f ms, max %.0f ms), %zu of "
                "%zu paths 12 m ahead complete\n",
                b.size(), b.empty() ? 0.0 : percentile(b, 0.5), b.empty() ? 0.0 : percentile(b, 1.0),
                nav_results.complete, nav_results.paths);
  }
  std::printf("peak resident memory %.0f MB (setup %.0f ms, not in the frame figures)\n", peak_rss_mb(), setup_ms);
  return 0;
}
