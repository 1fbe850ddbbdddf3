// walk_cells: the hierarchical walk declared in cell_index.h. Kept apart from
// what each query does in a cell (the visitor), as libfive keeps its walk
// apart from its mesher.
#pragma once

#include <algorithm>
#include <bit>
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

// floor() for values well inside the int range, without a libm call.
inline int fast_floor(double x) {
  const int i = static_cast<int>(x);
  return i - (x < static_cast<double>(i) ? 1 : 0);
}

template <class Visit>
void walk_cells(const Queries& queries, const World& world, const glm::dvec3& o, const glm::dvec3& d,
                double t_begin, double t_end, Visit&& visit) {
  const int c = world.chunk_size();
  const int shift = std::countr_zero(static_cast<unsigned>(c));  // C is a power of two
  // Cells one layer below the box can hold surface: their far edges are the box's face rays.
  const glm::ivec3 box_lo = world.node_min() - 1, box_hi = world.node_end();
  // A zero component counts as positive with an infinite inverse: its exit time is +inf.
  glm::dvec3 inv_d;
  glm::bvec3 pos;
  for (int a = 0; a < 3; ++a) {
    pos[a] = d[a] >= 0.0;
    inv_d[a] = d[a] != 0.0 ? 1.0 / d[a] : std::numeric_limits<double>::infinity();
  }
  double t = t_begin, t_stop = t_end;
  if (!clip_to_box(o, inv_d, glm::dvec3(box_lo), glm::dvec3(box_hi), &t, &t_stop)) return;

  glm::ivec3 cell;
  for (int a = 0; a < 3; ++a) cell[a] = std::clamp(fast_floor(o[a] + t * d[a]), box_lo[a], box_hi[a] - 1);
  int entry_axis = -1;
  glm::ivec3 chunk(std::numeric_limits<int>::min());
  const CellIndex* index = nullptr;
  for (;;) {
    const glm::ivec3 ch(cell.x >> shift, cell.y >> shift, cell.z >> shift);  // floor division
    glm::ivec3 block_lo = cell, block_hi = cell + 1;
    bool skip_chunk = false;
    if (ch != chunk) {
      chunk = ch;
      index = queries.cell_index(ch);
      if (!index->clear) {
        // Jump to where the ray meets the chunk's busy box, or past the chunk if it does not.
        const glm::dvec3 lo(ch * c + index->busy_lo), hi(ch * c + index->busy_hi);
        double t_in = t, t_out = t_stop;
        if (!clip_to_box(o, inv_d, lo, hi, &t_in, &t_out)) {
          skip_chunk = true;
        } else if (t_in > t) {
          t = t_in;
          for (int a = 0; a < 3; ++a)
            cell[a] = std::clamp(fast_floor(o[a] + t * d[a]), int(lo[a]), int(hi[a]) - 1);
          entry_axis = -1;
          for (int a = 0; a < 3; ++a)
            if (!std::isinf(inv_d[a]) && ((pos[a] ? lo[a] : hi[a]) - o[a]) * inv_d[a] == t_in) entry_axis = a;
          block_lo = cell, block_hi = cell + 1;
        }
      }
    }
    const glm::ivec3 local = cell - ch * c;
    if (index->clear || skip_chunk) {
      if (index->clear_inside) {
        if (visit(cell, CellKind::kInside, t, t_stop, entry_axis)) return;
      }
      block_lo = ch * c;
      block_hi = block_lo + c;
    } else if (const int r = index->empty_radius[size_t(index->brick_of(local))]; r > 0) {
      // Every brick within r - 1 of this one (in the chunk) is empty: leave that cube.
      const glm::ivec3 brick = local >> kBrickShift;
      block_lo = ch * c + (glm::max(brick - (r - 1), glm::ivec3(0)) << kBrickShift);
      block_hi = ch * c + (glm::min(brick + r, glm::ivec3(index->bricks_per_axis)) << kBrickShift);
    }
    // Leave the block through the face the ray meets first.
    int axis = 0;
    double t_next = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      const double ta = (double(pos[a] ? block_hi[a] : block_lo[a]) - o[a]) * inv_d[a];
      if (ta < t_next) t_next = ta, axis = a;
    }
    if (block_hi.x - block_lo.x == 1 && !index->clear && !skip_chunk) {
      const int brick = index->brick_of(local), bit = CellIndex::cell_bit(local);
      const bool surface = (index->surface[size_t(brick)] >> bit) & 1u;
      if (surface || ((index->inside[size_t(brick)] >> bit) & 1u)) {
        if (visit(cell, surface ? CellKind::kSurface : CellKind::kInside, t, std::min(t_next, t_stop), entry_axis))
          return;
      }
    }
    if (t_next > t_stop) return;
    t = std::max(t, t_next);
    for (int a = 0; a < 3; ++a) {
      if (a == axis) continue;
      cell[a] = std::clamp(fast_floor(o[a] + t * d[a]), block_lo[a], block_hi[a] - 1);
    }
    cell[axis] = pos[axis] ? block_hi[axis] : block_lo[axis] - 1;
    if (cell[axis] < box_lo[axis] || cell[axis] >= box_hi[axis]) return;
    entry_axis = axis;
  }
}

}  // namespace ldc::detail
