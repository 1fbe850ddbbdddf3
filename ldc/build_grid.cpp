// Lattice planning and chunk assembly shared by the builders.
#include <cmath>
#include <sstream>

#include <tbb/parallel_for.h>

#include "ldc/internal/build_common.h"
#include "ldc/internal/lattice_range.h"
#include "ldc/internal/ray_math.h"

namespace ldc::detail {
namespace {

Status check_grid(const GridConfig& g, const char* what) {
  auto bad = [&](const std::string& field, const std::string& value, const char* rule) {
    return Status(ErrorCode::kInvalidArgument,
                  std::string(what) + ": " + field + " = " + value + " " + rule);
  };
  if (g.cell_size == 0.0 && (g.cells < 1 || g.cells > 65536)) {
    return bad("cells", std::to_string(g.cells), "must be in 1 .. 65536");
  }
  if (!(g.cell_size >= 0.0) || !std::isfinite(g.cell_size)) {
    return bad("cell_size", std::to_string(g.cell_size), "must be finite and >= 0");
  }
  if (g.chunk_size != 8 && g.chunk_size != 16 && g.chunk_size != 32 && g.chunk_size != 64) {
    return bad("chunk_size", std::to_string(g.chunk_size), "must be 8, 16, 32 or 64");
  }
  if (g.padding < 1 || g.padding > 64) {
    return bad("padding", std::to_string(g.padding), "must be in 1 .. 64");
  }
  if (g.use_origin && !(std::isfinite(g.origin.x) && std::isfinite(g.origin.y) &&
                        std::isfinite(g.origin.z))) {
    return bad("origin", "(non-finite)", "must be finite");
  }
  return {};
}

std::string mib(double bytes) {
  std::ostringstream s;
  s.precision(3);
  s << bytes / (1024.0 * 1024.0) << " MiB";
  return s.str();
}

}  // namespace

Result<WorldConfig> plan_grid(const WorldBox& b, const GridConfig& grid, double surface_area,
                              const char* what) {
  Status s = check_grid(grid, what);
  if (!s.ok()) return s;
  glm::dvec3 extent = b.max - b.min;
  double longest = std::max(extent.x, std::max(extent.y, extent.z));
  if (!std::isfinite(longest)) {
    return Status(ErrorCode::kInvalidArgument, std::string(what) + ": bounds are not finite");
  }
  double h = grid.cell_size > 0.0 ? grid.cell_size : longest / grid.cells;
  if (!(h > 0.0)) {
    return Status(ErrorCode::kInvalidArgument,
                  std::string(what) + ": input has zero extent; give --cell-size explicitly");
  }
  WorldConfig wc;
  wc.chunk_size = grid.chunk_size;
  wc.lattice.cell_size = h;
  wc.lattice.origin = grid.use_origin ? grid.origin : b.min - double(grid.padding) * h;
  const int c = grid.chunk_size;
  for (int a = 0; a < 3; ++a) {
    double lo = (b.min[a] - wc.lattice.origin[a]) / h - grid.padding;
    double hi = (b.max[a] - wc.lattice.origin[a]) / h + grid.padding;
    if (std::abs(lo) > double(kMaxNodeCoordinate) || std::abs(hi) > double(kMaxNodeCoordinate)) {
      return Status(ErrorCode::kTooLarge,
                    std::string(what) + ": " + std::to_string(int64_t(hi - lo)) + " cells along " +
                        axis_name(a) + " exceed the limit of " +
                        std::to_string(kMaxNodeCoordinate) + "; use a larger cell size");
    }
    int first = int(std::floor(lo / c));
    int end = int(std::floor(hi / c)) + 1;
    wc.chunk_origin[a] = first;
    wc.chunk_dims[a] = end - first;
  }
  // Precision and range: what World::create would refuse, named for this builder.
  if (Status range = check_lattice_range(wc, what); !range.ok()) return range;
  double slots = double(wc.chunk_dims.x) * wc.chunk_dims.y * wc.chunk_dims.z;
  // ~2 points per unit of surface per axis pair, 8 bytes stored plus ~40 in flight
  // during a build; 64 bytes of table per chunk slot.
  double estimate = slots * 64.0 + 2.0 * surface_area / (h * h) * 48.0;
  if (estimate > double(grid.max_memory) || slots > double(kMaxChunkSlots)) {
    return Status(ErrorCode::kTooLarge,
                  std::string(what) + ": h = " + std::to_string(h) + " needs about " +
                      mib(estimate) + " (" + std::to_string(int64_t(slots)) +
                      " chunk slots), over the limit of " + mib(double(grid.max_memory)) +
                      "; use fewer cells");
  }
  return wc;
}

ChunkAssembly::ChunkAssembly(const World& world) {
  const glm::ivec3 d = world.chunk_dims();
  families_.resize(size_t(d.x) * d.y * d.z);
}

void ChunkAssembly::set_uniform(size_t slot, bool solid) {
  for (RayFamily& f : families_[slot]) f = RayFamily::uniform(solid);
}

size_t ChunkAssembly::finish(World& world) {
  std::atomic<size_t> mixed{0};
  tbb::parallel_for(size_t{0}, families_.size(), [&](size_t slot) {
    auto chunk = std::make_shared<Chunk>();
    for (int a = 0; a < 3; ++a) chunk->axis[a] = std::move(families_[slot][a]);
    bool inside = false;
    glm::ivec3 coord = slot_chunk(world, slot);
    // set_chunk writes only this slot's entries: safe in parallel.
    if (chunk->is_uniform(&inside)) {
      world.set_uniform_chunk(coord, inside);
    } else {
      world.set_chunk(coord, std::move(chunk));
      mixed.fetch_add(1);
    }
  });
  families_.clear();
  return mixed.load();
}

void record_build_report(World& world, const BuildReport& r) {
  world.set_metadata("build.seconds", std::to_string(r.seconds));
  if (r.triangles) world.set_metadata("build.triangles", std::to_string(r.triangles));
  world.set_metadata("build.input_closed", r.input_closed ? "yes" : "no");
  world.set_metadata("build.boundary_edges", std::to_string(r.boundary_edges));
  world.set_metadata("build.repaired_rays", std::to_string(r.repaired_rays));
  world.set_metadata("build.synthesized_points", std::to_string(r.synthesized_points));
  world.set_metadata("build.dropped_crossings", std::to_string(r.dropped_crossings));
  world.set_metadata("build.normal_flips", std::to_string(r.normal_flips));
  world.set_metadata("build.nudged_points", std::to_string(r.nudged_points));
  world.set_metadata("build.degenerate_triangles", std::to_string(r.degenerate_triangles));
}

}  // namespace ldc::detail
