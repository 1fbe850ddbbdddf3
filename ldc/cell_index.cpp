// CellIndex (which cells of a chunk hold surface) and CellSurface (the
// tangent planes in one cell): what every query reads from the span lists.
#include "ldc/detail/cell_index.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ldc/internal/ray_math.h"

namespace ldc::detail {
namespace {

glm::ivec3 compose(int axis, int along, int u, int v) {
  glm::ivec3 r;
  r[axis] = along;
  r[axis_u(axis)] = u;
  r[axis_v(axis)] = v;
  return r;
}

void set_bit(CellIndex* index, const glm::ivec3& l) {
  index->surface[size_t(index->brick_of(l))] |= uint64_t{1} << CellIndex::cell_bit(l);
}

// Visits the points of every ray of `family` with (u, v) local in [u_lo, u_hi) x [v_lo, v_hi).
template <class Fn>
void for_each_ray_points(const RayFamily& family, int c, int u_lo, int u_hi, int v_lo, int v_hi, Fn&& fn) {
  if (family.is_uniform()) return;
  std::span<const PackedPoint> all = family.all_points();
  for (int v = v_lo; v < v_hi; ++v) {
    uint32_t offset = family.first_point(v * c + u_lo);
    for (int u = u_lo; u < u_hi; ++u) {
      const uint32_t n = family.point_count(v * c + u);
      if (n) fn(u, v, all.subspan(offset, n));
      offset += n;
    }
  }
}

// Marks the cells around every edge of the chunk's own rays and of the
// neighbours' rays on its far faces that holds a point.
void mark_surface_cells(const World& world, const glm::ivec3& chunk, CellIndex* index) {
  const int c = index->size;
  const uint32_t q = depth_steps_per_cell(c);
  for (int a = 0; a < 3; ++a) {
    const int au = axis_u(a), av = axis_v(a);
    for (int du = 0; du <= 1; ++du)
      for (int dv = 0; dv <= 1; ++dv) {
        glm::ivec3 offset(0);
        offset[au] = du;
        offset[av] = dv;
        const Chunk* source = world.chunk(chunk + offset);
        if (!source) continue;
        // Only the neighbour's first row of rays (u or v local 0) borders our cells.
        const int u_hi = du ? 1 : c, v_hi = dv ? 1 : c;
        for_each_ray_points(source->axis[a], c, 0, u_hi, 0, v_hi,
                            [&](int u, int v, std::span<const PackedPoint> points) {
                              const int gu = u + du * c, gv = v + dv * c;
                              for (const PackedPoint& p : points) {
                                const int e = int(p.depth / q);
                                for (int cu = gu - 1; cu <= gu; ++cu)
                                  for (int cv = gv - 1; cv <= gv; ++cv)
                                    if (cu >= 0 && cu < c && cv >= 0 && cv < c)
                                      set_bit(index, compose(a, e, cu, cv));
                              }
                            });
      }
  }
}

// The cells whose first corner is inside, from the chunk's own X rays.
void mark_inside_cells(const Chunk* own, ChunkKind kind, CellIndex* index) {
  const int c = index->size;
  if (!own) {
    if (kind == ChunkKind::kSolid) std::fill(index->inside.begin(), index->inside.end(), ~uint64_t{0});
    return;
  }
  const RayFamily& xs = own->axis[0];
  RayReader rays(xs);
  for (int ray = 0; ray < c * c; ++ray) {  // X rays: ray = z*C + y
    const RayPoints points = rays.next();
    const uint64_t word = node_word(points.starts_inside, points.points, c);
    if (!word) continue;
    const int y = ray % c, z = ray / c;
    for (int bx = 0; bx < index->bricks_per_axis; ++bx) {
      const uint64_t nibble = (word >> (bx << kBrickShift)) & 0xF;
      if (nibble) index->inside[size_t(index->brick_of({bx << kBrickShift, y, z}))] |= nibble << CellIndex::cell_bit({0, y, z});
    }
  }
}

// Chebyshev distance, in bricks, from each empty brick to the nearest busy one
// (plus one), by repeated one-brick dilation of row masks: B <= 16 bricks.
void mark_empty_radius(CellIndex* index) {
  const int b = index->bricks_per_axis;
  std::vector<uint16_t> reach(size_t(b) * b, 0);  // row (bz, by): bit bx within the current distance of a busy brick
  for (int bz = 0; bz < b; ++bz)
    for (int by = 0; by < b; ++by)
      for (int bx = 0; bx < b; ++bx) {
        const size_t k = (size_t(bz) * b + by) * b + bx;
        if (index->surface[k] | index->inside[k]) reach[size_t(bz) * b + by] |= uint16_t(1u << bx);
      }
  index->empty_radius.assign(size_t(b) * b * b, 0);
  glm::ivec3 lo(b), hi(0);
  for (int bz = 0; bz < b; ++bz)
    for (int by = 0; by < b; ++by)
      for (int bx = 0; bx < b; ++bx)
        if ((reach[size_t(bz) * b + by] >> bx) & 1u) {
          lo = glm::min(lo, glm::ivec3(bx, by, bz));
          hi = glm::max(hi, glm::ivec3(bx, by, bz) + 1);
        }
  index->busy_lo = lo << kBrickShift;
  index->busy_hi = glm::max(lo, hi) << kBrickShift;
  std::vector<uint16_t> next(reach.size());
  const uint16_t row_mask = uint16_t((1u << b) - 1);
  for (int r = 1; r <= b; ++r) {
    // Bricks not yet reached get radius r; then grow the reach by one brick.
    bool any = false;
    for (int bz = 0; bz < b; ++bz)
      for (int by = 0; by < b; ++by) {
        const uint16_t row = reach[size_t(bz) * b + by];
        for (int bx = 0; bx < b; ++bx) {
          const size_t k = (size_t(bz) * b + by) * b + bx;
          if (!((row >> bx) & 1u) && index->empty_radius[k] == 0) index->empty_radius[k] = uint8_t(r), any = true;
        }
      }
    if (!any) break;
    for (int bz = 0; bz < b; ++bz)
      for (int by = 0; by < b; ++by) {
        uint16_t grown = 0;
        for (int z = std::max(0, bz - 1); z <= std::min(b - 1, bz + 1); ++z)
          for (int y = std::max(0, by - 1); y <= std::min(b - 1, by + 1); ++y) {
            const uint16_t row = reach[size_t(z) * b + y];
            grown |= uint16_t(row | (row << 1) | (row >> 1));
          }
        next[size_t(bz) * b + by] = grown & row_mask;
      }
    reach.swap(next);
  }
}

// The chunks within r - 1 of c are clear outside when each one's sources
// (itself and its +x, +y, +z neighbours and their sums) are empty: when
// every chunk of the cube [c - (r - 1), c + r) is.
bool clear_within(const World& world, const glm::ivec3& c, int r) {
  const glm::ivec3 lo = c - (r - 1), hi = c + r;
  for (int z = lo.z; z < hi.z; ++z)
    for (int y = lo.y; y < hi.y; ++y)
      for (int x = lo.x; x < hi.x; ++x)
        if (world.chunk_kind({x, y, z}) != ChunkKind::kEmpty) return false;
  return true;
}

int clear_radius_of(const World& world, const glm::ivec3& c) {
  int r = 1;
  while (r < CellIndex::kMaxClearRadius && clear_within(world, c, r + 1)) ++r;
  return r;
}

}  // namespace

size_t CellIndex::memory_bytes() const {
  return sizeof(CellIndex) + (surface.capacity() + inside.capacity()) * sizeof(uint64_t) + empty_radius.capacity();
}

bool index_current(const CellIndex& index, const World& world, const glm::ivec3& c) {
  for (int s = 0; s < kIndexSources; ++s) {
    const glm::ivec3 ch = c + kIndexSourceOffsets[size_t(s)];
    if (world.chunk(ch) != index.sources[size_t(s)].get() || world.chunk_kind(ch) != index.kinds[size_t(s)]) return false;
  }
  return index.clear_radius == 1 || clear_within(world, c, index.clear_radius);
}

std::unique_ptr<CellIndex> build_cell_index(const World& world, const glm::ivec3& chunk) {
  auto index = std::make_unique<CellIndex>();
  const int c = world.chunk_size();
  index->size = c;
  index->checked_stamp.store(world.stamp(), std::memory_order_relaxed);
  bool uniform = true;
  for (int s = 0; s < kIndexSources; ++s) {
    const glm::ivec3 ch = chunk + kIndexSourceOffsets[size_t(s)];
    index->sources[size_t(s)] = world.chunk_shared(ch);
    index->kinds[size_t(s)] = world.chunk_kind(ch);
    uniform = uniform && index->kinds[size_t(s)] == index->kinds[0] && index->kinds[0] != ChunkKind::kMixed;
  }
  if (uniform) {
    index->clear = true;
    index->clear_inside = index->kinds[0] == ChunkKind::kSolid;
    if (index->kinds[0] == ChunkKind::kEmpty) index->clear_radius = clear_radius_of(world, chunk);
    return index;
  }
  const int b = c >> kBrickShift;
  index->bricks_per_axis = b;
  index->surface.assign(size_t(b) * b * b, 0);
  index->inside.assign(size_t(b) * b * b, 0);
  mark_surface_cells(world, chunk, index.get());
  mark_inside_cells(index->sources[0].get(), index->kinds[0], index.get());
  mark_empty_radius(index.get());
  return index;
}

// ---------------------------------------------------------------------------
// CellSurface

namespace {

// Adds the points of one ray, starting at all_points()[first], whose depth
// steps lie in [lo, hi): the crossings of the edge from `node` along `axis`.
void add_edge_points(const RayFamily& family, uint32_t first, uint32_t count, uint32_t lo, uint32_t hi,
                     const glm::dvec3& node_local, int axis, CellSurface* out) {
  const double cells_per_step = 1.0 / (hi - lo);
  const PackedPoint* p = family.all_points().data() + first;
  for (uint32_t i = 0; i < count && p[i].depth < hi; ++i) {
    if (p[i].depth < lo || out->count == CellSurface::kMaxPlanes) continue;
    CellPlane& plane = out->planes[size_t(out->count++)];
    plane.p = node_local;
    plane.p[axis] = double(p[i].depth - lo) * cells_per_step;
    plane.n = glm::dvec3(decode_normal(p[i].normal));
    plane.material = p[i].material;
  }
}

// The general case: the edge's ray may belong to a neighbouring chunk.
void gather_edge(const World& world, const glm::ivec3& node, int axis, const glm::ivec3& cell, CellSurface* out) {
  const int c = world.chunk_size();
  const glm::ivec3 ch = world.chunk_of_node(node);
  const Chunk* data = world.chunk(ch);
  if (!data) return;
  const RayFamily& family = data->axis[axis];
  const int ray = ray_index(node, axis, c);
  if (!family.holds_points(ray)) return;
  uint32_t n = 0;
  const uint32_t first = family.first_point(ray, std::span<uint32_t>(&n, 1));
  const uint32_t q = depth_steps_per_cell(c);
  const uint32_t lo = uint32_t(node[axis] - ch[axis] * c) * q;
  add_edge_points(family, first, n, lo, lo + q, glm::dvec3(node - cell), axis, out);
}

// The common case: all twelve edges lie in the cell's own chunk, so the four
// rays of each axis are neighbours in one family (ray, ray+1, ray+C, ray+C+1).
void gather_inner_cell(const Chunk& chunk, int c, const glm::ivec3& local, CellSurface* out) {
  const uint32_t q = depth_steps_per_cell(c);
  // The six pairs of rays (two per axis) lie in six rows of three families:
  // each read waits on memory, so every row is requested before any is read,
  // then every pair's points before any is added.
  int ray0[3][2];
  for (int a = 0; a < 3; ++a)
    for (int dv = 0; dv <= 1; ++dv) {
      ray0[a][dv] = (local[axis_v(a)] + dv) * c + local[axis_u(a)];
      chunk.axis[a].prefetch_ray(ray0[a][dv]);
    }
  uint32_t first[3][2] = {}, n[3][2][2] = {};
  for (int a = 0; a < 3; ++a) {
    const RayFamily& family = chunk.axis[a];
    for (int dv = 0; dv <= 1; ++dv) {
      if (family.is_uniform() || (!family.holds_points(ray0[a][dv]) && !family.holds_points(ray0[a][dv] + 1))) continue;
      first[a][dv] = family.first_point(ray0[a][dv], n[a][dv]);
      family.prefetch_points(first[a][dv]);
    }
  }
  for (int a = 0; a < 3; ++a) {
    const RayFamily& family = chunk.axis[a];
    const uint32_t lo = uint32_t(local[a]) * q;
    for (int dv = 0; dv <= 1; ++dv) {
      const uint32_t n0 = n[a][dv][0], n1 = n[a][dv][1];
      glm::dvec3 node(0.0);
      node[axis_v(a)] = dv;
      if (n0) add_edge_points(family, first[a][dv], n0, lo, lo + q, node, a, out);
      node[axis_u(a)] = 1.0;
      if (n1) add_edge_points(family, first[a][dv] + n0, n1, lo, lo + q, node, a, out);
    }
  }
}

// Points of a convex piece lie behind every other point's plane; of a concave
// piece, in front. 0.02 cells absorbs the rounding of stored depths and normals.
constexpr double kShapeTolerance = 0.02;

void classify(CellSurface* s) {
  bool convex = true, concave = true;
  for (int i = 0; i < s->count && (convex || concave); ++i)
    for (int j = 0; j < s->count; ++j) {
      const double side = glm::dot(s->planes[size_t(i)].n, s->planes[size_t(j)].p - s->planes[size_t(i)].p);
      convex = convex && side <= kShapeTolerance;
      concave = concave && side >= -kShapeTolerance;
    }
  if (convex) {
    s->shape = CellShape::kConvex;
    return;
  }
  if (concave) {
    s->shape = CellShape::kConcave;
    return;
  }
  // A saddle: one plane through the points' centre with their mean normal.
  glm::dvec3 p(0.0), n(0.0);
  for (int i = 0; i < s->count; ++i) p += s->planes[size_t(i)].p, n += s->planes[size_t(i)].n;
  p /= double(s->count);
  const double len = glm::length(n);
  n = len > 1e-9 ? n / len : s->planes[0].n;
  // The material of the point nearest the centre.
  int nearest = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < s->count; ++i) {
    const double d2 = glm::dot(s->planes[size_t(i)].p - p, s->planes[size_t(i)].p - p);
    if (d2 < best) best = d2, nearest = i;
  }
  s->planes[0] = CellPlane{p, n, s->planes[size_t(nearest)].material};
  s->count = 1;
  s->shape = CellShape::kPlane;
}

}  // namespace

bool gather_cell_surface(const World& world, const glm::ivec3& cell, CellSurface* out) {
  out->count = 0;
  const int c = world.chunk_size();
  const glm::ivec3 ch = world.chunk_of_node(cell);  // a cell is named by its first node
  const glm::ivec3 local = cell - ch * c;
  if (glm::all(glm::lessThan(local, glm::ivec3(c - 1)))) {
    if (const Chunk* data = world.chunk(ch)) gather_inner_cell(*data, c, local, out);
  } else {
    for (int a = 0; a < 3; ++a)
      for (int du = 0; du <= 1; ++du)
        for (int dv = 0; dv <= 1; ++dv) {
          glm::ivec3 node = cell;
          node[axis_u(a)] += du;
          node[axis_v(a)] += dv;
          gather_edge(world, node, a, cell, out);
        }
  }
  if (out->count == 0) return false;
  classify(out);
  return true;
}

namespace {

// Direct-mapped: a lookup is one hash and one compare, and a miss costs a
// gather as before. 64 entries hold a few rows of a camera's cells.
struct SurfaceCache {
  static constexpr size_t kEntries = 64;
  struct Entry {
    uint64_t stamp = 0;  // 0: empty (stamps start at 1)
    glm::ivec3 cell{0};
    bool has_surface = false;
    CellSurface surface;
  };
  std::array<Entry, kEntries> entries;

  static size_t slot(const glm::ivec3& c) {
    const uint32_t h = uint32_t(c.x) * 73856093u ^ uint32_t(c.y) * 19349663u ^ uint32_t(c.z) * 83492791u;
    return (h ^ (h >> 11)) & (kEntries - 1);
  }
};

}  // namespace

const CellSurface* cached_cell_surface(const World& world, const glm::ivec3& cell) {
  thread_local std::unique_ptr<SurfaceCache> cache;  // on the heap: about 90 KB
  if (!cache) cache = std::make_unique<SurfaceCache>();
  SurfaceCache::Entry& e = cache->entries[SurfaceCache::slot(cell)];
  const uint64_t stamp = world.stamp();
  if (e.stamp != stamp || e.cell != cell) {
    e.stamp = stamp;
    e.cell = cell;
    e.has_surface = gather_cell_surface(world, cell, &e.surface);
  }
  return e.has_surface ? &e.surface : nullptr;
}

double CellSurface::inside_value(const glm::dvec3& x, int* plane) const {
  // Convex: the largest plane value (inside all); concave and plane: the smallest.
  const bool use_max = shape == CellShape::kConvex;
  double best = use_max ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
  int best_plane = 0;
  for (int i = 0; i < count; ++i) {
    const double v = glm::dot(planes[size_t(i)].n, x - planes[size_t(i)].p);
    if (use_max ? v > best : v < best) best = v, best_plane = i;
  }
  if (plane) *plane = best_plane;
  return best;
}

CellHit intersect_cell(const CellSurface& s, const glm::dvec3& o, const glm::dvec3& d, double t0, double t1) {
  CellHit hit;
  if (s.shape == CellShape::kConvex) {
    // Clip [t0, t1] by every inner half-space: n.(o + t d - p) <= 0.
    double lo = t0, hi = t1;
    int lo_plane = -1;
    for (int i = 0; i < s.count; ++i) {
      const CellPlane& pl = s.planes[size_t(i)];
      const double denom = glm::dot(pl.n, d), value = glm::dot(pl.n, o - pl.p);
      if (denom == 0.0) {
        if (value > 0.0) return hit;
        continue;
      }
      const double t = -value / denom;
      if (denom < 0.0) {
        if (t > lo) lo = t, lo_plane = i;
      } else {
        hi = std::min(hi, t);
      }
      if (lo > hi) return hit;
    }
    hit.hit = true;
    hit.t = lo;
    if (lo_plane < 0) s.inside_value(o + t0 * d, &lo_plane);  // inside on entry: the nearest face
    hit.plane = lo_plane;
    return hit;
  }
  // Concave or one plane: the earliest t in [t0, t1] inside any half-space.
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < s.count; ++i) {
    const CellPlane& pl = s.planes[size_t(i)];
    const double denom = glm::dot(pl.n, d), value0 = glm::dot(pl.n, o + t0 * d - pl.p);
    double t;
    if (value0 <= 0.0) t = t0;
    else if (denom < 0.0) t = t0 + value0 / -denom;
    else continue;
    if (t <= t1 && t < best) best = t, hit.plane = i;
  }
  if (best <= t1) hit.hit = true, hit.t = best;
  return hit;
}

bool closest_in_cell(const CellSurface& s, const glm::dvec3& x, CellClosest* out) {
  bool found = false;
  auto consider = [&](const glm::dvec3& q, int plane) {
    const double d2 = glm::dot(q - x, q - x);
    if (!found || d2 < out->distance2) *out = CellClosest{q, d2, plane}, found = true;
  };
  auto in_cell = [](const glm::dvec3& q, double slack) {
    return glm::all(glm::greaterThanEqual(q, glm::dvec3(-slack))) &&
           glm::all(glm::lessThanEqual(q, glm::dvec3(1.0 + slack)));
  };
  // The plane the model's value comes from (convex: the largest, concave: the
  // smallest) is the nearest face in its region: project x onto it.
  int k = 0;
  const double value = s.inside_value(x, &k);
  const glm::dvec3 q = x - s.planes[size_t(k)].n * value;
  constexpr double kOnSurface = 0.02, kSlack = 0.1;  // cells
  if (in_cell(q, kSlack) && std::abs(s.inside_value(q)) <= kOnSurface) {
    consider(q, k);
    return true;
  }
  // Near an edge or corner of the model: the other projections that stay on
  // it, clamped to the cell, and the stored points themselves.
  for (int i = 0; i < s.count; ++i) {
    const CellPlane& pl = s.planes[size_t(i)];
    glm::dvec3 p = glm::clamp(x - pl.n * glm::dot(pl.n, x - pl.p), glm::dvec3(0.0), glm::dvec3(1.0));
    p -= pl.n * glm::dot(pl.n, p - pl.p);  // back onto the plane
    if (in_cell(p, kSlack) && std::abs(s.inside_value(p)) <= kOnSurface) consider(p, i);
    consider(pl.p, i);  // a stored point, or the centre of the averaged plane
  }
  return found;
}

}  // namespace ldc::detail
