// contour_levels(): dual contouring of a world whose chunks sit at different
// levels of detail, closed across the seams (see contour/contour.h).
//
// The cells form one conforming complex. A chunk at level k is tiled by cubes
// of s = 2^k lattice cells. Where a cube's face lies on a chunk face whose
// neighbour is finer, the face is cut into the neighbour's smaller squares
// ("pieces"), and every side of a piece lying on a lattice line is cut at the
// finest level of the chunks that touch that line. So both cells sharing a
// piece see the same polygon of nodes, and every edge between two
// consecutive nodes (a "minimal edge", of length 2^m) is an edge of the
// level-m world, whose crossing coarsen() keeps exactly (read here in place:
// a Region with stride 2^m). The sheets of a cell are the loops its
// polygons' segments close into (the face rule of detail/cell_sheets.h,
// generalised from squares to polygons: each run of inside nodes is cut off
// by one segment; a piece whose two cells would both link two of its
// segments into one loop cuts off its outside runs instead, from both
// sides, as the uniform mesher joins a face); one vertex per sheet, and one
// polygon per crossing minimal edge, joining the sheets of the 3 or 4 cells
// around it. That is the uniform mesher's argument for a closed 2-manifold,
// unchanged: every segment lies on one polygon shared by two cells, and every
// sheet is one loop. On a level-k world it gives contour_world's mesh of
// coarsen(world, k) (tested, without relaxation and local untangling).
#include <algorithm>
#include <atomic>
#include <bit>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "contour/contour.h"
#include "contour/detail/cell_sheets.h"
#include "contour/detail/placement.h"
#include "contour/detail/region.h"
#include "ldc/lod.h"

namespace ldc {
namespace {

using detail::CellPlanes;
using detail::EdgeCrossing;
using detail::Qef;
using detail::Region;
using detail::axis_unit;

// The level of every chunk: the world's, and any other one as its nearest
// chunk of the world (the layer below the box holds cells too).
class LevelMap {
 public:
  // The chunks of the world's box within [lo, hi) (all of them by default).
  Status build(const World& world, const std::function<int(const glm::ivec3&)>& level_of,
               glm::ivec3 lo = glm::ivec3(INT32_MIN), glm::ivec3 hi = glm::ivec3(INT32_MAX)) {
    lo = glm::max(lo, world.chunk_origin());
    hi = glm::min(hi, world.chunk_origin() + world.chunk_dims());
    origin_ = lo;
    dims_ = hi - lo;
    shift_ = world.chunk_shift();
    const int max_level = max_lod_level(world.chunk_size());
    levels_.assign(size_t(dims_.x) * size_t(dims_.y) * size_t(dims_.z), 0);
    for (int z = 0; z < dims_.z; ++z)
      for (int y = 0; y < dims_.y; ++y)
        for (int x = 0; x < dims_.x; ++x) {
          const glm::ivec3 chunk = origin_ + glm::ivec3(x, y, z);
          const int level = level_of(chunk);
          if (level < 0 || level > max_level) {
            return Status(ErrorCode::kInvalidArgument,
                          "contour_levels: chunk (" + std::to_string(chunk.x) + ", " + std::to_string(chunk.y) +
                              ", " + std::to_string(chunk.z) + ") has level " + std::to_string(level) +
                              ", outside 0 .. " + std::to_string(max_level) + " for chunks of " +
                              std::to_string(world.chunk_size()) + " cells");
          }
          levels_[index(chunk)] = int8_t(level);
          highest_ = std::max(highest_, level);
        }
    return {};
  }
  int at(const glm::ivec3& chunk) const { return levels_[index(glm::clamp(chunk, origin_, origin_ + dims_ - 1))]; }
  int highest() const { return highest_; }
  int chunk_shift() const { return shift_; }
  // The chunk holding the point 2 * doubled (coordinates in half lattice cells, never on a chunk face).
  glm::ivec3 chunk_of_doubled(const glm::ivec3& doubled) const { return doubled >> (shift_ + 1); }

 private:
  size_t index(const glm::ivec3& c) const {
    const glm::ivec3 r = c - origin_;
    return (size_t(r.z) * size_t(dims_.y) + size_t(r.y)) * size_t(dims_.x) + size_t(r.x);
  }
  glm::ivec3 origin_{0}, dims_{1};
  int shift_ = 5;
  int highest_ = 0;
  std::vector<int8_t> levels_;
};

// A cube of 2^level lattice cells with its lowest node at `lo` (level-0 nodes).
struct Cell {
  glm::ivec3 lo{0};
  int level = 0;
  int size() const { return 1 << level; }
};

// The cell holding a point given in half lattice cells (off every cell face).
Cell cell_at_doubled(const LevelMap& levels, const glm::ivec3& doubled) {
  Cell c;
  c.level = levels.at(levels.chunk_of_doubled(doubled));
  c.lo = (doubled >> (c.level + 1)) * (1 << c.level);  // floor to the level-k cell (a multiply: the coordinate may be negative)
  return c;
}

// Signs and crossings of the lattice at each level: an edge of length 2^m
// whose ends are multiples of 2^m is an edge of coarsen(world, m), read
// with a Region of stride 2^m (the same crossing as that world's contouring
// reads). Keeps the last few chunk regions loaded (least recently used goes
// first).
class LevelReader {
 public:
  LevelReader(const World* world, int highest_level) : world_(world), highest_(highest_level) {}
  // Reads another world (or the same after a change) next: forgets what was
  // loaded, keeping the regions' buffers.
  void rebind(const World* world, int highest_level) {
    world_ = world;
    highest_ = highest_level;
    forget();
    focus_level_ = -1;
  }

  // Loads chunk `chunk` of the level-`level` world as the region looked at
  // first (the chunk being meshed). Other chunks' regions are then read
  // only near it (what meshing it reads: within C / 4 + 1 nodes of its box),
  // and whole where a read falls beyond that.
  const Region& focus(int level, const glm::ivec3& chunk) {
    forget();  // the near parts were cut for the last focus
    focus_level_ = -1;
    load(focus_, level, chunk, false);
    focus_level_ = level;
    focus_lo_ = chunk * world_->chunk_size();
    focus_hi_ = focus_lo_ + world_->chunk_size();
    return focus_;
  }

  bool inside(const glm::ivec3& node) {
    if (in_focus(node)) return focus_.inside(node >> focus_level_);
    const unsigned bits = unsigned(node.x) | unsigned(node.y) | unsigned(node.z);
    const int m = std::min(std::countr_zero(bits), highest_);
    const glm::ivec3 at = node >> m;
    return holding(m, at, at).inside(at);
  }
  // The crossing of the edge from `lower` along `axis`, 2^level long.
  const EdgeCrossing* crossing(const glm::ivec3& lower, int axis, int level) {
    if (level == focus_level_ && in_focus(lower) && lower[axis] < focus_hi_[axis])
      return focus_.crossing(axis, lower >> level);
    const glm::ivec3 at = lower >> level;
    return holding(level, at, at + axis_unit(axis)).crossing(axis, at);
  }

 private:
  static constexpr size_t kSlots = 32;
  struct Slot {
    int level;
    glm::ivec3 chunk;
    bool near;  // only the part near the focus
    uint64_t used;
    std::unique_ptr<Region> region;
  };

  void forget() {
    for (Slot& s : slots_) s.level = -1;
  }
  bool in_focus(const glm::ivec3& node) const {
    const unsigned mask = (1u << focus_level_) - 1u;
    return focus_level_ >= 0 && ((unsigned(node.x) | unsigned(node.y) | unsigned(node.z)) & mask) == 0 &&
           detail::in_box(node, focus_lo_, focus_hi_ + 1);
  }
  int chunk_shift(int level) const { return world_->chunk_shift() - level; }

  // A region of the level-m world holding its nodes a and b, of the chunk
  // holding a: the part near the focus when it holds both, else the whole chunk.
  const Region& holding(int level, const glm::ivec3& a, const glm::ivec3& b) {
    const glm::ivec3 chunk = a >> chunk_shift(level);
    const Region& near = region(level, chunk, true);
    if (near.contains(a) && near.contains(b)) return near;
    return region(level, chunk, false);
  }

  const Region& region(int level, const glm::ivec3& chunk, bool near) {
    ++clock_;
    auto is = [&](const Slot& s) { return s.level == level && s.near == near && s.chunk == chunk; };
    if (last_ < slots_.size() && is(slots_[last_])) {
      slots_[last_].used = clock_;
      return *slots_[last_].region;
    }
    for (Slot& s : slots_) {
      if (is(s)) {
        s.used = clock_;
        last_ = size_t(&s - slots_.data());
        return *s.region;
      }
    }
    Slot* slot = nullptr;
    if (slots_.size() < kSlots) {
      slots_.push_back({level, chunk, near, clock_, std::make_unique<Region>()});
      slot = &slots_.back();
    } else {
      slot = &*std::min_element(slots_.begin(), slots_.end(),
                                [](const Slot& a, const Slot& b) { return a.used < b.used; });
      *slot = {level, chunk, near, clock_, std::move(slot->region)};
    }
    load(*slot->region, level, chunk, near);
    last_ = size_t(slot - slots_.data());
    return *slot->region;
  }

  // Nodes [c C_m, (c + 1) C_m] of the level-m world (its chunk c, closed);
  // with `near`, only those within C / 4 + 1 level-0 nodes of the focus.
  void load(Region& region, int level, const glm::ivec3& chunk, bool near) const {
    const int c = world_->chunk_size() >> level;
    glm::ivec3 lo = chunk * c, hi = chunk * c + c + 1;
    if (near && focus_level_ >= 0) {
      const int reach = world_->chunk_size() / 4 + 1;
      const glm::ivec3 near_lo = glm::max(lo, (focus_lo_ - reach) >> level);
      const glm::ivec3 near_hi = glm::min(hi, ((focus_hi_ + reach) >> level) + 1);
      if (glm::all(glm::lessThan(near_lo, near_hi))) lo = near_lo, hi = near_hi;
    }
    region.load(*world_, lo, hi, lo, lo, 1 << level);
  }

  const World* world_;
  int highest_;
  std::vector<Slot> slots_;
  size_t last_ = 0;
  uint64_t clock_ = 0;
  Region focus_;
  int focus_level_ = -1;
  glm::ivec3 focus_lo_{0}, focus_hi_{0};  // its closed box, level-0 nodes
};

// --- One cell's polygons, crossings and sheets -----------------------------------

struct CellCrossing {
  glm::ivec3 lower{0};  // level-0 node
  int axis = 0;
  int level = 0;        // the edge is 2^level long
  const EdgeCrossing* x = nullptr;
  int next = -1;        // the crossing after this one on its loop
  int sheet = -1;
};

struct Piece {
  int begin = 0, end = 0;      // its nodes in CellShape::nodes, counter-clockwise seen from outside the cell
  glm::ivec3 across_doubled;   // a point (half cells) inside the cell across the piece
};

struct CellShape {
  Cell cell;
  std::vector<glm::ivec3> nodes;
  std::vector<Piece> pieces;
  std::vector<uint8_t> in;           // per node
  std::vector<int> edge_crossing;    // per node: crossing of the edge to the piece's next node, or -1
  std::vector<CellCrossing> crossings;
  int sheets = 0;
};

// The finest level among the chunks whose closed boxes hold the segment from
// `a` along `axis` (its length divides the chunk size, so it lies in one
// chunk interval along `axis`).
int line_level(const LevelMap& levels, const glm::ivec3& a, int axis, int chunk_size) {
  const int shift = levels.chunk_shift();
  const glm::ivec3 base = a >> shift;
  int level = 99;
  const int u = axis_u(axis), v = axis_v(axis);
  const int du = (a[u] & (chunk_size - 1)) == 0 ? 2 : 1, dv = (a[v] & (chunk_size - 1)) == 0 ? 2 : 1;
  for (int i = 0; i < du; ++i)
    for (int j = 0; j < dv; ++j) {
      glm::ivec3 c = base;
      c[u] -= i;
      c[v] -= j;
      level = std::min(level, levels.at(c));
    }
  return level;
}

// Appends one piece: a square of side q at `corner` on face (axis, side),
// its sides cut at their lines' finest level (with `cut_sides`; otherwise
// its four corners only).
void add_piece(const LevelMap& levels, int chunk_size, int axis, int side, const glm::ivec3& corner, int q,
               bool cut_sides, CellShape& shape) {
  const int u = axis_u(axis), v = axis_v(axis);
  // Counter-clockwise seen from outside: u then v on the +axis face, v then u on the -axis face.
  const int first = side ? u : v, second = side ? v : u;
  glm::ivec3 corners[4] = {corner, corner, corner, corner};
  corners[1][first] += q;
  corners[2][first] += q;
  corners[2][second] += q;
  corners[3][second] += q;
  Piece piece;
  piece.begin = int(shape.nodes.size());
  for (int k = 0; k < 4; ++k) {
    const glm::ivec3 from = corners[k], to = corners[(k + 1) % 4];
    const int along = from[first] != to[first] ? first : second;
    const int sign = to[along] > from[along] ? 1 : -1;
    const int step = cut_sides ? std::min(q, 1 << line_level(levels, glm::min(from, to), along, chunk_size)) : q;
    for (int t = 0; t < q; t += step) {
      glm::ivec3 n = from;
      n[along] += sign * t;
      shape.nodes.push_back(n);
    }
  }
  piece.end = int(shape.nodes.size());
  glm::ivec3 centre2 = 2 * corner;
  centre2[u] += q;
  centre2[v] += q;
  centre2[axis] += side ? 1 : -1;
  piece.across_doubled = centre2;
  shape.pieces.push_back(piece);
}

// The cell's boundary as pieces: each face whole, or cut into the squares
// of a finer chunk across it.
// `plain`: no chunk touching the cell is finer, so every face is one square
// with its four corners (the common case, kept cheap).
void build_pieces(const LevelMap& levels, int chunk_size, const Cell& cell, bool plain, CellShape& shape) {
  shape.cell = cell;
  shape.nodes.clear();
  shape.pieces.clear();
  const int s = cell.size();
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      glm::ivec3 across2 = 2 * cell.lo + glm::ivec3(s);
      across2[axis] = side ? 2 * (cell.lo[axis] + s) + 1 : 2 * cell.lo[axis] - 1;
      const int q = plain ? s : std::min(s, 1 << levels.at(levels.chunk_of_doubled(across2)));
      const int u = axis_u(axis), v = axis_v(axis);
      for (int i = 0; i < s; i += q)
        for (int j = 0; j < s; j += q) {
          glm::ivec3 corner = cell.lo;
          corner[axis] += side * s;
          corner[u] += i;
          corner[v] += j;
          add_piece(levels, chunk_size, axis, side, corner, q, !plain, shape);
        }
    }
  }
}

int crossing_index(const CellShape& shape, const glm::ivec3& lower, int axis) {
  for (size_t i = 0; i < shape.crossings.size(); ++i)
    if (shape.crossings[i].lower == lower && shape.crossings[i].axis == axis) return int(i);
  return -1;
}

int find_or_add_crossing(CellShape& shape, const glm::ivec3& a, const glm::ivec3& b, LevelReader& reader) {
  const glm::ivec3 lower = glm::min(a, b);
  const glm::ivec3 d = glm::abs(b - a);
  const int axis = d.x ? 0 : d.y ? 1 : 2;
  if (const int i = crossing_index(shape, lower, axis); i >= 0) return i;
  CellCrossing c;
  c.lower = lower;
  c.axis = axis;
  c.level = std::countr_zero(unsigned(d[axis]));
  c.x = reader.crossing(lower, axis, c.level);
  shape.crossings.push_back(c);
  return int(shape.crossings.size()) - 1;
}

// Node signs and the crossings of the edges whose ends differ. False when the
// cell has none. A crossing with no point (the ends differ but the edge holds
// none: a box face cut through the solid) leaves the cell unmeshed.
bool read_crossings(LevelReader& reader, CellShape& shape) {
  shape.in.resize(shape.nodes.size());
  for (size_t i = 0; i < shape.nodes.size(); ++i) shape.in[i] = reader.inside(shape.nodes[i]);
  shape.edge_crossing.assign(shape.nodes.size(), -1);
  shape.crossings.clear();
  for (const Piece& p : shape.pieces) {
    for (int i = p.begin; i < p.end; ++i) {
      const int j = i + 1 < p.end ? i + 1 : p.begin;
      if (shape.in[size_t(i)] == shape.in[size_t(j)]) continue;
      shape.edge_crossing[size_t(i)] = find_or_add_crossing(shape, shape.nodes[size_t(i)], shape.nodes[size_t(j)], reader);
    }
  }
  for (const CellCrossing& c : shape.crossings)
    if (!c.x) return false;
  return !shape.crossings.empty();
}

// Pairs the crossings of each piece into segments (each run of inside nodes
// cut off by one; on a joined piece each run of outside nodes instead) and
// follows them into loops: shape.sheets loops, crossings[].sheet.
void trace_sheets(CellShape& shape, const std::vector<uint8_t>& joined) {
  for (CellCrossing& c : shape.crossings) c.next = c.sheet = -1;
  for (size_t pi = 0; pi < shape.pieces.size(); ++pi) {
    const Piece& p = shape.pieces[pi];
    const int n = p.end - p.begin;
    auto in = [&](int k) { return shape.in[size_t(p.begin + ((k % n) + n) % n)] != 0; };
    auto crossing = [&](int k) { return shape.edge_crossing[size_t(p.begin + ((k % n) + n) % n)]; };
    for (int k = 0; k < n; ++k) {
      if (in(k) || !in(k + 1)) continue;  // entering the inside run at edge k
      int j = k + 1;
      if (joined[pi]) {
        j = k;
        while (!in(j - 1)) --j;
        shape.crossings[size_t(crossing(k))].next = crossing(j - 1);
      } else {
        while (in(j + 1)) ++j;
        shape.crossings[size_t(crossing(k))].next = crossing(j);
      }
    }
  }
  shape.sheets = 0;
  for (CellCrossing& start : shape.crossings) {
    if (start.sheet >= 0) continue;
    for (CellCrossing* c = &start; c->sheet < 0; c = &shape.crossings[size_t(c->next)]) c->sheet = shape.sheets;
    ++shape.sheets;
  }
}

// The entering crossings of a piece (one per segment).
void piece_segments(const CellShape& shape, const Piece& p, std::vector<int>& out) {
  out.clear();
  const int n = p.end - p.begin;
  for (int k = 0; k < n; ++k) {
    const size_t i = size_t(p.begin + k), j = size_t(p.begin + (k + 1) % n);
    if (!shape.in[i] && shape.in[j]) out.push_back(shape.edge_crossing[i]);
  }
}

// Whether two segments of piece `pi` lie on one loop of `shape` and on one
// loop of the cell across, `other` (default rule both): their two vertices
// would share two mesh edges, so the piece is joined from both sides instead.
bool piece_links_twice(const CellShape& shape, size_t pi, CellShape& other, std::vector<int>& scratch) {
  piece_segments(shape, shape.pieces[pi], scratch);
  for (size_t a = 0; a < scratch.size(); ++a)
    for (size_t b = a + 1; b < scratch.size(); ++b) {
      const CellCrossing& ca = shape.crossings[size_t(scratch[a])];
      const CellCrossing& cb = shape.crossings[size_t(scratch[b])];
      if (ca.sheet != cb.sheet) continue;
      const int oa = crossing_index(other, ca.lower, ca.axis), ob = crossing_index(other, cb.lower, cb.axis);
      if (oa >= 0 && ob >= 0 && other.crossings[size_t(oa)].sheet == other.crossings[size_t(ob)].sheet) return true;
    }
  return false;
}

// --- Per chunk ---------------------------------------------------------------

struct LevelVertex {
  glm::dvec3 x{0.0};  // level-0 lattice coordinates
  glm::vec3 normal{0.0f};
  uint16_t material = 0;
  glm::ivec3 cell_lo{0};
  uint8_t sheet = 0;
  uint8_t level = 0;  // the cell is 2^level lattice cells wide
  Qef qef;            // level-0 units, about cell_lo
};

struct OwnedEdge {
  glm::ivec3 lower{0};
  int axis = 0;
  int level = 0;
  bool lower_inside = false;
  uint16_t material = 0;
};

struct ChunkPart {
  std::vector<LevelVertex> vertices;
  std::vector<std::pair<uint32_t, uint32_t>> keys;  // (edge and quadrant, vertex), sorted
  std::vector<OwnedEdge> edges;
  size_t first_vertex = 0;
  size_t cells = 0;
};

// Quadrant q of the edge (lower, axis, 2^level) as a point in half cells:
// counter-clockwise about +axis from (-u, -v).
glm::ivec3 quadrant_point(const glm::ivec3& lower, int axis, int level, int q) {
  static constexpr int kU[4] = {-1, 1, 1, -1}, kV[4] = {-1, -1, 1, 1};
  glm::ivec3 p = 2 * lower;
  p[axis] += 1 << level;
  p[axis_u(axis)] += kU[q];
  p[axis_v(axis)] += kV[q];
  return p;
}

uint32_t quadrant_key(const glm::ivec3& lower, int axis, int q, const glm::ivec3& chunk, int chunk_size) {
  const glm::ivec3 r = lower - chunk * chunk_size;  // 0 .. C: the edge lies on a cell of the chunk
  return uint32_t(r.x) | uint32_t(r.y) << 7 | uint32_t(r.z) << 14 | uint32_t(axis) << 21 | uint32_t(q) << 23;
}

class ChunkMesher {
 public:
  ChunkMesher(const LevelMap* levels, const World* world, const ContourConfig* config)
      : levels_(levels), reader_(world, levels->highest()), chunk_size_(world->chunk_size()), config_(config) {}
  // Meshes with other levels, world or config next, keeping the buffers.
  void rebind(const LevelMap* levels, const World* world, const ContourConfig* config) {
    levels_ = levels;
    reader_.rebind(world, levels->highest());
    chunk_size_ = world->chunk_size();
    config_ = config;
  }

  void mesh(const glm::ivec3& chunk, ChunkPart& out) {
    out = ChunkPart();
    chunk_ = chunk;
    finer_neighbour_ = has_finer_neighbour(chunk, levels_->at(chunk));
    const std::vector<Cell> cells = candidate_cells(chunk);
    // About a vertex, an owned edge and five quadrant keys per cell: growing
    // these by doubling cost a tenth of a level-0 chunk in copies and page faults.
    out.vertices.reserve(cells.size());
    out.edges.reserve(cells.size());
    out.keys.reserve(6 * cells.size());
    for (const Cell& cell : cells) mesh_cell(cell, true, out);
    std::sort(out.keys.begin(), out.keys.end());
  }

  // The vertices of one cell (any chunk's) appended to out, with its keys;
  // with emit_edges, also the crossing edges it emits.
  void mesh_cell(const Cell& cell, bool emit_edges, ChunkPart& out) {
    if (!default_sheets(cell, shape_)) return;
    std::vector<uint8_t>& joined = joined_;
    joined.assign(shape_.pieces.size(), 0);
    bool any_joined = false;
    for (size_t pi = 0; pi < shape_.pieces.size(); ++pi) {
      piece_segments(shape_, shape_.pieces[pi], segments_);
      if (segments_.size() < 2) continue;
      const Cell across = cell_at_doubled(*levels_, shape_.pieces[pi].across_doubled);
      if (!default_sheets(across, other_)) continue;
      if (piece_links_twice(shape_, pi, other_, segments_)) joined[pi] = any_joined = 1;
    }
    if (any_joined) trace_sheets(shape_, joined);
    ++out.cells;
    const uint32_t first = uint32_t(out.vertices.size());
    sheet_mass_.resize(size_t(shape_.sheets));
    for (int sheet = 0; sheet < shape_.sheets; ++sheet) out.vertices.push_back(place(sheet));
    if (shape_.sheets > 1) {
      for (int sheet = 0; sheet < shape_.sheets; ++sheet) {
        glm::dvec3& x = out.vertices[first + uint32_t(sheet)].x;
        x = detail::keep_to_own_sheet(x, sheet, sheet_mass_.data(), shape_.sheets);
      }
    }
    record_edges(first, emit_edges, out);
  }


 private:
  // Cells of the chunk next to a crossing edge of its own level, and its
  // border cells when a neighbour is finer (their cut faces may hold more).
  std::vector<Cell> candidate_cells(const glm::ivec3& chunk) {
    const int level = levels_->at(chunk), s = 1 << level, n = chunk_size_ >> level;
    std::vector<uint8_t> mark(size_t(n) * size_t(n) * size_t(n), 0);
    auto mark_cell = [&](const glm::ivec3& c) {  // c in level-`level` cells, relative to the chunk
      if (detail::in_box(c, glm::ivec3(0), glm::ivec3(n)))
        mark[(size_t(c.z) * size_t(n) + size_t(c.y)) * size_t(n) + size_t(c.x)] = 1;
    };
    for (const Region::EdgeRef& e : reader_.focus(level, chunk).crossing_edges()) {
      const glm::ivec3 r = e.node - chunk * n;
      const glm::ivec3 eu = axis_unit(axis_u(e.axis)), ev = axis_unit(axis_v(e.axis));
      mark_cell(r);
      mark_cell(r - eu);
      mark_cell(r - ev);
      mark_cell(r - eu - ev);
    }
    if (finer_neighbour_) {  // the cells touching a finer chunk: its cut faces may hold more
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const glm::ivec3 d(dx, dy, dz);
            if (d == glm::ivec3(0) || levels_->at(chunk + d) >= level) continue;
            glm::ivec3 lo(0), hi(n - 1);  // the layer, line or corner of cells beside that neighbour
            for (int k = 0; k < 3; ++k)
              if (d[k] != 0) lo[k] = hi[k] = d[k] < 0 ? 0 : n - 1;
            for (int z = lo.z; z <= hi.z; ++z)
              for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x) mark_cell({x, y, z});
          }
    }
    std::vector<Cell> cells;
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
          if (mark[(size_t(z) * size_t(n) + size_t(y)) * size_t(n) + size_t(x)])
            cells.push_back({chunk * chunk_size_ + glm::ivec3(x, y, z) * s, level});
    return cells;
  }

  // The finest level among the chunks whose closed boxes the cell's closed
  // box touches: its own, and across each chunk face, edge or corner it lies
  // on (the cell's own level inside a chunk whose neighbours are no finer).
  // The cell is plain when no touching chunk is finer than it; otherwise
  // every node the pieces' way reads lies on its boundary at a multiple of
  // 2^that level.
  int finest_touching_level(const Cell& cell) const {
    const glm::ivec3 chunk = cell.lo >> levels_->chunk_shift();
    if (chunk == chunk_ && !finer_neighbour_) return cell.level;
    const glm::ivec3 r = cell.lo - chunk * chunk_size_;
    glm::ivec3 lo(0), hi(0);
    for (int k = 0; k < 3; ++k) {
      lo[k] = r[k] == 0 ? -1 : 0;
      hi[k] = r[k] + cell.size() == chunk_size_ ? 1 : 0;
    }
    int level = levels_->at(chunk);
    for (int dz = lo.z; dz <= hi.z; ++dz)
      for (int dy = lo.y; dy <= hi.y; ++dy)
        for (int dx = lo.x; dx <= hi.x; ++dx) level = std::min(level, levels_->at(chunk + glm::ivec3(dx, dy, dz)));
    return level;
  }

  // Whether every node on the cell's boundary at that finest spacing is on
  // one side: then no edge the pieces' way would read changes sign and the
  // cell has no crossing. Most cells beside a finer chunk are such (the
  // whole layer is a candidate; on a bunny-and-sphere union at 256 cells 95%
  // of them were empty), and this reads their nodes without building pieces.
  bool boundary_on_one_side(const Cell& cell, int finest) {
    const int s = cell.size(), step = 1 << finest;
    const bool first = reader_.inside(cell.lo);
    for (int z = 0; z <= s; z += step)
      for (int y = 0; y <= s; y += step) {
        const bool face = z == 0 || z == s || y == 0 || y == s;
        for (int x = 0; x <= s; x += face ? step : s)  // inside the cube: only x = 0 and x = s
          if (reader_.inside(cell.lo + glm::ivec3(x, y, z)) != first) return false;
      }
    return true;
  }

  bool has_finer_neighbour(const glm::ivec3& chunk, int level) const {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (levels_->at(chunk + glm::ivec3(dx, dy, dz)) < level) return true;
    return false;
  }

  // The cell's sheets under the default rule; false when it has no crossing.
  bool default_sheets(const Cell& cell, CellShape& shape) {
    const int finest = finest_touching_level(cell);
    const bool plain = finest >= cell.level;
    if (plain) {
      if (const int found = plain_sheets(cell, shape); found >= 0) return found == 1;
    } else if (boundary_on_one_side(cell, finest)) {
      return false;
    }
    build_pieces(*levels_, chunk_size_, cell, plain, shape);
    if (!read_crossings(reader_, shape)) return false;
    no_joins_.assign(shape.pieces.size(), 0);
    trace_sheets(shape, no_joins_);
    return true;
  }


  // A plain cell's sheets (six whole faces, as in the uniform mesher) from
  // the uniform mesher's table: 8 corner reads and 12 edges, where the
  // pieces' way reads 24 nodes and traces their loops (that way costs a
  // level-0 chunk about 2.5 times contour_world's). 1: sheets found; 0: no
  // crossing, or an edge with none to read (as read_crossings); -1: a face
  // has both its segments on one sheet, so the cell across may ask for a
  // join, which the pieces' way decides.
  int plain_sheets(const Cell& cell, CellShape& shape) {
    const int s = cell.size();
    unsigned inside = 0;
    for (int c = 0; c < 8; ++c)
      if (reader_.inside(cell.lo + s * glm::ivec3(c & 1, (c >> 1) & 1, c >> 2))) inside |= 1u << c;
    if (inside == 0 || inside == 255) return 0;
    for (int face = 0; face < 6; ++face)
      if (detail::face_links_both_segments(inside, face)) return -1;
    const detail::CellSheets& table = detail::cell_sheets(inside);
    shape.cell = cell;
    shape.nodes.clear();
    shape.pieces.clear();
    shape.crossings.clear();
    for (int slot = 0; slot < 12; ++slot) {
      if (table.sheet_of_edge[slot] < 0) continue;
      CellCrossing c;
      c.axis = detail::cell_edge_axis(slot);
      c.lower = cell.lo + s * detail::cell_edge_offset(slot);
      c.level = cell.level;
      c.x = reader_.crossing(c.lower, c.axis, c.level);
      if (!c.x) return 0;
      c.sheet = table.sheet_of_edge[slot];
      shape.crossings.push_back(c);
    }
    shape.sheets = table.count;
    return 1;
  }

  LevelVertex place(int sheet) {
    const Cell& cell = shape_.cell;
    const double s = cell.size();
    std::vector<const CellCrossing*>& on_loop = on_loop_;
    on_loop.clear();
    for (const CellCrossing& c : shape_.crossings)
      if (c.sheet == sheet) on_loop.push_back(&c);
    CellPlanes unit_planes, planes;  // in cell units (placement), in lattice cells about cell.lo (quad split)
    const size_t n = on_loop.size(), kept = std::min<size_t>(n, 12);
    for (size_t i = 0; i < kept; ++i) {  // at most 12 planes: evenly spread over the loop
      const CellCrossing& c = *on_loop[i * n / kept];
      glm::dvec3 p = glm::dvec3(c.lower - cell.lo);
      p[c.axis] += double(c.x->t) * double(1 << c.level);
      unit_planes.add(p / s, glm::dvec3(c.x->normal), c.x->material, c.axis);
      planes.add(p, glm::dvec3(c.x->normal), c.x->material, c.axis);
    }
    LevelVertex v;
    const Qef unit_qef = Qef::of(unit_planes);
    v.x = glm::dvec3(cell.lo) + s * detail::place_vertex(unit_planes, unit_qef, *config_).position;
    sheet_mass_[size_t(sheet)] = glm::dvec3(cell.lo) + s * unit_planes.mass_point();
    v.normal = planes.mean_normal();
    v.material = planes.majority_material();
    v.cell_lo = cell.lo;
    v.level = uint8_t(cell.level);
    v.sheet = uint8_t(sheet);
    v.qef = Qef::of(planes);
    return v;
  }

  // Keys (about the cell's chunk) for every quadrant the cell fills around
  // each of its crossing edges; with emit_edges, the edges whose (+u, +v)
  // quadrant it fills, which its chunk emits.
  void record_edges(uint32_t first_vertex, bool emit_edges, ChunkPart& out) {
    const Cell& cell = shape_.cell;
    const glm::ivec3 chunk = cell.lo >> levels_->chunk_shift();
    const glm::ivec3 lo2 = 2 * cell.lo, hi2 = 2 * (cell.lo + cell.size());
    for (const CellCrossing& c : shape_.crossings) {
      for (int q = 0; q < 4; ++q) {
        const glm::ivec3 p = quadrant_point(c.lower, c.axis, c.level, q);
        if (!detail::in_box(p, lo2 + 1, hi2)) continue;
        out.keys.emplace_back(quadrant_key(c.lower, c.axis, q, chunk, chunk_size_), first_vertex + uint32_t(c.sheet));
        if (q == 2 && emit_edges) out.edges.push_back({c.lower, c.axis, c.level, reader_.inside(c.lower), c.x->material});
      }
    }
  }

  const LevelMap* levels_;
  LevelReader reader_;
  int chunk_size_;
  const ContourConfig* config_;
  glm::ivec3 chunk_{0};
  bool finer_neighbour_ = false;  // of chunk_
  CellShape shape_, other_;
  std::vector<uint8_t> no_joins_, joined_;
  std::vector<int> segments_;
  std::vector<const CellCrossing*> on_loop_;
  std::vector<glm::dvec3> sheet_mass_;  // place(): each sheet's mass point, level-0 lattice coordinates
};

// --- Polygons and assembly -----------------------------------------------------

struct PolygonVertex {
  uint32_t index;
  const LevelVertex* v;
};

// Triangles of a quad around an edge 2^e.level long: the uniform mesher's
// rule (detail::split_along_02: a diagonal that folds no triangle over, then
// the one whose midpoint fits the Hermite planes of its two end cells best,
// then the shorter), except across two cells both wider
// than the edge. Those meet along a line cut into several edges (a coarse
// line beside a finer chunk), and the quads of the next edges on it have
// the same two cells as opposite corners: where two such edges cross, one
// diagonal in both would give an edge of four triangles (found on two
// turned boxes' union, a sheet of the third cell looping over those two
// edges alone). The other diagonal holds a cell as wide as the edge (the
// finest chunk around the line has one there), so it lies in this quad only.
bool split_along_02(const PolygonVertex p[4], const OwnedEdge& e) {
  const int edge_level = e.level;
  auto wider = [&](int i) { return p[i].v->level > edge_level; };
  if (wider(0) && wider(2)) return false;
  if (wider(1) && wider(3)) return true;
  const glm::dvec3 m02 = 0.5 * (p[0].v->x + p[2].v->x), m13 = 0.5 * (p[1].v->x + p[3].v->x);
  auto err = [&](int i, const glm::dvec3& m) { return p[i].v->qef.error(m - glm::dvec3(p[i].v->cell_lo)); };
  const glm::dvec3 corners[4] = {p[0].v->x, p[1].v->x, p[2].v->x, p[3].v->x};
  glm::dvec3 facing(0.0);
  facing[e.axis] = e.lower_inside ? 1.0 : -1.0;
  return detail::split_along_02(err(0, m02) + err(2, m02), err(1, m13) + err(3, m13), corners, facing);
}

// The triangles of one crossing edge, its cells' vertices found by
// lookup(e, quadrant, PolygonVertex&); false when a cell around it has no
// vertex (not expected).
template <class Lookup>
bool emit_polygon(const OwnedEdge& e, Lookup&& lookup, std::vector<glm::uvec3>& tris, std::vector<uint16_t>& mats) {
  PolygonVertex ring[4];
  int n = 0;
  for (int k = 0; k < 4; ++k) {
    const int q = e.lower_inside ? k : 3 - k;  // counter-clockwise seen from outside the solid
    PolygonVertex pv;
    if (!lookup(e, q, pv)) return false;
    if (n > 0 && ring[n - 1].index == pv.index) continue;
    ring[n++] = pv;
  }
  if (n > 1 && ring[n - 1].index == ring[0].index) --n;
  if (n < 3) return false;
  if (n == 3) {
    tris.emplace_back(ring[0].index, ring[1].index, ring[2].index);
    mats.push_back(e.material);
  } else if (split_along_02(ring, e)) {
    tris.emplace_back(ring[0].index, ring[1].index, ring[2].index);
    tris.emplace_back(ring[0].index, ring[2].index, ring[3].index);
    mats.insert(mats.end(), 2, e.material);
  } else {
    tris.emplace_back(ring[0].index, ring[1].index, ring[3].index);
    tris.emplace_back(ring[1].index, ring[2].index, ring[3].index);
    mats.insert(mats.end(), 2, e.material);
  }
  return true;
}

// The vertex of `part` (its keys sorted) filling quadrant q of the edge, chunk `chunk`'s.
bool find_in_part(const ChunkPart& part, const OwnedEdge& e, int q, const glm::ivec3& chunk, int chunk_size,
                  PolygonVertex& out) {
  const uint32_t key = quadrant_key(e.lower, e.axis, q, chunk, chunk_size);
  auto it = std::lower_bound(part.keys.begin(), part.keys.end(), std::make_pair(key, uint32_t{0}));
  if (it == part.keys.end() || it->first != key) return false;
  out.index = uint32_t(part.first_vertex + it->second);
  out.v = &part.vertices[it->second];
  return true;
}

// Vertices for the whole world's polygons: every chunk's part, meshed first.
class WorldParts {
 public:
  WorldParts(const LevelMap& levels, const std::vector<ChunkPart>& parts, const glm::ivec3& first_chunk,
             const glm::ivec3& chunk_dims, int chunk_size)
      : levels_(levels), parts_(parts), first_(first_chunk), dims_(chunk_dims), chunk_size_(chunk_size) {}

  bool operator()(const OwnedEdge& e, int q, PolygonVertex& out) const {
    const glm::ivec3 chunk = levels_.chunk_of_doubled(quadrant_point(e.lower, e.axis, e.level, q));
    const glm::ivec3 r = chunk - first_;
    if (glm::any(glm::lessThan(r, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(r, dims_))) return false;
    const ChunkPart& part = parts_[(size_t(r.z) * size_t(dims_.y) + size_t(r.y)) * size_t(dims_.x) + size_t(r.x)];
    return find_in_part(part, e, q, chunk, chunk_size_, out);
  }

 private:
  const LevelMap& levels_;
  const std::vector<ChunkPart>& parts_;
  glm::ivec3 first_, dims_;
  int chunk_size_;
};

// Vertices for one chunk's polygons: its own part's, then cells of the
// neighbouring chunks meshed on first use and numbered after the chunk's own
// vertices as polygons use them (kept in a deque: polygons hold pointers).
class ChunkAndNeighbours {
 public:
  ChunkAndNeighbours(ChunkMesher& mesher, const LevelMap& levels, const ChunkPart& own, const glm::ivec3& chunk,
                     int chunk_size)
      : mesher_(mesher), levels_(levels), own_(own), chunk_(chunk), chunk_size_(chunk_size) {}

  bool operator()(const OwnedEdge& e, int q, PolygonVertex& out) {
    const glm::ivec3 p = quadrant_point(e.lower, e.axis, e.level, q);
    const glm::ivec3 chunk = levels_.chunk_of_doubled(p);
    if (chunk == chunk_) return find_in_part(own_, e, q, chunk, chunk_size_, out);
    const Cell cell = cell_at_doubled(levels_, p);
    auto [it, fresh] = cells_.try_emplace(std::make_tuple(cell.lo.x, cell.lo.y, cell.lo.z), KeyRange{});
    if (fresh) it->second = mesh_foreign(cell);
    const uint32_t key = quadrant_key(e.lower, e.axis, q, chunk, chunk_size_);
    for (size_t k = it->second.begin; k < it->second.end; ++k) {
      if (keys_[k].first != key) continue;
      const uint32_t v = keys_[k].second;
      if (index_[v] < 0) {
        index_[v] = int32_t(own_.vertices.size() + used_.size());
        used_.push_back(v);
      }
      out.index = uint32_t(index_[v]);
      out.v = &vertices_[v];
      return true;
    }
    return false;
  }
  // The neighbours' vertices the polygons used, in their numbering's order.
  std::vector<const LevelVertex*> used() const {
    std::vector<const LevelVertex*> out;
    for (uint32_t v : used_) out.push_back(&vertices_[v]);
    return out;
  }

 private:
  struct KeyRange {
    size_t begin = 0, end = 0;
  };
  KeyRange mesh_foreign(const Cell& cell) {
    scratch_ = ChunkPart();
    mesher_.mesh_cell(cell, false, scratch_);
    const uint32_t base = uint32_t(vertices_.size());
    vertices_.insert(vertices_.end(), scratch_.vertices.begin(), scratch_.vertices.end());
    index_.resize(vertices_.size(), -1);
    KeyRange r{keys_.size(), keys_.size() + scratch_.keys.size()};
    for (const auto& [key, v] : scratch_.keys) keys_.emplace_back(key, base + v);
    return r;
  }

  ChunkMesher& mesher_;
  const LevelMap& levels_;
  const ChunkPart& own_;
  glm::ivec3 chunk_;
  int chunk_size_;
  std::map<std::tuple<int, int, int>, KeyRange> cells_;
  std::deque<LevelVertex> vertices_;
  std::vector<std::pair<uint32_t, uint32_t>> keys_;
  std::vector<int32_t> index_;  // per vertex: its number in the chunk mesh, -1 until used
  std::vector<uint32_t> used_;
  ChunkPart scratch_;
};

// The parts' vertices (numbered from their first_vertex) and triangles in
// one mesh, filled in parallel at each part's offsets.
ContourMesh assemble(const World& world, const std::vector<ChunkPart>& parts,
                     const std::vector<std::vector<glm::uvec3>>& tris,
                     const std::vector<std::vector<uint16_t>>& mats) {
  std::vector<size_t> first_triangle(parts.size() + 1, 0);
  for (size_t i = 0; i < parts.size(); ++i) first_triangle[i + 1] = first_triangle[i] + tris[i].size();
  const size_t vertices = parts.empty() ? 0 : parts.back().first_vertex + parts.back().vertices.size();
  ContourMesh mesh;
  mesh.positions.resize(vertices);
  mesh.normals.resize(vertices);
  mesh.vertex_material.resize(vertices);
  mesh.triangles.resize(first_triangle.back());
  mesh.triangle_material.resize(first_triangle.back());
  const Lattice& lattice = world.lattice();
  tbb::parallel_for(size_t{0}, parts.size(), [&](size_t i) {
    size_t k = parts[i].first_vertex;
    for (const LevelVertex& v : parts[i].vertices) {
      mesh.positions[k] = lattice.to_world(v.x);
      mesh.normals[k] = v.normal;
      mesh.vertex_material[k++] = v.material;
    }
    std::copy(tris[i].begin(), tris[i].end(), mesh.triangles.begin() + std::ptrdiff_t(first_triangle[i]));
    std::copy(mats[i].begin(), mats[i].end(), mesh.triangle_material.begin() + std::ptrdiff_t(first_triangle[i]));
  });
  return mesh;
}

// How far, in chunks, one chunk's mesh reaches. It meshes its own cells,
// the cells of neighbouring chunks that its polygons use (each shares an edge
// with one of its cells), and the cells across their faces (conflict
// checks): all within two cells of the chunk, and a cell is at most C / 8
// wide, so their nodes and the chunks touching them lie in the chunk's 26
// neighbours. (The plain-cell shortcut looks one chunk further, but only
// chooses between two ways to the same shape.)
constexpr int kLevelMapReach = 2;

// The chunks contour_levels meshes: the world's and the layer below its box.
bool chunk_is_meshable(const World& world, const glm::ivec3& chunk) {
  const glm::ivec3 lo = world.chunk_origin() - 1, hi = world.chunk_origin() + world.chunk_dims();
  return glm::all(glm::greaterThanEqual(chunk, lo)) && glm::all(glm::lessThan(chunk, hi));
}

Result<ContourMesh> mesh_levels(const World& world, const LevelMap& levels, const ContourConfig& config,
                                Context* ctx, ContourStats& stats) {
  // The world's chunks and the layer below the box, x fastest (WorldParts indexes them so).
  const std::vector<glm::ivec3> chunks = chunks_to_mesh(world);
  const glm::ivec3 first = world.chunk_origin() - 1, dims = world.chunk_dims() + 1;
  const size_t count = chunks.size();
  std::vector<ChunkPart> parts(count);
  tbb::enumerable_thread_specific<ChunkMesher> meshers([&] { return ChunkMesher(&levels, &world, &config); });
  std::atomic<size_t> done{0};
  tbb::parallel_for(size_t{0}, count, [&](size_t i) {
    if (ctx && ctx->cancelled()) return;
    meshers.local().mesh(chunks[i], parts[i]);
    const size_t n = done.fetch_add(1) + 1;
    if (ctx && n % 16 == 0) ctx->report_progress("contour levels", double(n) / double(2 * count));
  });
  if (ctx && ctx->cancelled()) return Status(ErrorCode::kCancelled, "contour_levels: cancelled");
  size_t vertices = 0;
  for (ChunkPart& p : parts) {
    p.first_vertex = vertices;
    vertices += p.vertices.size();
    stats.cells += p.cells;
    stats.chunks_meshed += p.cells > 0;
  }
  if (vertices > size_t(UINT32_MAX)) return Status(ErrorCode::kTooLarge, "contour_levels: over 2^32 vertices");
  const WorldParts lookup(levels, parts, first, dims, world.chunk_size());
  std::vector<std::vector<glm::uvec3>> tris(count);
  std::vector<std::vector<uint16_t>> mats(count);
  std::atomic<size_t> missing{0};
  tbb::parallel_for(size_t{0}, count, [&](size_t i) {
    for (const OwnedEdge& e : parts[i].edges)
      if (!emit_polygon(e, lookup, tris[i], mats[i])) missing.fetch_add(1);
  });
  if (missing.load() > 0) {
    return Status(ErrorCode::kInternal, "contour_levels: " + std::to_string(missing.load()) +
                                            " crossing edges found no vertex in a cell around them");
  }
  for (const ChunkPart& p : parts) stats.quads += p.edges.size();
  return assemble(world, parts, tris, mats);
}

}  // namespace

Result<ContourMesh> contour_levels(const World& world, const std::function<int(const glm::ivec3&)>& level_of_chunk,
                                   const ContourConfig& config, Context* ctx, ContourStats* stats) {
  Status s = check_contour_config(config);
  if (!s.ok()) return s;
  if (!level_of_chunk) return Status(ErrorCode::kInvalidArgument, "contour_levels: no level function");
  if (s = check_box_faces_outside(world); !s.ok()) return s;
  try {
    ScopedTimer timer(ctx, "contour_levels");
    LevelMap levels;
    if (s = levels.build(world, level_of_chunk); !s.ok()) return s;
    ContourStats local;
    Result<ContourMesh> mesh = mesh_levels(world, levels, config, ctx, local);
    if (!mesh.ok()) return mesh.status();
    if (config.untangle) {
      Result<UntangleMeshStats> u = untangle_mesh(mesh.value(), {}, ctx);
      if (!u.ok()) return u.status();
      local.untangled_vertices = u.value().vertices_moved;
    }
    local.seconds = timer.seconds();
    if (stats) *stats = local;
    return mesh;
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, "contour_levels: out of memory");
  }
}

namespace {

// The thread's mesher for contour_chunk_levels, kept between calls: its
// regions' buffers are allocated once (allocating them was most of a small
// chunk's cost).
ChunkMesher& thread_mesher(const LevelMap& levels, const World& world, const ContourConfig& config) {
  thread_local std::unique_ptr<ChunkMesher> kept;
  if (kept) kept->rebind(&levels, &world, &config);
  else kept = std::make_unique<ChunkMesher>(&levels, &world, &config);
  return *kept;
}

// One chunk's mesh: its polygons, its own vertices, then its neighbours' it uses.
Result<ChunkMesh> chunk_mesh(const World& world, const glm::ivec3& chunk, ChunkMesher& mesher, const LevelMap& levels,
                             ContourStats* stats) {
  ChunkPart own;
  mesher.mesh(chunk, own);
  ChunkAndNeighbours lookup(mesher, levels, own, chunk, world.chunk_size());
  ChunkMesh out;
  out.chunk = chunk;
  size_t missing = 0;
  for (const OwnedEdge& e : own.edges)
    if (!emit_polygon(e, lookup, out.mesh.triangles, out.mesh.triangle_material)) ++missing;
  if (missing > 0) {
    return Status(ErrorCode::kInternal, "contour_chunk_levels: " + std::to_string(missing) +
                                            " crossing edges found no vertex in a cell around them");
  }
  out.own_vertices = own.vertices.size();
  auto add = [&](const LevelVertex& v) {
    out.mesh.positions.push_back(world.lattice().to_world(v.x));
    out.mesh.normals.push_back(v.normal);
    out.mesh.vertex_material.push_back(v.material);
    out.vertex_cell.push_back(v.cell_lo);
    out.vertex_sheet.push_back(v.sheet);
  };
  for (const LevelVertex& v : own.vertices) add(v);
  for (const LevelVertex* v : lookup.used()) add(*v);
  if (stats) {
    *stats = ContourStats();
    stats->cells = own.cells;
    stats->quads = own.edges.size();
    stats->chunks_meshed = 1;
  }
  return out;
}

}  // namespace

Result<ChunkMesh> contour_chunk_levels(const World& world, const glm::ivec3& chunk,
                                       const std::function<int(const glm::ivec3&)>& level_of_chunk,
                                       const ContourConfig& config, ContourStats* stats) {
  Status s = check_contour_config(config);
  if (!s.ok()) return s;
  if (!level_of_chunk) return Status(ErrorCode::kInvalidArgument, "contour_chunk_levels: no level function");
  if (!chunk_is_meshable(world, chunk)) {
    return Status(ErrorCode::kInvalidArgument, "contour_chunk_levels: chunk (" + std::to_string(chunk.x) + ", " +
                                                   std::to_string(chunk.y) + ", " + std::to_string(chunk.z) +
                                                   ") is outside the world's box and the layer below it");
  }
  // What the chunk's mesh reads lies within two of its cells (at most C / 4) of it.
  const int c = world.chunk_size(), reach = c / 4 + 1;
  if (s = check_box_faces_outside(world, chunk * c - reach, (chunk + 1) * c + reach + 1); !s.ok()) return s;
  try {
    ScopedTimer timer(nullptr, "contour_chunk_levels");
    LevelMap levels;
    if (s = levels.build(world, level_of_chunk, chunk - kLevelMapReach, chunk + kLevelMapReach + 1); !s.ok()) return s;
    Result<ChunkMesh> out = chunk_mesh(world, chunk, thread_mesher(levels, world, config), levels, stats);
    if (stats) stats->seconds = timer.seconds();
    return out;
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, "contour_chunk_levels: out of memory");
  }
}

}  // namespace ldc

// --- LevelChunkedMesh ----------------------------------------------------------

namespace ldc {
namespace {

using LevelOf = LevelChunkedMesh::LevelOf;

struct ChunkOrder {
  bool operator()(const glm::ivec3& a, const glm::ivec3& b) const { return chunk_order_less(a, b); }
};

bool same_mesh(const ChunkMesh& a, const ChunkMesh& b) {
  return a.mesh.positions == b.mesh.positions && a.mesh.triangles == b.mesh.triangles &&
         a.mesh.triangle_material == b.mesh.triangle_material && a.mesh.vertex_material == b.mesh.vertex_material;
}

size_t box_index(const glm::ivec3& origin, const glm::ivec3& dims, const glm::ivec3& chunk) {
  const glm::ivec3 r = glm::clamp(chunk, origin, origin + dims - 1) - origin;
  return (size_t(r.z) * size_t(dims.y) + size_t(r.y)) * size_t(dims.x) + size_t(r.x);
}

}  // namespace

Result<std::vector<int8_t>> LevelChunkedMesh::levels_of(const World& world, const LevelOf& level_of) const {
  if (!level_of) return Status(ErrorCode::kInvalidArgument, "LevelChunkedMesh: no level function");
  LevelMap map;
  if (Status s = map.build(world, level_of); !s.ok()) return s;
  std::vector<int8_t> out;
  world.for_each_chunk([&](const glm::ivec3& c, ChunkKind, const Chunk*) { out.push_back(int8_t(map.at(c))); });
  return out;
}

Status LevelChunkedMesh::mesh_chunks(const World& world, const std::vector<glm::ivec3>& chunks,
                                     const std::vector<int8_t>& levels, std::vector<ChunkMesh>& out,
                                     Context* ctx) const {
  const glm::ivec3 origin = world.chunk_origin(), dims = world.chunk_dims();
  auto level_of = [&](const glm::ivec3& c) { return int(levels[box_index(origin, dims, c)]); };
  out.assign(chunks.size(), ChunkMesh());
  std::mutex mutex;
  Status first_error;
  std::atomic<size_t> done{0};
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t i) {
    if (ctx && ctx->cancelled()) return;
    out[i].chunk = chunks[i];
    if (chunk_is_quiet(world, chunks[i])) return;
    Result<ChunkMesh> m = contour_chunk_levels(world, chunks[i], level_of, config_);
    if (m.ok()) {
      out[i] = std::move(m).value();
    } else {
      std::lock_guard<std::mutex> lock(mutex);
      if (first_error.ok()) first_error = m.status();
    }
    const size_t n = done.fetch_add(1) + 1;
    if (ctx && n % 16 == 0) ctx->report_progress("contour levels", double(n) / double(chunks.size()));
  });
  if (ctx && ctx->cancelled()) return Status(ErrorCode::kCancelled, "LevelChunkedMesh: cancelled");
  return first_error;
}

Status LevelChunkedMesh::build(const World& world, const LevelOf& level_of, Context* ctx) {
  Result<MeshUpdate> u = update(world, {}, level_of, ctx);  // box_ differs from a built one's: a whole build
  if (!u.ok()) return u.status();
  return {};
}

Result<MeshUpdate> LevelChunkedMesh::update(const World& world, std::span<const glm::ivec3> changed_chunks,
                                            const LevelOf& level_of, Context* ctx) {
  if (Status s = check_contour_config(config_); !s.ok()) return s;
  Result<std::vector<int8_t>> levels = levels_of(world, level_of);
  if (!levels.ok()) return levels.status();
  const Box box{world.chunk_origin(), world.chunk_dims()};
  const bool whole = !(box == box_) || levels_.empty();
  const std::vector<glm::ivec3> targets = whole ? chunks_to_mesh(world) : near_changes(world, changed_chunks, levels.value());
  std::vector<ChunkMesh> made;
  if (Status s = mesh_chunks(world, targets, levels.value(), made, ctx); !s.ok()) return s;
  MeshUpdate result = merge(made, whole, [&](const glm::ivec3& c) {
    return int(levels.value()[box_index(box.origin, box.dims, c)]);
  });
  box_ = box;
  levels_ = std::move(levels).value();
  return result;
}

std::vector<glm::ivec3> LevelChunkedMesh::near_changes(const World& world, std::span<const glm::ivec3> changed_chunks,
                                                       const std::vector<int8_t>& levels) const {
  std::vector<glm::ivec3> changed(changed_chunks.begin(), changed_chunks.end());
  world.for_each_chunk([&](const glm::ivec3& c, ChunkKind, const Chunk*) {
    const size_t i = box_index(box_.origin, box_.dims, c);
    if (levels[i] != levels_[i]) changed.push_back(c);
  });
  const glm::ivec3 lo = box_.origin - 1, hi = box_.origin + box_.dims;
  std::vector<glm::ivec3> out = chunks_a_change_reaches(changed);
  std::erase_if(out, [&](const glm::ivec3& n) { return !detail::in_box(n, lo, hi); });
  return out;
}

std::vector<glm::ivec3> LevelChunkedMesh::chunks_a_change_reaches(std::span<const glm::ivec3> changed) {
  std::set<glm::ivec3, ChunkOrder> out;
  for (const glm::ivec3& c : changed)
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) out.insert(c + glm::ivec3(dx, dy, dz));
  return {out.begin(), out.end()};
}

MeshUpdate LevelChunkedMesh::merge(std::vector<ChunkMesh>& made, bool whole, const LevelOf& level_now) {
  MeshUpdate result;
  result.chunks_remeshed = made.size();
  const uint64_t version = version_ + 1;
  std::set<glm::ivec3, ChunkOrder> old_present;
  for (const ChunkMesh& m : meshes_) old_present.insert(m.chunk);
  std::map<glm::ivec3, ChunkMesh, ChunkOrder> next;  // a whole build keeps nothing of the old meshes
  for (ChunkMesh& m : meshes_) {
    if (!whole) next.emplace(m.chunk, std::move(m));
  }
  for (ChunkMesh& m : made) {
    auto it = next.find(m.chunk);
    const bool empty = m.mesh.triangles.empty();
    if (it != next.end() && !empty && same_mesh(it->second, m)) continue;  // unchanged
    if (empty) {
      if (it != next.end()) next.erase(it);
      if (old_present.count(m.chunk)) result.changes.push_back({m.chunk, 0, level_now(m.chunk)});
      continue;
    }
    m.version = version;
    result.changes.push_back({m.chunk, version, level_now(m.chunk)});
    next[m.chunk] = std::move(m);
  }
  for (const glm::ivec3& c : old_present)  // a whole build: meshes of the old box that the new one has not
    if (whole && !next.count(c)) result.changes.push_back({c, 0, 0});
  std::sort(result.changes.begin(), result.changes.end(),
            [](const ChunkMeshChange& a, const ChunkMeshChange& b) { return chunk_order_less(a.chunk, b.chunk); });
  meshes_.clear();
  for (auto& [c, m] : next) meshes_.push_back(std::move(m));
  if (!result.changes.empty()) version_ = version;
  return result;
}

const ChunkMesh* LevelChunkedMesh::find(const glm::ivec3& chunk) const {
  auto it = std::lower_bound(meshes_.begin(), meshes_.end(), chunk,
                             [](const ChunkMesh& m, const glm::ivec3& c) { return chunk_order_less(m.chunk, c); });
  return it != meshes_.end() && it->chunk == chunk ? &*it : nullptr;
}

int LevelChunkedMesh::level(const glm::ivec3& chunk) const {
  return levels_.empty() ? 0 : int(levels_[box_index(box_.origin, box_.dims, chunk)]);
}

std::vector<const ChunkMesh*> LevelChunkedMesh::chunks() const {
  std::vector<const ChunkMesh*> out;
  for (const ChunkMesh& m : meshes_) out.push_back(&m);
  return out;
}

ContourMesh LevelChunkedMesh::assemble() const {
  ContourMesh out;
  std::map<std::tuple<int, int, int, int>, uint32_t> index;
  for (const ChunkMesh& m : meshes_) {
    std::vector<uint32_t> map(m.mesh.positions.size());
    for (size_t i = 0; i < map.size(); ++i) {
      const glm::ivec3 c = m.vertex_cell[i];
      auto [it, added] = index.try_emplace({c.x, c.y, c.z, int(m.vertex_sheet[i])}, uint32_t(out.positions.size()));
      if (added) {
        out.positions.push_back(m.mesh.positions[i]);
        out.normals.push_back(m.mesh.normals[i]);
        out.vertex_material.push_back(m.mesh.vertex_material[i]);
      }
      map[i] = it->second;
    }
    for (const glm::uvec3& t : m.mesh.triangles) out.triangles.emplace_back(map[t.x], map[t.y], map[t.z]);
    out.triangle_material.insert(out.triangle_material.end(), m.mesh.triangle_material.begin(),
                                 m.mesh.triangle_material.end());
  }
  return out;
}

}  // namespace ldc
