// walk_cells: the hierarchical walk declared in cell_index.h. Kept apart from
// what each query does in a cell (the visitor), as libfive keeps its walk
// apart from its mesher.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "ldc/detail/cell_index.h"
#include "ldc/detail/ray_math.h"
#include "ldc/query.h"

namespace ldc::detail {

// The parameter range [t_in, t_out] in which o + t*d lies in the box [lo, hi].
inline bool clip_to_box(const glm::dvec3& o, const glm::dvec3& inv_d, const glm::dvec3& lo, const glm::dvec3& hi,
                        double* t_in, double* t_out) {
  for (int a = 0; a < 3; ++a) {
    if (std::isinf(inv_d[a])) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - o[a]) * inv_d[a], tb = (hi[a] - o[a]) * inv_d[a];
    if (ta > tb) std::swap(ta, tb);
    *t_in = std::max(*t_in, ta);
    *t_out = std::min(*t_out, tb);
  }
  return *t_in <= *t_out;
}

template <class Visit>
void walk_cells(const Queries& queries, const World& world, const glm::dvec3& o, const glm::dvec3& d,
                double t_begin, double t_end, Visit&& visit) {
  const int c = world.chunk_size();
  // Cells one layer below the box can hold surface: their far edges are the box's face rays.
  const glm::ivec3 box_lo = world.node_min() - 1, box_hi = world.node_end();
  glm::dvec3 inv_d;
  for (int a = 0; a < 3; ++a) inv_d[a] = d[a] != 0.0 ? 1.0 / d[a] : std::numeric_limits<double>::infinity();
  double t = t_begin, t_stop = t_end;
  if (!clip_to_box(o, inv_d, glm::dvec3(box_lo), glm::dvec3(box_hi), &t, &t_stop)) return;

  glm::ivec3 cell;
  for (int a = 0; a < 3; ++a)
    cell[a] = std::clamp(static_cast<int>(std::floor(o[a] + t * d[a])), box_lo[a], box_hi[a] - 1);
  int entry_axis = -1;
  glm::ivec3 chunk(std::numeric_limits<int>::min());
  const CellIndex* index = nullptr;
  for (;;) {
    const glm::ivec3 ch(floor_div(cell.x, c), floor_div(cell.y, c), floor_div(cell.z, c));
    if (ch != chunk) {
      chunk = ch;
      index = queries.cell_index(ch);
    }
    // The block to leave next: the whole chunk, a 4^3 brick, or the cell.
    glm::ivec3 block_lo = cell, block_hi = cell + 1;
    const glm::ivec3 local = cell - ch * c;
    if (index->clear) {
      if (index->clear_inside) {
        double t1 = t_stop;
        if (visit(cell, CellKind::kInside, t, t1, entry_axis)) return;
      }
      block_lo = ch * c;
      block_hi = block_lo + c;
    } else if (!index->brick_busy(local)) {
      block_lo = ch * c + ((local >> kBrickShift) << kBrickShift);
      block_hi = block_lo + (1 << kBrickShift);
    }
    // Leave the block through the face the ray meets first.
    int axis = 0;
    double t_next = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (std::isinf(inv_d[a])) continue;
      double ta = (double(d[a] > 0.0 ? block_hi[a] : block_lo[a]) - o[a]) * inv_d[a];
      if (ta < t_next) t_next = ta, axis = a;
    }
    if (!index->clear && block_hi - block_lo == glm::ivec3(1)) {
      const bool surface = index->is_surface(local);
      if (surface || index->is_inside(local)) {
        if (visit(cell, surface ? CellKind::kSurface : CellKind::kInside, t, std::min(t_next, t_stop), entry_axis))
          return;
      }
    }
    if (t_next > t_stop) return;
    t = std::max(t, t_next);
    for (int a = 0; a < 3; ++a) {
      if (a == axis) continue;
      int k = static_cast<int>(std::floor(o[a] + t * d[a]));
      cell[a] = std::clamp(k, block_lo[a], block_hi[a] - 1);
    }
    cell[axis] = d[axis] > 0.0 ? block_hi[axis] : block_lo[axis] - 1;
    if (cell[axis] < box_lo[axis] || cell[axis] >= box_hi[axis]) return;
    entry_axis = axis;
  }
}

}  // namespace ldc::detail
