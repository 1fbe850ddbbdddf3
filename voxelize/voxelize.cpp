// Dense voxelization: config checks, materials, the block loop and its sinks.
#include "voxelize/voxelize.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <sstream>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "ldc/internal/huge_pages.h"
#include "ldc/materials.h"
#include "ldc/terrain.h"
#include "voxelize/detail/block.h"
#include "voxelize/detail/objects.h"
#include "voxelize/detail/voxel_common.h"

namespace ldc {

namespace {

std::string number(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

Status check_channel(const glm::vec3& v, double max, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    if (!(v[c] >= 0.0f && double(v[c]) <= max)) {
      return {ErrorCode::kInvalidArgument, what + " channel " + std::to_string(c) + " = " + number(v[c]) +
                                               ": must be in 0 .. " + number(max)};
    }
  }
  return {};
}

}  // namespace

MaterialTable default_material_table() {
  MaterialTable t;
  t.materials.resize(kPaletteSize);
  for (int id = 0; id < kPaletteSize; ++id) t.materials[size_t(id)].albedo = material_albedo(uint16_t(id));
  t.fallback.albedo = glm::vec3(0.5f);
  return t;
}

Status check_material_table(const MaterialTable& table) {
  for (size_t i = 0; i <= table.materials.size(); ++i) {
    const VoxelMaterial& m = i < table.materials.size() ? table.materials[i] : table.fallback;
    const std::string name = i < table.materials.size() ? "material " + std::to_string(i) : "fallback material";
    Status s = check_channel(m.albedo, 1.0, name + ": albedo");
    if (s.ok()) s = check_channel(m.emission, 65000.0, name + ": emission");
    if (!s.ok()) return s;
  }
  return {};
}

Result<int> voxel_cells(const Lattice& lattice, const VoxelConfig& config) {
  const double h = lattice.cell_size;
  const double s = config.voxel_size;
  if (!std::isfinite(s) || !(s > 0.0)) {
    return Status(ErrorCode::kInvalidArgument, "voxel size " + number(s) + ": must be a positive number");
  }
  const double ratio = s / h;
  const double m = std::round(ratio);
  if (!(m >= 1.0) || m > kMaxVoxelCells) {
    return Status(ErrorCode::kInvalidArgument, "voxel size " + number(s) + " m is " + number(ratio) +
                                                   " cells of h = " + number(h) + " m: must be 1 .. " +
                                                   std::to_string(kMaxVoxelCells) + " cells");
  }
  if (std::abs(ratio - m) > 1e-6 * m) {
    return Status(ErrorCode::kInvalidArgument, "voxel size " + number(s) + " m is " + number(ratio) +
                                                   " cells of h = " + number(h) +
                                                   " m: must be a whole number of cells (e.g. " + number(m * h) + ")");
  }
  return int(m);
}

Status check_voxel_config(const Lattice& lattice, const VoxelConfig& config) {
  Result<int> m = voxel_cells(lattice, config);
  if (!m.ok()) return m.status();
  if (config.axis < 0 || config.axis > 2) {
    return {ErrorCode::kInvalidArgument, "axis " + std::to_string(config.axis) + ": must be 0 (x), 1 (y) or 2 (z)"};
  }
  if (config.supersampling < 1 || config.supersampling > kMaxVoxelCells) {
    return {ErrorCode::kInvalidArgument,
            "supersampling " + std::to_string(config.supersampling) + ": must be 1 .. " + std::to_string(kMaxVoxelCells)};
  }
  return {};
}

VoxelBox intersect(const VoxelBox& a, const VoxelBox& b) {
  const glm::ivec3 lo = glm::max(a.lo, b.lo);
  const glm::ivec3 hi = glm::min(a.hi(), b.hi());
  return {lo, glm::max(hi - lo, glm::ivec3(0))};
}

VoxelBox solid_voxel_box(const World& world, int m) {
  std::optional<WorldBox> b = world.solid_bounds();
  if (!b) return {};
  const glm::dvec3 lo = world.lattice().to_lattice(b->min) / double(m);
  const glm::dvec3 hi = world.lattice().to_lattice(b->max) / double(m);
  const glm::ivec3 l(glm::floor(lo)), h(glm::floor(hi));
  return {l, h - l + 1};
}

double VoxelGrid::volume() const {
  double sum = 0.0;
  for (float o : occupancy) sum += double(o);
  return sum * voxel_size * voxel_size * voxel_size;
}

namespace detail {

Result<PreparedSources> prepare_sources(const World& world, const VoxelConfig& config, const MaterialTable& materials,
                                        std::span<const StaticObject> objects, Context* ctx) {
  Status s = check_voxel_config(world.lattice(), config);
  if (s.ok()) s = check_material_table(materials);
  if (!s.ok()) return s;
  PreparedSources out;
  const int m = voxel_cells(world.lattice(), config).value();
  out.land.world = &world;
  out.land.m = m;
  out.land.stride = sample_stride(m, config.supersampling);
  out.land.occ_axis = config.axis;
  out.land.materials = &materials;
  for (size_t i = 0; i < objects.size(); ++i) {
    Result<ObjectWorld> o = build_object_world(objects[i], world.lattice().origin, config.voxel_size, ctx);
    if (!o.ok()) return Status(o.status().code(), "object " + std::to_string(i) + ": " + o.status().message());
    out.objects.push_back(std::make_unique<ObjectWorld>(std::move(o).value()));
  }
  return out;
}

void voxelize_sources(const VoxelSource& land, const std::vector<ObjectRef>& objects, const VoxelBox& block,
                      bool faces, BlockPair* scratch, BlockCounters* counters) {
  scratch->land.reset(block, faces);
  voxelize_block(land, &scratch->land, counters);
  for (const ObjectRef& o : objects) {
    if (intersect(o.voxels, block).empty()) continue;
    scratch->object.reset(block, faces);
    voxelize_block(o.source, &scratch->object, counters);
    combine_blocks(&scratch->land, scratch->object);
  }
}

Status for_each_block(const std::vector<VoxelBox>& blocks, Context* ctx, const char* stage,
                      const std::function<void(size_t)>& fn) {
  std::atomic<size_t> done{0};
  std::atomic<bool> cancelled{false};
  std::mutex progress;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      if (ctx && ctx->cancelled()) {
        cancelled = true;
        return;
      }
      fn(i);
      const size_t n = ++done;
      if (ctx && (n % 64 == 0 || n == blocks.size())) {
        std::lock_guard<std::mutex> lock(progress);
        ctx->report_progress(stage, double(n) / double(blocks.size()));
      }
    }
  });
  if (cancelled) return {ErrorCode::kCancelled, std::string(stage) + ": cancelled"};
  return {};
}

std::vector<ObjectRef> object_refs(const PreparedSources& p, const MaterialTable& materials, int occ_axis) {
  std::vector<ObjectRef> refs;
  for (const auto& o : p.objects) refs.push_back({object_source(*o, materials, occ_axis), o->voxels});
  return refs;
}

}  // namespace detail

namespace {

using detail::BlockPair;

bool is_surface(const detail::BlockScratch& b, size_t i) {
  const float o = b.occupancy[i];
  return b.surface[i] || (o > 0.0f && o < 1.0f);
}

Status check_box(const VoxelBox& box) {
  if (glm::any(glm::lessThan(box.dims, glm::ivec3(0)))) {
    return {ErrorCode::kInvalidArgument, "voxel box dims must be >= 0"};
  }
  if (double(box.dims.x) * double(box.dims.y) * double(box.dims.z) > double(kMaxDenseVoxels)) {
    std::ostringstream s;
    s << "voxel box of " << box.dims.x << " x " << box.dims.y << " x " << box.dims.z << " voxels: at most "
      << kMaxDenseVoxels << " voxels (use a bigger voxel size)";
    return {ErrorCode::kTooLarge, s.str()};
  }
  return {};
}

void add_stats(VoxelStats* stats, const tbb::enumerable_thread_specific<detail::BlockCounters>& counters) {
  if (!stats) return;
  for (const auto& c : counters) {
    stats->chunk_columns_closed += c.closed;
    stats->chunk_columns_walked += c.walked;
    stats->rays_walked += c.rays;
  }
}

}  // namespace

Result<VoxelGrid> voxelize(const World& world, const VoxelConfig& config, const VoxelizeOptions& options,
                           Context* ctx, VoxelStats* stats) {
  ScopedTimer timer(ctx, "voxelize");
  const auto start = std::chrono::steady_clock::now();
  const MaterialTable fallback = options.materials ? MaterialTable{} : default_material_table();
  const MaterialTable& materials = options.materials ? *options.materials : fallback;
  Result<detail::PreparedSources> prepared = detail::prepare_sources(world, config, materials, options.objects, ctx);
  if (!prepared.ok()) return prepared.status();
  const detail::PreparedSources& p = prepared.value();
  VoxelBox box = options.box ? *options.box : solid_voxel_box(world, p.land.m);
  if (!options.box) {
    for (const auto& o : p.objects) {
      if (box.empty()) box = o->voxels;
      const glm::ivec3 lo = glm::min(box.lo, o->voxels.lo), hi = glm::max(box.hi(), o->voxels.hi());
      box = {lo, hi - lo};
    }
  }
  Status s = check_box(box);
  if (!s.ok()) return s;
  VoxelGrid grid;
  grid.box = box;
  grid.voxel_size = config.voxel_size;
  grid.origin = world.lattice().origin;
  grid.has_faces = options.faces;
  detail::assign_on_huge_pages(grid.occupancy, box.count(), 0.0f);
  const std::vector<VoxelBox> blocks = detail::split_blocks(box, options.faces ? 16 : 32);
  const std::vector<detail::ObjectRef> objects = detail::object_refs(p, materials, config.axis);
  std::vector<std::vector<glm::ivec3>> surface(blocks.size());
  std::vector<std::vector<VoxelFaces>> surface_faces(options.faces ? blocks.size() : 0);
  tbb::enumerable_thread_specific<BlockPair> scratch;
  tbb::enumerable_thread_specific<detail::BlockCounters> counters;
  s = detail::for_each_block(blocks, ctx, "voxelize", [&](size_t bi) {
    BlockPair& sc = scratch.local();
    detail::voxelize_sources(p.land, objects, blocks[bi], options.faces, &sc, &counters.local());
    const detail::BlockScratch& b = sc.land;
    if (b.uniform == ChunkKind::kEmpty) return;  // nothing to copy: the grid holds 0 there already
    const VoxelBox& bb = blocks[bi];
    for (int z = 0; z < bb.dims.z; ++z) {
      for (int y = 0; y < bb.dims.y; ++y) {
        const size_t row = bb.index(bb.lo + glm::ivec3(0, y, z));
        std::memcpy(&grid.occupancy[box.index(bb.lo + glm::ivec3(0, y, z))], &b.occupancy[row],
                    size_t(bb.dims.x) * sizeof(float));
        if (b.uniform != ChunkKind::kMixed) continue;  // no surface in an empty or solid block
        for (int x = 0; x < bb.dims.x; ++x) {
          const size_t i = row + size_t(x);
          if (!is_surface(b, i)) continue;
          const glm::ivec3 g = bb.lo + glm::ivec3(x, y, z);
          surface[bi].push_back(g);
          if (!options.faces) continue;
          VoxelFaces faces;
          for (int f = 0; f < kFaces; ++f) faces[size_t(f)] = detail::face_sample(b, i, f);
          surface_faces[bi].push_back(faces);
        }
      }
    }
  });
  if (!s.ok()) return s;
  for (auto& v : surface) grid.surface.insert(grid.surface.end(), v.begin(), v.end());
  for (auto& v : surface_faces) grid.surface_faces.insert(grid.surface_faces.end(), v.begin(), v.end());
  if (stats) {
    add_stats(stats, counters);
    stats->voxels += box.count();
    stats->blocks += blocks.size();
    stats->surface_voxels += grid.surface.size();
    stats->seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return grid;
}

namespace {

glm::ivec3 face_direction(int f) {
  glm::ivec3 d(0);
  d[face_axis(f)] = face_positive(f) ? 1 : -1;
  return d;
}

// The talk's post-processing on a dense float G-buffer (see the header).
void propagate(GBuffer* gb) {
  const VoxelBox& box = gb->box;
  const size_t n = box.count();
  tbb::parallel_for(0, box.dims.z, [&](int z) {
    for (int y = 0; y < box.dims.y; ++y) {
      for (int x = 0; x < box.dims.x; ++x) {
        const glm::ivec3 g = box.lo + glm::ivec3(x, y, z);
        const size_t i = box.index(g);
        if (!(gb->occupancy[i] > 0.0f)) continue;
        for (int f = 0; f < kFaces; ++f) {
          FaceSample& mine = gb->faces[size_t(f) * n + i];
          const glm::ivec3 nb = g + face_direction(f);
          if (mine.flags == kFaceOwn || !box.contains(nb)) continue;
          const FaceSample& theirs = gb->faces[size_t(f) * n + box.index(nb)];
          if (theirs.flags != kFaceOwn) continue;
          mine.albedo = theirs.albedo;
          mine.normal = theirs.normal;
          mine.emission = theirs.emission;
          mine.flags = kFacePropagated;
        }
      }
    }
  });
}

}  // namespace

Result<GBuffer> voxelize_gbuffer(const World& world, const VoxelConfig& config, const VoxelBox& box,
                                 const MaterialTable& materials, std::span<const StaticObject> objects_in,
                                 Context* ctx, VoxelStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  Result<detail::PreparedSources> prepared = detail::prepare_sources(world, config, materials, objects_in, ctx);
  if (!prepared.ok()) return prepared.status();
  Status s = check_box(box);
  if (!s.ok()) return s;
  if (double(box.count()) * double(sizeof(FaceSample) * kFaces) > double(size_t(1) << 34)) {
    return Status(ErrorCode::kTooLarge, "G-buffer of " + std::to_string(box.count()) +
                                            " voxels: too large for the dense float form (at most 16 GiB)");
  }
  const detail::PreparedSources& p = prepared.value();
  GBuffer gb;
  gb.box = box;
  gb.voxel_size = config.voxel_size;
  gb.origin = world.lattice().origin;
  detail::assign_on_huge_pages(gb.occupancy, box.count(), 0.0f);
  detail::assign_on_huge_pages(gb.faces, box.count() * kFaces);
  const std::vector<VoxelBox> blocks = detail::split_blocks(box, 16);
  const std::vector<detail::ObjectRef> objects = detail::object_refs(p, materials, config.axis);
  std::vector<std::vector<glm::ivec3>> surface(blocks.size());
  tbb::enumerable_thread_specific<BlockPair> scratch;
  tbb::enumerable_thread_specific<detail::BlockCounters> counters;
  const size_t n = box.count();
  s = detail::for_each_block(blocks, ctx, "gbuffer", [&](size_t bi) {
    BlockPair& sc = scratch.local();
    detail::voxelize_sources(p.land, objects, blocks[bi], true, &sc, &counters.local());
    const detail::BlockScratch& b = sc.land;
    const VoxelBox& bb = blocks[bi];
    for (int z = 0; z < bb.dims.z; ++z) {
      for (int y = 0; y < bb.dims.y; ++y) {
        for (int x = 0; x < bb.dims.x; ++x) {
          const glm::ivec3 g = bb.lo + glm::ivec3(x, y, z);
          const size_t i = bb.index(g), o = box.index(g);
          gb.occupancy[o] = b.occupancy[i];
          for (int f = 0; f < kFaces; ++f) gb.faces[size_t(f) * n + o] = detail::face_sample(b, i, f);
          if (is_surface(b, i)) surface[bi].push_back(g);
        }
      }
    }
  });
  if (!s.ok()) return s;
  propagate(&gb);
  for (auto& v : surface) gb.surface.insert(gb.surface.end(), v.begin(), v.end());
  if (stats) {
    add_stats(stats, counters);
    stats->voxels += box.count();
    stats->blocks += blocks.size();
    stats->surface_voxels += gb.surface.size();
    stats->seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return gb;
}

}  // namespace ldc
