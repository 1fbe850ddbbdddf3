// The C API (capi/ldc.h) over the C++ modules. Each entry point checks its
// arguments, calls the C++ API inside a guard that turns exceptions
// (std::bad_alloc, anything else) into a status, and records the message of
// a failure in a thread-local string. Every handle goes through a table that
// refuses dead or busy ones (see "Handles" below).
//
// A world handle owns a LiveWorld (live/live.h): the world, its editor, the
// query cache, the chunk meshes, the navigation mesh and the cascades made
// from it. The LiveWorld fans every edit's dirty chunks out to them and to
// the list ldc_world_take_dirty hands to the caller; the C API brings each
// consumer up to date lazily, before its next use.
#include "capi/ldc.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <tbb/global_control.h>

#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/io.h"
#include "ldc/query.h"
#include "ldc/terrain.h"
#include "ldc/version.h"
#include "ldc/world.h"
#include "live/live.h"
#include "nav/nav.h"
#include "voxelize/voxelize.h"

static_assert(LDC_FORMAT_VERSION == ldc::kLdcFormatVersion, "ldc/version.h and ldc/io.h disagree");

namespace {

thread_local std::string g_last_error;

ldc_status fail(ldc_status status, std::string message) {
  g_last_error = std::move(message);
  return status;
}

ldc_status from_status(const ldc::Status& status) {
  if (status.ok()) return LDC_OK;
  return fail(static_cast<ldc_status>(status.code()), status.message());
}

// Runs fn (returning ldc_status) with exceptions turned into statuses.
template <class Fn>
ldc_status guarded(const char* call, Fn&& fn) {
  try {
    return fn();
  } catch (const std::bad_alloc&) {
    // Building a message may itself fail for lack of memory: then the code alone.
    try {
      return fail(LDC_TOO_LARGE, std::string(call) + ": out of memory");
    } catch (...) {
      return LDC_TOO_LARGE;
    }
  } catch (const std::exception& e) {
    return fail(LDC_INTERNAL, std::string(call) + ": " + e.what());
  } catch (...) {
    return fail(LDC_INTERNAL, std::string(call) + ": unknown exception");
  }
}

ldc_status null_argument(const char* call, const char* name) {
  return fail(LDC_INVALID_ARGUMENT, std::string(call) + ": " + name + " is NULL");
}

// The value of an enum a C caller passed, read as the int it is: a C caller
// may pass any int, and loading a C++ enum outside its enumerators' range is
// undefined (UBSan flags it).
template <class E>
int32_t raw_enum(const E& e) {
  static_assert(sizeof(E) == sizeof(int32_t));
  int32_t v;
  std::memcpy(&v, &e, sizeof v);
  return v;
}

glm::dvec3 vec3(const double v[3]) { return {v[0], v[1], v[2]}; }
glm::ivec3 ivec3(const int32_t v[3]) { return {v[0], v[1], v[2]}; }
void put(const glm::dvec3& v, double out[3]) { out[0] = v.x, out[1] = v.y, out[2] = v.z; }
void put(const glm::ivec3& v, int32_t out[3]) { out[0] = v.x, out[1] = v.y, out[2] = v.z; }
void put(const glm::vec3& v, float out[3]) { out[0] = v.x, out[1] = v.y, out[2] = v.z; }

// ---------------------------------------------------------------------------
// Handles (see "Handles" in ldc.h)
//
// The ldc_world* and ldc_cascades* a caller holds are not addresses: each
// packs a type tag (the magic number), a slot index and the slot's
// generation into the pointer's bits. The slot, in a process-wide table that
// is never freed, holds the object and one atomic word: the generation, a
// live bit and the in-use count. So a stale, forged or wrong-type handle is
// refused without reading freed memory (ASan-clean), and a call that would
// overlap another in a conflicting way is refused without waiting.

enum class Access { kRead, kWrite };  // shared with other reads / alone

constexpr int kPointerBits = int(sizeof(uintptr_t) * 8);
constexpr int kIndexBits = kPointerBits == 64 ? 20 : 14;       // live handles per type
constexpr int kGenerationBits = kPointerBits == 64 ? 32 : 12;  // destroys per slot
constexpr int kTagBits = kPointerBits - kIndexBits - kGenerationBits;
constexpr uint64_t kMaxGeneration = (uint64_t(1) << kGenerationBits) - 1;
constexpr uint32_t kSegmentSlots = 1024;
constexpr uint32_t kSegments = (uint32_t(1) << kIndexBits) / kSegmentSlots;
// The slot's atomic word: generation << 32 | kLive | kWriter | readers.
constexpr uint64_t kLive = uint64_t(1) << 31;
constexpr uint64_t kWriter = uint64_t(1) << 30;
constexpr uint64_t kReaders = kWriter - 1;

class HandleTable {
 public:
  // tag: the magic number of this table's handles [1 .. 2^kTagBits - 1].
  HandleTable(uintptr_t tag, const char* kind) : tag_(tag), kind_(kind) {}

  const char* kind() const { return kind_; }

  // A handle for `object`; 0 when every slot is live (the object stays the caller's).
  uintptr_t insert(void* object) {
    std::lock_guard<std::mutex> lock(mutex_);
    uint32_t index;
    if (!free_.empty()) {
      index = free_.back();
    } else if (used_ < (uint32_t(1) << kIndexBits)) {
      index = used_;
      std::atomic<Slot*>& segment = segments_[index / kSegmentSlots];
      if (!segment.load(std::memory_order_relaxed)) segment.store(new Slot[kSegmentSlots], std::memory_order_release);
    } else {
      return 0;
    }
    Slot& slot = *find(index);
    const uint64_t generation = slot.state.load(std::memory_order_relaxed) >> 32;
    slot.object = object;
    slot.state.store(generation << 32 | kLive, std::memory_order_release);
    if (!free_.empty()) {
      free_.pop_back();
    } else {
      ++used_;
    }
    return tag_ << (kGenerationBits + kIndexBits) | uintptr_t(generation) << kIndexBits | index;
  }

  // The object of a live handle, marked in use; LDC_INVALID_HANDLE or LDC_BUSY otherwise.
  ldc_status acquire(uintptr_t handle, Access access, void** object) const {
    Slot* slot = lookup(handle);
    if (!slot) return LDC_INVALID_HANDLE;
    const uint64_t generation = (handle >> kIndexBits) & kMaxGeneration;
    uint64_t s = slot->state.load(std::memory_order_acquire);
    for (;;) {
      if (s >> 32 != generation || !(s & kLive)) return LDC_INVALID_HANDLE;
      if ((s & kWriter) || (access == Access::kWrite ? (s & kReaders) != 0 : (s & kReaders) == kReaders)) {
        return LDC_BUSY;
      }
      const uint64_t next = access == Access::kWrite ? s | kWriter : s + 1;
      if (slot->state.compare_exchange_weak(s, next, std::memory_order_acquire)) break;
    }
    *object = slot->object;
    return LDC_OK;
  }

  void release(uintptr_t handle, Access access) const {
    Slot* slot = lookup(handle);
    if (access == Access::kWrite) {
      slot->state.fetch_and(~kWriter, std::memory_order_release);
    } else {
      slot->state.fetch_sub(1, std::memory_order_release);
    }
  }

  // Ends a handle acquired for writing: later calls with it get
  // LDC_INVALID_HANDLE. A slot whose generation would wrap is never reused,
  // so an old handle can never name a newer object.
  void retire(uintptr_t handle) {
    Slot* slot = lookup(handle);
    const uint64_t generation = slot->state.load(std::memory_order_relaxed) >> 32;
    slot->object = nullptr;
    slot->state.store(std::min(generation + 1, kMaxGeneration) << 32, std::memory_order_release);
    if (generation + 1 >= kMaxGeneration) return;
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      free_.push_back(uint32_t(handle & ((uintptr_t(1) << kIndexBits) - 1)));
    } catch (const std::bad_alloc&) {
      // The slot is lost to reuse, which is harmless.
    }
  }

 private:
  struct Slot {
    std::atomic<uint64_t> state{0};
    void* object = nullptr;  // written before state publishes it, read after acquiring it
  };

  Slot* find(uint32_t index) const {
    Slot* segment = segments_[index / kSegmentSlots].load(std::memory_order_acquire);
    return segment ? &segment[index % kSegmentSlots] : nullptr;
  }

  // The slot a handle of this table names (any generation), null for another value.
  Slot* lookup(uintptr_t handle) const {
    if (handle >> (kGenerationBits + kIndexBits) != tag_) return nullptr;
    return find(uint32_t(handle & ((uintptr_t(1) << kIndexBits) - 1)));
  }

  const uintptr_t tag_;
  const char* const kind_;
  std::atomic<Slot*> segments_[kSegments] = {};  // allocated on first use, never freed
  std::mutex mutex_;                             // guards free_ and used_ (insert, retire)
  std::vector<uint32_t> free_;
  uint32_t used_ = 0;
};

static_assert(kTagBits >= 4, "the handle layout needs 4 bits for its tag");
// Made on first use and never destroyed: a call from another library's static
// constructor or destructor (or an atexit handler) still finds its table.
HandleTable& world_handles() {
  static HandleTable* table = new HandleTable(0x1d1 & ((uintptr_t(1) << kTagBits) - 1), "world");
  return *table;
}
HandleTable& cascades_handles() {
  static HandleTable* table = new HandleTable(0x1dc & ((uintptr_t(1) << kTagBits) - 1), "cascades");
  return *table;
}

uintptr_t handle_bits(const void* handle) { return reinterpret_cast<uintptr_t>(handle); }

// A handle in use for the length of one call: released when it goes out of scope.
class Lease {
 public:
  Lease(HandleTable& table, uintptr_t handle, Access access) : table_(table), handle_(handle), access_(access) {
    status_ = table.acquire(handle, access, &object_);
  }
  ~Lease() {
    if (status_ == LDC_OK) table_.release(handle_, access_);
  }
  Lease(const Lease&) = delete;
  Lease& operator=(const Lease&) = delete;

  ldc_status status() const { return status_; }
  template <class T>
  T& get() const { return *static_cast<T*>(object_); }
  // Frees the handle for good (the lease must be for writing); the object is the caller's to delete.
  template <class T>
  T* retire() {
    table_.retire(handle_);
    status_ = LDC_INVALID_HANDLE;
    return static_cast<T*>(object_);
  }
  // The message of a refused lease, naming the call and the argument.
  ldc_status refusal(const char* call, const char* name) const {
    if (status_ == LDC_BUSY) {
      return fail(LDC_BUSY, std::string(call) + ": " + name + " is busy: a call on this " + table_.kind() +
                                " from another thread has not returned (editing calls need it alone, "
                                "reading calls may share it); retry, or lock around it");
    }
    return fail(LDC_INVALID_HANDLE, std::string(call) + ": " + name + " is not a live " + table_.kind() +
                                        " handle (destroyed already, or not one this library made)");
  }

 private:
  HandleTable& table_;
  uintptr_t handle_;
  Access access_;
  void* object_ = nullptr;
  ldc_status status_ = LDC_INVALID_HANDLE;
};

// ---------------------------------------------------------------------------
// Buffer sizes

// Whether `count` elements of `element_size` bytes exceed what one array can
// take (PTRDIFF_MAX bytes): no caller buffer is that large.
bool impossible_array(size_t count, size_t element_size) { return count > size_t(PTRDIFF_MAX) / element_size; }

ldc_status too_large_array(const char* call, const char* name, size_t count, size_t element_size) {
  return fail(LDC_TOO_LARGE, std::string(call) + ": " + name + " " + std::to_string(count) + " (elements of " +
                                 std::to_string(element_size) + " bytes) is larger than any array can be");
}

// The checks of a caller buffer (pointer, capacity in elements): NULL with a
// non-zero capacity is refused (a failed allocation, not a size query), and so
// is a capacity no array can have. The caller's word on the capacity is all
// the library has: it never writes past it.
ldc_status check_buffer(const char* call, const char* name, const void* buffer, size_t capacity,
                        size_t element_size) {
  if (!buffer && capacity != 0) {
    return fail(LDC_INVALID_ARGUMENT, std::string(call) + ": " + name + " is NULL with capacity " +
                                          std::to_string(capacity) + " (a size query passes capacity 0)");
  }
  if (buffer && impossible_array(capacity, element_size)) return too_large_array(call, name, capacity, element_size);
  return LDC_OK;
}

// What a cascades handle holds.
struct CascadesState {
  uintptr_t world = 0;      // its world's handle; 0 once the world is destroyed
  ldc::CascadesId id = 0;   // the world's cascades while `world` is set
  std::unique_ptr<ldc::Cascades> orphan;  // handed over when the world was destroyed
  ldc::PackedGBuffer scratch;
};

// What a world handle holds.
struct WorldState {
  explicit WorldState(ldc::LiveWorld l) : live(std::move(l)) {}

  ldc::LiveWorld live;
  ldc::NavConfig nav_config;  // the agent of the nav mesh built at the next path query
  glm::dvec3 search_half_extents{2.0, 2.0, 4.0};
  ldc::NavFilter nav_filter;  // of every path query
  // Off-mesh links by the caller's id, each with its id on the current nav
  // mesh (none while the mesh is not built). A mesh built afresh (the first
  // query, or one after ldc_world_set_nav_config) starts without links: they
  // are added again then, so the caller's ids outlive it.
  struct Link {
    ldc::NavLink link;
    std::optional<uint32_t> mesh_id;
  };
  std::map<uint32_t, Link> nav_links;
  uint32_t next_link_id = 0;
  std::vector<uintptr_t> cascades;  // handles of the cascades made from it

  const ldc::World& world() const { return live.world(); }
};

// Runs fn(WorldState&) on a live world handle, refusing a NULL, dead or busy one.
template <class Fn>
ldc_status with_world(const char* call, const ldc_world* world, Access access, Fn&& fn) {
  return guarded(call, [&] {
    if (!world) return null_argument(call, "world");
    Lease lease(world_handles(), handle_bits(world), access);
    if (lease.status() != LDC_OK) return lease.refusal(call, "world");
    return fn(lease.get<WorldState>());
  });
}

// Runs fn(CascadesState&, WorldState* or null once the world is destroyed) on
// a live cascades handle taken alone, with its world taken for `world_access`.
template <class Fn>
ldc_status with_cascades(const char* call, const ldc_cascades* cascades, Access world_access, Fn&& fn) {
  return guarded(call, [&] {
    if (!cascades) return null_argument(call, "cascades");
    Lease lease(cascades_handles(), handle_bits(cascades), Access::kWrite);
    if (lease.status() != LDC_OK) return lease.refusal(call, "cascades");
    CascadesState& c = lease.get<CascadesState>();
    if (!c.world) return fn(c, static_cast<WorldState*>(nullptr));
    Lease world(world_handles(), c.world, world_access);
    if (world.status() != LDC_OK) return world.refusal(call, "the world of cascades");
    return fn(c, &world.get<WorldState>());
  });
}

ldc::Cascades& cascades_of(CascadesState& c, WorldState* w) { return w ? *w->live.cascades(c.id) : *c.orphan; }

}  // namespace

// ---------------------------------------------------------------------------
// Status and version

extern "C" {

const char* ldc_status_name(ldc_status status) {
  const int32_t s = raw_enum(status);
  switch (s) {
    case LDC_OK: return "ok";
    case LDC_BUFFER_TOO_SMALL: return "buffer too small";
    case LDC_NOT_FOUND: return "not found";
    case LDC_INVALID_HANDLE: return "invalid handle";
    case LDC_BUSY: return "busy";
    default: break;
  }
  if (s > LDC_OK && s <= LDC_INTERNAL) {
    return ldc::error_code_name(static_cast<ldc::ErrorCode>(s));
  }
  return "unknown status";
}

const char* ldc_last_error(void) { return g_last_error.c_str(); }
const char* ldc_version_string(void) { return LDC_VERSION_STRING; }
int ldc_version(void) { return LDC_VERSION; }
int ldc_format_version(void) { return LDC_FORMAT_VERSION; }

// The cap ldc_set_max_threads set (null: none). TBB's own limit is process-wide
// whatever the holder; one holder keeps it from stacking up.
static std::unique_ptr<tbb::global_control> g_thread_cap;
static std::mutex g_thread_cap_mutex;

ldc_status ldc_set_max_threads(int32_t max_threads) {
  return guarded("ldc_set_max_threads", [&] {
    if (max_threads < 0 || max_threads > 4096) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_set_max_threads: max_threads " + std::to_string(max_threads) +
                                            " must be in 0 .. 4096 (0 lifts the cap)");
    }
    std::lock_guard<std::mutex> lock(g_thread_cap_mutex);
    g_thread_cap.reset();
    if (max_threads > 0) {
      g_thread_cap = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                           size_t(max_threads));
    }
    return LDC_OK;
  });
}

int32_t ldc_max_threads(void) {
  return int32_t(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

// ---------------------------------------------------------------------------
// Worlds

void ldc_world_config_default(ldc_world_config* config) {
  if (!config) return;
  const ldc::WorldConfig d;
  *config = ldc_world_config{};
  put(d.lattice.origin, config->origin);
  config->cell_size = d.lattice.cell_size;
  config->chunk_size = d.chunk_size;
  put(d.chunk_origin, config->chunk_origin);
  put(d.chunk_dims, config->chunk_dims);
}

void ldc_terrain_config_default(ldc_terrain_config* config) {
  if (!config) return;
  const ldc::TerrainConfig d;
  *config = ldc_terrain_config{};
  config->seed = d.seed;
  config->size_x = d.size_x;
  config->size_y = d.size_y;
  config->base_height = d.base_height;
  config->relief = d.relief;
  config->cave_radius = d.cave_radius;
  config->arches = d.arches;
  config->cell_size = 0.2;
}

static ldc_status adopt(ldc::Result<ldc::World> world, ldc_world** out) {
  if (!world.ok()) return from_status(world.status());
  ldc::Result<ldc::LiveWorld> live = ldc::LiveWorld::create(std::move(world).value());
  if (!live.ok()) return from_status(live.status());
  auto state = std::make_unique<WorldState>(std::move(live).value());
  const uintptr_t handle = world_handles().insert(state.get());
  if (!handle) return fail(LDC_TOO_LARGE, "too many live worlds (destroy some first)");
  state.release();  // the handle owns it now
  *out = reinterpret_cast<ldc_world*>(handle);
  return LDC_OK;
}

ldc_status ldc_world_create(const ldc_world_config* config, ldc_world** out) {
  return guarded("ldc_world_create", [&] {
    if (!config) return null_argument("ldc_world_create", "config");
    if (!out) return null_argument("ldc_world_create", "out");
    ldc::WorldConfig c;
    c.lattice.origin = vec3(config->origin);
    c.lattice.cell_size = config->cell_size;
    c.chunk_size = config->chunk_size;
    c.chunk_origin = ivec3(config->chunk_origin);
    c.chunk_dims = ivec3(config->chunk_dims);
    return adopt(ldc::World::create(c), out);
  });
}

ldc_status ldc_world_create_terrain(const ldc_terrain_config* config, ldc_world** out) {
  return guarded("ldc_world_create_terrain", [&] {
    if (!out) return null_argument("ldc_world_create_terrain", "out");
    ldc_terrain_config d;
    ldc_terrain_config_default(&d);
    const ldc_terrain_config& in = config ? *config : d;
    ldc::TerrainConfig c;
    c.seed = in.seed;
    c.size_x = in.size_x;
    c.size_y = in.size_y;
    c.base_height = in.base_height;
    c.relief = in.relief;
    c.cave_radius = in.cave_radius;
    c.arches = in.arches;
    if (!(in.cell_size > 0.0) || !std::isfinite(in.cell_size)) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_create_terrain: cell_size " +
                                            std::to_string(in.cell_size) + " must be a finite number > 0");
    }
    return adopt(ldc::build_terrain(c, in.cell_size), out);
  });
}

ldc_status ldc_world_load(const char* path, ldc_world** out) {
  return guarded("ldc_world_load", [&] {
    if (!path) return null_argument("ldc_world_load", "path");
    if (!out) return null_argument("ldc_world_load", "out");
    return adopt(ldc::load_world(path), out);
  });
}

ldc_status ldc_world_save(const ldc_world* world, const char* path) {
  return with_world("ldc_world_save", world, Access::kRead, [&](WorldState& w) {
    if (!path) return null_argument("ldc_world_save", "path");
    return from_status(ldc::save_world(w.world(), path));
  });
}

ldc_status ldc_world_destroy(ldc_world* world) {
  if (!world) return LDC_OK;
  return guarded("ldc_world_destroy", [&] {
    Lease lease(world_handles(), handle_bits(world), Access::kWrite);
    if (lease.status() != LDC_OK) return lease.refusal("ldc_world_destroy", "world");
    WorldState& w = lease.get<WorldState>();
    // Its cascades outlive it (they keep what was voxelized): each is taken
    // alone first, so none is in use while it is handed over.
    std::vector<std::unique_ptr<Lease>> cascades;
    cascades.reserve(w.cascades.size());
    for (uintptr_t handle : w.cascades) {
      cascades.push_back(std::make_unique<Lease>(cascades_handles(), handle, Access::kWrite));
      const Lease& c = *cascades.back();
      if (c.status() != LDC_OK) return c.refusal("ldc_world_destroy", "cascades made from the world");
    }
    for (const std::unique_ptr<Lease>& c : cascades) {
      CascadesState& state = c->get<CascadesState>();
      state.orphan = w.live.release_cascades(state.id);
      state.world = 0;
    }
    delete lease.retire<WorldState>();
    return LDC_OK;
  });
}

ldc_status ldc_world_get_info(const ldc_world* world, ldc_world_info* out) {
  return with_world("ldc_world_get_info", world, Access::kRead, [&](WorldState& state) {
    if (!out) return null_argument("ldc_world_get_info", "out");
    const ldc::World& w = state.world();
    const ldc::WorldStats s = w.stats();
    const ldc::WorldBox box = w.box();
    ldc_world_info info{};
    put(w.lattice().origin, info.origin);
    info.cell_size = w.lattice().cell_size;
    info.chunk_size = w.chunk_size();
    put(w.chunk_origin(), info.chunk_origin);
    put(w.chunk_dims(), info.chunk_dims);
    put(box.min, info.box_min);
    put(box.max, info.box_max);
    info.chunks_empty = s.chunks_empty;
    info.chunks_solid = s.chunks_solid;
    info.chunks_mixed = s.chunks_mixed;
    info.points = s.points;
    info.memory_bytes = s.memory_bytes;
    info.edit_version = state.live.version();
    *out = info;
    return LDC_OK;
  });
}

int ldc_world_inside(const ldc_world* world, const double point[3]) {
  int inside = 0;
  with_world("ldc_world_inside", world, Access::kRead, [&](WorldState& w) {
    if (!point) return null_argument("ldc_world_inside", "point");
    const glm::dvec3 p = vec3(point);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_inside: point must be finite");
    }
    inside = w.world().inside(p) ? 1 : 0;
    return LDC_OK;
  });
  return inside;
}

// ---------------------------------------------------------------------------
// Edits

static ldc::Result<ldc::Brush> to_brush(const ldc_brush& b) {
  const int32_t shape = raw_enum(b.shape);
  switch (shape) {
    case LDC_BRUSH_SPHERE: return ldc::Brush::sphere(vec3(b.centre), b.radius, b.material);
    case LDC_BRUSH_BOX: return ldc::Brush::box(vec3(b.centre), vec3(b.half_extents), b.material);
    case LDC_BRUSH_CAPSULE: return ldc::Brush::capsule(vec3(b.a), vec3(b.b), b.radius, b.material);
  }
  return ldc::Status(ldc::ErrorCode::kInvalidArgument,
                     "brush shape " + std::to_string(shape) + ": use sphere (0), box (1) or capsule (2)");
}

static ldc::Result<ldc::EditOp> to_op(int32_t op) {
  switch (op) {
    case LDC_EDIT_SUBTRACT: return ldc::EditOp::kSubtract;
    case LDC_EDIT_UNION: return ldc::EditOp::kUnion;
    case LDC_EDIT_PAINT: return ldc::EditOp::kPaint;
    case LDC_EDIT_INTERSECT: return ldc::EditOp::kIntersect;
  }
  return ldc::Status(ldc::ErrorCode::kInvalidArgument,
                     "edit op " + std::to_string(op) + ": use subtract (0), union (1), paint (2) or intersect (3)");
}

ldc_status ldc_world_edit(ldc_world* world, const ldc_brush* brush, ldc_edit_op op, ldc_edit_result* out) {
  return with_world("ldc_world_edit", world, Access::kWrite, [&](WorldState& w) {
    if (!brush) return null_argument("ldc_world_edit", "brush");
    ldc::Result<ldc::Brush> b = to_brush(*brush);
    if (!b.ok()) return from_status(b.status());
    ldc::Result<ldc::EditOp> o = to_op(raw_enum(op));
    if (!o.ok()) return from_status(o.status());
    ldc::Result<ldc::EditReceipt> receipt = w.live.apply(b.value(), o.value());
    if (!receipt.ok()) return from_status(receipt.status());
    if (out) {
      out->version = receipt->version;
      out->chunks_changed = receipt->changed_chunks.size();
    }
    return LDC_OK;
  });
}

ldc_status ldc_world_take_dirty(ldc_world* world, ldc_dirty_chunk* out, size_t capacity, size_t* count) {
  return with_world("ldc_world_take_dirty", world, Access::kWrite, [&](WorldState& w) {
    if (!count) return null_argument("ldc_world_take_dirty", "count");
    if (ldc_status s = check_buffer("ldc_world_take_dirty", "out", out, capacity, sizeof *out); s != LDC_OK) return s;
    const size_t n = w.live.pending_changes();
    *count = n;
    if (!out) return LDC_OK;
    if (capacity < n) {
      return fail(LDC_BUFFER_TOO_SMALL, "ldc_world_take_dirty: " + std::to_string(n) +
                                            " dirty chunks, capacity " + std::to_string(capacity));
    }
    size_t i = 0;
    for (const ldc::ChunkChange& c : w.live.take_changes()) {
      ldc_dirty_chunk d{};
      put(c.chunk, d.chunk);
      d.flags = (c.data ? LDC_DIRTY_DATA : 0u) | (c.mesh ? LDC_DIRTY_MESH : 0u);
      d.version = c.version;
      if (c.data) {
        put(c.node_lo, d.node_lo);
        put(c.node_hi, d.node_hi);
      }
      out[i++] = d;
    }
    return LDC_OK;
  });
}

// ---------------------------------------------------------------------------
// Meshing

// The chunk meshes, built on first use and brought up to date with the edits since.
static ldc::Result<const ldc::ChunkedMesh*> synced_meshes(WorldState& w) {
  if (!w.live.meshes()) {
    ldc::Status s = w.live.enable_meshes(w.live.config().contour);
    if (!s.ok()) return s;
  }
  ldc::Status s = w.live.update_meshes();
  if (!s.ok()) return s;
  return w.live.meshes();
}

// The buffer checks of ldc_world_mesh_chunk, before any meshing.
static ldc_status check_mesh_buffers(const ldc_mesh_buffers& b) {
  const char* call = "ldc_world_mesh_chunk";
  if (!b.positions && !b.indices) {  // a size query
    if (b.vertex_capacity == 0 && b.triangle_capacity == 0) return LDC_OK;
    return fail(LDC_INVALID_ARGUMENT, std::string(call) + ": positions and indices are NULL with capacities " +
                                          std::to_string(b.vertex_capacity) + " and " +
                                          std::to_string(b.triangle_capacity) + " (a size query passes 0 and 0)");
  }
  if (!b.positions || !b.indices) {
    return fail(LDC_INVALID_ARGUMENT, std::string(call) + ": positions and indices must both be set "
                                                          "(or both NULL for a size query)");
  }
  if (impossible_array(b.vertex_capacity, 3 * sizeof(float))) {
    return too_large_array(call, "vertex_capacity", b.vertex_capacity, 3 * sizeof(float));
  }
  if (impossible_array(b.triangle_capacity, 3 * sizeof(uint32_t))) {
    return too_large_array(call, "triangle_capacity", b.triangle_capacity, 3 * sizeof(uint32_t));
  }
  return LDC_OK;
}

static void copy_mesh(const ldc::ContourMesh& m, ldc_mesh_buffers* b) {
  for (size_t i = 0; i < m.vertex_count(); ++i) {
    for (int k = 0; k < 3; ++k) b->positions[3 * i + k] = float(m.positions[i][k]);
    if (b->normals) put(m.normals[i], b->normals + 3 * i);
    if (b->vertex_materials) b->vertex_materials[i] = m.vertex_material[i];
  }
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) b->indices[3 * t + k] = m.triangles[t][k];
    if (b->triangle_materials) b->triangle_materials[t] = m.triangle_material[t];
  }
}

ldc_status ldc_world_mesh_chunk(ldc_world* world, const int32_t chunk[3], ldc_mesh_buffers* buffers) {
  return with_world("ldc_world_mesh_chunk", world, Access::kWrite, [&](WorldState& w) {
    if (!chunk) return null_argument("ldc_world_mesh_chunk", "chunk");
    if (!buffers) return null_argument("ldc_world_mesh_chunk", "buffers");
    if (ldc_status s = check_mesh_buffers(*buffers); s != LDC_OK) return s;
    ldc::Result<const ldc::ChunkedMesh*> meshes = synced_meshes(w);
    if (!meshes.ok()) return from_status(meshes.status());
    const ldc::ChunkMesh* cm = (*meshes)->find(ivec3(chunk));
    static const ldc::ContourMesh kEmpty;
    const ldc::ContourMesh& m = cm ? cm->mesh : kEmpty;
    buffers->vertex_count = m.vertex_count();
    buffers->triangle_count = m.triangle_count();
    if (!buffers->positions) return LDC_OK;  // a size query (check_mesh_buffers)
    if (buffers->vertex_capacity < m.vertex_count() || buffers->triangle_capacity < m.triangle_count()) {
      return fail(LDC_BUFFER_TOO_SMALL,
                  "ldc_world_mesh_chunk: chunk (" + std::to_string(chunk[0]) + ", " + std::to_string(chunk[1]) +
                      ", " + std::to_string(chunk[2]) + ") has " + std::to_string(m.vertex_count()) +
                      " vertices and " + std::to_string(m.triangle_count()) + " triangles; capacity " +
                      std::to_string(buffers->vertex_capacity) + " and " +
                      std::to_string(buffers->triangle_capacity));
    }
    copy_mesh(m, buffers);
    return LDC_OK;
  });
}

// ---------------------------------------------------------------------------
// Ray casts

// The largest of the arrays a ray cast of `count` rays takes, the caller's and its own.
constexpr size_t kRayBytes = std::max({sizeof(ldc_ray), sizeof(ldc_ray_hit), sizeof(ldc::Ray), sizeof(ldc::RayHit)});

ldc_status ldc_world_ray_cast(ldc_world* world, const ldc_ray* rays, size_t count, ldc_ray_hit* hits) {
  return with_world("ldc_world_ray_cast", world, Access::kWrite, [&](WorldState& w) {
    if (count == 0) return LDC_OK;
    if (!rays) return null_argument("ldc_world_ray_cast", "rays");
    if (!hits) return null_argument("ldc_world_ray_cast", "hits");
    if (impossible_array(count, kRayBytes)) return too_large_array("ldc_world_ray_cast", "count", count, kRayBytes);
    w.live.update_queries();
    std::vector<ldc::Ray> in(count);
    for (size_t i = 0; i < count; ++i) {
      in[i].origin = vec3(rays[i].origin);
      in[i].direction = vec3(rays[i].direction);
      in[i].max_distance = rays[i].max_distance;
    }
    std::vector<ldc::RayHit> out(count);
    if (ldc_status s = from_status(w.live.queries().ray_cast(in, out)); s != LDC_OK) return s;
    for (size_t i = 0; i < count; ++i) {
      ldc_ray_hit h{};
      h.hit = out[i].hit ? 1 : 0;
      h.started_inside = out[i].started_inside ? 1 : 0;
      h.distance = out[i].distance;
      put(out[i].point, h.point);
      put(out[i].normal, h.normal);
      h.material = out[i].material;
      hits[i] = h;
    }
    return LDC_OK;
  });
}

// ---------------------------------------------------------------------------
// Navigation

void ldc_nav_config_default(ldc_nav_config* config) {
  if (!config) return;
  const ldc::NavConfig d;
  *config = ldc_nav_config{};
  config->up_axis = d.up_axis;
  config->agent_height = d.agent_height;
  config->agent_radius = d.agent_radius;
  config->max_climb = d.max_climb;
  config->max_slope_degrees = d.max_slope_degrees;
  config->max_nodes = 2048;
  put(ldc::PathQueryOptions{}.search_half_extents, config->search_half_extents);
  config->filters = (d.filter_low_hanging_obstacles ? LDC_NAV_FILTER_LOW_HANGING : 0u) |
                    (d.filter_ledge_spans ? LDC_NAV_FILTER_LEDGES : 0u) |
                    (d.filter_low_height_spans ? LDC_NAV_FILTER_LOW_HEIGHT : 0u);
}

ldc_status ldc_world_set_nav_config(ldc_world* world, const ldc_nav_config* config) {
  return with_world("ldc_world_set_nav_config", world, Access::kWrite, [&](WorldState& w) {
    if (!config) return null_argument("ldc_world_set_nav_config", "config");
    ldc::NavConfig c;
    c.up_axis = config->up_axis;
    c.agent_height = config->agent_height;
    c.agent_radius = config->agent_radius;
    c.max_climb = config->max_climb;
    c.max_slope_degrees = config->max_slope_degrees;
    c.filter_low_hanging_obstacles = (config->filters & LDC_NAV_FILTER_LOW_HANGING) != 0;
    c.filter_ledge_spans = (config->filters & LDC_NAV_FILTER_LEDGES) != 0;
    c.filter_low_height_spans = (config->filters & LDC_NAV_FILTER_LOW_HEIGHT) != 0;
    if (config->material_area_count > 65536) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_set_nav_config: material_area_count " +
                                            std::to_string(config->material_area_count) +
                                            " must be at most 65536 (one area per 16-bit material id)");
    }
    if (config->material_area_count > 0 && !config->material_areas) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_set_nav_config: material_areas is NULL with material_area_count " +
                                            std::to_string(config->material_area_count));
    }
    if (config->material_area_count > 0) {
      c.material_areas.assign(config->material_areas, config->material_areas + config->material_area_count);
    }
    if (config->filters & ~(LDC_NAV_FILTER_LOW_HANGING | LDC_NAV_FILTER_LEDGES | LDC_NAV_FILTER_LOW_HEIGHT)) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_set_nav_config: filters has unknown bits " +
                                            std::to_string(config->filters));
    }
    if (ldc_status s = from_status(ldc::check_nav_config(c, w.world())); s != LDC_OK) return s;
    if (config->max_nodes < 16 || config->max_nodes > (1 << 20)) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_set_nav_config: max_nodes " +
                                            std::to_string(config->max_nodes) + " must be in 16 .. 1048576");
    }
    const glm::dvec3 half = vec3(config->search_half_extents);
    if (!(half.x > 0 && half.y > 0 && half.z > 0) || !std::isfinite(half.x + half.y + half.z)) {
      return fail(LDC_INVALID_ARGUMENT,
                  "ldc_world_set_nav_config: search_half_extents must be finite and > 0 on every axis");
    }
    w.live.disable_nav();  // rebuilt with these at the next path query
    for (auto& [id, l] : w.nav_links) l.mesh_id.reset();
    if (ldc_status s = from_status(w.live.set_max_path_nodes(config->max_nodes)); s != LDC_OK) return s;
    w.nav_config = c;
    w.search_half_extents = half;
    return LDC_OK;
  });
}

// The path query on a nav mesh built on first use and brought up to date with the edits since.
// A mesh built afresh gets the world's off-mesh links.
static ldc::Result<ldc::NavQuery*> synced_path_query(WorldState& w) {
  if (!w.live.nav()) {
    ldc::Status s = w.live.enable_nav(w.nav_config);
    if (!s.ok()) return s;
    ldc::NavMesh& nav = *w.live.nav();
    for (auto& [id, l] : w.nav_links) {
      ldc::Result<uint32_t> added = nav.add_link(l.link);  // checked when the caller added it
      if (!added.ok()) {
        w.live.disable_nav();
        for (auto& [other, m] : w.nav_links) m.mesh_id.reset();
        return ldc::Status(added.status().code(), "nav link " + std::to_string(id) + ": " + added.status().message());
      }
      l.mesh_id = added.value();
    }
  }
  return w.live.path_query();
}

ldc_status ldc_world_find_path(ldc_world* world, const double from[3], const double to[3], double* corners,
                               size_t corner_capacity, ldc_path_info* info) {
  return with_world("ldc_world_find_path", world, Access::kWrite, [&](WorldState& w) {
    if (!from || !to) return null_argument("ldc_world_find_path", from ? "to" : "from");
    if (!info) return null_argument("ldc_world_find_path", "info");
    if (ldc_status s = check_buffer("ldc_world_find_path", "corners", corners, corner_capacity, 3 * sizeof(double));
        s != LDC_OK) {
      return s;
    }
    ldc::Result<ldc::NavQuery*> query = synced_path_query(w);
    if (!query.ok()) return from_status(query.status());
    ldc::PathQueryOptions options;
    options.search_half_extents = w.search_half_extents;
    options.filter = w.nav_filter;
    ldc::Result<ldc::NavPath> path = (*query)->find_path(vec3(from), vec3(to), options);
    if (!path.ok()) {
      const bool no_floor = path.status().message().find("no walkable floor") != std::string::npos;
      return fail(no_floor ? LDC_NOT_FOUND : static_cast<ldc_status>(path.status().code()),
                  path.status().message());
    }
    const ldc::NavPath& p = path.value();
    ldc_path_info r{};
    r.status = static_cast<ldc_path_status>(p.status);
    r.corner_count = p.corners.size();
    r.length = p.length;
    r.nodes_searched = p.nodes_searched;
    *info = r;
    if (corners && corner_capacity < p.corners.size()) {
      return fail(LDC_BUFFER_TOO_SMALL, "ldc_world_find_path: " + std::to_string(p.corners.size()) +
                                            " corners, capacity " + std::to_string(corner_capacity));
    }
    if (corners) {
      for (size_t i = 0; i < p.corners.size(); ++i) put(p.corners[i], corners + 3 * i);
    }
    return LDC_OK;
  });
}

void ldc_nav_filter_default(ldc_nav_filter* filter) {
  if (!filter) return;
  const ldc::NavFilter d;
  *filter = ldc_nav_filter{};
  filter->include_flags = d.include_flags;
  filter->exclude_flags = d.exclude_flags;
}

ldc_status ldc_world_set_nav_filter(ldc_world* world, const ldc_nav_filter* filter) {
  return with_world("ldc_world_set_nav_filter", world, Access::kWrite, [&](WorldState& w) {
    ldc::NavFilter f;
    if (filter) {
      // 64 areas (0 .. 63): a longer array is a wrong count, not more areas.
      for (auto [count, set, name] : {std::tuple{filter->area_cost_count, filter->area_costs != nullptr, "area_cost"},
                                      std::tuple{filter->area_flag_count, filter->area_flags != nullptr, "area_flag"}}) {
        if (count > 64) {
          return fail(LDC_INVALID_ARGUMENT, std::string("ldc_world_set_nav_filter: ") + name + "_count " +
                                                std::to_string(count) + " must be at most 64 (areas 0 .. 63)");
        }
        if (count > 0 && !set) {
          return fail(LDC_INVALID_ARGUMENT, std::string("ldc_world_set_nav_filter: ") + name + "s is NULL with " +
                                                name + "_count " + std::to_string(count));
        }
      }
      if (filter->area_cost_count > 0) {
        f.area_cost.assign(filter->area_costs, filter->area_costs + filter->area_cost_count);
      }
      if (filter->area_flag_count > 0) {
        f.area_flags.assign(filter->area_flags, filter->area_flags + filter->area_flag_count);
      }
      f.include_flags = filter->include_flags;
      f.exclude_flags = filter->exclude_flags;
      for (size_t i = 0; i < f.area_cost.size(); ++i) {
        if (!(f.area_cost[i] >= 0.01) || !std::isfinite(f.area_cost[i])) {
          return fail(LDC_INVALID_ARGUMENT, "ldc_world_set_nav_filter: area_costs[" + std::to_string(i) + "] = " +
                                                std::to_string(f.area_cost[i]) + " must be a finite number >= 0.01");
        }
      }
      if (ldc_status s = from_status(ldc::check_nav_filter(f)); s != LDC_OK) return s;
    }
    w.nav_filter = std::move(f);
    return LDC_OK;
  });
}

void ldc_nav_link_default(ldc_nav_link* link) {
  if (!link) return;
  const ldc::NavLink d;
  *link = ldc_nav_link{};
  put(d.a, link->a);
  put(d.b, link->b);
  link->bidirectional = d.bidirectional ? 1 : 0;
  link->cost = d.cost;
  link->flags = d.flags;
  link->radius = d.radius;
}

ldc_status ldc_world_add_nav_link(ldc_world* world, const ldc_nav_link* link, uint32_t* id_out) {
  return with_world("ldc_world_add_nav_link", world, Access::kWrite, [&](WorldState& w) {
    if (!link) return null_argument("ldc_world_add_nav_link", "link");
    if (!id_out) return null_argument("ldc_world_add_nav_link", "id_out");
    // Checked here, not only by NavMesh::add_link: the mesh may not be built
    // yet, and the caller's names are the fields of ldc_nav_link.
    for (auto [end, name] : {std::pair{link->a, "a"}, std::pair{link->b, "b"}}) {
      if (!std::isfinite(end[0]) || !std::isfinite(end[1]) || !std::isfinite(end[2])) {
        return fail(LDC_INVALID_ARGUMENT, std::string("ldc_world_add_nav_link: link->") + name +
                                              " must be finite (" + std::to_string(end[0]) + ", " +
                                              std::to_string(end[1]) + ", " + std::to_string(end[2]) + ")");
      }
    }
    if (!std::isfinite(link->cost)) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_add_nav_link: link->cost " + std::to_string(link->cost) +
                                            " must be finite (< 0: the straight distance)");
    }
    if (!(link->radius > 0.0 && link->radius <= 100.0)) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_add_nav_link: link->radius " + std::to_string(link->radius) +
                                            " must be in (0, 100] m");
    }
    if (link->bidirectional != 0 && link->bidirectional != 1) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_add_nav_link: link->bidirectional " +
                                            std::to_string(link->bidirectional) + " must be 0 or 1");
    }
    WorldState::Link l;
    l.link.a = vec3(link->a);
    l.link.b = vec3(link->b);
    l.link.bidirectional = link->bidirectional != 0;
    l.link.cost = link->cost;
    l.link.flags = link->flags;
    l.link.radius = link->radius;
    if (w.next_link_id == UINT32_MAX) {
      return fail(LDC_TOO_LARGE, "ldc_world_add_nav_link: every link id has been used");
    }
    const uint32_t id = w.next_link_id;
    auto it = w.nav_links.emplace(id, l).first;
    if (ldc::NavMesh* nav = w.live.nav()) {  // built: the link joins it now
      ldc::Result<uint32_t> added = nav->add_link(l.link);
      if (!added.ok()) {
        w.nav_links.erase(it);
        return from_status(added.status());
      }
      it->second.mesh_id = added.value();
    }
    ++w.next_link_id;
    *id_out = id;
    return LDC_OK;
  });
}

ldc_status ldc_world_remove_nav_link(ldc_world* world, uint32_t id) {
  return with_world("ldc_world_remove_nav_link", world, Access::kWrite, [&](WorldState& w) {
    auto it = w.nav_links.find(id);
    if (it == w.nav_links.end()) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_remove_nav_link: no nav link with id " + std::to_string(id));
    }
    ldc::NavMesh* nav = w.live.nav();
    if (nav && it->second.mesh_id) {
      if (ldc_status s = from_status(nav->remove_link(*it->second.mesh_id)); s != LDC_OK) return s;
    }
    w.nav_links.erase(it);
    return LDC_OK;
  });
}

ldc_status ldc_world_nav_link_attached(ldc_world* world, uint32_t id, int32_t* attached) {
  return with_world("ldc_world_nav_link_attached", world, Access::kWrite, [&](WorldState& w) {
    if (!attached) return null_argument("ldc_world_nav_link_attached", "attached");
    if (!w.nav_links.count(id)) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_world_nav_link_attached: no nav link with id " + std::to_string(id));
    }
    ldc::Result<ldc::NavQuery*> query = synced_path_query(w);  // builds or updates the mesh
    if (!query.ok()) return from_status(query.status());
    const std::optional<uint32_t> mesh_id = w.nav_links.at(id).mesh_id;
    *attached = mesh_id && w.live.nav()->link_attached(*mesh_id) ? 1 : 0;
    return LDC_OK;
  });
}

// ---------------------------------------------------------------------------
// Cascades

void ldc_cascade_config_default(ldc_cascade_config* config) {
  if (!config) return;
  const ldc::CascadeConfig d;
  *config = ldc_cascade_config{};
  config->levels = d.levels;
  config->resolution = d.resolution;
  config->voxel_size = d.voxel_size;
}

ldc_status ldc_cascades_create(ldc_world* world, const ldc_cascade_config* config, ldc_cascades** out) {
  return with_world("ldc_cascades_create", world, Access::kWrite, [&](WorldState& w) {
    if (!config) return null_argument("ldc_cascades_create", "config");
    if (!out) return null_argument("ldc_cascades_create", "out");
    ldc::CascadeConfig c;
    c.levels = config->levels;
    c.resolution = config->resolution;
    c.voxel_size = config->voxel_size;
    w.cascades.reserve(w.cascades.size() + 1);  // the push_back below cannot fail
    auto state = std::make_unique<CascadesState>();
    ldc::Result<ldc::CascadesId> id = w.live.add_cascades(c);
    if (!id.ok()) return from_status(id.status());
    state->world = handle_bits(world);
    state->id = id.value();
    const uintptr_t handle = cascades_handles().insert(state.get());
    if (!handle) {
      (void)w.live.release_cascades(id.value());
      return fail(LDC_TOO_LARGE, "ldc_cascades_create: too many live cascades (destroy some first)");
    }
    state.release();  // the handle owns it now
    w.cascades.push_back(handle);
    *out = reinterpret_cast<ldc_cascades*>(handle);
    return LDC_OK;
  });
}

ldc_status ldc_cascades_destroy(ldc_cascades* cascades) {
  if (!cascades) return LDC_OK;
  return guarded("ldc_cascades_destroy", [&] {
    Lease lease(cascades_handles(), handle_bits(cascades), Access::kWrite);
    if (lease.status() != LDC_OK) return lease.refusal("ldc_cascades_destroy", "cascades");
    CascadesState& c = lease.get<CascadesState>();
    if (c.world) {  // the world stops feeding them
      Lease world(world_handles(), c.world, Access::kWrite);
      if (world.status() != LDC_OK) return world.refusal("ldc_cascades_destroy", "the world of cascades");
      WorldState& w = world.get<WorldState>();
      std::erase(w.cascades, handle_bits(cascades));
      (void)w.live.release_cascades(c.id);
    }
    delete lease.retire<CascadesState>();
    return LDC_OK;
  });
}

ldc_status ldc_cascades_update_level(ldc_cascades* cascades, int32_t level, const double camera[3],
                                     ldc_cascade_update* out) {
  const char* call = "ldc_cascades_update_level";
  return with_cascades(call, cascades, Access::kRead, [&](CascadesState& state, WorldState* w) {
    if (!camera) return null_argument(call, "camera");
    if (!w) {
      return fail(LDC_INVALID_ARGUMENT,
                  std::string(call) + ": the world these cascades were made from has been destroyed");
    }
    ldc::Cascades& c = cascades_of(state, w);
    if (level < 0 || level >= c.levels()) {
      return fail(LDC_INVALID_ARGUMENT, std::string(call) + ": level " + std::to_string(level) + " must be in 0 .. " +
                                            std::to_string(c.levels() - 1));
    }
    ldc::Result<ldc::CascadeUpdate> u = c.update_level(w->world(), level, vec3(camera));
    if (!u.ok()) return from_status(u.status());
    if (out) {
      ldc_cascade_update r{};
      r.level = u->level;
      put(u->shift, r.shift);
      r.full = u->full ? 1 : 0;
      r.voxels = u->voxels;
      r.seconds = u->seconds;
      put(c.level_box(level).lo, r.box_lo);
      put(c.level_box(level).dims, r.box_dims);
      *out = r;
    }
    return LDC_OK;
  });
}

// The buffer checks of ldc_cascades_read_level, before any packing.
static ldc_status check_gbuffer_buffers(const ldc_gbuffer_buffers& b) {
  const char* call = "ldc_cascades_read_level";
  if (!b.albedo && !b.normal && !b.occupancy && !b.emission) {  // a size query
    return check_buffer(call, "every texel array", nullptr, b.texel_capacity, sizeof(uint32_t));
  }
  if (impossible_array(b.texel_capacity, sizeof(uint32_t))) {
    return too_large_array(call, "texel_capacity", b.texel_capacity, sizeof(uint32_t));
  }
  return LDC_OK;
}

ldc_status ldc_cascades_read_level(const ldc_cascades* cascades, int32_t level, ldc_gbuffer_buffers* buffers) {
  return with_cascades("ldc_cascades_read_level", cascades, Access::kRead, [&](CascadesState& state, WorldState* w) {
    if (!buffers) return null_argument("ldc_cascades_read_level", "buffers");
    if (ldc_status s = check_gbuffer_buffers(*buffers); s != LDC_OK) return s;
    const ldc::Cascades& c = cascades_of(state, w);
    if (level < 0 || level >= c.levels()) {
      return fail(LDC_INVALID_ARGUMENT, "ldc_cascades_read_level: level " + std::to_string(level) +
                                            " must be in 0 .. " + std::to_string(c.levels() - 1));
    }
    const size_t n = size_t(c.resolution());
    const size_t texels = size_t(ldc::kFaces) * n * n * n;
    buffers->texel_count = texels;
    ldc_gbuffer_buffers& b = *buffers;
    if (!b.albedo && !b.normal && !b.occupancy && !b.emission) return LDC_OK;
    if (b.texel_capacity < texels) {
      return fail(LDC_BUFFER_TOO_SMALL, "ldc_cascades_read_level: " + std::to_string(texels) +
                                            " texels, capacity " + std::to_string(b.texel_capacity));
    }
    ldc::PackedGBuffer& p = state.scratch;
    c.pack_level(level, &p);
    for (int f = 0; f < ldc::kFaces; ++f)
      for (int z = 0; z < int(n); ++z)
        for (int y = 0; y < int(n); ++y)
          for (int x = 0; x < int(n); ++x) {
            const size_t src = p.texel(f, level, {x, y, z});
            const size_t dst = (size_t(z) * n + size_t(y)) * n * ldc::kFaces + size_t(f) * n + size_t(x);
            if (b.albedo) b.albedo[dst] = p.albedo[src];
            if (b.normal) b.normal[dst] = p.normal[src];
            if (b.occupancy) b.occupancy[dst] = p.occupancy[src];
            if (b.emission) b.emission[dst] = p.emission[src];
          }
    return LDC_OK;
  });
}

}  // extern "C"
