// Stages 2-4 of the mesh builder: rasterize, vote (open meshes), emit.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>

#include <tbb/parallel_for.h>

#include "ldc/internal/build_common.h"
#include "ldc/detail/mesh_raster.h"
#include "ldc/internal/ray_math.h"

namespace ldc::detail {

static_assert(kFixedOne == kDepthSteps, "depth steps and fixed point share the 2^16 unit");

void SnappedMesh::resize(size_t n) {
  triangles.resize(n);
  material.resize(n);
  normal_code.resize(n);
  normal_positive.resize(n);
  box.resize(n);
}

void SnappedMesh::set_triangle(size_t i, const std::array<uint32_t, 3>& t,
                               const std::array<i128, 3>& n, uint16_t mat) {
  triangles[i] = t;
  material[i] = mat;
  glm::dvec3 nd{static_cast<double>(n[0]), static_cast<double>(n[1]), static_cast<double>(n[2])};
  normal_code[i] = encode_normal(glm::normalize(nd));
  normal_positive[i] = uint8_t((n[0] > 0) | ((n[1] > 0) << 1) | ((n[2] > 0) << 2));
  for (int a = 0; a < 3; ++a) {
    int64_t p0 = vertices[t[0]][a], p1 = vertices[t[1]][a], p2 = vertices[t[2]][a];
    box[i][a] = std::min(p0, std::min(p1, p2));
    box[i][a + 3] = std::max(p0, std::max(p1, p2));
  }
}

std::array<i128, 3> triangle_normal(const std::vector<Vec3i>& v, const std::array<uint32_t, 3>& t) {
  const Vec3i& a = v[t[0]];
  const Vec3i& b = v[t[1]];
  const Vec3i& c = v[t[2]];
  i128 e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  i128 e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
          e1[0] * e2[1] - e1[1] * e2[0]};
}

namespace {

constexpr int64_t ceil_div64(int64_t a, int64_t b) { return -floor_div64(-a, b); }

// One ray/triangle crossing inside a tile.
struct Crossing {
  int64_t d;      // global depth in steps (1/Q cell)
  uint32_t tri;
  uint16_t ray;   // ray index within the tile (= within each chunk's family)
  int8_t delta;   // winding change: +1 entering (normal against the ray), -1 leaving
};

// A winding step of one ray: after depth d the winding number is w.
struct RawEntry {
  int64_t d;
  int32_t w;
  uint32_t tri;
};

// The rays of one axis in one chunk column, as winding steps.
struct TileRaw {
  std::vector<uint32_t> first;    // C*C + 1 offsets into entries
  std::vector<RawEntry> entries;
  std::vector<int32_t> w_final;   // winding after the last crossing
  std::vector<uint8_t> repaired;
  // Chunks along the column (global chunk index) holding entries: [k_first, k_last],
  // empty when k_first > k_last. Outside it every ray of a balanced tile is outside.
  int64_t k_first = 1, k_last = 0;
  bool balanced = true;           // every ray's winding returns to 0

  bool quiet(int64_t k) const { return balanced && (k < k_first || k > k_last); }
};

struct AxisTiles {
  int axis = 0;
  int tiles_u = 0, tiles_v = 0;
  std::vector<uint32_t> tri_first;  // CSR of triangles per tile
  std::vector<uint32_t> tri_ids;
  std::vector<TileRaw> raw;
};

struct Shared {
  const SnappedMesh& mesh;
  World& world;
  int c;
  uint32_t q;
  glm::ivec3 origin;  // chunk origin
  glm::ivec3 dims;
};

struct NodeRange {
  int64_t u_lo, u_hi, v_lo, v_hi;  // inclusive node coordinates
};

NodeRange triangle_node_range(const SnappedMesh& m, uint32_t t, int u, int v) {
  const auto& b = m.box[t];
  return {ceil_div64(b[u], kFixedOne), floor_div64(b[u + 3], kFixedOne), ceil_div64(b[v], kFixedOne),
          floor_div64(b[v + 3], kFixedOne)};
}

// Bins triangles into the chunk columns of one axis (CSR).
void bin_triangles(const Shared& sh, AxisTiles& at) {
  const int a = at.axis, u = axis_u(a), v = axis_v(a);
  at.tiles_u = sh.dims[u];
  at.tiles_v = sh.dims[v];
  const size_t tiles = size_t(at.tiles_u) * at.tiles_v;
  std::vector<std::array<int, 4>> range(sh.mesh.triangles.size());
  std::vector<uint32_t> count(tiles + 1, 0);
  for (uint32_t t = 0; t < sh.mesh.triangles.size(); ++t) {
    NodeRange r = triangle_node_range(sh.mesh, t, u, v);
    if (r.u_lo > r.u_hi || r.v_lo > r.v_hi) {
      range[t] = {1, 0, 1, 0};
      continue;
    }
    range[t] = {int(floor_div64(r.u_lo, sh.c)) - sh.origin[u],
                int(floor_div64(r.u_hi, sh.c)) - sh.origin[u],
                int(floor_div64(r.v_lo, sh.c)) - sh.origin[v],
                int(floor_div64(r.v_hi, sh.c)) - sh.origin[v]};
    for (int tv = range[t][2]; tv <= range[t][3]; ++tv)
      for (int tu = range[t][0]; tu <= range[t][1]; ++tu) ++count[size_t(tv) * at.tiles_u + tu];
  }
  at.tri_first.assign(tiles + 1, 0);
  for (size_t i = 0; i < tiles; ++i) at.tri_first[i + 1] = at.tri_first[i] + count[i];
  at.tri_ids.resize(at.tri_first[tiles]);
  std::vector<uint32_t> fill(at.tri_first.begin(), at.tri_first.end() - 1);
  for (uint32_t t = 0; t < sh.mesh.triangles.size(); ++t) {
    for (int tv = range[t][2]; tv <= range[t][3]; ++tv)
      for (int tu = range[t][0]; tu <= range[t][1]; ++tu)
        at.tri_ids[fill[size_t(tv) * at.tiles_u + tu]++] = t;
  }
  at.raw.resize(tiles);
}

// ---------------------------------------------------------------------------
// Stage 2: rasterize one triangle into one tile

struct TriangleSetup {
  Vec3i p[3];             // snapped vertices as (w, u, v)
  i128 n_w, n_u, n_v;     // exact normal in (w, u, v)
  i128 n_xyz[3];
  int sign_o;             // sign of the projected orientation (= sign of n_w)
  glm::dvec3 a_in;        // first vertex before snapping, as (w, u, v)
  glm::dvec3 n_in;        // normal before snapping, as (w, u, v)
};

TriangleSetup setup_triangle(const SnappedMesh& m, uint32_t t, int a) {
  TriangleSetup s;
  const int u = axis_u(a), v = axis_v(a);
  std::array<i128, 3> n = triangle_normal(m.vertices, m.triangles[t]);
  for (int i = 0; i < 3; ++i) {
    const Vec3i& p = m.vertices[m.triangles[t][i]];
    s.p[i] = {p[a], p[u], p[v]};
    s.n_xyz[i] = n[i];
  }
  s.n_w = n[a];
  s.n_u = n[u];
  s.n_v = n[v];
  s.sign_o = sign_of(s.n_w);
  const auto& tri = m.triangles[t];
  glm::dvec3 p0 = m.unsnapped[tri[0]], p1 = m.unsnapped[tri[1]], p2 = m.unsnapped[tri[2]];
  glm::dvec3 ni = glm::cross(p1 - p0, p2 - p0);
  s.a_in = {p0[a], p0[u], p0[v]};
  s.n_in = {ni[a], ni[u], ni[v]};
  return s;
}

// Depth (fixed-point units) where the ray (ru, rv) meets the plane through a
// with normal n, both as (w, u, v); NaN when the plane is parallel to the ray.
double plane_depth(const glm::dvec3& a, const glm::dvec3& n, int64_t ru, int64_t rv) {
  double du = double(ru * kFixedOne) - a.y, dv = double(rv * kFixedOne) - a.z;
  return n.x != 0.0 ? a.x - (n.y * du + n.z * dv) / n.x : std::nan("");
}

// Quantized depth of the crossing at ray (ru, rv) (node coordinates). The cell
// it falls in is decided on the snapped triangle, exactly: a crossing that
// rounds onto a node moves one step to the side the exact predicate says.
// Within that cell the depth comes from the unsnapped triangle.
int64_t crossing_depth(const TriangleSetup& s, int64_t ru, int64_t rv, uint32_t q,
                       size_t& nudged) {
  const Vec3i& A = s.p[0];
  glm::dvec3 a_snapped{static_cast<double>(A[0]), static_cast<double>(A[1]), static_cast<double>(A[2])};
  glm::dvec3 n_snapped{static_cast<double>(s.n_w), static_cast<double>(s.n_u), static_cast<double>(s.n_v)};
  const double scale = double(q) / double(kFixedOne);
  int64_t d = std::llround(plane_depth(a_snapped, n_snapped, ru, rv) * scale);
  if (floor_div64(d, q) * int64_t(q) == d) {
    // On a node: the node is after the crossing when the plane value at the
    // (perturbed) node has the sign of n_w.
    int64_t node_w = (d / int64_t(q)) * kFixedOne;
    i128 plane = s.n_w * i128(node_w - A[0]) + s.n_u * i128(ru * kFixedOne - A[1]) +
                 s.n_v * i128(rv * kFixedOne - A[2]);
    int side = perturbed_plane_sign(plane, s.n_xyz[0], s.n_xyz[1], s.n_xyz[2]);
    ++nudged;
    d = side == s.sign_o ? d - 1 : d + 1;
  }
  double t_in = plane_depth(s.a_in, s.n_in, ru, rv);
  if (!std::isfinite(t_in)) return d;
  const int64_t cell = floor_div64(d, q) * int64_t(q);
  return std::clamp<int64_t>(std::llround(t_in * scale), cell + 1, cell + int64_t(q) - 1);
}

// Edge function E(R) = du*(R.v - P.v) - dv*(R.u - P.u), turned so that inside
// is E >= bias (bias 0 when the perturbation puts on-edge points inside).
template <class Int>
struct Edge {
  Int du, dv;
  int bias;
};

template <class Int>
Edge<Int> make_edge(const Vec3i& P, const Vec3i& Q, int sign_o, bool u_dominates) {
  int64_t du = Q[1] - P[1], dv = Q[2] - P[2];
  int tie = edge_tie_sign(du, dv, u_dominates) * sign_o;
  return {Int(du) * sign_o, Int(dv) * sign_o, tie > 0 ? 0 : 1};
}

template <class Int>
void raster_in_tile(const TriangleSetup& s, uint32_t tri, int a, const NodeRange& r,
                    const glm::i64vec2& tile_node0, int c, uint32_t q,
                    std::vector<Crossing>& out, size_t& nudged) {
  const bool udom = u_perturbation_dominates(a);
  // Coordinates relative to the triangle's bounding-box corner keep every
  // product within Int (see the caller's choice of Int).
  const int64_t base_u = std::min({s.p[0][1], s.p[1][1], s.p[2][1]});
  const int64_t base_v = std::min({s.p[0][2], s.p[1][2], s.p[2][2]});
  Edge<Int> e[3] = {make_edge<Int>(s.p[0], s.p[1], s.sign_o, udom),
                    make_edge<Int>(s.p[1], s.p[2], s.sign_o, udom),
                    make_edge<Int>(s.p[2], s.p[0], s.sign_o, udom)};
  const int8_t delta = s.sign_o < 0 ? int8_t{1} : int8_t{-1};
  const Int ru0 = Int(r.u_lo * kFixedOne - base_u);
  for (int64_t rv = r.v_lo; rv <= r.v_hi; ++rv) {
    const Int rvr = Int(rv * kFixedOne - base_v);
    Int val[3];
    for (int i = 0; i < 3; ++i) {
      Int pu = Int(s.p[i][1] - base_u), pv = Int(s.p[i][2] - base_v);
      val[i] = e[i].du * (rvr - pv) - e[i].dv * (ru0 - pu);
    }
    const int row = int(rv - tile_node0.y) * c;
    for (int64_t ru = r.u_lo; ru <= r.u_hi; ++ru) {
      if (val[0] >= e[0].bias && val[1] >= e[1].bias && val[2] >= e[2].bias) {
        out.push_back({crossing_depth(s, ru, rv, q, nudged), tri,
                       uint16_t(row + int(ru - tile_node0.x)), delta});
      }
      for (int i = 0; i < 3; ++i) val[i] -= e[i].dv * Int(kFixedOne);
    }
  }
}

// Rasterizes one triangle into the rays of one tile, with 64-bit arithmetic
// when its extent allows (nearly always) and 128-bit otherwise.
void raster_triangle(const Shared& sh, int a, uint32_t tri, int tu, int tv,
                     std::vector<Crossing>& out, size_t& nudged) {
  const int u = axis_u(a), v = axis_v(a);
  NodeRange r = triangle_node_range(sh.mesh, tri, u, v);
  const glm::i64vec2 tile0(int64_t(sh.origin[u] + tu) * sh.c, int64_t(sh.origin[v] + tv) * sh.c);
  r.u_lo = std::max(r.u_lo, tile0.x);
  r.u_hi = std::min(r.u_hi, tile0.x + sh.c - 1);
  r.v_lo = std::max(r.v_lo, tile0.y);
  r.v_hi = std::min(r.v_hi, tile0.y + sh.c - 1);
  if (r.u_lo > r.u_hi || r.v_lo > r.v_hi) return;
  TriangleSetup s = setup_triangle(sh.mesh, tri, a);
  if (s.sign_o == 0) return;  // seen edge-on from this axis: no ray hits it
  int64_t ext = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 1; j < 3; ++j) ext = std::max(ext, std::abs(s.p[i][j] - s.p[(i + 1) % 3][j]));
  }
  if (ext < (int64_t{1} << 31)) {
    raster_in_tile<int64_t>(s, tri, a, r, tile0, sh.c, sh.q, out, nudged);
  } else {
    raster_in_tile<i128>(s, tri, a, r, tile0, sh.c, sh.q, out, nudged);
  }
}

// Sorts a tile's crossings by ray, then depth, and merges each ray's crossings
// into winding steps (crossings at one depth are summed; steps that change
// nothing are dropped).
void merge_crossings(std::vector<Crossing>& xs, int c, TileRaw& raw) {
  const size_t rays = size_t(c) * c;
  std::vector<uint32_t> first(rays + 1, 0);
  for (const Crossing& x : xs) ++first[x.ray + 1];
  for (size_t i = 0; i < rays; ++i) first[i + 1] += first[i];
  std::vector<Crossing> sorted(xs.size());
  {
    std::vector<uint32_t> fill(first.begin(), first.end() - 1);
    for (const Crossing& x : xs) sorted[fill[x.ray]++] = x;
  }
  raw.first.assign(rays + 1, 0);
  raw.w_final.assign(rays, 0);
  raw.repaired.assign(rays, 0);
  raw.balanced = true;
  raw.k_first = 1;
  raw.k_last = 0;
  raw.entries.clear();
  raw.entries.reserve(xs.size());
  auto by_depth = [](const Crossing& p, const Crossing& q) {
    return p.d != q.d ? p.d < q.d : p.tri < q.tri;
  };
  for (size_t r = 0; r < rays; ++r) {
    auto b = sorted.begin() + first[r], e = sorted.begin() + first[r + 1];
    std::sort(b, e, by_depth);
    int32_t w = 0;
    for (auto it = b; it != e;) {
      auto jt = it;
      int net = 0;
      while (jt != e && jt->d == it->d) net += (jt++)->delta;
      if (net != 0) {
        // The normal comes from a crossing that moves the winding the same way.
        auto pick = std::find_if(it, jt, [&](const Crossing& x) { return (x.delta > 0) == (net > 0); });
        w += net;
        raw.entries.push_back({it->d, w, pick->tri});
      }
      it = jt;
    }
    raw.w_final[r] = w;
    raw.balanced = raw.balanced && w == 0;
    raw.first[r + 1] = uint32_t(raw.entries.size());
  }
  for (const RawEntry& x : raw.entries) {
    int64_t k = floor_div64(x.d, kDepthSteps);
    if (raw.k_first > raw.k_last) raw.k_first = raw.k_last = k;
    raw.k_first = std::min(raw.k_first, k);
    raw.k_last = std::max(raw.k_last, k);
  }
}

void rasterize_tile(const Shared& sh, AxisTiles& at, size_t tile, size_t& nudged,
                    size_t& crossings) {
  const int tu = int(tile % size_t(at.tiles_u)), tv = int(tile / size_t(at.tiles_u));
  std::vector<Crossing> xs;
  for (uint32_t k = at.tri_first[tile]; k < at.tri_first[tile + 1]; ++k) {
    raster_triangle(sh, at.axis, at.tri_ids[k], tu, tv, xs, nudged);
  }
  crossings += xs.size();
  merge_crossings(xs, sh.c, at.raw[tile]);
}

// ---------------------------------------------------------------------------
// Stage 3: votes (open meshes)

// Node word of a predicate on the winding over one chunk segment of a ray:
// bit n set when the predicate holds at local node n.
uint64_t winding_word(const RawEntry* b, const RawEntry* e, int32_t w_before, int32_t w_ref,
                      int64_t start, int c, uint32_t q) {
  bool state = (w_before - w_ref) != 0;
  bool first = state;
  uint64_t toggles = 0;
  for (const RawEntry* it = b; it != e; ++it) {
    bool now = (it->w - w_ref) != 0;
    if (now == state) continue;
    state = now;
    uint32_t next_node = uint32_t((it->d - start) / q) + 1;
    if (next_node < uint32_t(c)) toggles ^= uint64_t{1} << next_node;
  }
  uint64_t word = prefix_xor(toggles);
  if (first) word = ~word;
  return c == 64 ? word : word & ((uint64_t{1} << c) - 1);
}

// The entries of tile ray r with depth in [start, end), and the winding before them.
struct RaySlice {
  const RawEntry* b;
  const RawEntry* e;
  int32_t w_before;
};

RaySlice ray_slice(const TileRaw& raw, int r, int64_t start, int64_t end) {
  const RawEntry* rb = raw.entries.data() + raw.first[r];
  const RawEntry* re = raw.entries.data() + raw.first[r + 1];
  auto lo = std::lower_bound(rb, re, start, [](const RawEntry& x, int64_t d) { return x.d < d; });
  auto hi = std::lower_bound(lo, re, end, [](const RawEntry& x, int64_t d) { return x.d < d; });
  return {lo, hi, lo == rb ? 0 : (lo - 1)->w};
}

// Majority of six votes per bit; ties (three each way) count as inside, since
// the usual cause is a hole that one axis sees through.
uint64_t majority6(uint64_t a, uint64_t b, uint64_t c, uint64_t d, uint64_t e, uint64_t f) {
  uint64_t s1 = a ^ b ^ c, c1 = (a & b) | (c & (a ^ b));
  uint64_t s2 = d ^ e ^ f, c2 = (d & e) | (f & (d ^ e));
  uint64_t ones = s1 ^ s2, c3 = s1 & s2;
  uint64_t twos = c1 ^ c2 ^ c3, fours = (c1 & c2) | (c3 & (c1 ^ c2));
  return fours | (twos & ones);  // count >= 3
}

struct TileSet {
  std::array<AxisTiles, 3> axes;
  const TileRaw& tile_of(const Shared& sh, int a, const glm::ivec3& ch) const {
    const AxisTiles& at = axes[a];
    int tu = ch[axis_u(a)] - sh.origin[axis_u(a)], tv = ch[axis_v(a)] - sh.origin[axis_v(a)];
    return at.raw[size_t(tv) * at.tiles_u + tu];
  }
};

// The voted node signs of one chunk: all nodes alike (uniform, value), or
// words in the X layout (c*64 words, index z*64 + y, bit x). Bit a of
// `agrees` says the votes equal axis a's own winding labelling in this chunk,
// so that axis's rays need no repair here.
struct ChunkVotes {
  bool uniform = true;
  bool value = false;
  uint8_t agrees = 7;
  std::vector<uint64_t> words;

  bool node(const glm::ivec3& local) const {
    return uniform ? value : (words[size_t(local.z) * 64 + local.y] >> local.x) & 1u;
  }
};

// Own-labelling ("below") and end-counted ("above") node words of one axis.
struct AxisWords {
  std::vector<uint64_t> below, above;
  bool balanced = true;  // below == above for every ray
};

void axis_words(const Shared& sh, const TileRaw& raw, int a, const glm::ivec3& ch, AxisWords& w) {
  const int c = sh.c;
  const int64_t start = int64_t(ch[a]) * kDepthSteps;
  w.below.resize(size_t(c) * c);
  w.above.resize(size_t(c) * c);
  w.balanced = true;
  for (int r = 0; r < c * c; ++r) {
    if (raw.first[r] == raw.first[r + 1]) {  // no crossing on this ray at all
      w.below[r] = w.above[r] = 0;
      continue;
    }
    RaySlice s = ray_slice(raw, r, start, start + kDepthSteps);
    w.below[r] = winding_word(s.b, s.e, s.w_before, 0, start, c, sh.q);
    w.above[r] = raw.w_final[r] == 0 ? w.below[r]
                                     : winding_word(s.b, s.e, s.w_before, raw.w_final[r], start, c, sh.q);
    w.balanced = w.balanced && w.below[r] == w.above[r];
  }
}

ChunkVotes chunk_votes(const Shared& sh, const TileSet& ts, const glm::ivec3& ch) {
  const int c = sh.c;
  if (ts.tile_of(sh, 0, ch).quiet(ch[0]) && ts.tile_of(sh, 1, ch).quiet(ch[1]) &&
      ts.tile_of(sh, 2, ch).quiet(ch[2])) {
    return {};  // no entry near and every ray balanced: all six votes say outside
  }
  const uint64_t ones = c == 64 ? ~uint64_t{0} : (uint64_t{1} << c) - 1;
  std::array<AxisWords, 3> fam;
  bool all_zero = true, all_ones = true;
  for (int a = 0; a < 3; ++a) {
    axis_words(sh, ts.tile_of(sh, a, ch), a, ch, fam[a]);
    for (size_t r = 0; r < fam[a].below.size(); ++r) {
      all_zero = all_zero && (fam[a].below[r] | fam[a].above[r]) == 0;
      all_ones = all_ones && (fam[a].below[r] & fam[a].above[r]) == ones;
    }
  }
  ChunkVotes out;
  if (all_zero || all_ones) {  // every vote agrees: no transposes needed
    out.value = all_ones;
    return out;
  }
  std::array<std::vector<uint64_t>, 6> xl;
  for (int i = 0; i < 6; ++i) {
    const AxisWords& w = fam[i / 2];
    if (i % 2 == 1 && w.balanced) {
      xl[i] = xl[i - 1];
      continue;
    }
    xl[i].assign(size_t(c) * 64, 0);
    convert_layout(i / 2, c, (i % 2 ? w.above : w.below).data(), xl[i].data(), false);
  }
  out.uniform = false;
  out.agrees = 0;
  out.words.assign(size_t(c) * 64, 0);
  uint64_t diff[3] = {0, 0, 0};
  for (size_t i = 0; i < out.words.size(); ++i) {
    out.words[i] = majority6(xl[0][i], xl[1][i], xl[2][i], xl[3][i], xl[4][i], xl[5][i]);
    for (int a = 0; a < 3; ++a) diff[a] |= out.words[i] ^ xl[2 * a][i];
  }
  for (int a = 0; a < 3; ++a) out.agrees |= uint8_t((diff[a] == 0) << a);
  return out;
}

// ---------------------------------------------------------------------------
// Stage 4: emit points

constexpr uint32_t kNoTriangle = 0xFFFFFFFFu;

struct EmitCounts {
  size_t repaired = 0, synthesized = 0, dropped = 0, flips = 0;
};

// Emits the points of one family's rays; `in` is the ray's current state.
class PointEmitter {
 public:
  PointEmitter(const SnappedMesh& mesh, int axis, int64_t start, EmitCounts& counts)
      : mesh_(mesh), axis_(axis), start_(start), counts_(counts) {
    glm::dvec3 n(0.0);
    n[axis] = -1.0;
    enter_code_ = encode_normal(n);
    exit_code_ = encode_normal(-n);
  }

  // A point at global depth d; its normal turned to point out of the solid.
  void point(RayFamilyWriter& wr, int64_t d, bool enter, uint32_t tri) {
    PackedPoint p;
    p.depth = uint16_t(d - start_);
    uint32_t code;
    if (tri == kNoTriangle) {
      code = enter ? enter_code_ : exit_code_;
    } else {
      bool positive = (mesh_.normal_positive[tri] >> axis_) & 1u;
      bool wrong_side = enter == positive;  // entering needs n_axis < 0
      code = mesh_.normal_code[tri];
      if (wrong_side) code = encode_normal(-glm::dvec3(decode_normal(code)));
      counts_.flips += wrong_side;
      p.material = mesh_.material[tri];
    }
    p.normal = code | (enter ? 0u : kPointExitBit);
    wr.add_point(p);
  }

  // Points where "winding - w_ref != 0" changes, from state at w0.
  void transitions(RayFamilyWriter& wr, const RawEntry* b, const RawEntry* e, int32_t w0,
                   int32_t w_ref) {
    bool state = (w0 - w_ref) != 0;
    for (const RawEntry* it = b; it != e; ++it) {
      bool now = (it->w - w_ref) != 0;
      if (now == state) continue;
      point(wr, it->d, now, it->tri);
      state = now;
    }
  }

  int64_t start() const { return start_; }
  EmitCounts& counts() { return counts_; }

 private:
  const SnappedMesh& mesh_;
  int axis_;
  int64_t start_;
  EmitCounts& counts_;
  uint32_t enter_code_, exit_code_;
};

// The node states a ray must have, from the votes: bits 0..c-1 of this chunk
// and the first node of the next chunk.
struct RayTarget {
  uint64_t nodes;
  bool next;
};

// One cell edge [n, n+1] of a repaired ray: keep the ray's own crossings where
// either winding labelling (from the start or from the end of the ray) fits the
// voted nodes, else drop them, or keep (or make) one point where the state must change.
void emit_interval(PointEmitter& em, RayFamilyWriter& wr, const RawEntry* b, const RawEntry* e,
                   int32_t w0, int32_t w1, int32_t wf, bool in0, bool in1, int64_t interval_start,
                   uint32_t q) {
  if (((w0 != 0) == in0) && ((w1 != 0) == in1)) return em.transitions(wr, b, e, w0, 0);
  if ((((w0 - wf) != 0) == in0) && (((w1 - wf) != 0) == in1)) {
    return em.transitions(wr, b, e, w0, wf);
  }
  if (in0 == in1) {
    em.counts().dropped += size_t(e - b);
    return;
  }
  if (b == e) {
    ++em.counts().synthesized;
    return em.point(wr, interval_start + q / 2, in1, kNoTriangle);
  }
  const int64_t centre = interval_start + q / 2;
  const RawEntry* best = b;
  for (const RawEntry* it = b; it != e; ++it) {
    if (std::llabs(it->d - centre) < std::llabs(best->d - centre)) best = it;
  }
  em.counts().dropped += size_t(e - b) - 1;
  em.point(wr, best->d, in1, best->tri);
}

void emit_repaired_ray(PointEmitter& em, RayFamilyWriter& wr, const RaySlice& sl, int32_t wf,
                       const RayTarget& t, int c, uint32_t q) {
  const int64_t start = em.start();
  const uint64_t low = c == 64 ? ~uint64_t{0} : (uint64_t{1} << c) - 1;
  const uint64_t shifted = (t.nodes >> 1) | (uint64_t(t.next) << (c - 1));
  uint64_t entry_mask = 0;
  for (const RawEntry* it = sl.b; it != sl.e; ++it) entry_mask |= uint64_t{1} << ((it->d - start) / q);
  uint64_t todo = ((t.nodes ^ shifted) & low) | entry_mask;
  wr.begin_ray(t.nodes & 1u);
  const RawEntry* it = sl.b;
  int32_t w = sl.w_before;
  while (todo) {
    int n = std::countr_zero(todo);
    todo &= todo - 1;
    const int64_t interval_start = start + int64_t(n) * q;
    const RawEntry* p = it;
    while (it != sl.e && it->d < interval_start + q) ++it;
    int32_t w0 = w;
    w = it != p ? (it - 1)->w : w0;
    emit_interval(em, wr, p, it, w0, w, wf, (t.nodes >> n) & 1u, (shifted >> n) & 1u,
                  interval_start, q);
  }
}

// Node states of a ray slice under the ray's own (non-zero winding) labelling.
RayTarget own_target(const RaySlice& sl, int64_t start, int c, uint32_t q) {
  int32_t w_end = sl.e != sl.b ? (sl.e - 1)->w : sl.w_before;
  return {winding_word(sl.b, sl.e, sl.w_before, 0, start, c, q), w_end != 0};
}

// Walks the rays of one tile column chunk by chunk: slices[r] holds ray r's
// entries inside the current chunk.
class ColumnCursor {
 public:
  explicit ColumnCursor(const TileRaw& raw) : raw_(raw), slices_(raw.first.size() - 1) {
    for (size_t r = 0; r < slices_.size(); ++r) {
      const RawEntry* b = raw.entries.data() + raw.first[r];
      slices_[r] = {b, b, 0};
    }
  }
  // Advances to the chunk whose depths are [start, start + kDepthSteps).
  // Returns true when no ray has an entry in it.
  bool advance(int64_t start) {
    bool none = true;
    for (size_t r = 0; r < slices_.size(); ++r) {
      RaySlice& s = slices_[r];
      if (s.e != s.b) s.w_before = (s.e - 1)->w;
      s.b = s.e;
      const RawEntry* end = raw_.entries.data() + raw_.first[r + 1];
      while (s.e != end && s.e->d < start + int64_t(kDepthSteps)) ++s.e;
      none = none && s.e == s.b;
    }
    return none;
  }
  const RaySlice& slice(int r) const { return slices_[r]; }

 private:
  const TileRaw& raw_;
  std::vector<RaySlice> slices_;
};

// Uniform state of a chunk's rays with no entries, or -1 when they differ.
int uniform_state(const ColumnCursor& cur, int c) {
  bool in0 = cur.slice(0).w_before != 0;
  for (int r = 1; r < c * c; ++r) {
    if ((cur.slice(r).w_before != 0) != in0) return -1;
  }
  return in0 ? 1 : 0;
}

// Voted target states of every ray of a family: this chunk's nodes in family
// layout, and each ray's first node in the next chunk along the axis.
struct FamilyTarget {
  std::vector<uint64_t> words;
  std::vector<uint8_t> next;
};

void family_target(const Shared& sh, int a, const ChunkVotes& here, const ChunkVotes* ahead,
                   FamilyTarget& t) {
  const int c = sh.c;
  const uint64_t ones = c == 64 ? ~uint64_t{0} : (uint64_t{1} << c) - 1;
  t.words.assign(size_t(c) * c, here.value ? ones : 0);
  if (!here.uniform) convert_layout(a, c, here.words.data(), t.words.data(), true);
  t.next.assign(size_t(c) * c, 0);
  if (!ahead) return;
  for (int r = 0; r < c * c; ++r) {
    glm::ivec3 local(0);
    local[axis_u(a)] = r % c;
    local[axis_v(a)] = r / c;
    t.next[r] = ahead->node(local);
  }
}

RayFamily emit_family(const Shared& sh, int a, const TileRaw& raw, const ColumnCursor& cur,
                      int64_t start, const FamilyTarget* target, std::vector<uint8_t>& repaired,
                      EmitCounts& counts) {
  const int c = sh.c;
  PointEmitter em(sh.mesh, a, start, counts);
  RayFamilyWriter wr(c);
  for (int r = 0; r < c * c; ++r) {
    const RaySlice& sl = cur.slice(r);
    if (target) {
      RayTarget want{target->words[r], bool(target->next[r])};
      RayTarget own = own_target(sl, start, c, sh.q);
      if (own.nodes != want.nodes || own.next != want.next) {
        repaired[r] = 1;
        emit_repaired_ray(em, wr, sl, raw.w_final[r], want, c, sh.q);
        continue;
      }
    }
    wr.begin_ray(sl.w_before != 0);
    em.transitions(wr, sl.b, sl.e, sl.w_before, 0);
  }
  return wr.finish();
}

// Can chunk k of this column be stored as uniform without looking at rays?
bool uniform_by_votes(const ChunkVotes* votes, const ChunkVotes* ahead, int state) {
  if (!votes) return true;
  if (!votes->uniform || votes->value != bool(state)) return false;
  return ahead ? (ahead->uniform && ahead->value == bool(state)) : state == 0;
}

// Emits every chunk of one tile column of axis a.
void emit_tile(const Shared& sh, TileSet& ts, int a, size_t tile, ChunkAssembly& assembly,
               const std::vector<ChunkVotes>* votes, EmitCounts& counts) {
  AxisTiles& at = ts.axes[a];
  TileRaw& raw = at.raw[tile];
  const int u = axis_u(a), v = axis_v(a);
  glm::ivec3 ch;
  ch[u] = sh.origin[u] + int(tile % size_t(at.tiles_u));
  ch[v] = sh.origin[v] + int(tile / size_t(at.tiles_u));
  ColumnCursor cur(raw);
  FamilyTarget target;
  for (int k = 0; k < sh.dims[a]; ++k) {
    ch[a] = sh.origin[a] + k;
    const int64_t start = int64_t(ch[a]) * kDepthSteps;
    size_t slot = sh.world.chunk_slot(ch);
    const ChunkVotes* here = votes ? &(*votes)[slot] : nullptr;
    const ChunkVotes* ahead = nullptr;
    if (votes && k + 1 < sh.dims[a]) {
      glm::ivec3 nc = ch;
      nc[a] += 1;
      ahead = &(*votes)[sh.world.chunk_slot(nc)];
    }
    if (raw.quiet(ch[a]) && uniform_by_votes(here, ahead, 0)) {
      assembly.families(slot)[a] = RayFamily::uniform(false);
      continue;
    }
    bool no_entries = cur.advance(start);
    int state = no_entries ? uniform_state(cur, sh.c) : -1;
    if (state >= 0 && uniform_by_votes(here, ahead, state)) {
      assembly.families(slot)[a] = RayFamily::uniform(state == 1);
      continue;
    }
    // Votes that equal this axis's own labelling here and at the next chunk's
    // first nodes leave its rays as they are.
    bool needs_target = here && !((here->agrees >> a) & 1u && (!ahead || (ahead->agrees >> a) & 1u));
    if (needs_target) family_target(sh, a, *here, ahead, target);
    assembly.families(slot)[a] =
        emit_family(sh, a, raw, cur, start, needs_target ? &target : nullptr, raw.repaired, counts);
  }
}

}  // namespace

Status rasterize_mesh_into(const SnappedMesh& mesh, World& world, Context* ctx,
                           BuildReport& report) {
  Shared sh{mesh, world, world.chunk_size(), depth_steps_per_cell(world.chunk_size()),
            world.chunk_origin(), world.chunk_dims()};
  TileSet ts;
  {
    ScopedTimer t(ctx, "build.bin");
    tbb::parallel_for(0, 3, [&](int a) {
      ts.axes[a].axis = a;
      bin_triangles(sh, ts.axes[a]);
    });
  }
  std::vector<std::pair<int, size_t>> tasks;
  for (int a = 0; a < 3; ++a)
    for (size_t t = 0; t < ts.axes[a].raw.size(); ++t) tasks.emplace_back(a, t);

  std::atomic<size_t> nudged{0}, crossings{0};
  {
    ScopedTimer t(ctx, "build.rasterize");
    ProgressCounter progress(ctx, "rasterize", tasks.size());
    tbb::parallel_for(size_t{0}, tasks.size(), [&](size_t i) {
      if (progress.cancelled()) return;
      size_t n = 0, x = 0;
      rasterize_tile(sh, ts.axes[tasks[i].first], tasks[i].second, n, x);
      nudged += n;
      crossings += x;
      progress.step();
    });
    if (progress.cancelled()) return cancelled_status("mesh");
  }
  std::vector<ChunkVotes> votes;
  if (!report.input_closed) {
    ScopedTimer t(ctx, "build.votes");
    votes.resize(size_t(sh.dims.x) * sh.dims.y * sh.dims.z);
    tbb::parallel_for(size_t{0}, votes.size(), [&](size_t slot) {
      votes[slot] = chunk_votes(sh, ts, slot_chunk(world, slot));
    });
  }
  ChunkAssembly assembly(world);
  std::atomic<size_t> synthesized{0}, dropped{0}, flips{0};
  {
    ScopedTimer t(ctx, "build.emit");
    ProgressCounter progress(ctx, "emit", tasks.size());
    tbb::parallel_for(size_t{0}, tasks.size(), [&](size_t i) {
      if (progress.cancelled()) return;
      EmitCounts counts;
      emit_tile(sh, ts, tasks[i].first, tasks[i].second, assembly,
                votes.empty() ? nullptr : &votes, counts);
      synthesized += counts.synthesized;
      dropped += counts.dropped;
      flips += counts.flips;
      progress.step();
    });
    if (progress.cancelled()) return cancelled_status("mesh");
  }
  {
    ScopedTimer t(ctx, "build.assemble");
    assembly.finish(world);
  }
  size_t repaired = 0;
  for (const AxisTiles& at : ts.axes)
    for (const TileRaw& raw : at.raw)
      for (uint8_t r : raw.repaired) repaired += r;
  report.crossings = crossings;
  report.nudged_points = nudged;
  report.repaired_rays = repaired;
  report.synthesized_points = synthesized;
  report.dropped_crossings = dropped;
  report.normal_flips = flips;
  return {};
}

}  // namespace ldc::detail
