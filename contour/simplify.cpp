// simplify_mesh: half-edge collapses within a quadric error bound, refusing
// any collapse that would change topology, move a material border, flip or
// crush a triangle or make two triangles meet. See contour/contour.h for the
// guarantees; this file says how.
//
// Setup (once, parallel over vertices, each vertex summing its own terms in a
// fixed order, so deterministic): a vertex -> triangles table; each vertex's
// lock (a manifold interior vertex or not) and its quadric.
//
// Passes: a pass cuts space into a grid of blocks. A vertex belongs to the
// block its position falls in; a block may move a vertex only when every
// vertex of its triangles belongs to the block too, so a block changes only
// triangles lying inside its box. A triangle that may meet a changed one has
// a point in that box, so it is one of the block's own triangles (changed by
// this block alone, in order) or one that straddles a border (which nobody
// changes during the pass). Blocks therefore run in parallel, each in its own
// fixed order, and the result does not depend on the thread count.
//   1. blocks of block_size;
//   2. the same blocks shifted by half a block, seeded with the vertices that
//      pass 1 left because their fan crossed a border;
//   3. the whole mesh as one block, seeded with what pass 2 left (fans that
//      crossed both layouts' borders, or grew wider than a block).
// In a block: a heap of vertices by their cheapest collapse; the popped vertex
// tries its targets cheapest first; after a collapse the kept vertex and the
// two opposite the edge are evaluated again, the other neighbours lazily (an
// entry at a lower bound of their cost, evaluated when popped; a version
// number drops stale entries). Evaluating a vertex whose fan has one material
// only takes the minimum over its neighbours (no ring is built or sorted),
// with each vertex's own quadric error at its position kept up to date.
//
// The intersection test (the largest cost, with the spatial gather of nearby
// triangles from a uniform grid) is filtered before the exact predicates:
// - pairs sharing a vertex with a changed triangle are left out when the
//   fans around the changed triangles' corners are certainly stars. v's fan
//   is tested in full (star_after); a neighbour of u whose fan was proven a
//   star by an earlier collapse keeps that proof's direction, and only its
//   sectors that take v for u are tested again (star_kept);
// - every other pair first goes through the changed triangle's own
//   separating axes (its normal and its edges' normals in its plane, set up
//   once per changed triangle: this parts most pairs, coplanar ones on flat
//   faces too), then may_meet's per-pair axes; each with a margin far above
//   rounding. Only the pairs left go to the exact predicates.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "contour/contour.h"
#include "contour/detail/remove_triangles.h"
#include "contour/detail/triangle_intersection.h"
#include "ldc/internal/huge_pages.h"

namespace ldc {
namespace {

// --- Quadrics -------------------------------------------------------------------

// Sum of squared distances to planes: error(p) = p^T A p + 2 b.p + c, A
// symmetric. Coordinates are relative to the mesh's centre, so that far from
// the origin the terms do not cancel.
struct Quadric {
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0, b0 = 0, b1 = 0, b2 = 0, c = 0;

  // (n.p + d)^2 for a unit normal n.
  static Quadric plane(const glm::dvec3& n, double d) {
    return {n.x * n.x, n.x * n.y, n.x * n.z, n.y * n.y, n.y * n.z, n.z * n.z, n.x * d, n.y * d, n.z * d, d * d};
  }
  Quadric& operator+=(const Quadric& q) {
    a00 += q.a00, a01 += q.a01, a02 += q.a02, a11 += q.a11, a12 += q.a12, a22 += q.a22;
    b0 += q.b0, b1 += q.b1, b2 += q.b2, c += q.c;
    return *this;
  }
  double error(const glm::dvec3& p) const {
    const double x = p.x, y = p.y, z = p.z;
    const double e = x * (a00 * x + 2.0 * (a01 * y + a02 * z + b0)) + y * (a11 * y + 2.0 * (a12 * z + b1)) +
                     z * (a22 * z + 2.0 * b2) + c;
    return std::max(e, 0.0);  // rounding may dip below 0
  }
};

// --- Mesh state shared by all passes ----------------------------------------------

struct Box {
  glm::dvec3 lo, hi;
};

bool boxes_overlap(const Box& a, const Box& b) {
  return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y && a.lo.z <= b.hi.z &&
         b.lo.z <= a.hi.z;
}

Box triangle_box(const glm::dvec3* p, const glm::uvec3& t) {
  return {glm::min(p[t.x], glm::min(p[t.y], p[t.z])), glm::max(p[t.x], glm::max(p[t.y], p[t.z]))};
}

constexpr uint32_t kNoVertex = std::numeric_limits<uint32_t>::max();

enum TriangleState : uint8_t {
  kAlive = 0,   // tested for intersections, may change
  kFlat = 1,    // corners exactly collinear: kept as is, left out of the intersection tests (as mesh_quality does)
  kFrozen = 2,  // a repeated index: no edges, kept as is and ignored
  kDead = 3,    // removed by a collapse
};

enum VertexFlag : uint8_t {
  kUsed = 1,    // on a live triangle
  kLocked = 2,  // not a manifold interior vertex: never moves
  kSeam = 4,    // its last evaluation found its fan crossing a block border
};

struct Shared {
  const glm::dvec3* pos = nullptr;
  std::vector<uint16_t> material;  // per triangle
  glm::dvec3 centre{0.0};
  std::vector<glm::uvec3> tris;    // the working copy of the triangles
  std::vector<uint8_t> tstate;     // TriangleState
  std::vector<Quadric> quadric;    // per vertex
  std::vector<double> self_error;  // per vertex: its quadric's error at its own position
  std::vector<uint8_t> vflags;     // VertexFlag bits
  Box bounds{};
  double max_error2 = 0.0;         // max_error^2
  double cos_normal = 0.0;         // cos(max_normal_change)
  double min_angle_tan = 0.0;      // tan(min_angle_deg)
};

// --- Setup: incidence, locks, quadrics ----------------------------------------------

struct Incidence {
  std::vector<size_t> offset;    // triangles of v: tri[offset[v] .. offset[v + 1])
  std::vector<uint32_t> tri;
};

Incidence incidence(const Shared& s, size_t vertex_count) {
  Incidence table;
  detail::assign_on_huge_pages(table.offset, vertex_count + 1);
  for (size_t t = 0; t < s.tris.size(); ++t)
    if (s.tstate[t] != kFrozen)
      for (int k = 0; k < 3; ++k) ++table.offset[s.tris[t][k] + 1];
  for (size_t v = 0; v < vertex_count; ++v) table.offset[v + 1] += table.offset[v];
  detail::assign_on_huge_pages(table.tri, table.offset.back());
  std::vector<size_t> next(table.offset.begin(), table.offset.end() - 1);
  for (size_t t = 0; t < s.tris.size(); ++t)
    if (s.tstate[t] != kFrozen)
      for (int k = 0; k < 3; ++k) table.tri[next[s.tris[t][k]]++] = static_cast<uint32_t>(t);
  return table;
}

// The corners of t rotated so that v comes first: (v, a, b), counter-clockwise.
glm::uvec3 rotated_to(const glm::uvec3& t, uint32_t v) {
  return t.x == v ? t : t.y == v ? glm::uvec3(t.y, t.z, t.x) : glm::uvec3(t.z, t.x, t.y);
}

// One edge end at a vertex: the edge's other end, the triangle, and whether
// the triangle walks the edge away from the vertex.
struct EdgeEnd {
  uint32_t other;
  uint32_t tri;
  bool outgoing;
  bool operator<(const EdgeEnd& e) const { return other != e.other ? other < e.other : outgoing < e.outgoing; }
};

// Fills `ends` with the 2k edge ends of v's k triangles, sorted.
void edge_ends(const Shared& s, uint32_t v, const uint32_t* tris, size_t count, std::vector<EdgeEnd>& ends) {
  ends.clear();
  for (size_t i = 0; i < count; ++i) {
    const glm::uvec3 r = rotated_to(s.tris[tris[i]], v);
    ends.push_back({r.y, tris[i], true});
    ends.push_back({r.z, tris[i], false});
  }
  for (size_t i = 1; i < ends.size(); ++i)  // insertion sort: fans are small
    for (size_t j = i; j > 0 && ends[j] < ends[j - 1]; --j) std::swap(ends[j], ends[j - 1]);
}

// Manifold interior: every edge used twice, once each way (sorted ends come
// in pairs incoming, outgoing), and the triangles form one cycle around v.
bool manifold_interior(const Shared& s, uint32_t v, const std::vector<EdgeEnd>& ends) {
  if (ends.size() < 6 || ends.size() % 2 != 0) return false;
  for (size_t i = 0; i < ends.size(); i += 2) {
    if (ends[i].other != ends[i + 1].other || ends[i].outgoing || !ends[i + 1].outgoing) return false;
    if (i + 2 < ends.size() && ends[i + 2].other == ends[i].other) return false;
  }
  // Walk the fan: from triangle (v, a, b) to the one that leaves v along v -> b.
  const size_t k = ends.size() / 2;
  uint32_t tri = ends[0].tri;
  for (size_t step = 1; step <= k; ++step) {
    const uint32_t b = rotated_to(s.tris[tri], v).z;
    const size_t at = 2 * static_cast<size_t>(std::lower_bound(ends.begin(), ends.end(), EdgeEnd{b, 0, false}) -
                                              ends.begin()) / 2;
    tri = ends[at + 1].tri;  // the outgoing end of the edge v -> b
    if (tri == ends[0].tri) return step == k;
  }
  return false;
}

glm::dvec3 unit_normal(const glm::dvec3* p, const glm::uvec3& t) {
  return glm::normalize(glm::cross(p[t.y] - p[t.x], p[t.z] - p[t.x]));
}

// The planes merged into v at the start: its triangles' planes, and on a
// material border edge v -> x, for both triangles, the plane through the edge
// standing on the triangle (Garland & Heckbert's boundary constraint), so that
// the bound also holds the border line in place.
void add_initial_quadric(Shared& s, uint32_t v, const std::vector<EdgeEnd>& ends,
                         const std::vector<glm::dvec3>& normal) {
  Quadric q;
  const glm::dvec3 pv = s.pos[v];
  auto add = [&](const glm::dvec3& n) { q += Quadric::plane(n, -glm::dot(n, pv - s.centre)); };
  for (size_t i = 0; i < ends.size(); ++i)
    if (ends[i].outgoing) add(normal[ends[i].tri]);  // each triangle once
  for (size_t i = 0; i + 1 < ends.size(); ++i) {
    if (ends[i].other != ends[i + 1].other || s.material[ends[i].tri] == s.material[ends[i + 1].tri]) continue;
    const glm::dvec3 edge = s.pos[ends[i].other] - pv;
    for (size_t j : {i, i + 1}) {
      const glm::dvec3 m = glm::cross(edge, normal[ends[j].tri]);
      const double length = glm::length(m);
      if (length > 0.0) add(m / length);
    }
  }
  s.quadric[v] = q;
  s.self_error[v] = q.error(pv - s.centre);
}

// Locks and quadrics of every vertex (parallel; each vertex on its own).
void analyse_vertices(Shared& s, const Incidence& table) {
  const size_t n = table.offset.size() - 1;
  s.vflags.assign(n, 0);
  detail::assign_on_huge_pages(s.quadric, n);
  detail::assign_on_huge_pages(s.self_error, n);
  std::vector<glm::dvec3> normal;  // unit normals, each computed once
  detail::assign_on_huge_pages(normal, s.tris.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, s.tris.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t)
      if (s.tstate[t] != kFrozen) normal[t] = unit_normal(s.pos, s.tris[t]);
  });
  tbb::enumerable_thread_specific<std::vector<EdgeEnd>> scratch;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 2048), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<EdgeEnd>& ends = scratch.local();
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const size_t count = table.offset[v + 1] - table.offset[v];
      if (count == 0) continue;
      const uint32_t* tris = table.tri.data() + table.offset[v];
      bool flat = false;
      for (size_t i = 0; i < count; ++i) flat = flat || s.tstate[tris[i]] == kFlat;
      edge_ends(s, static_cast<uint32_t>(v), tris, count, ends);
      const bool movable = !flat && manifold_interior(s, static_cast<uint32_t>(v), ends);
      s.vflags[v] = kUsed | (movable ? 0 : kLocked);
      add_initial_quadric(s, static_cast<uint32_t>(v), ends, normal);
    }
  });
}

// --- Block layouts -------------------------------------------------------------------

// detail::clamped_grid_cell's cell (the same for every point), without
// std::floor, a library call on plain x86-64: the quotient is clamped first,
// and truncation is floor for the positive values left.
inline glm::ivec3 grid_cell(const glm::dvec3& p, const glm::dvec3& origin, double size, const glm::ivec3& dims) {
  glm::ivec3 c;
  for (int k = 0; k < 3; ++k) {
    const double x = (p[k] - origin[k]) / size;
    c[k] = x <= 0.0 ? 0 : x >= dims[k] - 1 ? dims[k] - 1 : static_cast<int>(x);
  }
  return c;
}

struct Layout {
  glm::dvec3 origin{0.0};
  double size = 1.0;
  glm::ivec3 dims{1};

  // Monotone in each coordinate (clamped into the grid).
  glm::ivec3 coords(const glm::dvec3& p) const { return grid_cell(p, origin, size, dims); }
  uint32_t index(const glm::ivec3& c) const { return static_cast<uint32_t>((c.z * dims.y + c.y) * dims.x + c.x); }
  size_t count() const { return size_t(dims.x) * size_t(dims.y) * size_t(dims.z); }
  glm::ivec3 coords_of(uint32_t i) const { return {int(i % dims.x), int(i / dims.x % dims.y), int(i / dims.x / dims.y)}; }
  // The region a block's grid covers: its box within the mesh's bounds.
  Box region(uint32_t i, const Box& bounds) const {
    if (count() == 1) return bounds;
    const glm::dvec3 lo = origin + glm::dvec3(coords_of(i)) * size;
    return {glm::max(lo, bounds.lo), glm::min(lo + size, bounds.hi)};
  }
};

constexpr size_t kMaxBlocks = size_t(1) << 21;

// Blocks of `size`, the grid shifted by `shift` (in [0, size)).
Layout block_layout(const Box& bounds, double size, double shift) {
  Layout layout;
  for (;;) {
    layout.size = size;
    layout.origin = bounds.lo - shift;
    for (int k = 0; k < 3; ++k)
      layout.dims[k] = static_cast<int>(std::min(std::floor((bounds.hi[k] - layout.origin[k]) / size) + 1.0, 4096.0));
    if (layout.count() <= kMaxBlocks) return layout;
    size *= 2.0, shift *= 2.0;
  }
}

Layout whole_mesh_layout(const Box& bounds) {
  Layout layout;
  layout.origin = bounds.lo;
  layout.size = std::numeric_limits<double>::max();
  return layout;
}

// What a pass hands its blocks: vertices and triangles by block.
struct PassInput {
  Layout layout;
  std::vector<uint32_t> vertex_block;  // per used vertex
  std::vector<uint32_t> local_of;      // per used vertex: its index in its block's list
  std::vector<uint32_t> vstart, vlist;
  std::vector<uint32_t> tstart, tlist;  // triangles whose box overlaps the block (by block coordinates)
  std::vector<uint32_t> blocks;         // blocks to run
  std::vector<size_t> quota;            // per block: triangles it may remove
  bool seed_all = true;                 // evaluate every vertex, or only the kSeam ones
  bool overshoot = false;               // a block may end one triangle below its quota (the last pass)
};

// Counting sort of items into blocks: start[b] .. start[b + 1] in `list`.
template <class ForEachItem>
void bucket(size_t blocks, ForEachItem for_each, std::vector<uint32_t>& start, std::vector<uint32_t>& list) {
  start.assign(blocks + 1, 0);
  for_each([&](uint32_t, uint32_t b) { ++start[b + 1]; });
  for (size_t b = 0; b < blocks; ++b) start[b + 1] += start[b];
  list.resize(start.back());
  std::vector<uint32_t> next(start.begin(), start.end() - 1);
  for_each([&](uint32_t item, uint32_t b) { list[next[b]++] = item; });
}

void build_pass(const Shared& s, PassInput& p) {
  const size_t nv = s.vflags.size();
  const size_t nb = p.layout.count();
  p.vertex_block.resize(nv);
  p.local_of.resize(nv);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 8192), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      if (s.vflags[v] & kUsed) p.vertex_block[v] = p.layout.index(p.layout.coords(s.pos[v]));
  });
  bucket(nb, [&](auto add) {
    for (uint32_t v = 0; v < nv; ++v) if (s.vflags[v] & kUsed) add(v, p.vertex_block[v]);
  }, p.vstart, p.vlist);
  for (size_t b = 0; b < nb; ++b)
    for (uint32_t i = p.vstart[b]; i < p.vstart[b + 1]; ++i) p.local_of[p.vlist[i]] = i - p.vstart[b];
  bucket(nb, [&](auto add) {
    for (uint32_t t = 0; t < s.tris.size(); ++t) {
      if (s.tstate[t] == kDead || s.tstate[t] == kFrozen) continue;
      // Corners in one block: so is the box (coordinates are monotone).
      const glm::uvec3& c = s.tris[t];
      const uint32_t b = p.vertex_block[c.x];
      if (p.vertex_block[c.y] == b && p.vertex_block[c.z] == b) {
        add(t, b);
        continue;
      }
      const Box box = triangle_box(s.pos, c);
      const glm::ivec3 lo = p.layout.coords(box.lo), hi = p.layout.coords(box.hi);
      for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
          for (int x = lo.x; x <= hi.x; ++x) add(t, p.layout.index({x, y, z}));
    }
  }, p.tstart, p.tlist);
  p.blocks.clear();
  for (uint32_t b = 0; b < nb; ++b) {
    bool run = false;
    for (uint32_t i = p.vstart[b]; i < p.vstart[b + 1] && !run; ++i)
      run = p.seed_all || (s.vflags[p.vlist[i]] & kSeam);
    if (run) p.blocks.push_back(b);
  }
}

// --- The spatial index of a block ----------------------------------------------------

// A uniform grid over the block's region holding its triangles' boxes (cell
// coordinates clamped, so triangles reaching outside are still found where
// they overlap the region). Changed triangles are inserted again; stale
// entries stay and are filtered by the caller (a triangle's current box).
class TriangleGrid {
 public:
  void reset(const Box& region, size_t triangles) {
    origin_ = region.lo;
    const glm::dvec3 extent = glm::max(region.hi - region.lo, glm::dvec3(0.0));
    const double longest = std::max({extent.x, extent.y, extent.z, 1e-300});
    const int per_axis = std::clamp(static_cast<int>(std::cbrt(double(triangles))), 1, 64);
    size_ = longest / per_axis;
    for (int k = 0; k < 3; ++k) dims_[k] = std::clamp(static_cast<int>(extent[k] / size_) + 1, 1, per_axis);
    const size_t count = size_t(dims_.x) * size_t(dims_.y) * size_t(dims_.z);
    if (cells_.size() < count) cells_.resize(count);
    for (size_t i = 0; i < count; ++i) cells_[i].clear();
    large_.clear();
    entries_ = 0;
  }
  // Entries made, stale ones included.
  size_t entries() const { return entries_; }
  void insert(uint32_t tri, const Box& box) {
    const glm::ivec3 lo = cell(box.lo), hi = cell(box.hi);
    if (cell_count(lo, hi) > kLargeCells) {
      large_.push_back(tri);
      ++entries_;
      return;
    }
    entries_ += cell_count(lo, hi);
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) cells_[key({x, y, z})].push_back(tri);
  }
  // Calls f(tri) for every triangle that may overlap `box` (repeats possible);
  // returns false, calling nothing, when `box` covers too many cells to be
  // worth it (the caller then scans all its triangles).
  template <class F>
  bool for_each_near(const Box& box, F&& f) const {
    const glm::ivec3 lo = cell(box.lo), hi = cell(box.hi);
    if (cell_count(lo, hi) > kLargeCells) return false;
    for (uint32_t t : large_) f(t);
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x)
          for (uint32_t t : cells_[key({x, y, z})]) f(t);
    return true;
  }

 private:
  static constexpr size_t kLargeCells = 64;
  glm::ivec3 cell(const glm::dvec3& p) const { return grid_cell(p, origin_, size_, dims_); }
  static size_t cell_count(const glm::ivec3& lo, const glm::ivec3& hi) {
    return size_t(hi.x - lo.x + 1) * size_t(hi.y - lo.y + 1) * size_t(hi.z - lo.z + 1);
  }
  size_t key(const glm::ivec3& c) const { return (size_t(c.z) * dims_.y + c.y) * dims_.x + c.x; }

  glm::dvec3 origin_{0.0};
  double size_ = 1.0;
  glm::ivec3 dims_{1};
  std::vector<std::vector<uint32_t>> cells_;
  std::vector<uint32_t> large_;
  size_t entries_ = 0;
};

// --- A floating-point filter before the exact pair test ----------------------------------

// L1 norm (at least the Euclidean one).
inline double norm1(const glm::dvec3& x) { return std::abs(x.x) + std::abs(x.y) + std::abs(x.z); }

// A relative margin far above the rounding of the few products below (each
// sign is certified when the computed value exceeds margin times the product
// of the L1 norms of its factors, which bounds the rounding of the inputs'
// differences, the cross product and the dot product together).
constexpr double kMargin = 1e-12;

// Whether x, y lie strictly on the side dot(m, .) > 0, or both strictly < 0.
inline int strict_side(const glm::dvec3& m, const glm::dvec3& x) {
  const double d = glm::dot(m, x), tol = kMargin * norm1(m) * norm1(x);
  return d > tol ? 1 : d < -tol ? -1 : 0;
}

// False only where the pair certainly does not count as intersecting under
// detail::triangle_pair_intersects's rules (so the exact test can be
// skipped); true when unsure.
bool may_meet(const glm::dvec3* p, const glm::uvec3& t, const glm::uvec3& u) {
  int shared = 0, tk = -1, uk = -1;
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l)
      if (t[k] == u[l]) ++shared, tk = k, uk = l;
  if (shared >= 3) return true;
  if (shared == 2) {
    // Counted only when c and d lie in one plane with a-b, on the same side
    // of it: then (b - a) x (c - a) and (b - a) x (d - a) point the same way.
    int free_t = 0, free_u = 0;
    for (int k = 0; k < 3; ++k) {
      if (t[k] != u[0] && t[k] != u[1] && t[k] != u[2]) free_t = k;
      if (u[k] != t[0] && u[k] != t[1] && u[k] != t[2]) free_u = k;
    }
    const glm::dvec3& a = p[t[(free_t + 1) % 3]];
    const glm::dvec3 e = p[t[(free_t + 2) % 3]] - a, c = p[t[free_t]] - a, d = p[u[free_u]] - a;
    const glm::dvec3 n1 = glm::cross(e, c), n2 = glm::cross(e, d);
    const double l1 = glm::length(n1), l2 = glm::length(n2);
    // Each cross product is known to within a tiny part of |e| |c| (|e| |d|);
    // far above that, an angle over 60 degrees between them is certain.
    const double en = norm1(e);
    if (l1 <= 1e-9 * en * norm1(c) || l2 <= 1e-9 * en * norm1(d)) return true;
    return glm::dot(n1, n2) > 0.5 * l1 * l2;
  }
  if (shared == 1) {
    // t = (v, a, b), u = (v, c, d): counted when a-b meets u or c-d meets t.
    const glm::dvec3& v = p[t[tk]];
    const glm::dvec3 a = p[t[(tk + 1) % 3]] - v, b = p[t[(tk + 2) % 3]] - v;
    const glm::dvec3 c = p[u[(uk + 1) % 3]] - v, d = p[u[(uk + 2) % 3]] - v;
    const glm::dvec3 nt = glm::cross(a, b), nu = glm::cross(c, d);
    // Each plane with the other's far corners strictly on one side of it.
    {
      const double cd = norm1(c) * norm1(d), ab = norm1(a) * norm1(b);
      const double sa = glm::dot(nu, a), sb = glm::dot(nu, b), sc = glm::dot(nt, c), sd = glm::dot(nt, d);
      const double ta = kMargin * cd * norm1(a), tb = kMargin * cd * norm1(b);
      const double tc = kMargin * ab * norm1(c), td = kMargin * ab * norm1(d);
      const bool ab_off = (sa > ta && sb > tb) || (sa < -ta && sb < -tb);
      const bool cd_off = (sc > tc && sd > td) || (sc < -tc && sd < -td);
      if (ab_off && cd_off) return false;
    }
    // A plane through v with t's far corners strictly on one side and u's on
    // the other: they meet at v only. Tried: planes holding the mean normal
    // and a line through the gaps between the two corners' sectors.
    const double lt = glm::length(nt), lu = glm::length(nu);
    if (!(lt > 0.0 && lu > 0.0)) return true;
    const glm::dvec3 n = nt / lt + nu / lu;
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c), ld = glm::length(d);
    if (!(la > 0.0 && lb > 0.0 && lc > 0.0 && ld > 0.0)) return true;
    const glm::dvec3 g1 = b / lb + c / lc, g2 = d / ld + a / la;
    const glm::dvec3 ws[3] = {g1, g2, g1 - g2};
    for (const glm::dvec3& w : ws) {
      const glm::dvec3 m = glm::cross(n, w);
      const int s = strict_side(m, a);
      if (s != 0 && strict_side(m, b) == s && strict_side(m, c) == -s && strict_side(m, d) == -s) return false;
    }
    return true;
  }
  // No shared vertex: an axis along which the two triangles' projections
  // are certainly apart (each projection known to within its margin). Tried:
  // the two normals, then (coplanar or nearly, as on flat ground) the axes
  // in the mean plane across each edge.
  const glm::dvec3 pt[3] = {p[t.x], p[t.y], p[t.z]}, pu[3] = {p[u.x], p[u.y], p[u.z]};
  const glm::dvec3& o = pt[0];
  glm::dvec3 rt[3], ru[3];
  double nt1[3], nu1[3];
  for (int k = 0; k < 3; ++k) rt[k] = pt[k] - o, ru[k] = pu[k] - o, nt1[k] = norm1(rt[k]), nu1[k] = norm1(ru[k]);
  auto apart = [&](const glm::dvec3& m) {
    const double mn = kMargin * norm1(m);
    double t_lo = INFINITY, t_hi = -INFINITY, u_lo = INFINITY, u_hi = -INFINITY;
    for (int k = 0; k < 3; ++k) {
      const double dt = glm::dot(m, rt[k]), et = mn * nt1[k];
      const double du = glm::dot(m, ru[k]), eu = mn * nu1[k];
      t_lo = std::min(t_lo, dt - et), t_hi = std::max(t_hi, dt + et);
      u_lo = std::min(u_lo, du - eu), u_hi = std::max(u_hi, du + eu);
    }
    return t_hi < u_lo || u_hi < t_lo;
  };
  const glm::dvec3 et[3] = {rt[1] - rt[0], rt[2] - rt[1], rt[0] - rt[2]};
  const glm::dvec3 eu[3] = {ru[1] - ru[0], ru[2] - ru[1], ru[0] - ru[2]};
  const glm::dvec3 nt = glm::cross(et[0], et[1]), nu = glm::cross(eu[0], eu[1]);
  if (apart(nt) || apart(nu)) return false;
  const double lt = glm::length(nt), lu = glm::length(nu);
  if (!(lt > 0.0 && lu > 0.0)) return true;
  glm::dvec3 n = nt / lt;
  n += glm::dot(n, nu) >= 0.0 ? nu / lu : -nu / lu;
  for (const glm::dvec3& e : et)
    if (apart(glm::cross(n, e))) return false;
  for (const glm::dvec3& e : eu)
    if (apart(glm::cross(n, e))) return false;
  return true;
}

// One triangle's separating axes, set up once for all the triangles it is
// tested against: its normal and, in its plane, its edges' normals, with its
// extent along each (the margins of may_meet's axes). Most pairs sharing no
// vertex are parted on one of them (coplanar pairs on flat faces too), which
// costs a few dot products where may_meet builds its axes for each pair.
struct Axes {
  glm::dvec3 origin{0.0};
  glm::dvec3 m[4];
  double margin[4], lo[4], hi[4];
};

Axes axes_of(const glm::dvec3* p, const glm::uvec3& t) {
  Axes a;
  a.origin = p[t.x];
  const glm::dvec3 r[3] = {glm::dvec3(0.0), p[t.y] - a.origin, p[t.z] - a.origin};
  const glm::dvec3 n = glm::cross(r[1], r[2]);
  a.m[0] = n;
  for (int k = 0; k < 3; ++k) a.m[k + 1] = glm::cross(n, r[(k + 1) % 3] - r[k]);
  for (int j = 0; j < 4; ++j) {
    a.margin[j] = kMargin * norm1(a.m[j]);
    a.lo[j] = INFINITY, a.hi[j] = -INFINITY;
    for (const glm::dvec3& x : r) {
      const double d = glm::dot(a.m[j], x), e = a.margin[j] * norm1(x);
      a.lo[j] = std::min(a.lo[j], d - e), a.hi[j] = std::max(a.hi[j], d + e);
    }
  }
  return a;
}

// Whether triangle u lies certainly apart from the one of `a` along one of
// its axes (then the two closed triangles do not meet).
bool apart(const Axes& a, const glm::dvec3* p, const glm::uvec3& u) {
  const glm::dvec3 r[3] = {p[u.x] - a.origin, p[u.y] - a.origin, p[u.z] - a.origin};
  const double n1[3] = {norm1(r[0]), norm1(r[1]), norm1(r[2])};
  for (int j = 0; j < 4; ++j) {
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < 3; ++k) {
      const double d = glm::dot(a.m[j], r[k]), e = a.margin[j] * n1[k];
      lo = std::min(lo, d - e), hi = std::max(hi, d + e);
    }
    if (hi < a.lo[j] || a.hi[j] < lo) return true;
  }
  return false;
}

bool pair_intersects(const glm::dvec3* p, const glm::uvec3& t, const glm::uvec3& u) {
  return may_meet(p, t, u) && detail::triangle_pair_intersects(p, t, u);
}

// --- One block ------------------------------------------------------------------------

struct BlockStats {
  size_t collapses = 0, removed = 0;
  size_t rejected_topology = 0, rejected_flip = 0, rejected_sliver = 0, rejected_intersection = 0;
  double max_error2 = 0.0;
};

// Tangent of a triangle's smallest angle, the one opposite its shortest
// edge (at most 60 degrees, so tan is increasing there; no atan2 needed).
double min_angle_tan(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 p[3] = {a, b, c};
  int shortest = 0;
  double best = INFINITY;
  for (int k = 0; k < 3; ++k) {
    const double length = glm::dot(p[(k + 1) % 3] - p[k], p[(k + 1) % 3] - p[k]);
    if (length < best) best = length, shortest = k;
  }
  const glm::dvec3& apex = p[(shortest + 2) % 3];
  const glm::dvec3 e1 = p[shortest] - apex, e2 = p[(shortest + 1) % 3] - apex;
  const double cross = glm::length(glm::cross(e1, e2)), dot = glm::dot(e1, e2);
  return dot > 0.0 ? cross / dot : cross == 0.0 ? 0.0 : INFINITY;
}

class BlockSimplifier {
 public:
  explicit BlockSimplifier(Shared& s) : s_(s) {}

  BlockStats run(const PassInput& pass, uint32_t block);

 private:
  struct Candidate {
    double error;     // quadric error at the target
    uint32_t target;  // global vertex
    bool operator<(const Candidate& c) const { return error != c.error ? error < c.error : target < c.target; }
  };
  struct HeapEntry {
    double error;
    uint32_t local;
    uint32_t version;
    // std::push_heap keeps the largest on top: the cheapest, then the smallest index.
    bool operator<(const HeapEntry& e) const { return error != e.error ? error > e.error : local > e.local; }
  };
  enum class Verdict { kOk, kTopology, kFlip, kSliver, kIntersection };

  bool owned(uint32_t v) const { return pass_->vertex_block[v] == block_; }
  uint32_t local(uint32_t v) const { return pass_->local_of[v]; }
  uint32_t global(uint32_t lv) const { return pass_->vlist[pass_->vstart[block_] + lv]; }

  void load();
  void rebuild_grid();
  bool gather_ring(uint32_t lu);
  bool targets(uint32_t lu, std::vector<Candidate>& out);
  double cheapest(uint32_t lu);
  void evaluate(uint32_t lu);
  void try_collapse(uint32_t lu, BlockStats& stats);
  bool link_condition(uint32_t gu, uint32_t gv);
  Verdict shape_kept(uint32_t gu, uint32_t gv);
  size_t count_meets(const std::vector<glm::uvec3>& tris, size_t limit, bool& foreign, uint32_t skip_sharing);
  bool star_after(uint32_t gw, uint32_t gu, uint32_t gv, glm::dvec3& dir);
  bool star_kept(uint32_t gw, uint32_t gu, uint32_t gv);
  bool stars_after(uint32_t gu, uint32_t gv);
  bool intersection_free(uint32_t lu, uint32_t gv);
  Verdict check(uint32_t lu, uint32_t gv);
  void apply(uint32_t lu, uint32_t gv);
  void remove_from_fan(uint32_t lv, uint32_t lt);
  void reevaluate_after(uint32_t gu, uint32_t gv);
  void touch(uint32_t lx, double bound);

  Shared& s_;
  const PassInput* pass_ = nullptr;
  uint32_t block_ = 0;
  // Local triangles (index lt): the block's slice of the pass's list.
  std::vector<uint32_t> tri_id;  // global index
  std::vector<glm::uvec3> tri_;  // current corners (global vertices)
  std::vector<Box> box_;
  std::vector<uint8_t> testable_;
  std::vector<uint32_t> seen_, excluded_;
  uint32_t query_ = 0, collapse_ = 0;
  TriangleGrid grid_;
  size_t grid_fresh_entries_ = 0;
  // Local vertices (index lv): the block's own vertices.
  std::vector<std::vector<uint32_t>> fan_;  // local triangles around the vertex
  std::vector<uint32_t> version_;
  // Lazy evaluation: a dirty vertex's entry holds a lower bound of its
  // cheapest option (key_: the lowest entry still valid, or infinity;
  // best_: its cheapest option at its last evaluation) and is evaluated
  // when popped. A collapse u -> v changes the options of v's neighbours
  // only by the cost of going to v (v's quadric grew; u's neighbours gain v
  // for u), except for the two vertices opposite the edge (they lose a
  // triangle and maybe a border edge) and v itself: those are evaluated at
  // once. The order of collapses is the one of evaluating all at once.
  std::vector<uint8_t> dirty_;
  std::vector<double> key_, best_;
  std::vector<HeapEntry> heap_;
  // Scratch of the vertex being evaluated or collapsed.
  struct RingEntry {
    uint32_t other;   // neighbour (global)
    uint16_t mat_out; // material of the triangle leaving u along u -> other
    uint16_t mat_in;  // material of the triangle arriving at u along other -> u
  };
  std::vector<RingEntry> ring_;
  std::vector<uint32_t> ring_u_, ring_v_;
  std::vector<uint32_t> old_ring_u_, old_ring_v_;
  std::vector<uint16_t> tmat_;  // per local triangle: its material
  std::vector<uint8_t> arrived_;
  struct Sector {
    glm::dvec3 a, b, n;  // edges from w and their cross product
    double ab;           // norm1(a) * norm1(b)
  };
  std::vector<Sector> sectors_;
  // Fans known to be stars: star_dir_ is a direction along which every
  // sector turns counter-clockwise, once around (valid while star_known_).
  // star_pending_: the directions of the fans a collapse being checked
  // leaves (v's and u's neighbours'), committed when it is made.
  std::vector<glm::dvec3> star_dir_;
  std::vector<uint8_t> star_known_;
  std::vector<std::pair<uint32_t, glm::dvec3>> star_pending_;
  bool pending_stars_ = false;
  std::vector<Candidate> candidates_, tries_;
  std::vector<uint32_t> neighbours_;
  std::vector<uint32_t> near_;  // triangles near a collapse
  std::vector<Box> near_box_;   // their boxes
  Axes axes_;                   // of the changed triangle being tested
  std::vector<glm::uvec3> changed_;  // u's triangles after the collapse (those not on the edge)
  std::vector<glm::uvec3> old_fan_;  // u's triangles before it
};

void BlockSimplifier::load() {
  const uint32_t* ids = pass_->tlist.data() + pass_->tstart[block_];
  const size_t n = pass_->tstart[block_ + 1] - pass_->tstart[block_];
  tri_id.assign(ids, ids + n);
  tri_.resize(n);
  box_.resize(n);
  testable_.resize(n);
  tmat_.resize(n);
  seen_.assign(n, 0);
  excluded_.assign(n, 0);
  query_ = collapse_ = 0;
  const size_t nv = pass_->vstart[block_ + 1] - pass_->vstart[block_];
  if (fan_.size() < nv) fan_.resize(nv);
  for (size_t i = 0; i < nv; ++i) fan_[i].clear();
  version_.assign(nv, 0);
  dirty_.assign(nv, 0);
  key_.assign(nv, INFINITY);
  best_.assign(nv, INFINITY);
  star_dir_.resize(nv);
  star_known_.assign(nv, 0);
  for (uint32_t lt = 0; lt < n; ++lt) {
    tri_[lt] = s_.tris[tri_id[lt]];
    box_[lt] = triangle_box(s_.pos, tri_[lt]);
    testable_[lt] = s_.tstate[tri_id[lt]] == kAlive;
    tmat_[lt] = s_.material[tri_id[lt]];
    for (int k = 0; k < 3; ++k)
      if (owned(tri_[lt][k])) fan_[local(tri_[lt][k])].push_back(lt);
  }
  rebuild_grid();
}

// The grid afresh from the live triangles (changed triangles leave stale
// entries behind; rebuilt when they outnumber the live ones).
void BlockSimplifier::rebuild_grid() {
  size_t live = 0;
  for (uint8_t t : testable_) live += t;
  grid_.reset(pass_->layout.region(block_, s_.bounds), live);
  for (uint32_t lt = 0; lt < tri_.size(); ++lt)
    if (testable_[lt]) grid_.insert(lt, box_[lt]);
  grid_fresh_entries_ = grid_.entries();
}

// Fills ring_ with u's neighbours (sorted, with the materials of the
// triangles on each side of the edge) and ring_u_ with the neighbours alone;
// false when u may not move in this block (locked, or its fan leaves the
// block: then flagged kSeam for the next pass).
bool BlockSimplifier::gather_ring(uint32_t lu) {
  const uint32_t gu = global(lu);
  if (s_.vflags[gu] & kLocked) return false;
  const std::vector<uint32_t>& fan = fan_[lu];
  const size_t k = fan.size();
  bool inside = true;
  ring_.resize(k);
  for (size_t i = 0; i < k; ++i) {
    const glm::uvec3 r = rotated_to(tri_[fan[i]], gu);
    inside = inside && owned(r.y) && owned(r.z);
    ring_[i] = {r.y, tmat_[fan[i]], 0};
  }
  s_.vflags[gu] = inside ? (s_.vflags[gu] & ~kSeam) : (s_.vflags[gu] | kSeam);
  if (!inside || k < 3) return false;
  // Insertion sort: fans are small.
  for (size_t i = 1; i < k; ++i) {
    const RingEntry e = ring_[i];
    size_t j = i;
    for (; j > 0 && ring_[j - 1].other > e.other; --j) ring_[j] = ring_[j - 1];
    ring_[j] = e;
  }
  // Collapses keep u manifold (each neighbour once leaving u and once
  // arriving); checked all the same, as a cheap guard.
  arrived_.assign(k, 0);
  for (size_t i = 0; i < k; ++i) {
    if (i > 0 && ring_[i].other == ring_[i - 1].other) return false;
    const uint32_t b = rotated_to(tri_[fan[i]], gu).z;
    size_t lo = 0, hi = k;
    while (lo < hi) {
      const size_t mid = (lo + hi) / 2;
      if (ring_[mid].other < b) lo = mid + 1; else hi = mid;
    }
    if (lo == k || ring_[lo].other != b || arrived_[lo]) return false;
    arrived_[lo] = 1;
    ring_[lo].mat_in = tmat_[fan[i]];
  }
  ring_u_.resize(k);
  for (size_t i = 0; i < k; ++i) ring_u_[i] = ring_[i].other;
  return true;
}

// u's allowed targets within the bound, cheapest first. One material: any
// neighbour. Two: a border between them passing through u along exactly two
// edges, with at least two triangles of each material: only the border's two
// neighbours, so the border slides along itself. Otherwise none.
bool BlockSimplifier::targets(uint32_t lu, std::vector<Candidate>& out) {
  out.clear();
  if (!gather_ring(lu)) return false;
  const uint32_t gu = global(lu);
  const size_t k = ring_.size();
  const uint16_t first = ring_[0].mat_out;
  size_t same = 0, border_edges = 0;
  uint32_t border[2] = {0, 0};
  for (size_t i = 0; i < k; ++i) {
    same += ring_[i].mat_out == first ? 1 : 0;  // each triangle counted once: where it leaves u
    if (ring_[i].mat_out == ring_[i].mat_in) continue;
    if (border_edges < 2) border[border_edges] = ring_[i].other;
    ++border_edges;
  }
  const Quadric& qu = s_.quadric[gu];
  auto add = [&](uint32_t gv) {
    const glm::dvec3 q = s_.pos[gv] - s_.centre;
    const double error = qu.error(q) + s_.self_error[gv];
    if (error <= s_.max_error2) out.push_back({error, gv});
  };
  if (border_edges == 0) {
    for (size_t i = 0; i < k; ++i) add(ring_[i].other);
  } else if (border_edges == 2 && same >= 2 && k - same >= 2) {
    // Two materials only: the triangles not of the first material are all of one other.
    uint16_t other = first;
    bool two = true;
    for (size_t i = 0; i < k; ++i) {
      const uint16_t m = ring_[i].mat_out;
      if (m != first && other != first && m != other) two = false;
      if (m != first) other = m;
    }
    if (two) add(border[0]), add(border[1]);
  }
  if (out.size() > 1) std::sort(out.begin(), out.end());
  return !out.empty();
}

// The error of u's cheapest target (infinity if none). Fans of one
// material (the common case) take a short way: every neighbour is a target,
// met once as the corner after u in its triangle; no ring is built (the
// manifold guard runs when u is tried).
double BlockSimplifier::cheapest(uint32_t lu) {
  const uint32_t gu = global(lu);
  if (s_.vflags[gu] & kLocked) return INFINITY;
  const std::vector<uint32_t>& fan = fan_[lu];
  const uint16_t first = fan.empty() ? 0 : tmat_[fan[0]];
  const Quadric& qu = s_.quadric[gu];
  bool inside = true, one_material = true;
  double best = INFINITY;
  for (uint32_t lt : fan) {  // each neighbour comes once after u in a disc (try_collapse checks the disc)
    const uint32_t gv = rotated_to(tri_[lt], gu).y;
    inside = inside && owned(gv);
    one_material = one_material && tmat_[lt] == first;
    best = std::min(best, qu.error(s_.pos[gv] - s_.centre) + s_.self_error[gv]);
  }
  if (!inside || fan.size() < 3 || !one_material) return targets(lu, candidates_) ? candidates_[0].error : INFINITY;
  s_.vflags[gu] &= ~kSeam;
  return best <= s_.max_error2 ? best : INFINITY;
}

void BlockSimplifier::evaluate(uint32_t lu) {
  ++version_[lu];
  dirty_[lu] = 0;
  const double best = cheapest(lu);
  best_[lu] = key_[lu] = best;
  if (best < INFINITY) heap_.push_back({best, lu, version_[lu]}), std::push_heap(heap_.begin(), heap_.end());
}

// x's options changed without a full evaluation: marked dirty (evaluated
// when popped), with an entry at a lower bound of its cheapest option.
void BlockSimplifier::touch(uint32_t lx, double bound) {
  dirty_[lx] = 1;
  if (bound <= s_.max_error2 && bound < key_[lx]) {
    key_[lx] = bound;
    heap_.push_back({bound, lx, version_[lx]}), std::push_heap(heap_.begin(), heap_.end());
  }
}

// The two ends share exactly the two vertices opposite the edge, and the kept
// vertex keeps at least three triangles.
bool BlockSimplifier::link_condition(uint32_t gu, uint32_t gv) {
  ring_v_.clear();
  for (uint32_t lt : fan_[local(gv)])
    for (int k = 0; k < 3; ++k)
      if (tri_[lt][k] != gv) ring_v_.push_back(tri_[lt][k]);
  for (size_t i = 1; i < ring_v_.size(); ++i)  // insertion sort: rings are small
    for (size_t j = i; j > 0 && ring_v_[j] < ring_v_[j - 1]; --j) std::swap(ring_v_[j], ring_v_[j - 1]);
  ring_v_.erase(std::unique(ring_v_.begin(), ring_v_.end()), ring_v_.end());
  size_t common = 0, opposite = 0;
  auto u_it = ring_u_.begin();
  for (uint32_t x : ring_v_) {
    while (u_it != ring_u_.end() && *u_it < x) ++u_it;
    if (u_it == ring_u_.end() || *u_it != x) continue;
    ++common;
    for (uint32_t lt : fan_[local(gu)]) {
      const glm::uvec3& t = tri_[lt];
      const bool has_v = t.x == gv || t.y == gv || t.z == gv, has_x = t.x == x || t.y == x || t.z == x;
      if (has_v && has_x) ++opposite;
    }
  }
  return common == 2 && opposite == 2 && ring_u_.size() + ring_v_.size() >= 7;
}

// Fills changed_ with u's triangles that survive, u replaced by v, and checks
// each: not degenerate, its normal turned by at most the limit, and no angle
// below the minimum unless it had one already.
BlockSimplifier::Verdict BlockSimplifier::shape_kept(uint32_t gu, uint32_t gv) {
  changed_.clear();
  const glm::dvec3* p = s_.pos;
  for (uint32_t lt : fan_[local(gu)]) {
    const glm::uvec3 old = tri_[lt];
    if (old.x == gv || old.y == gv || old.z == gv) continue;
    const glm::uvec3 now(old.x == gu ? gv : old.x, old.y == gu ? gv : old.y, old.z == gu ? gv : old.z);
    const glm::dvec3 n0 = glm::cross(p[old.y] - p[old.x], p[old.z] - p[old.x]);
    const glm::dvec3 e1 = p[now.y] - p[now.x], e2 = p[now.z] - p[now.x];
    const glm::dvec3 n1 = glm::cross(e1, e2);
    if (glm::dot(n0, n1) < s_.cos_normal * glm::length(n0) * glm::length(n1)) return Verdict::kFlip;
    // Exactly collinear corners (rows of lattice-aligned vertices): the exact
    // test only where the cross product is too small to tell by rounding.
    const double cross2 = glm::dot(n1, n1);
    if (cross2 <= 1e-20 * glm::dot(e1, e1) * glm::dot(e2, e2) && detail::collinear(p[now.x], p[now.y], p[now.z]))
      return Verdict::kFlip;
    if (s_.min_angle_tan > 0.0) {
      const double after = min_angle_tan(p[now.x], p[now.y], p[now.z]);
      if (after < s_.min_angle_tan && after < min_angle_tan(p[old.x], p[old.y], p[old.z])) return Verdict::kSliver;
    }
    changed_.push_back(now);
  }
  return Verdict::kOk;
}

// Whether w's fan after the collapse u -> v (u's changed triangles in
// changed_) is certainly a star: seen along the sum N of its triangles'
// normals, every triangle turns counter-clockwise (dot(n, N) > 0) and the
// sectors go around w once (a direction inside the first sector is inside
// no other). Its triangles then meet only where the fan joins them: at w,
// along shared edges without folding, so no pair of them counts. Each sign
// certified with a margin over rounding (see kMargin). The fan of an
// unlocked vertex is one cycle (collapses keep it manifold). The direction
// goes to `dir`.
bool BlockSimplifier::star_after(uint32_t gw, uint32_t gu, uint32_t gv, glm::dvec3& dir) {
  if (s_.vflags[gw] & kLocked) return false;
  const glm::dvec3* p = s_.pos;
  const glm::dvec3 pw = p[gw];
  sectors_.clear();
  glm::dvec3 n(0.0);
  auto add = [&](glm::uvec3 t) {
    const glm::uvec3 r = rotated_to(t, gw);
    const glm::dvec3 a = p[r.y] - pw, b = p[r.z] - pw;
    const glm::dvec3 c = glm::cross(a, b);
    sectors_.push_back({a, b, c, norm1(a) * norm1(b)});
    n += c;
  };
  if (gw == gv) {
    for (uint32_t lt : fan_[local(gv)]) {
      const glm::uvec3& t = tri_[lt];
      if (t.x != gu && t.y != gu && t.z != gu) add(t);
    }
    for (const glm::uvec3& t : changed_) add(t);
  } else {
    for (uint32_t lt : fan_[local(gw)]) {
      const glm::uvec3& t = tri_[lt];
      const bool has_u = t.x == gu || t.y == gu || t.z == gu, has_v = t.x == gv || t.y == gv || t.z == gv;
      if (has_u && has_v) continue;  // dies
      add(has_u ? glm::uvec3(t.x == gu ? gv : t.x, t.y == gu ? gv : t.y, t.z == gu ? gv : t.z) : t);
    }
  }
  if (sectors_.size() < 3) return false;
  const double nn = norm1(n);
  for (const Sector& sec : sectors_)
    if (!(glm::dot(sec.n, n) > kMargin * sec.ab * nn)) return false;
  const glm::dvec3 d = sectors_[0].a + sectors_[0].b;
  const double dn = norm1(d) * nn;
  for (size_t i = 1; i < sectors_.size(); ++i) {
    const Sector& sec = sectors_[i];
    const double ad = glm::dot(n, glm::cross(sec.a, d)), db = glm::dot(n, glm::cross(d, sec.b));
    const bool outside = ad < -kMargin * norm1(sec.a) * dn || db < -kMargin * norm1(sec.b) * dn;
    if (!outside) return false;
  }
  dir = n;
  return true;
}

// How many pairs `tris` (u's fan, before or after the collapse) are in: with
// each other and with the block's other live triangles (by mesh_quality's
// rules). Counting stops past `limit`. A triangle met that straddles the
// block's border sets `foreign`. skip_sharing: a vertex all of `tris` have
// (v) when pairs sharing a vertex are known not to count (stars_after), or
// kNoVertex. Pairs sharing none go through the triangle's own separating
// axes, then may_meet, then the exact test.
size_t BlockSimplifier::count_meets(const std::vector<glm::uvec3>& tris, size_t limit, bool& foreign,
                                    uint32_t skip_sharing) {
  const glm::dvec3* p = s_.pos;
  // The triangles near any of them, gathered once.
  Box all = triangle_box(p, tris[0]);
  for (const glm::uvec3& t : tris) {
    const Box box = triangle_box(p, t);
    all = {glm::min(all.lo, box.lo), glm::max(all.hi, box.hi)};
  }
  ++query_;
  near_.clear();
  near_box_.clear();
  auto gather = [&](uint32_t lt) {
    if (seen_[lt] == query_) return;
    seen_[lt] = query_;
    if (!testable_[lt] || excluded_[lt] == collapse_ || !boxes_overlap(all, box_[lt])) return;
    const glm::uvec3& t = tri_[lt];
    if (t.x == skip_sharing || t.y == skip_sharing || t.z == skip_sharing) return;  // shares v with all
    near_.push_back(lt);
    near_box_.push_back(box_[lt]);
  };
  if (!grid_.for_each_near(all, gather))
    for (uint32_t lt = 0; lt < tri_.size(); ++lt) gather(lt);
  size_t count = 0;
  for (size_t i = 0; i < tris.size() && count <= limit; ++i) {
    const glm::uvec3 ti = tris[i];
    if (skip_sharing == kNoVertex)  // (otherwise all share v)
      for (size_t j = 0; j < i; ++j) count += pair_intersects(p, ti, tris[j]) ? 1 : 0;
    const Box box = triangle_box(p, ti);
    bool have_axes = false;
    for (size_t j = 0; j < near_.size(); ++j) {
      if (!boxes_overlap(box, near_box_[j])) continue;
      const uint32_t lt = near_[j];
      const glm::uvec3& t = tri_[lt];
      const bool shares = t.x == ti.x || t.x == ti.y || t.x == ti.z || t.y == ti.x || t.y == ti.y ||
                          t.y == ti.z || t.z == ti.x || t.z == ti.y || t.z == ti.z;
      if (shares && skip_sharing != kNoVertex) continue;
      if (!shares) {
        if (!have_axes) axes_ = axes_of(p, ti), have_axes = true;
        if (apart(axes_, p, t)) continue;
      }
      if (!pair_intersects(p, ti, t)) continue;
      ++count;
      foreign = foreign || !owned(t.x) || !owned(t.y) || !owned(t.z);
    }
  }
  return count;
}

// The collapse may not add to the self-intersecting pairs: its changed
// triangles meet nothing, or (where the input already had folds) they are in
// fewer pairs than the triangles they replace, so the mesh's count drops.
// When a triangle in the way straddles the block's border, u is flagged
// kSeam: the next pass, where that triangle may have been simplified, tries
// u again.
// Pairs sharing a vertex with a changed triangle are left out when the fans
// of v and of u's neighbours are certainly stars after the collapse (every
// such pair lies in one of those fans; see star_after).
bool BlockSimplifier::intersection_free(uint32_t lu, uint32_t gv) {
  ++collapse_;
  for (uint32_t lt : fan_[lu]) excluded_[lt] = collapse_;
  const uint32_t gu = global(lu);
  const bool stars = stars_after(gu, gv);
  bool foreign = false;
  const size_t after = count_meets(changed_, std::numeric_limits<size_t>::max(), foreign, stars ? gv : kNoVertex);
  if (after == 0) return true;
  old_fan_.clear();
  for (uint32_t lt : fan_[lu]) old_fan_.push_back(tri_[lt]);
  bool unused = false;
  if (count_meets(old_fan_, after, unused, kNoVertex) > after) return true;
  if (foreign) s_.vflags[global(lu)] |= kSeam;
  return false;
}

// A fan known to be a star around direction N stays one when the sectors
// that take v for u still turn counter-clockwise around N: each such change
// replaces a wedge x -> u -> y (or x -> u -> v, the sector u -> v dying) by
// sectors of angle in (0, pi) with the same ends, so the angles still sum
// to 2 pi (a sum in (0, 2 pi) either way, equal modulo 2 pi) and the fan
// still goes around once.
bool BlockSimplifier::star_kept(uint32_t gw, uint32_t gu, uint32_t gv) {
  const uint32_t lw = local(gw);
  if (!star_known_[lw]) return false;
  const glm::dvec3* p = s_.pos;
  const glm::dvec3 pw = p[gw], n = star_dir_[lw];
  const double nn = norm1(n);
  size_t kept = 0;
  for (uint32_t lt : fan_[lw]) {
    const glm::uvec3& t = tri_[lt];
    const bool has_u = t.x == gu || t.y == gu || t.z == gu, has_v = t.x == gv || t.y == gv || t.z == gv;
    if (has_u && has_v) continue;  // dies
    ++kept;
    if (!has_u) continue;
    const glm::uvec3 r = rotated_to(glm::uvec3(t.x == gu ? gv : t.x, t.y == gu ? gv : t.y, t.z == gu ? gv : t.z), gw);
    const glm::dvec3 a = p[r.y] - pw, b = p[r.z] - pw;
    if (!(glm::dot(glm::cross(a, b), n) > kMargin * norm1(a) * norm1(b) * nn)) return false;
  }
  return kept >= 3;
}

// Whether the fans of v and of u's other neighbours are certainly stars
// after u -> v; their directions go to star_pending_.
bool BlockSimplifier::stars_after(uint32_t gu, uint32_t gv) {
  star_pending_.clear();
  pending_stars_ = false;
  glm::dvec3 dir;
  if (!star_after(gv, gu, gv, dir)) return false;
  star_pending_.push_back({local(gv), dir});
  for (uint32_t w : ring_u_) {
    if (w == gv) continue;
    if (star_kept(w, gu, gv)) {
      star_pending_.push_back({local(w), star_dir_[local(w)]});
    } else {
      if (!star_after(w, gu, gv, dir)) return false;
      star_pending_.push_back({local(w), dir});
    }
  }
  return pending_stars_ = true;
}

BlockSimplifier::Verdict BlockSimplifier::check(uint32_t lu, uint32_t gv) {
  const uint32_t gu = global(lu);
  if (const Verdict shape = shape_kept(gu, gv); shape != Verdict::kOk) return shape;  // the cheapest first
  if (!link_condition(gu, gv)) return Verdict::kTopology;
  if (!intersection_free(lu, gv)) return Verdict::kIntersection;
  return Verdict::kOk;
}

void BlockSimplifier::remove_from_fan(uint32_t lv, uint32_t lt) {
  std::vector<uint32_t>& fan = fan_[lv];
  fan.erase(std::find(fan.begin(), fan.end(), lt));
}

// u -> v: u's two triangles on the edge die, the others take v for u.
void BlockSimplifier::apply(uint32_t lu, uint32_t gv) {
  const uint32_t gu = global(lu), lv = local(gv);
  for (uint32_t lt : fan_[lu]) {
    glm::uvec3& t = tri_[lt];
    if (t.x == gv || t.y == gv || t.z == gv) {
      testable_[lt] = 0;
      s_.tstate[tri_id[lt]] = kDead;
      for (int k = 0; k < 3; ++k)
        if (t[k] != gu) remove_from_fan(local(t[k]), lt);
      continue;
    }
    for (int k = 0; k < 3; ++k)
      if (t[k] == gu) t[k] = gv;
    s_.tris[tri_id[lt]] = t;
    box_[lt] = triangle_box(s_.pos, t);
    grid_.insert(lt, box_[lt]);
    fan_[lv].push_back(lt);
  }
  fan_[lu].clear();
  // The fans that changed: known stars when the check proved them.
  star_known_[lv] = 0;
  for (uint32_t w : ring_u_) star_known_[local(w)] = 0;
  if (pending_stars_)
    for (const auto& [lw, dir] : star_pending_) star_known_[lw] = 1, star_dir_[lw] = dir;
  if (grid_.entries() > 3 * grid_fresh_entries_ + 64) rebuild_grid();
  s_.quadric[gv] += s_.quadric[gu];
  s_.self_error[gv] = s_.quadric[gv].error(s_.pos[gv] - s_.centre);
  s_.vflags[gu] &= ~(kUsed | kSeam);
  ++version_[lu];
}

void BlockSimplifier::try_collapse(uint32_t lu, BlockStats& stats) {
  if (!targets(lu, tries_)) return;
  for (const Candidate& c : tries_) {
    switch (check(lu, c.target)) {
      case Verdict::kTopology: ++stats.rejected_topology; continue;
      case Verdict::kFlip: ++stats.rejected_flip; continue;
      case Verdict::kSliver: ++stats.rejected_sliver; continue;
      case Verdict::kIntersection: ++stats.rejected_intersection; continue;
      case Verdict::kOk: break;
    }
    apply(lu, c.target);
    ++stats.collapses;
    stats.removed += 2;
    stats.max_error2 = std::max(stats.max_error2, c.error);
    reevaluate_after(global(lu), c.target);
    return;
  }
}

// After u -> v: v and the two opposite vertices evaluated, the other
// neighbours touched (see dirty_). ring_u_ and ring_v_ still hold the two
// rings before the collapse (sorted).
void BlockSimplifier::reevaluate_after(uint32_t gu, uint32_t gv) {
  old_ring_u_.swap(ring_u_);  // evaluate() refills ring_u_ and ring_v_
  old_ring_v_.swap(ring_v_);
  const std::vector<uint32_t>& ring_u = old_ring_u_;
  const std::vector<uint32_t>& ring_v = old_ring_v_;
  const uint32_t lv = local(gv);
  evaluate(lv);
  const glm::dvec3 qv = s_.pos[gv] - s_.centre;
  const double to_v = s_.self_error[gv];
  auto v_it = ring_v.begin();
  for (uint32_t x : ring_u) {
    if (x == gv || !owned(x)) continue;
    while (v_it != ring_v.end() && *v_it < x) ++v_it;
    const uint32_t lx = local(x);
    if (v_it != ring_v.end() && *v_it == x) {
      evaluate(lx);  // opposite the edge
      continue;
    }
    if (s_.vflags[x] & kLocked) continue;
    touch(lx, std::min(best_[lx], s_.quadric[x].error(qv) + to_v));
  }
  auto u_it = ring_u.begin();
  for (uint32_t x : ring_v) {
    if (x == gu || !owned(x)) continue;
    while (u_it != ring_u.end() && *u_it < x) ++u_it;
    if (u_it != ring_u.end() && *u_it == x) continue;  // done above
    if (s_.vflags[x] & kLocked) continue;
    touch(local(x), best_[local(x)]);
  }
}

// Whether the block has removed its share: a parallel pass stops before going
// past it, the last pass (overshoot) once it reaches it.
bool quota_reached(const PassInput& pass, size_t quota, size_t removed) {
  return pass.overshoot ? removed >= quota : removed + 2 > quota;
}

BlockStats BlockSimplifier::run(const PassInput& pass, uint32_t block) {
  pass_ = &pass;
  block_ = block;
  load();
  heap_.clear();
  const size_t nv = pass.vstart[block + 1] - pass.vstart[block];
  for (uint32_t lv = 0; lv < nv; ++lv)
    if (pass.seed_all || (s_.vflags[global(lv)] & kSeam)) evaluate(lv);
  BlockStats stats;
  const size_t quota = pass.quota[block];
  while (!heap_.empty()) {
    if (quota_reached(pass, quota, stats.removed)) break;
    std::pop_heap(heap_.begin(), heap_.end());
    const HeapEntry e = heap_.back();
    heap_.pop_back();
    if (e.version != version_[e.local]) continue;
    key_[e.local] = INFINITY;  // this entry is used up
    if (dirty_[e.local])
      evaluate(e.local);
    else
      try_collapse(e.local, stats);
  }
  return stats;
}

// --- Driver ------------------------------------------------------------------------------

Status check_mesh(const ContourMesh& mesh) {
  const size_t n = mesh.vertex_count();
  if (!mesh.normals.empty() && mesh.normals.size() != n)
    return Status(ErrorCode::kInvalidArgument, "simplify: " + std::to_string(mesh.normals.size()) + " normals for " +
                                                   std::to_string(n) + " vertices");
  if (!mesh.vertex_material.empty() && mesh.vertex_material.size() != n)
    return Status(ErrorCode::kInvalidArgument, "simplify: " + std::to_string(mesh.vertex_material.size()) +
                                                   " vertex materials for " + std::to_string(n) + " vertices");
  if (!mesh.triangle_material.empty() && mesh.triangle_material.size() != mesh.triangle_count())
    return Status(ErrorCode::kInvalidArgument, "simplify: " + std::to_string(mesh.triangle_material.size()) +
                                                   " triangle materials for " +
                                                   std::to_string(mesh.triangle_count()) + " triangles");
  if (n >= std::numeric_limits<uint32_t>::max() || mesh.triangle_count() >= std::numeric_limits<uint32_t>::max())
    return Status(ErrorCode::kTooLarge, "simplify: more than 2^32 - 1 vertices or triangles");
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const glm::uvec3& tri = mesh.triangles[t];
    if (tri.x >= n || tri.y >= n || tri.z >= n)
      return Status(ErrorCode::kInvalidArgument, "simplify: triangle " + std::to_string(t) +
                                                     " has a vertex index out of range (" + std::to_string(n) +
                                                     " vertices)");
  }
  for (const glm::dvec3& p : mesh.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      return Status(ErrorCode::kInvalidArgument, "simplify: a vertex position is not finite");
  return {};
}

void init_shared(const ContourMesh& mesh, const SimplifyOptions& o, Shared& s) {
  s.pos = mesh.positions.data();
  s.material = mesh.triangle_material;
  s.material.resize(mesh.triangle_count(), 0);
  detail::reserve_on_huge_pages(s.tris, mesh.triangles.size());
  s.tris = mesh.triangles;
  s.tstate.resize(s.tris.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, s.tris.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      const glm::uvec3& c = s.tris[t];
      s.tstate[t] = (c.x == c.y || c.y == c.z || c.x == c.z)                    ? kFrozen
                    : detail::collinear(s.pos[c.x], s.pos[c.y], s.pos[c.z]) ? kFlat
                                                                             : kAlive;
    }
  });
  s.bounds = {glm::dvec3(INFINITY), glm::dvec3(-INFINITY)};
  for (const glm::uvec3& t : s.tris)
    for (int k = 0; k < 3; ++k) s.bounds.lo = glm::min(s.bounds.lo, s.pos[t[k]]), s.bounds.hi = glm::max(s.bounds.hi, s.pos[t[k]]);
  s.centre = 0.5 * (s.bounds.lo + s.bounds.hi);
  s.max_error2 = o.max_error * o.max_error;

  s.cos_normal = std::cos(o.max_normal_change_deg * std::numbers::pi / 180.0);
  s.min_angle_tan = std::tan(o.min_angle_deg * std::numbers::pi / 180.0);
}

// 32 times the mean edge length (summed in order: deterministic).
double default_block_size(const Shared& s) {
  double sum = 0.0;
  size_t count = 0;
  for (size_t t = 0; t < s.tris.size(); ++t) {
    if (s.tstate[t] != kAlive) continue;
    const glm::uvec3& c = s.tris[t];
    sum += glm::length(s.pos[c.y] - s.pos[c.x]) + glm::length(s.pos[c.z] - s.pos[c.y]) +
           glm::length(s.pos[c.x] - s.pos[c.z]);
    count += 3;
  }
  return count == 0 ? 1.0 : 32.0 * sum / double(count);
}

size_t live_triangles(const Shared& s) {
  return static_cast<size_t>(std::count_if(s.tstate.begin(), s.tstate.end(), [](uint8_t t) { return t != kDead; }));
}

// Each block's share of the triangles still to remove (by its triangle count).
void set_quotas(PassInput& p, size_t live, size_t target) {
  p.quota.assign(p.layout.count(), std::numeric_limits<size_t>::max());
  if (target == 0) return;
  const size_t excess = live > target ? live - target : 0;
  const double total = double(std::max<size_t>(p.tlist.size(), 1));
  for (uint32_t b : p.blocks)
    p.quota[b] = p.overshoot ? excess
                             : static_cast<size_t>(std::floor(double(excess) * double(p.tstart[b + 1] - p.tstart[b]) / total));
}

void run_pass(Shared& s, PassInput& pass, SimplifyStats& stats) {
  std::vector<BlockStats> results(pass.blocks.size());
  tbb::enumerable_thread_specific<BlockSimplifier> simplifiers([&] { return BlockSimplifier(s); });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pass.blocks.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
    BlockSimplifier& simplifier = simplifiers.local();
    for (size_t i = r.begin(); i != r.end(); ++i) results[i] = simplifier.run(pass, pass.blocks[i]);
  });
  for (const BlockStats& b : results) {
    stats.collapses += b.collapses;
    stats.rejected_topology += b.rejected_topology;
    stats.rejected_flip += b.rejected_flip;
    stats.rejected_sliver += b.rejected_sliver;
    stats.rejected_intersection += b.rejected_intersection;
    stats.max_error_reached = std::max(stats.max_error_reached, std::sqrt(b.max_error2));
  }
  stats.blocks += pass.blocks.size();
  ++stats.passes;
}

// Writes the survivors back, in their order; unused vertices are dropped.
void compact(const Shared& s, ContourMesh& mesh) {
  std::vector<uint8_t> dead(s.tris.size());
  for (size_t t = 0; t < s.tris.size(); ++t) dead[t] = s.tstate[t] == kDead;
  mesh.triangles = s.tris;
  detail::remove_triangles(mesh, dead);
}

}  // namespace

Status check_simplify_options(const SimplifyOptions& o) {
  auto bad = [](const std::string& field, double value, const char* rule) {
    return Status(ErrorCode::kInvalidArgument, "simplify: " + field + " = " + std::to_string(value) + " must be " + rule);
  };
  if (!(o.max_error >= 0.0 && std::isfinite(o.max_error))) return bad("max_error", o.max_error, "finite and >= 0");
  if (!(o.max_normal_change_deg > 0.0 && o.max_normal_change_deg < 180.0))
    return bad("max_normal_change_deg", o.max_normal_change_deg, "in (0, 180)");
  if (!(o.min_angle_deg >= 0.0 && o.min_angle_deg <= 30.0)) return bad("min_angle_deg", o.min_angle_deg, "in [0, 30]");
  if (!(o.block_size >= 0.0 && std::isfinite(o.block_size))) return bad("block_size", o.block_size, "finite and >= 0");
  return {};
}

Result<SimplifyStats> simplify_mesh(ContourMesh& mesh, const SimplifyOptions& options, Context* ctx) {
  ScopedTimer timer(ctx, "simplify");
  if (Status s = check_simplify_options(options); !s.ok()) return s;
  if (Status s = check_mesh(mesh); !s.ok()) return s;
  SimplifyStats stats;
  stats.triangles_before = stats.triangles_after = mesh.triangle_count();
  stats.vertices_before = stats.vertices_after = mesh.vertex_count();
  if (options.max_error == 0.0 || mesh.triangles.empty()) return stats;

  Shared s;
  init_shared(mesh, options, s);
  analyse_vertices(s, incidence(s, mesh.vertex_count()));
  for (uint8_t f : s.vflags) stats.locked_vertices += (f & kLocked) ? 1 : 0;
  const double size = options.block_size > 0.0 ? options.block_size : default_block_size(s);
  const bool target = options.target_triangles > 0;
  const Layout layouts[3] = {block_layout(s.bounds, size, 0.0), block_layout(s.bounds, size, 0.5 * size),
                             whole_mesh_layout(s.bounds)};
  PassInput pass;
  size_t live = mesh.triangle_count();
  for (int i = 0; i < 3; ++i) {
    if (ctx && ctx->cancelled()) return Status(ErrorCode::kCancelled, "simplify: cancelled");
    if (target && live <= options.target_triangles) break;
    pass.layout = layouts[i];
    pass.seed_all = i == 0 || target;  // with a target, blocks may have stopped at their quota
    pass.overshoot = i == 2;
    build_pass(s, pass);
    set_quotas(pass, live, options.target_triangles);
    run_pass(s, pass, stats);
    live = live_triangles(s);
    if (ctx) ctx->report_progress("simplify", double(i + 1) / 3.0);
  }
  compact(s, mesh);
  stats.triangles_after = mesh.triangle_count();
  stats.vertices_after = mesh.vertex_count();
  stats.seconds = timer.seconds();
  return stats;
}

}  // namespace ldc
