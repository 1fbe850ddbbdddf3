// Camera-centred cascades: toroidal storage, scrolling, dirty refresh, schedule.
#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <sstream>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "ldc/internal/ray_math.h"
#include "ldc/internal/vec_text.h"
#include "voxelize/detail/voxel_common.h"
#include "voxelize/voxelize.h"

namespace ldc {

namespace {

// Blocks of a level's update: 16^3 voxels, halved (down to 4^3) while
// fewer than kBusyBlocksPerWorker blocks per worker overlap the world's box
// of chunks. A coarse level's 32^3 box is mostly air around a landscape that
// fits in one or two 16^3 blocks, which left the second core idle (level 4
// of the default landscape: 13.1 ms on 1 thread, 12.3 ms on 2). Smaller
// blocks cost more per voxel (each ray is entered once per block), so
// levels whose work is already spread keep 16.
constexpr int kBlockEdge = 16;
constexpr int kSmallestBlockEdge = 4;
constexpr int kBusyBlocksPerWorker = 2;
constexpr uint32_t kOwnAlpha = 127u << 24;
constexpr uint32_t kPropagatedAlpha = 64u << 24;
constexpr uint32_t kAlphaMask = 0xffu << 24;
// Largest camera coordinate in level voxels: keeps every box in int range.
constexpr double kMaxCameraVoxel = double(1 << 28);

int wrap(int g, int n) { return detail::floor_mod(g, n); }
glm::ivec3 wrap(const glm::ivec3& g, int n) { return {wrap(g.x, n), wrap(g.y, n), wrap(g.z, n)}; }

size_t local_index(const glm::ivec3& t, int n) {
  return (size_t(t.z) * size_t(n) + size_t(t.y)) * size_t(n) + size_t(t.x);
}

glm::ivec3 face_direction(int f) {
  glm::ivec3 d(0);
  d[face_axis(f)] = face_positive(f) ? 1 : -1;
  return d;
}

VoxelBox grow(const VoxelBox& b, int r) { return {b.lo - r, b.dims + 2 * r}; }

// The voxels, of m lattice cells each, of the world's box of chunks: outside
// it everything is air.
VoxelBox chunk_voxel_box(const World& world, int m) {
  const int64_t c = world.chunk_size();
  glm::ivec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = int(detail::floor_div64(int64_t(world.chunk_origin()[a]) * c, m));
    hi[a] = int(detail::floor_div64((int64_t(world.chunk_origin()[a]) + world.chunk_dims()[a]) * c - 1, m));
  }
  return {lo, glm::max(hi - lo + 1, glm::ivec3(0))};  // empty for a world of no chunks
}

// `region` cut into blocks for the workers (see kBlockEdge). `busy`: where
// the work is (chunk_voxel_box), or empty to keep kBlockEdge.
std::vector<VoxelBox> update_blocks(const VoxelBox& region, const VoxelBox& busy, int workers) {
  std::vector<VoxelBox> blocks = detail::split_blocks(region, kBlockEdge);
  if (busy.empty()) return blocks;
  const auto holds_work = [&](const VoxelBox& b) { return !intersect(b, busy).empty(); };
  for (int edge = kBlockEdge / 2; edge >= kSmallestBlockEdge; edge /= 2) {
    if (std::count_if(blocks.begin(), blocks.end(), holds_work) >= kBusyBlocksPerWorker * workers) break;
    blocks = detail::split_blocks(region, edge);
  }
  return blocks;
}

// The exposed slabs when a box of edge n moves from `old_lo` to `lo` (|shift| < n).
std::vector<VoxelBox> exposed_slabs(const glm::ivec3& old_lo, const glm::ivec3& lo, int n) {
  std::vector<VoxelBox> out;
  glm::ivec3 keep_lo = lo, keep_hi = lo + n;  // the part of the new box already covered
  for (int a = 0; a < 3; ++a) {
    const int s = lo[a] - old_lo[a];
    if (s == 0) continue;
    VoxelBox slab{keep_lo, keep_hi - keep_lo};
    if (s > 0) {
      slab.lo[a] = lo[a] + n - s;
      slab.dims[a] = s;
      keep_hi[a] = lo[a] + n - s;
    } else {
      slab.lo[a] = lo[a];
      slab.dims[a] = -s;
      keep_lo[a] = lo[a] - s;
    }
    out.push_back(slab);
  }
  return out;
}

}  // namespace

struct Cascades::ObjectCache {
  // [level][object]: built on first use.
  std::vector<std::vector<std::unique_ptr<detail::ObjectWorld>>> worlds;
  std::vector<WorldBox> bounds;  // per object
};

Cascades::Cascades(Cascades&&) noexcept = default;
Cascades& Cascades::operator=(Cascades&&) noexcept = default;
Cascades::~Cascades() = default;

Status check_cascade_config(const Lattice& lattice, const CascadeConfig& config) {
  if (config.levels < 1 || config.levels > 16) {
    return {ErrorCode::kInvalidArgument, "cascade levels " + std::to_string(config.levels) + ": must be 1 .. 16"};
  }
  if (config.resolution < 4 || config.resolution > 256 || config.resolution % 2 != 0) {
    return {ErrorCode::kInvalidArgument,
            "cascade resolution " + std::to_string(config.resolution) + ": must be even, 4 .. 256"};
  }
  VoxelConfig vc{config.voxel_size, config.axis, config.supersampling};
  Status s = check_voxel_config(lattice, vc);
  if (!s.ok()) return Status(s.code(), "cascade level 0: " + s.message());
  const int m = voxel_cells(lattice, vc).value();
  if (int64_t(m) << (config.levels - 1) > kMaxVoxelCells) {
    return {ErrorCode::kInvalidArgument, "cascade: level " + std::to_string(config.levels - 1) + " would have " +
                                             std::to_string(int64_t(m) << (config.levels - 1)) +
                                             " cells per voxel (at most " + std::to_string(kMaxVoxelCells) +
                                             "): use fewer levels or a smaller voxel size"};
  }
  return check_material_table(config.materials);
}

Result<Cascades> Cascades::create(const Lattice& lattice, const CascadeConfig& config) {
  Status s = check_cascade_config(lattice, config);
  if (!s.ok()) return s;
  Cascades c;
  c.lattice_ = lattice;
  c.config_ = config;
  c.base_cells_ = voxel_cells(lattice, VoxelConfig{config.voxel_size, config.axis, config.supersampling}).value();
  c.texture_.resize(config.resolution, config.levels);
  const size_t n3 = size_t(config.resolution) * size_t(config.resolution) * size_t(config.resolution);
  c.occupancy_.assign(size_t(config.levels), std::vector<float>(n3, 0.0f));
  c.own_faces_.assign(size_t(config.levels), std::vector<uint8_t>(n3, 0));
  c.propagated_faces_.assign(size_t(config.levels), std::vector<uint8_t>(n3, 0));
  c.boxes_.assign(size_t(config.levels), VoxelBox{});
  c.valid_.assign(size_t(config.levels), false);
  c.pending_.resize(size_t(config.levels));
  c.object_cache_ = std::make_unique<ObjectCache>();
  c.object_cache_->worlds.resize(size_t(config.levels));
  return c;
}

int Cascades::scheduled_level(uint64_t frame, int levels) {
  return std::min(std::countr_one(frame), levels - 1);
}

Status Cascades::add_object(const StaticObject& object) {
  Status s = check_static_object(object);
  if (!s.ok()) return s;
  objects_.push_back(object);
  object_cache_->bounds.push_back(detail::object_bounds(object));
  for (auto& level : object_cache_->worlds) level.resize(objects_.size());
  for (int k = 0; k < levels(); ++k) {
    if (!valid_[size_t(k)]) continue;
    const VoxelBox vb = detail::voxels_of_box(object_cache_->bounds.back(), lattice_.origin, voxel_size(k));
    if (!intersect(vb, boxes_[size_t(k)]).empty()) pending_[size_t(k)].push_back(vb);
  }
  return {};
}

Status Cascades::object_sources(int level, Context* ctx) {
  auto& built = object_cache_->worlds[size_t(level)];
  for (size_t i = 0; i < objects_.size(); ++i) {
    if (built[i]) continue;
    const VoxelBox vb = detail::voxels_of_box(object_cache_->bounds[i], lattice_.origin, voxel_size(level));
    if (intersect(vb, grow(boxes_[size_t(level)], 1)).empty()) continue;
    Result<detail::ObjectWorld> w = detail::build_object_world(objects_[i], lattice_.origin, voxel_size(level), ctx);
    if (!w.ok()) return Status(w.status().code(), "object " + std::to_string(i) + ": " + w.status().message());
    built[i] = std::make_unique<detail::ObjectWorld>(std::move(w).value());
  }
  return {};
}

namespace {

// Index of face 0 of tile coordinate (0, t.y, t.z) of a level: add f * n + t.x.
size_t row_base(const PackedGBuffer& tex, int level, int ty, int tz) { return tex.texel(0, level, {0, ty, tz}); }

uint8_t unorm8(float x) { return uint8_t(std::clamp(x, 0.0f, 1.0f) * 255.0f + 0.5f); }

// A level's storage besides the textures.
struct LevelArrays {
  std::vector<float>* occupancy;
  std::vector<uint8_t>* own;
  std::vector<uint8_t>* propagated;
};

// Writes a resolved block into level k's toroidal storage, row by row and
// face by face (each face's row is contiguous in the textures but for the
// wrap).
void store_block(const detail::BlockScratch& b, int level, int n, PackedGBuffer* tex, const LevelArrays& arrays) {
  const VoxelBox& bb = b.box;
  const size_t vox = b.voxels();
  std::array<int, 256> tx{};
  for (int x = 0; x < bb.dims.x; ++x) tx[size_t(x)] = wrap(bb.lo.x + x, n);
  for (int z = 0; z < bb.dims.z; ++z) {
    const int tz = wrap(bb.lo.z + z, n);
    for (int y = 0; y < bb.dims.y; ++y) {
      const int ty = wrap(bb.lo.y + y, n);
      const size_t row = row_base(*tex, level, ty, tz);
      const size_t occ_row = local_index({0, ty, tz}, n);
      const size_t i0 = bb.index(bb.lo + glm::ivec3(0, y, z));
      for (int x = 0; x < bb.dims.x; ++x) {
        const size_t o = occ_row + size_t(tx[size_t(x)]);
        (*arrays.occupancy)[o] = b.occupancy[i0 + size_t(x)];
        (*arrays.own)[o] = b.touched[i0 + size_t(x)];
        (*arrays.propagated)[o] = 0;
      }
      uint8_t row_faces = 0;  // faces with a surface somewhere in this row
      for (int x = 0; x < bb.dims.x; ++x) row_faces = uint8_t(row_faces | b.touched[i0 + size_t(x)]);
      for (int f = 0; f < kFaces; ++f) {
        const float* coverage = b.coverage.data() + size_t(face_axis(f)) * vox + i0;
        const size_t face_row = row + size_t(f * n);
        for (int x = 0; x < bb.dims.x; ++x) tex->occupancy[face_row + size_t(tx[size_t(x)])] = unorm8(coverage[x]);
        if (!((row_faces >> f) & 1u) && tx[size_t(bb.dims.x - 1)] == tx[0] + bb.dims.x - 1) {
          const size_t first = face_row + size_t(tx[0]), count = size_t(bb.dims.x);
          std::memset(&tex->albedo[first], 0, count * sizeof(uint32_t));
          std::memset(&tex->normal[first], 0, count * sizeof(uint32_t));
          std::memset(&tex->emission[first], 0, count * sizeof(uint32_t));
          continue;
        }
        for (int x = 0; x < bb.dims.x; ++x) {
          const size_t texel = face_row + size_t(tx[size_t(x)]);
          const size_t i = i0 + size_t(x);
          if (!(b.touched[i] & (1u << f))) {
            tex->albedo[texel] = 0;
            tex->normal[texel] = 0;
            tex->emission[texel] = 0;
            continue;
          }
          const detail::FaceAccum& a = b.face[i * kFaces + size_t(f)];
          tex->albedo[texel] = pack_unorm8x4(glm::vec4(a.albedo, a.weight));
          tex->normal[texel] = (pack_snorm8x4(glm::vec4(a.normal, 0.0f)) & ~kAlphaMask) | kOwnAlpha;
          tex->emission[texel] = pack_r11g11b10f(a.emission);
        }
      }
    }
  }
}

}  // namespace

// The talk's post-processing on the packed storage, for the voxels of
// `region` (inside the level box): a solid voxel's face without a surface of
// its own takes the neighbour's on that side; stale copies are cleared. Reads
// the per-voxel face masks, touching texels only where something is copied.
static void propagate_packed(PackedGBuffer* tex, const LevelArrays& arrays, int level, int n, const VoxelBox& box,
                             const VoxelBox& region) {
  const std::vector<float>& occ = *arrays.occupancy;
  const std::vector<uint8_t>& own = *arrays.own;
  std::vector<uint8_t>& prop = *arrays.propagated;
  tbb::parallel_for(0, region.dims.z, [&](int z) {
    for (int y = 0; y < region.dims.y; ++y) {
      const glm::ivec3 g0 = region.lo + glm::ivec3(0, y, z);
      const int ty = wrap(g0.y, n), tz = wrap(g0.z, n);
      const size_t occ_row = local_index({0, ty, tz}, n);
      // Tile coordinates step with the voxel and wrap by comparison: no
      // division per voxel or neighbour (floor_mod took about 5% of a level-0
      // update in a profile; the update is 2-3% faster without it).
      int tx = wrap(g0.x, n);
      for (int x = 0; x < region.dims.x; ++x, tx = tx + 1 == n ? 0 : tx + 1) {
        const glm::ivec3 g = g0 + glm::ivec3(x, 0, 0);
        const size_t v = occ_row + size_t(tx);
        const bool solid = occ[v] > 0.0f;
        if (!solid && prop[v] == 0) continue;
        uint8_t want = 0;
        std::array<size_t, kFaces> from{};
        if (solid) {
          const glm::ivec3 t(tx, ty, tz);
          for (int f = 0; f < kFaces; ++f) {
            const glm::ivec3 d = face_direction(f);
            if ((own[v] >> f) & 1u || !box.contains(g + d)) continue;
            glm::ivec3 tn = t + d;
            const int a = face_axis(f);
            tn[a] = tn[a] == n ? 0 : tn[a] < 0 ? n - 1 : tn[a];
            const size_t w = local_index(tn, n);
            if ((own[w] >> f) & 1u) want = uint8_t(want | (1u << f)), from[size_t(f)] = w;
          }
        }
        const uint8_t change = uint8_t(want | prop[v]);
        if (change == 0) continue;
        const size_t row = row_base(*tex, level, ty, tz);
        for (int f = 0; f < kFaces; ++f) {
          if (!((change >> f) & 1u)) continue;
          const size_t mine = row + size_t(f * n + tx);
          if ((want >> f) & 1u) {
            const size_t w = from[size_t(f)];
            const size_t theirs = row_base(*tex, level, int(w / size_t(n)) % n, int(w / size_t(n * n))) +
                                  size_t(f * n) + w % size_t(n);
            tex->albedo[mine] = tex->albedo[theirs];
            tex->normal[mine] = (tex->normal[theirs] & ~kAlphaMask) | kPropagatedAlpha;
            tex->emission[mine] = tex->emission[theirs];
          } else {
            tex->albedo[mine] = 0;
            tex->normal[mine] = 0;
            tex->emission[mine] = 0;
          }
        }
        prop[v] = want;
      }
    }
  });
}

Status Cascades::voxelize_regions(const World& world, int level, const std::vector<VoxelBox>& regions, bool moved,
                                  Context* ctx, VoxelStats* stats) {
  Status s = object_sources(level, ctx);
  if (!s.ok()) return s;
  detail::VoxelSource land;
  land.world = &world;
  land.m = base_cells_ << level;
  land.stride = detail::sample_stride(land.m, config_.supersampling);
  land.occ_axis = config_.axis;
  land.materials = &config_.materials;
  std::vector<detail::ObjectRef> objects;
  for (const auto& o : object_cache_->worlds[size_t(level)]) {
    if (o) objects.push_back({detail::object_source(*o, config_.materials, config_.axis), o->voxels});
  }
  const int n = config_.resolution;
  const VoxelBox box = boxes_[size_t(level)];
  const LevelArrays arrays{&occupancy_[size_t(level)], &own_faces_[size_t(level)], &propagated_faces_[size_t(level)]};
  static thread_local detail::BlockPair scratch;  // reused across calls: no allocation per frame
  tbb::enumerable_thread_specific<detail::BlockCounters> counters;
  // Only a whole level is cut finer (scrolling slabs are many thin blocks
  // already).
  const bool whole_level = regions.size() == 1 && intersect(regions[0], box).count() == box.count();
  const VoxelBox busy = whole_level ? chunk_voxel_box(world, land.m) : VoxelBox{};
  const int workers = tbb::this_task_arena::max_concurrency();
  for (const VoxelBox& region : regions) {
    const std::vector<VoxelBox> blocks = update_blocks(intersect(region, box), busy, workers);
    s = detail::for_each_block(blocks, ctx, "cascade", [&](size_t bi) {
      detail::voxelize_sources(land, objects, blocks[bi], true, &scratch, &counters.local());
      store_block(scratch.land, level, n, &texture_, arrays);
    });
    if (!s.ok()) return s;
    if (stats) {
      stats->voxels += intersect(region, box).count();
      stats->blocks += blocks.size();
    }
  }
  for (const VoxelBox& region : regions) {
    const VoxelBox r = intersect(grow(region, 1), box);
    if (!r.empty()) propagate_packed(&texture_, arrays, level, n, box, r);
  }
  if (moved) {  // voxels on the box's faces may have lost the neighbour they took faces from
    for (int a = 0; a < 3; ++a) {
      for (int side = 0; side < 2; ++side) {
        VoxelBox shell = box;
        shell.lo[a] = side ? box.hi()[a] - 1 : box.lo[a];
        shell.dims[a] = 1;
        propagate_packed(&texture_, arrays, level, n, box, shell);
      }
    }
  }
  if (stats) {
    for (const auto& c : counters) {
      stats->chunk_columns_closed += c.closed;
      stats->chunk_columns_walked += c.walked;
      stats->rays_walked += c.rays;
    }
  }
  return {};
}

Result<CascadeUpdate> Cascades::update_level(const World& world, int level, const glm::dvec3& camera, Context* ctx) {
  const auto start = std::chrono::steady_clock::now();
  if (level < 0 || level >= levels()) {
    return Status(ErrorCode::kInvalidArgument, "cascade level " + std::to_string(level) + ": must be 0 .. " +
                                                   std::to_string(levels() - 1));
  }
  if (world.lattice().origin != lattice_.origin || world.lattice().cell_size != lattice_.cell_size) {
    return Status(ErrorCode::kInvalidArgument, "cascade: the world's lattice (origin " +
                                                   detail::vec_text(world.lattice().origin) + ", h " +
                                                   std::to_string(world.lattice().cell_size) +
                                                   ") is not the one the cascade was made for");
  }
  const glm::dvec3 c = (camera - lattice_.origin) / voxel_size(level);
  if (!detail::is_finite(camera) || glm::any(glm::greaterThan(glm::abs(c), glm::dvec3(kMaxCameraVoxel)))) {
    return Status(ErrorCode::kInvalidArgument, "cascade: camera " + detail::vec_text(camera) +
                                                   " must be finite and within " +
                                                   std::to_string(kMaxCameraVoxel * voxel_size(level)) +
                                                   " m of the lattice origin");
  }
  const int n = config_.resolution;
  const glm::ivec3 lo = glm::ivec3(glm::floor(c + 0.5)) - n / 2;
  CascadeUpdate up;
  up.level = level;
  std::vector<VoxelBox> regions;
  const size_t k = size_t(level);
  const VoxelBox old = boxes_[k];
  up.shift = valid_[k] ? lo - old.lo : glm::ivec3(0);
  up.full = !valid_[k] || glm::any(glm::greaterThanEqual(glm::abs(up.shift), glm::ivec3(n)));
  boxes_[k] = {lo, glm::ivec3(n)};
  if (up.full) {
    regions.push_back(boxes_[k]);
  } else {
    regions = exposed_slabs(old.lo, lo, n);
    for (const VoxelBox& d : pending_[k]) {
      const VoxelBox r = intersect(d, boxes_[k]);
      if (!r.empty()) regions.push_back(r), ++up.dirty_boxes;
    }
  }
  const bool moved = up.shift != glm::ivec3(0);
  VoxelStats stats;
  Status s = voxelize_regions(world, level, regions, moved && !up.full, ctx, &stats);
  if (!s.ok()) {
    valid_[k] = false;  // half-written: voxelize whole next time
    return s;
  }
  valid_[k] = true;
  pending_[k].clear();
  up.voxels = stats.voxels;
  up.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return up;
}

Status Cascades::update_all(const World& world, const glm::dvec3& camera, Context* ctx) {
  for (int k = 0; k < levels(); ++k) {
    Result<CascadeUpdate> r = update_level(world, k, camera, ctx);
    if (!r.ok()) return r.status();
  }
  return {};
}

Result<CascadeUpdate> Cascades::frame(const World& world, const glm::dvec3& camera, Context* ctx) {
  const int level = scheduled_level(frame_, levels());
  ++frame_;
  return update_level(world, level, camera, ctx);
}

void Cascades::invalidate(std::span<const DirtyChunk> dirty) {
  for (int k = 0; k < levels(); ++k) {
    if (!valid_[size_t(k)]) continue;
    const int64_t m = int64_t(base_cells_) << k;
    for (const DirtyChunk& d : dirty) {
      VoxelBox vb;
      for (int a = 0; a < 3; ++a) {
        const int64_t g0 = detail::floor_div64(int64_t(d.node_lo[a]) - 1, m);
        const int64_t g1 = detail::floor_div64(int64_t(d.node_hi[a]) - 1, m);
        vb.lo[a] = int(g0);
        vb.dims[a] = int(g1 - g0 + 1);
      }
      if (!intersect(vb, boxes_[size_t(k)]).empty()) pending_[size_t(k)].push_back(vb);
    }
  }
}

void Cascades::invalidate_level(int level) {
  if (level < 0 || level >= levels()) return;
  valid_[size_t(level)] = false;
  pending_[size_t(level)].clear();
}

Result<size_t> Cascades::refresh(const World& world, Context* ctx) {
  size_t voxels = 0;
  for (int k = 0; k < levels(); ++k) {
    if (!valid_[size_t(k)] || pending_[size_t(k)].empty()) continue;
    std::vector<VoxelBox> regions;
    for (const VoxelBox& d : pending_[size_t(k)]) {
      const VoxelBox r = intersect(d, boxes_[size_t(k)]);
      if (!r.empty()) regions.push_back(r);
    }
    VoxelStats stats;
    Status s = voxelize_regions(world, k, regions, false, ctx, &stats);
    if (!s.ok()) {
      valid_[size_t(k)] = false;
      return s;
    }
    pending_[size_t(k)].clear();
    voxels += stats.voxels;
  }
  return voxels;
}

FaceSample Cascades::sample(int level, int face, const glm::ivec3& g) const {
  if (!boxes_[size_t(level)].contains(g)) return {};
  return texture_.sample(face, level, wrap(g, config_.resolution));
}

float Cascades::occupancy(int level, const glm::ivec3& g) const {
  if (!boxes_[size_t(level)].contains(g)) return 0.0f;
  return occupancy_[size_t(level)][local_index(wrap(g, config_.resolution), config_.resolution)];
}

void Cascades::pack_level(int level, PackedGBuffer* out) const {
  const int n = config_.resolution;
  if (out->resolution != n || out->levels != levels()) out->resize(n, levels());
  const glm::ivec3 lo = boxes_[size_t(level)].lo;
  const glm::ivec3 shift = wrap(lo, n);  // tile coordinate of the box's first voxel
  tbb::parallel_for(0, n, [&](int z) {
    for (int y = 0; y < n; ++y) {
      const glm::ivec3 src_row(0, wrap(shift.y + y, n), wrap(shift.z + z, n));
      for (int f = 0; f < kFaces; ++f) {
        const size_t from = texture_.texel(f, level, src_row);
        const size_t to = out->texel(f, level, glm::ivec3(0, y, z));
        const size_t first = size_t(n - shift.x), rest = size_t(shift.x);
        auto copy = [&](auto& dst, const auto& src) {
          using T = typename std::decay_t<decltype(dst)>::value_type;
          std::memcpy(&dst[to], &src[from + size_t(shift.x)], first * sizeof(T));
          if (rest) std::memcpy(&dst[to + first], &src[from], rest * sizeof(T));
        };
        copy(out->albedo, texture_.albedo);
        copy(out->normal, texture_.normal);
        copy(out->occupancy, texture_.occupancy);
        copy(out->emission, texture_.emission);
      }
    }
  });
}

void Cascades::pack(PackedGBuffer* out) const {
  for (int k = 0; k < levels(); ++k) pack_level(k, out);
}

std::vector<NamedLevelGrid> valid_level_grids(const Cascades& cascades) {
  std::vector<NamedLevelGrid> out;
  for (int k = 0; k < cascades.levels(); ++k)
    if (cascades.level_valid(k)) out.push_back({cascades.level_grid(k), "_L" + std::to_string(k)});
  return out;
}

VoxelGrid Cascades::level_grid(int level) const {
  VoxelGrid g;
  g.box = boxes_[size_t(level)];
  g.voxel_size = voxel_size(level);
  g.origin = lattice_.origin;
  g.has_faces = true;
  g.occupancy.assign(g.box.count(), 0.0f);
  if (!valid_[size_t(level)]) return g;
  for (int z = 0; z < g.box.dims.z; ++z) {
    for (int y = 0; y < g.box.dims.y; ++y) {
      for (int x = 0; x < g.box.dims.x; ++x) {
        const glm::ivec3 v = g.box.lo + glm::ivec3(x, y, z);
        const float o = occupancy(level, v);
        g.occupancy[g.box.index(v)] = o;
        VoxelFaces faces;
        bool own = false;
        for (int f = 0; f < kFaces; ++f) {
          faces[size_t(f)] = sample(level, f, v);
          own |= faces[size_t(f)].flags == kFaceOwn;
        }
        if (!own && !(o > 0.0f && o < 1.0f)) continue;
        g.surface.push_back(v);
        g.surface_faces.push_back(faces);
      }
    }
  }
  return g;
}

}  // namespace ldc
