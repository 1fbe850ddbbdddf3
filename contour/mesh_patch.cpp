// Incremental re-meshing by patches; see detail/mesh_patch.h for why it is exact.
#include "contour/detail/mesh_patch.h"

#include <algorithm>
#include <optional>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "contour/detail/cell_sheets.h"
#include "contour/detail/region_mesher.h"

namespace ldc::detail {

namespace {

bool cell_less(const glm::ivec3& a, const glm::ivec3& b) {
  if (a.z != b.z) return a.z < b.z;
  if (a.y != b.y) return a.y < b.y;
  return a.x < b.x;
}

// Vertices are named by cell and sheet, sorted by cell then sheet.
bool vertex_less(const glm::ivec3& a, uint8_t sa, const glm::ivec3& b, uint8_t sb) {
  return a != b ? cell_less(a, b) : sa < sb;
}

// The edge a quad triangle came from: its three cells share the coordinate
// along the edge's axis, and the edge's node is their largest corner.
glm::ivec3 edge_node(const glm::ivec3 (&cell)[3]) {
  return glm::max(glm::max(cell[0], cell[1]), cell[2]);
}

// Cells around the edges a chunk owns lie in [own_lo - 1, own_hi): a dense
// index over that box (a slot per sheet) maps a cell's sheet to a vertex. The slots live in a buffer
// kept per thread and per slot (two per splice), all -1 between uses: only
// the slots a splice set are reset, so a splice does not pay for clearing or
// faulting in (C + 1)^3 slots (that was most of a small edit's splice).
// splice_patch starts no parallel work, so no thread re-enters it (and its
// buffers) through TBB's work stealing.
class CellIndex {
 public:
  CellIndex(const glm::ivec3& lo, int size, int slot) : lo_(lo), n_(size), index_(buffer(slot)) {
    const size_t cells = size_t(size) * size * size * CellSheets::kMaxSheets;
    if (index_.size() < cells) index_.assign(cells, -1);
  }
  ~CellIndex() {
    for (size_t i : touched_) index_[i] = -1;
  }
  CellIndex(const CellIndex&) = delete;
  CellIndex& operator=(const CellIndex&) = delete;

  int32_t get(const glm::ivec3& cell, uint8_t sheet) const { return index_[offset(cell, sheet)]; }
  void set(const glm::ivec3& cell, uint8_t sheet, int32_t value) {
    size_t i = offset(cell, sheet);
    if (index_[i] < 0) touched_.push_back(i);
    index_[i] = value;
  }
  bool contains(const glm::ivec3& cell) const { return in_box(cell, lo_, lo_ + n_); }

 private:
  static std::vector<int32_t>& buffer(int slot) {
    thread_local std::vector<int32_t> buffers[2];
    return buffers[slot];
  }
  size_t offset(const glm::ivec3& cell, uint8_t sheet) const {
    glm::ivec3 r = cell - lo_;
    return ((size_t(r.z) * n_ + size_t(r.y)) * n_ + size_t(r.x)) * CellSheets::kMaxSheets + sheet;
  }

  glm::ivec3 lo_;
  int n_;
  std::vector<int32_t>& index_;
  std::vector<size_t> touched_;
};

// Where a vertex of the spliced chunk comes from.
struct VertexSource {
  glm::ivec3 cell;
  uint8_t sheet;
  bool from_patch;
  size_t index;  // into the patch's arrays or the old mesh's
};

// Patches up to this many cells per slab mesh with a mesher kept per thread,
// so the re-mesh after a small edit allocates and faults in nothing (its
// region's edge tables alone are about a megabyte); larger ones use a fresh
// mesher, so no thread keeps a large edit's buffers.
constexpr size_t kKeptMesherCells = size_t(64) * 64 * 64;

// RegionMesher::mesh starts no parallel work, so no thread re-enters its
// kept mesher through TBB's work stealing.
RegionMesher& kept_mesher(const World& world, const ContourConfig& config) {
  thread_local std::optional<RegionMesher> mesher;
  if (mesher) mesher->rebind(world, config);
  else mesher.emplace(world, config);
  return *mesher;
}

}  // namespace

void patch_box(const glm::ivec3& node_lo, const glm::ivec3& node_hi, int reach, glm::ivec3* lo, glm::ivec3* hi) {
  *lo = node_lo - 1 - reach;
  *hi = node_hi + reach + 1;
}

// The axis to cut a patch along: the longest, x or y before z on a tie. A
// landscape's surface is a horizontal band, so slabs along z gave one thread
// nearly all of a dig's surface; cuts across x or y share it out.
int slab_axis(const glm::ivec3& size) {
  int axis = 1;
  if (size.x > size[axis]) axis = 0;
  if (size.z > size[axis]) axis = 2;
  return axis;
}

MeshPatch mesh_patch(const World& world, const ContourConfig& config, const glm::ivec3& lo, const glm::ivec3& hi,
                     ContourStats& stats) {
  // Slabs along one axis, one per thread (each re-reads a margin, so no more than that).
  const glm::ivec3 size = hi - lo;
  const int axis = slab_axis(size);
  const int depth = size[axis];
  const int slabs = std::max(1, std::min(tbb::this_task_arena::max_concurrency(), depth / 8));
  std::vector<ChunkMesh> pieces(static_cast<size_t>(slabs));
  std::vector<ContourStats> piece_stats(static_cast<size_t>(slabs));
  glm::ivec3 slab_size = size;
  slab_size[axis] = depth / slabs + 1;
  const bool small = size_t(slab_size.x) * size_t(slab_size.y) * size_t(slab_size.z) <= kKeptMesherCells;
  tbb::parallel_for(0, slabs, [&](int s) {
    glm::ivec3 a = lo, b = hi;
    a[axis] = lo[axis] + depth * s / slabs;
    b[axis] = lo[axis] + depth * (s + 1) / slabs;
    if (small) {
      kept_mesher(world, config).mesh(a, b, pieces[size_t(s)], piece_stats[size_t(s)], /*order_triangles=*/false);
    } else {
      RegionMesher(world, config).mesh(a, b, pieces[size_t(s)], piece_stats[size_t(s)], /*order_triangles=*/false);
    }
  });
  MeshPatch p;
  p.lo = lo;
  p.hi = hi;
  // Each slab's own vertices are sorted by cell then sheet: merged, they are
  // the patch's (slabs along z simply follow each other).
  std::vector<size_t> next(pieces.size(), 0);
  for (;;) {
    size_t best = pieces.size();
    for (size_t s = 0; s < pieces.size(); ++s) {
      const ChunkMesh& m = pieces[s];
      if (next[s] == m.own_vertices) continue;
      const ChunkMesh* b = best < pieces.size() ? &pieces[best] : nullptr;
      if (!b || vertex_less(m.vertex_cell[next[s]], m.vertex_sheet[next[s]], b->vertex_cell[next[best]],
                            b->vertex_sheet[next[best]])) {
        best = s;
      }
    }
    if (best == pieces.size()) break;
    const ChunkMesh& m = pieces[best];
    const size_t v = next[best]++;
    p.cells.push_back(m.vertex_cell[v]);
    p.sheets.push_back(m.vertex_sheet[v]);
    p.positions.push_back(m.mesh.positions[v]);
    p.normals.push_back(m.mesh.normals[v]);
    p.materials.push_back(m.mesh.vertex_material[v]);
  }
  for (size_t s = 0; s < pieces.size(); ++s) {
    const ChunkMesh& m = pieces[s];
    for (size_t t = 0; t < m.mesh.triangles.size(); ++t) {
      const glm::uvec3& tri = m.mesh.triangles[t];
      p.triangles.push_back({{m.vertex_cell[tri.x], m.vertex_cell[tri.y], m.vertex_cell[tri.z]},
                             {m.vertex_sheet[tri.x], m.vertex_sheet[tri.y], m.vertex_sheet[tri.z]},
                             m.mesh.triangle_material[t]});
    }
    stats.add_counts(piece_stats[s]);
  }
  return p;
}

ChunkMesh splice_patch(const ChunkMesh& old, const MeshPatch& patch, const glm::ivec3& chunk, int chunk_size) {
  const glm::ivec3 own_lo = chunk * chunk_size, own_hi = own_lo + chunk_size;
  // Scratch kept per thread: fresh large vectors would fault in new pages on
  // every splice (mmap'ed by malloc), which cost more than filling them.
  thread_local std::vector<VertexSource> sources;
  thread_local std::vector<int32_t> old_to_new;
  sources.clear();
  // Own vertices, sorted: the old ones outside the patch merged with the patch's in this chunk.
  auto patch_begin = std::lower_bound(patch.cells.begin(), patch.cells.end(), own_lo, cell_less);
  size_t p = size_t(patch_begin - patch.cells.begin());
  auto next_patch_own = [&]() -> bool {
    while (p < patch.cells.size() && !in_box(patch.cells[p], own_lo, own_hi)) {
      if (patch.cells[p].z >= own_hi.z) p = patch.cells.size();
      else ++p;
    }
    return p < patch.cells.size();
  };
  size_t o = 0;
  auto next_old_own = [&]() -> bool {
    while (o < old.own_vertices && in_box(old.vertex_cell[o], patch.lo, patch.hi)) ++o;
    return o < old.own_vertices;
  };
  while (true) {
    bool has_p = next_patch_own(), has_o = next_old_own();
    if (!has_p && !has_o) break;
    if (has_p && (!has_o || vertex_less(patch.cells[p], patch.sheets[p], old.vertex_cell[o], old.vertex_sheet[o]))) {
      sources.push_back({patch.cells[p], patch.sheets[p], true, p});
      ++p;
    } else {
      sources.push_back({old.vertex_cell[o], old.vertex_sheet[o], false, o});
      ++o;
    }
  }
  const size_t own = sources.size();
  // Copies of the neighbours' vertices the triangles use, in first-use order.
  CellIndex index(own_lo - 1, chunk_size + 1, 0);
  for (size_t v = 0; v < own; ++v) index.set(sources[v].cell, sources[v].sheet, int32_t(v));
  // The old copies of neighbours' vertices: own cells are all in `index` already.
  CellIndex old_index(own_lo - 1, chunk_size + 1, 1);
  for (size_t v = old.own_vertices; v < old.vertex_cell.size(); ++v) {
    if (old_index.contains(old.vertex_cell[v])) old_index.set(old.vertex_cell[v], old.vertex_sheet[v], int32_t(v));
  }
  // The spliced mesh's index of a vertex, a copy added on its first use:
  // from the patch inside its box, else from the old mesh.
  auto vertex_id = [&](const glm::ivec3& cell, uint8_t sheet) -> uint32_t {
    int32_t id = index.get(cell, sheet);
    if (id >= 0) return uint32_t(id);
    id = int32_t(sources.size());
    index.set(cell, sheet, id);
    if (in_box(cell, patch.lo, patch.hi)) {
      auto it = std::lower_bound(patch.cells.begin(), patch.cells.end(), cell, cell_less);
      sources.push_back({cell, sheet, true, size_t(it - patch.cells.begin()) + sheet});
    } else {
      sources.push_back({cell, sheet, false, size_t(old_index.get(cell, sheet))});
    }
    return uint32_t(id);
  };
  ChunkMesh out;
  out.chunk = chunk;
  out.mesh.triangles.reserve(old.mesh.triangles.size() + patch.triangles.size() / 4);
  out.mesh.triangle_material.reserve(out.mesh.triangles.capacity());
  // Triangles: the old ones on edges outside the patch (an old vertex's new
  // index looked up once, however many triangles share it), then the
  // patch's on edges this chunk owns.
  old_to_new.assign(old.vertex_cell.size(), -1);
  for (size_t t = 0; t < old.mesh.triangles.size(); ++t) {
    const glm::uvec3& i = old.mesh.triangles[t];
    const glm::ivec3 cells[3] = {old.vertex_cell[i.x], old.vertex_cell[i.y], old.vertex_cell[i.z]};
    if (in_box(edge_node(cells), patch.lo, patch.hi)) continue;
    glm::uvec3 ids;
    for (int j = 0; j < 3; ++j) {
      int32_t& id = old_to_new[i[j]];
      if (id < 0) id = int32_t(vertex_id(cells[j], old.vertex_sheet[i[j]]));
      ids[j] = uint32_t(id);
    }
    out.mesh.triangles.push_back(ids);
    out.mesh.triangle_material.push_back(old.mesh.triangle_material[t]);
  }
  for (const MeshPatch::Triangle& tri : patch.triangles) {
    if (!in_box(edge_node(tri.cell), own_lo, own_hi)) continue;
    out.mesh.triangles.push_back(
        {vertex_id(tri.cell[0], tri.sheet[0]), vertex_id(tri.cell[1], tri.sheet[1]), vertex_id(tri.cell[2], tri.sheet[2])});
    out.mesh.triangle_material.push_back(tri.material);
  }
  out.own_vertices = own;
  out.vertex_cell.reserve(sources.size());
  out.vertex_sheet.reserve(sources.size());
  out.mesh.positions.reserve(sources.size());
  out.mesh.normals.reserve(sources.size());
  out.mesh.vertex_material.reserve(sources.size());
  for (const VertexSource& s : sources) {
    out.vertex_cell.push_back(s.cell);
    out.vertex_sheet.push_back(s.sheet);
    out.mesh.positions.push_back(s.from_patch ? patch.positions[s.index] : old.mesh.positions[s.index]);
    out.mesh.normals.push_back(s.from_patch ? patch.normals[s.index] : old.mesh.normals[s.index]);
    out.mesh.vertex_material.push_back(s.from_patch ? patch.materials[s.index] : old.mesh.vertex_material[s.index]);
  }
  // No vertex-cache re-ordering here: it would cost more than the splice. The
  // kept triangles keep their optimized order and the patch's follow in cell
  // order, which is nearly as cache-friendly; a full build re-optimizes.
  return out;
}

}  // namespace ldc::detail
