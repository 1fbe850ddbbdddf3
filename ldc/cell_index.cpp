// CellIndex (which cells of a chunk hold surface) and CellSurface (the
// tangent planes in one cell): what every query reads from the span lists.
#include "ldc/detail/cell_index.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ldc/detail/ray_math.h"

namespace ldc::detail {
namespace {

glm::ivec3 compose(int axis, int along, int u, int v) {
  glm::ivec3 r;
  r[axis] = along;
  r[axis_u(axis)] = u;
  r[axis_v(axis)] = v;
  return r;
}

void set_bit(std::vector<uint64_t>& bits, int c, const glm::ivec3& l) {
  bits[size_t(l.z) * c + l.y] |= uint64_t{1} << l.x;
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
                                      set_bit(index->surface, c, compose(a, e, cu, cv));
                              }
                            });
      }
  }
}

void mark_inside_cells(const Chunk* own, ChunkKind kind, CellIndex* index) {
  const int c = index->size;
  if (!own) {
    if (kind == ChunkKind::kSolid) std::fill(index->inside.begin(), index->inside.end(), c == 64 ? ~uint64_t{0} : (uint64_t{1} << c) - 1);
    return;
  }
  const RayFamily& xs = own->axis[0];
  std::span<const PackedPoint> all = xs.all_points();
  uint32_t offset = 0;
  for (int ray = 0; ray < c * c; ++ray) {
    const uint32_t n = xs.point_count(ray);
    index->inside[size_t(ray)] = node_word(xs.starts_inside(ray), all.subspan(offset, n), c);
    offset += n;
  }
}

void mark_bricks(CellIndex* index) {
  const int c = index->size, b = c >> kBrickShift;
  index->bricks.assign((size_t(b) * b * b + 63) / 64, 0);
  for (int z = 0; z < c; ++z)
    for (int y = 0; y < c; ++y) {
      const uint64_t w = index->surface[size_t(z) * c + y] | index->inside[size_t(z) * c + y];
      for (int bx = 0; bx < b; ++bx) {
        if (!((w >> (bx << kBrickShift)) & 0xF)) continue;
        const size_t bit = (size_t(z >> kBrickShift) * b + (y >> kBrickShift)) * b + bx;
        index->bricks[bit >> 6] |= uint64_t{1} << (bit & 63);
      }
    }
}

}  // namespace

size_t CellIndex::memory_bytes() const {
  return sizeof(CellIndex) + (surface.capacity() + inside.capacity() + bricks.capacity()) * sizeof(uint64_t);
}

bool index_current(const CellIndex& index, const World& world, const glm::ivec3& c) {
  for (int s = 0; s < kIndexSources; ++s) {
    const glm::ivec3 ch = c + kIndexSourceOffsets[size_t(s)];
    if (world.chunk(ch) != index.sources[size_t(s)] || world.chunk_kind(ch) != index.kinds[size_t(s)]) return false;
  }
  return true;
}

std::unique_ptr<CellIndex> build_cell_index(const World& world, const glm::ivec3& chunk) {
  auto index = std::make_unique<CellIndex>();
  const int c = world.chunk_size();
  index->size = c;
  index->checked_stamp.store(world.stamp(), std::memory_order_relaxed);
  bool uniform = true;
  for (int s = 0; s < kIndexSources; ++s) {
    const glm::ivec3 ch = chunk + kIndexSourceOffsets[size_t(s)];
    index->keep[size_t(s)] = world.chunk_shared(ch);
    index->sources[size_t(s)] = index->keep[size_t(s)].get();
    index->kinds[size_t(s)] = world.chunk_kind(ch);
    uniform = uniform && index->kinds[size_t(s)] == index->kinds[0] && index->kinds[0] != ChunkKind::kMixed;
  }
  if (uniform) {
    index->clear = true;
    index->clear_inside = index->kinds[0] == ChunkKind::kSolid;
    return index;
  }
  index->surface.assign(size_t(c) * c, 0);
  index->inside.assign(size_t(c) * c, 0);
  mark_surface_cells(world, chunk, index.get());
  mark_inside_cells(index->sources[0], index->kinds[0], index.get());
  mark_bricks(index.get());
  return index;
}

// ---------------------------------------------------------------------------
// CellSurface

namespace {

// Adds the points on the edge from `node` along `axis` to the planes.
void gather_edge(const World& world, const glm::ivec3& node, int axis, const glm::ivec3& cell, CellSurface* out) {
  const int c = world.chunk_size();
  const glm::ivec3 ch(floor_div(node.x, c), floor_div(node.y, c), floor_div(node.z, c));
  const Chunk* data = world.chunk(ch);
  if (!data) return;
  const RayFamily& family = data->axis[axis];
  const int ray = ray_index(node, axis, c);
  const uint32_t n = family.point_count(ray);
  if (!n) return;
  const uint32_t q = depth_steps_per_cell(c);
  const int segment_start = ch[axis] * c;
  const uint32_t lo = uint32_t(node[axis] - segment_start) * q, hi = lo + q;
  const PackedPoint* p = family.all_points().data() + family.first_point(ray);
  for (uint32_t i = 0; i < n && p[i].depth < hi; ++i) {
    if (p[i].depth < lo || out->count == CellSurface::kMaxPlanes) continue;
    CellPlane& plane = out->planes[size_t(out->count++)];
    plane.p = glm::dvec3(node - cell);
    plane.p[axis] = double(segment_start - cell[axis]) + double(p[i].depth) / q;
    plane.n = glm::dvec3(decode_normal(p[i].normal));
    plane.material = p[i].material;
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
  for (int a = 0; a < 3; ++a)
    for (int du = 0; du <= 1; ++du)
      for (int dv = 0; dv <= 1; ++dv) {
        glm::ivec3 node = cell;
        node[axis_u(a)] += du;
        node[axis_v(a)] += dv;
        gather_edge(world, node, a, cell, out);
      }
  if (out->count == 0) return false;
  classify(out);
  return true;
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
