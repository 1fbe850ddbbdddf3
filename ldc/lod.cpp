// coarsen(): see ldc/lod.h.
#include "ldc/lod.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include <tbb/parallel_for.h>

namespace ldc {
namespace {

// Family `f` of a fine chunk of C cells, every stride-th ray of each row and
// column: ray (u, v) of the coarse family is ray (stride u, stride v) of the
// fine one, points and start state unchanged (a point's depth counts steps
// from the chunk segment's start, and a segment has the same steps at any C).
RayFamily coarse_family(const RayFamily& f, int chunk_size, int stride) {
  if (f.is_uniform()) return RayFamily::uniform(f.uniform_inside());
  const int coarse = chunk_size / stride;
  RayFamilyWriter out(coarse);
  for (int v = 0; v < coarse; ++v) {
    for (int u = 0; u < coarse; ++u) {
      const int fine_ray = v * stride * chunk_size + u * stride;
      const std::span<const PackedPoint> points = f.points(fine_ray);
      out.begin_ray(f.starts_inside(fine_ray, points));
      for (const PackedPoint& p : points) out.add_point(p);
    }
  }
  return out.finish();
}

}  // namespace

int max_lod_level(int chunk_size) {
  int level = 0;
  while ((chunk_size >> (level + 1)) >= 8) ++level;
  return level;
}

Result<World> coarsen(const World& world, int level) {
  const int c = world.chunk_size();
  if (level < 0 || level > max_lod_level(c)) {
    return Status(ErrorCode::kInvalidArgument,
                  "coarsen: level " + std::to_string(level) + " is outside 0 .. " + std::to_string(max_lod_level(c)) +
                      " for chunks of " + std::to_string(c) + " cells (coarse chunks keep at least 8 cells)");
  }
  const int stride = 1 << level;
  WorldConfig config = world.config();
  config.chunk_size = c / stride;
  config.lattice.cell_size = world.lattice().cell_size * stride;
  Result<World> made = World::create(config);
  if (!made.ok()) return made.status();
  World out = std::move(made).value();
  out.metadata() = world.metadata();
  out.set_metadata("lod.level", std::to_string(level));
  std::vector<glm::ivec3> mixed;
  world.for_each_chunk([&](const glm::ivec3& chunk, ChunkKind kind, const Chunk*) {
    if (kind == ChunkKind::kMixed) mixed.push_back(chunk);
    else if (kind == ChunkKind::kSolid) out.set_uniform_chunk(chunk, true);
  });
  std::vector<std::shared_ptr<const Chunk>> coarse(mixed.size());
  tbb::parallel_for(size_t{0}, mixed.size(), [&](size_t i) {
    const Chunk& fine = *world.chunk(mixed[i]);
    auto chunk = std::make_shared<Chunk>();
    for (int a = 0; a < 3; ++a) chunk->axis[size_t(a)] = coarse_family(fine.axis[size_t(a)], c, stride);
    coarse[i] = std::move(chunk);
  });
  for (size_t i = 0; i < mixed.size(); ++i) out.set_chunk(mixed[i], std::move(coarse[i]));
  return out;
}

Status check_lod_bands(const LodBands& bands) {
  if (!std::isfinite(bands.hysteresis) || bands.hysteresis < 0.0) {
    return Status(ErrorCode::kInvalidArgument, "lod bands: hysteresis " + std::to_string(bands.hysteresis) +
                                                   " must be finite and >= 0");
  }
  double previous = 0.0;
  for (size_t k = 0; k < bands.start.size(); ++k) {
    const double start = bands.start[k];
    if (!std::isfinite(start) || start <= previous) {
      return Status(ErrorCode::kInvalidArgument, "lod bands: start[" + std::to_string(k) + "] = " +
                                                     std::to_string(start) + " must be finite and above " +
                                                     std::to_string(previous));
    }
    if (start - previous <= 2.0 * bands.hysteresis) {
      return Status(ErrorCode::kInvalidArgument, "lod bands: the band before start[" + std::to_string(k) +
                                                     "] is not wider than twice the hysteresis (" +
                                                     std::to_string(bands.hysteresis) + " m)");
    }
    previous = start;
  }
  return {};
}

int lod_level(const LodBands& bands, double distance, int level) {
  if (!check_lod_bands(bands).ok()) return level;
  const int levels = int(bands.start.size()) + 1;
  level = std::clamp(level, 0, levels - 1);
  while (level + 1 < levels && distance >= bands.start[size_t(level)] + bands.hysteresis) ++level;
  while (level > 0 && distance < bands.start[size_t(level - 1)] - bands.hysteresis) --level;
  return level;
}

double chunk_distance(const Lattice& lattice, int chunk_size, const glm::ivec3& chunk, const glm::dvec3& point) {
  const glm::dvec3 lo = lattice.node_position(chunk * chunk_size);
  const glm::dvec3 hi = lattice.node_position((chunk + 1) * chunk_size);
  return glm::length(point - glm::clamp(point, lo, hi));
}

}  // namespace ldc
