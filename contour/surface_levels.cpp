// surface_levels: the coarsest level each chunk can be meshed at without
// losing the surface, so that adaptive output never builds the full
// uniform mesh of flat faces only to collapse it again.
//
// A chunk at level k is meshed from the crossings on the edges of its
// level-k cells (cubes of 2^k cells): each coarse cell's vertex is placed by
// those crossings' Hermite planes. The level-0 crossings in between are the
// surface the coarse mesh stands for. So level k is allowed when, in every
// coarse cell of the chunk, each level-0 crossing lies within the tolerance
// of the plane of some crossing of the same material on that cell's own
// edges (a flat face, or the faces meeting at a crease or corner, all pass;
// curvature fails once the chord's sag passes the tolerance). Where the surface only grazes a coarse cell
// (no crossing on its edges), a neighbouring cell's planes must explain it
// and the cell may enclose no level-0 node of the other sign: a bump or a
// wall thinner than the cell would vanish. Crossings on coarse edges that
// coarse meshing drops (several on one edge, or a pair on an edge whose ends
// agree) are level-0 crossings too, so the same test covers them.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "contour/contour.h"
#include "contour/detail/region.h"
#include "ldc/lod.h"

namespace ldc {
namespace {

using detail::EdgeCrossing;
using detail::Region;

// The level-0 and level-k lattices of one chunk, kept per thread (their buffers are reused).
struct ChunkReader {
  Region fine, coarse;
};

// How coarse cell `cell` (coarse lattice coordinates) explains point p: the
// smallest distance (cells) from p to the Hermite plane of a crossing of
// `material` on one of its sign-changing level-k edges (infinity when none),
// and whether it has any crossing at all.
struct CellFit {
  bool any_crossing = false;
  double distance = INFINITY;
};
CellFit fit_to_cell(const Region& coarse, const glm::ivec3& cell, int s, const glm::dvec3& p, uint16_t material) {
  CellFit fit;
  for (int axis = 0; axis < 3; ++axis) {
    const EdgeCrossing* edges[4];
    coarse.cell_edges(axis, cell, edges);
    for (int j = 0; j < 4; ++j) {
      const EdgeCrossing* q = edges[j];
      if (!q) continue;
      fit.any_crossing = true;
      if (q->material != material) continue;
      glm::dvec3 at(cell);
      at[axis_u(axis)] += j & 1;
      at[axis_v(axis)] += j >> 1;
      at[axis] += q->t;
      fit.distance = std::min(fit.distance, std::abs(glm::dot(glm::dvec3(q->normal), p - double(s) * at)));
    }
  }
  return fit;
}

// Whether a coarse cell with no sign-changing edge holds only level-0 nodes
// of its corners' sign: surface grazing it is then a sliver its neighbours'
// vertices stand for, not a part (a bump, a thin wall) that would vanish.
bool no_enclosed_part(const Region& fine, const Region& coarse, const glm::ivec3& cell, int s) {
  const bool corner = coarse.inside(cell);
  for (int z = 1; z < s; ++z)
    for (int y = 1; y < s; ++y)
      for (int x = 1; x < s; ++x)
        if (fine.inside(cell * s + glm::ivec3(x, y, z)) != corner) return false;
  return true;
}

bool several_materials(const Region& fine) {
  const std::vector<Region::EdgeRef>& edges = fine.crossing_edges();
  if (edges.empty()) return false;
  const uint16_t first = fine.crossing(edges[0].axis, edges[0].node)->material;
  for (const Region::EdgeRef& e : edges)
    if (fine.crossing(e.axis, e.node)->material != first) return true;
  return false;
}

// Whether level k keeps chunk `chunk`'s surface within `tolerance` cells
// (r.fine holds the chunk's level-0 lattice, not uniform). Each level-0
// crossing must lie near a plane of its coarse cell's own crossings; in a
// cell with none (the surface only grazes it), near a plane of a
// neighbouring cell's, with no part enclosed.
bool level_keeps_surface(const World& world, const glm::ivec3& chunk, int k, double tolerance, ChunkReader& r) {
  const int C = world.chunk_size(), s = 1 << k, n = C >> k;
  const glm::ivec3 coarse_lo = chunk * n, last_cell = coarse_lo + n - 1;
  r.coarse.load(world, coarse_lo, coarse_lo + n + 1, coarse_lo, coarse_lo, s);
  for (const Region::EdgeRef& e : r.fine.crossing_edges()) {
    const EdgeCrossing* c = r.fine.crossing(e.axis, e.node);
    glm::dvec3 p(e.node);
    p[e.axis] += c->t;
    // floor(p / s): the node's own coarse cell (t < 1 keeps p below the next coarse node).
    const glm::ivec3 cell = glm::clamp(e.node >> k, coarse_lo, last_cell);
    if (const CellFit own = fit_to_cell(r.coarse, cell, s, p, c->material); own.any_crossing) {
      if (own.distance > tolerance) return false;
      continue;
    }
    if (!no_enclosed_part(r.fine, r.coarse, cell, s)) return false;
    double best = INFINITY;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const glm::ivec3 other = cell + glm::ivec3(dx, dy, dz);
          if (!detail::in_box(other, coarse_lo, last_cell + 1)) continue;
          best = std::min(best, fit_to_cell(r.coarse, other, s, p, c->material).distance);
        }
    if (best > tolerance) return false;
  }
  return true;
}

}  // namespace

int ChunkLevels::operator()(const glm::ivec3& chunk) const {
  if (level.empty()) return 0;
  const glm::ivec3 r = glm::clamp(chunk, first, first + dims - 1) - first;
  return level[(size_t(r.z) * size_t(dims.y) + size_t(r.y)) * size_t(dims.x) + size_t(r.x)];
}

size_t ChunkLevels::surface_chunks(int k) const {
  size_t n = 0;
  for (size_t i = 0; i < level.size(); ++i) n += surface[i] && level[i] == k ? 1 : 0;
  return n;
}

Result<ChunkLevels> surface_levels(const World& world, const SurfaceLevelOptions& options, Context* ctx) {
  if (!(options.tolerance >= 0.0 && std::isfinite(options.tolerance)))
    return Status(ErrorCode::kInvalidArgument,
                  "surface_levels: tolerance = " + std::to_string(options.tolerance) + " must be finite and >= 0");
  if (options.max_level < 0)
    return Status(ErrorCode::kInvalidArgument,
                  "surface_levels: max_level = " + std::to_string(options.max_level) + " must be >= 0");
  ScopedTimer timer(ctx, "surface_levels");
  const int top = std::min(options.max_level, max_lod_level(world.chunk_size()));
  ChunkLevels out;
  out.first = world.chunk_origin();
  out.dims = world.chunk_dims();
  const size_t count = size_t(out.dims.x) * size_t(out.dims.y) * size_t(out.dims.z);
  out.level.assign(count, 0);
  out.surface.assign(count, 0);
  tbb::enumerable_thread_specific<ChunkReader> readers;
  std::atomic<bool> stop{false}, mixed{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count), [&](const tbb::blocked_range<size_t>& range) {
    ChunkReader& reader = readers.local();
    for (size_t i = range.begin(); i != range.end(); ++i) {
      if (ctx && ctx->cancelled()) return stop.store(true);
      const glm::ivec3 chunk = out.first + glm::ivec3(int(i % size_t(out.dims.x)),
                                                      int(i / size_t(out.dims.x) % size_t(out.dims.y)),
                                                      int(i / (size_t(out.dims.x) * size_t(out.dims.y))));
      const glm::ivec3 lo = chunk * world.chunk_size();
      reader.fine.load(world, lo, lo + world.chunk_size() + 1, lo, lo, 1);
      if (reader.fine.uniform()) {
        out.level[i] = uint8_t(top);
        continue;
      }
      out.surface[i] = 1;
      if (several_materials(reader.fine)) mixed.store(true, std::memory_order_relaxed);
      int k = 0;
      while (k < top && level_keeps_surface(world, chunk, k + 1, options.tolerance, reader)) ++k;
      out.level[i] = uint8_t(k);
    }
  });
  if (stop.load()) return Status(ErrorCode::kCancelled, "surface_levels: cancelled");
  out.several_materials = mixed.load();
  return out;
}

// The cost model. Per chunk with surface, meshing at level 0 costs one unit
// with contour_world and about kLevelsMeshing with contour_levels (its
// general cells cost more than the uniform mesher's), and simplifying the
// result about kSimplify; a level-k chunk has about 4^-k of the cells and
// triangles of a level-0 one. The levels are used when their estimate is
// below kPayOff of one level's: the estimate was optimistic by 1.3-1.4x on
// the shared meshes' booleans at 256 cells (measured in one run, 2 threads),
// so the margin keeps curved inputs, where most chunks stay at level 0, on
// the uniform mesher.
bool surface_levels_pay_off(const ChunkLevels& levels) {
  constexpr double kLevelsMeshing = 3.0, kSimplify = 6.0, kPayOff = 0.7;
  double one_level = 0.0, by_levels = 0.0;
  for (size_t i = 0; i < levels.level.size(); ++i) {
    if (!levels.surface[i]) continue;
    one_level += 1.0 + kSimplify;
    by_levels += (kLevelsMeshing + kSimplify) / double(1 << (2 * levels.level[i]));
  }
  return one_level > 0.0 && by_levels < kPayOff * one_level;
}

Result<ContourMesh> contour_at_surface_levels(const World& world, double tolerance, const ContourConfig& config,
                                              Context* ctx, ContourStats* stats, SurfaceLevelChoice* choice) {
  SurfaceLevelChoice local;
  SurfaceLevelChoice& c = choice ? *choice : local;
  c = SurfaceLevelChoice();
  ScopedTimer timer(nullptr, "");
  Result<ChunkLevels> levels = surface_levels(world, {.tolerance = tolerance}, ctx);
  if (!levels.ok()) return levels.status();
  c.levels = std::move(levels.value());
  c.levels_seconds = timer.seconds();
  c.borders_relaxed = c.levels.several_materials && config.relax_iterations > 0;
  if (!c.borders_relaxed && surface_levels_pay_off(c.levels)) {
    Result<ContourMesh> mesh = contour_levels(world, c.levels, config, ctx, stats);
    if (!mesh.ok()) return mesh;
    // The self-intersection search is skipped: only the topology is asked.
    const MeshQuality q = mesh_quality(mesh.value(), {.known_self_intersecting_pairs = 0});
    if (q.nonmanifold_edges == 0 && q.nonmanifold_vertices == 0) {
      c.used = true;
      return mesh;
    }
    c.fell_back = true;
  }
  return contour_world(world, config, ctx, stats);
}

}  // namespace ldc
