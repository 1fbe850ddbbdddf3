// walk_cells: the hierarchical walk declared in cell_index.h. Kept apart from
// what each query does in a cell (the visitor), as libfive keeps its walk
// apart from its mesher.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "ldc/detail/cell_index.h"
#include "ldc/internal/ray_math.h"
#include "ldc/query.h"

namespace ldc::detail {

// Narrows [t_in, t_out] to where o + t*d lies in the box [lo, hi]; false when
// nothing is left. entry_axis, when given, becomes the axis of the face the
// ray enters through if that raised t_in.
inline bool clip_to_box(const glm::dvec3& o, const glm::dvec3& inv_d, const glm::dvec3& lo, const glm::dvec3& hi,
                        double* t_in, double* t_out, int* entry_axis = nullptr) {
  for (int a = 0; a < 3; ++a) {
    if (std::isinf(inv_d[a])) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - o[a]) * inv_d[a], tb = (hi[a] - o[a]) * inv_d[a];
    if (ta > tb) std::swap(ta, tb);
    if (ta > *t_in) {
      *t_in = ta;
      if (entry_axis) *entry_axis = a;
    }
    *t_out = std::min(*t_out, tb);
  }
  return *t_in <= *t_out;
}

// 1 / d per axis, +inf where a component is zero (clip_to_box's input).
inline glm::dvec3 inverse_direction(const glm::dvec3& d) {
  glm::dvec3 inv;
  for (int a = 0; a < 3; ++a) inv[a] = d[a] != 0.0 ? 1.0 / d[a] : std::numeric_limits<double>::infinity();
  return inv;
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
  // Cells one layer below the box can hold surface: their far edges are the box's face rays.
  const glm::ivec3 box_lo = world.node_min() - 1, box_hi = world.node_end();
  // A zero component counts as positive with an infinite inverse: its exit time is +inf.
  const glm::dvec3 inv_d = inverse_direction(d);
  const glm::bvec3 pos = glm::greaterThanEqual(d, glm::dvec3(0.0));
  double t = t_begin, t_stop = t_end;
  if (!clip_to_box(o, inv_d, glm::dvec3(box_lo), glm::dvec3(box_hi), &t, &t_stop)) return;

  // The cell holding o + t*d, kept inside [lo, hi) against rounding at faces.
  auto cell_at = [&](double t_at, const glm::ivec3& lo, const glm::ivec3& hi, int skip_axis) {
    glm::ivec3 k(0);  // the caller sets skip_axis's coordinate itself
    for (int a = 0; a < 3; ++a)
      if (a != skip_axis) k[a] = std::clamp(fast_floor(o[a] + t_at * d[a]), lo[a], hi[a] - 1);
    return k;
  };
  glm::ivec3 cell = cell_at(t, box_lo, box_hi, -1);
  int entry_axis = -1;
  glm::ivec3 chunk(std::numeric_limits<int>::min());
  const CellIndex* index = nullptr;
  for (;;) {
    const glm::ivec3 ch = world.chunk_of_node(cell);  // a cell is named by its first node
    glm::ivec3 block_lo = cell, block_hi = cell + 1;
    bool skip_chunk = false;
    if (ch != chunk) {
      chunk = ch;
      index = queries.cell_index(ch);
      if (!index->clear) {
        // Jump to where the ray meets the chunk's busy box, or past the chunk if it does not.
        const glm::ivec3 lo = ch * c + index->busy_lo, hi = ch * c + index->busy_hi;
        double t_in = t, t_out = t_stop;
        int busy_entry = entry_axis;
        if (!clip_to_box(o, inv_d, glm::dvec3(lo), glm::dvec3(hi), &t_in, &t_out, &busy_entry)) {
          skip_chunk = true;
        } else if (t_in > t) {
          t = t_in;
          cell = cell_at(t, lo, hi, -1);
          entry_axis = busy_entry;
          block_lo = cell, block_hi = cell + 1;
        }
      }
    }
    const glm::ivec3 local = cell - ch * c;
    if (index->clear || skip_chunk) {
      if (index->clear_inside) {
        if (visit(cell, CellKind::kInside, t, t_stop, entry_axis)) return;
      }
      // Out of the chunk, or of the cube of clear chunks around it.
      block_lo = (ch - (index->clear_radius - 1)) * c;
      block_hi = (ch + index->clear_radius) * c;
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
    // Out of one cell, the other coordinates stay (cell_at would clamp them
    // to the cell's own); out of a bigger block, the exit point says.
    if (block_hi - block_lo != glm::ivec3(1)) cell = cell_at(t, block_lo, block_hi, axis);
    cell[axis] = pos[axis] ? block_hi[axis] : block_lo[axis] - 1;
    if (cell[axis] < box_lo[axis] || cell[axis] >= box_hi[axis]) return;
    entry_axis = axis;
  }
}

}  // namespace ldc::detail
