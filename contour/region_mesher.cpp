#include "contour/detail/region_mesher.h"

#include <algorithm>
#include <cstring>

#include <meshoptimizer.h>

namespace ldc::detail {

void optimize_triangle_order(ContourMesh& m);

bool RegionMesher::in_cell_box(const glm::ivec3& cell) const {
  return in_box(cell, cell_lo_, cell_hi_);
}

size_t RegionMesher::cell_index(const glm::ivec3& cell) const {
  glm::ivec3 r = cell - cell_lo_, s = cell_hi_ - cell_lo_;
  return (size_t(r.z) * s.y + size_t(r.y)) * s.x + size_t(r.x);
}

int32_t RegionMesher::vertex_index(const glm::ivec3& cell, int sheet) const {
  int32_t i = cell_vertex_[cell_index(cell)];  // callers stay inside the cell box
  return i < 0 ? -1 : i + sheet;
}

const RegionMesher::CellVertex* RegionMesher::vertex(const glm::ivec3& cell, int sheet) const {
  int32_t i = vertex_index(cell, sheet);
  return i < 0 ? nullptr : &verts_[size_t(i)];
}

// The faces of the cell to join (detail::joined_faces). Faces towards cells
// outside the cell box stay apart; no vertex that matters is there.
unsigned RegionMesher::joined_faces(const glm::ivec3& cell, unsigned corners) const {
  return detail::joined_faces(cell, corners,
                              [&](const glm::ivec3& c) { return in_cell_box(c) ? int(region_.cell_corners(c)) : -1; });
}

const CellSheets& RegionMesher::sheets_of(const glm::ivec3& cell) const {
  const uint16_t key = cell_sheet_key_[cell_index(cell)];
  return cell_sheets(key & 255u, key >> 8);
}

uint8_t RegionMesher::sheet_of(const glm::ivec3& cell, int axis, const glm::ivec3& node) const {
  const CellSheets& sheets = sheets_of(cell);
  return uint8_t(sheets.sheet_of_edge[cell_edge_slot(axis, node - cell)]);
}

// The quad of the edge from `node` along `axis`, if its ends differ: the four
// cells around the edge, counter-clockwise seen from the outside end.
bool RegionMesher::edge_quad(int axis, const glm::ivec3& node, Quad* quad) const {
  const EdgeCrossing* x = region_.crossing(axis, node);
  if (!x) return false;
  const glm::ivec3 eu = axis_unit(axis_u(axis)), ev = axis_unit(axis_v(axis));
  // Counter-clockwise seen from +axis (u x v = axis); reversed when +axis is inside.
  glm::ivec3 cells[4] = {node - eu - ev, node - ev, node, node - eu};
  bool outward_plus = region_.inside(node);
  for (int i = 0; i < 4; ++i) {
    quad->cell[i] = outward_plus ? cells[i] : cells[3 - i];
    quad->sheet[i] = in_cell_box(quad->cell[i]) ? sheet_of(quad->cell[i], axis, node) : 0;
  }
  quad->material = x->material;
  return true;
}

int RegionMesher::vertex_quads(const CellVertex& v, Quad* quads) const {
  const CellSheets& sheets = sheets_of(v.cell);
  int n = 0;
  for (int slot = 0; slot < 12; ++slot) {
    if (sheets.sheet_of_edge[slot] != v.sheet) continue;
    if (edge_quad(cell_edge_axis(slot), v.cell + cell_edge_offset(slot), &quads[n])) ++n;
  }
  return n;
}

// Positions are kept relative to each vertex's own cell, and a quad works in
// the frame of its first cell, so every region computes the same bits.
void RegionMesher::split(const Quad& q, int tri[2][3]) const {
  const CellVertex* v[4];
  glm::dvec3 p[4];
  const glm::ivec3 frame = q.cell[0];
  for (int i = 0; i < 4; ++i) {
    v[i] = vertex(q.cell[i], q.sheet[i]);
    p[i] = glm::dvec3(q.cell[i] - frame) + v[i]->x;
  }
  // The cells' centres go round the edge as the corners do: half their
  // diagonals' cross product is the edge's unit axis, outwards.
  const glm::dvec3 facing =
      0.5 * glm::cross(glm::dvec3(q.cell[2] - q.cell[0]), glm::dvec3(q.cell[3] - q.cell[1]));
  glm::dvec3 m02 = 0.5 * (p[0] + p[2]), m13 = 0.5 * (p[1] + p[3]);
  auto err = [&](int i, const glm::dvec3& m) { return v[i]->qef.error(m - glm::dvec3(q.cell[i] - frame)); };
  const bool use02 = split_along_02(err(0, m02) + err(2, m02), err(1, m13) + err(3, m13), p, facing);
  static const int kDiag02[2][3] = {{0, 1, 2}, {0, 2, 3}};
  static const int kDiag13[2][3] = {{0, 1, 3}, {1, 2, 3}};
  const int(*t)[3] = use02 ? kDiag02 : kDiag13;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 3; ++j) tri[i][j] = t[i][j];
}

// The cells around every edge with a crossing get a vertex; the rest of the
// region is never visited.
void RegionMesher::mark_cells_with_vertex() {
  std::vector<uint8_t>& marked = marked_;
  marked.assign(size_t(cell_hi_.x - cell_lo_.x) * (cell_hi_.y - cell_lo_.y) * (cell_hi_.z - cell_lo_.z), 0);
  for (const Region::EdgeRef& e : region_.crossing_edges()) {
    const glm::ivec3 eu = axis_unit(axis_u(e.axis)), ev = axis_unit(axis_v(e.axis));
    for (int k = 0; k < 4; ++k) {
      glm::ivec3 cell = e.node - ((k & 1) ? eu : glm::ivec3(0)) - ((k & 2) ? ev : glm::ivec3(0));
      if (glm::all(glm::greaterThanEqual(cell, cell_lo_)) && glm::all(glm::lessThan(cell, cell_hi_))) {
        marked[cell_index(cell)] = 1;
      }
    }
  }
}

// The crossings on the edges of one sheet of the cell, in a fixed order
// (axis, then the edge's offset in u and v), with positions relative to the
// cell's lowest node.
CellPlanes RegionMesher::planes_of(const glm::ivec3& cell, const CellSheets& sheets, int sheet) const {
  const glm::dvec3 base(0.0);
  CellPlanes planes;
  for (int a = 0; a < 3; ++a) {
    const EdgeCrossing* edges[4];
    region_.cell_edges(a, cell, edges);
    for (int k = 0; k < 4; ++k) {
      if (!edges[k] || sheets.sheet_of_edge[a * 4 + k] != sheet) continue;
      glm::dvec3 p = base;
      p[axis_u(a)] += k & 1;
      p[axis_v(a)] += (k >> 1) & 1;
      p[a] += edges[k]->t;
      planes.add(p, glm::dvec3(edges[k]->normal), edges[k]->material, a);
    }
  }
  return planes;
}

// Every vertex the box's quads use is placed; in the relaxation margin
// beyond them only cells with a border vertex are, as relaxation reads no
// others. A cell's sheets get consecutive vertices.
void RegionMesher::place_vertices(const glm::ivec3& used_lo, const glm::ivec3& used_hi) {
  mark_cells_with_vertex();
  const std::vector<uint8_t>& marked = marked_;
  cell_vertex_.assign(marked.size(), -1);
  cell_sheet_key_.assign(marked.size(), 0);
  verts_.clear();
  border_.clear();
  size_t i = 0;
  CellPlanes planes[CellSheets::kMaxSheets];
  for (int z = cell_lo_.z; z < cell_hi_.z; ++z) {
    for (int y = cell_lo_.y; y < cell_hi_.y; ++y) {
      for (int x = cell_lo_.x; x < cell_hi_.x; ++x, ++i) {
        if (!marked[i]) continue;
        const glm::ivec3 cell(x, y, z);
        const bool used = in_box(cell, used_lo, used_hi);
        if (!used && !has_mixed_crossings(cell)) continue;  // no sheet of it can be on a border
        const unsigned corners = region_.cell_corners(cell);
        const unsigned joined = joined_faces(cell, corners);
        const CellSheets& sheets = cell_sheets(corners, joined);
        bool any_border = false;
        for (int s = 0; s < sheets.count; ++s) {
          planes[s] = planes_of(cell, sheets, s);
          any_border = any_border || planes[s].mixed_materials();
        }
        if (!any_border && !used) continue;
        cell_vertex_[i] = int32_t(verts_.size());
        cell_sheet_key_[i] = uint16_t(corners | joined << 8);
        for (int s = 0; s < sheets.count; ++s) add_vertex(cell, s, planes[s]);
        if (sheets.count > 1) keep_sheets_apart(verts_.size() - size_t(sheets.count), sheets.count);
      }
    }
  }
}

// The vertices of one cell's sheets, verts_[first, first + count): each on its own side (keep_to_own_sheet).
void RegionMesher::keep_sheets_apart(size_t first, int count) {
  glm::dvec3 mass[CellSheets::kMaxSheets];
  for (int s = 0; s < count; ++s) mass[s] = verts_[first + size_t(s)].mass;
  for (int s = 0; s < count; ++s) {
    CellVertex& v = verts_[first + size_t(s)];
    v.x = keep_to_own_sheet(v.x, s, mass, count);
  }
}

// True when the crossings on the cell's edges have more than one material.
bool RegionMesher::has_mixed_crossings(const glm::ivec3& cell) const {
  int first = -1;
  for (int a = 0; a < 3; ++a) {
    const EdgeCrossing* edges[4];
    region_.cell_edges(a, cell, edges);
    for (const EdgeCrossing* e : edges) {
      if (!e) continue;
      if (first < 0) first = e->material;
      else if (e->material != first) return true;
    }
  }
  return false;
}

void RegionMesher::add_vertex(const glm::ivec3& cell, int sheet, const CellPlanes& planes) {
  CellVertex v;
  v.cell = cell;
  v.sheet = uint8_t(sheet);
  v.qef = Qef::of(planes);
  v.mass = planes.mass_point();
  PlacedVertex pv = place_vertex(planes, v.qef, config_);
  v.x = pv.position;
  v.material = planes.majority_material();
  v.normal = planes.mean_normal();
  v.border = planes.mixed_materials();
  v.rank = uint8_t(pv.rank);
  v.clamped = pv.clamped;
  if (v.border) border_.push_back(uint32_t(verts_.size()));
  verts_.push_back(v);
}

// Elastic net on material borders: every border vertex moves towards the mean
// of its border neighbours (cells sharing a quad edge with it), then back
// towards its planes, and stays in its cell. Jacobi steps, so the result does
// not depend on the order cells are visited in. The neighbours are found once:
// iterations move vertices, never which vertices are neighbours.
void RegionMesher::relax() {
  if (config_.relax_iterations <= 0 || config_.relax_strength <= 0.0) return;
  find_border_neighbours();
  std::vector<glm::dvec3>& next = relax_next_;
  next.resize(border_.size());
  for (int it = 0; it < config_.relax_iterations; ++it) {
    for (size_t b = 0; b < border_.size(); ++b) next[b] = relaxed_position(b);
    for (size_t b = 0; b < border_.size(); ++b) verts_[border_[b]].x = next[b];
  }
}

// For each border vertex, its border neighbours in quad order, each once per
// quad side that reaches it (as the mean counts them).
void RegionMesher::find_border_neighbours() {
  neighbour_begin_.assign(1, 0);
  neighbours_.clear();
  for (uint32_t vi : border_) {
    const CellVertex& v = verts_[vi];
    Quad quads[12];
    const int n = vertex_quads(v, quads);
    for (int k = 0; k < n; ++k) {
      int at = 0;
      while (quads[k].cell[at] != v.cell) ++at;
      for (int side : {1, 3}) {
        const glm::ivec3& other = quads[k].cell[(at + side) % 4];
        if (!in_cell_box(other)) continue;
        const int32_t nb = vertex_index(other, quads[k].sheet[(at + side) % 4]);
        if (nb >= 0 && verts_[size_t(nb)].border) neighbours_.push_back(uint32_t(nb));
      }
    }
    neighbour_begin_.push_back(uint32_t(neighbours_.size()));
  }
}

// The elastic step of border vertex b, in the vertex's own cell frame:
// towards the mean of its border neighbours, then back onto its planes (a few
// particle steps), and into its cell.
glm::dvec3 RegionMesher::relaxed_position(size_t b) const {
  const CellVertex& v = verts_[border_[b]];
  const uint32_t first = neighbour_begin_[b], last = neighbour_begin_[b + 1];
  if (first == last) return v.x;
  glm::dvec3 sum(0.0);
  for (uint32_t k = first; k < last; ++k) {
    const CellVertex& nb = verts_[neighbours_[k]];
    sum += glm::dvec3(nb.cell - v.cell) + nb.x;
  }
  const int count = int(last - first);
  glm::dvec3 p = v.x + config_.relax_strength * (sum / double(count) - v.x);
  double planes = v.qef.a00 + v.qef.a11 + v.qef.a22;  // = number of planes
  for (int it = 0; it < 8 && planes > 0.0; ++it) {
    p += config_.relax_plane_pull * (v.qef.b - v.qef.times(p)) / planes;  // sum_i n_i (n_i . (p_i - x)) / N
  }
  p = clamp_to_cell(p, glm::dvec3(0.0), config_.cell_slack, nullptr);
  if (left_the_cell(p) && far_side(planes_of(v.cell, sheets_of(v.cell), v.sheet)).holds(p)) {  // see FarSide
    p = clamp_to_cell(p, glm::dvec3(0.0), 0.0, nullptr);
  }
  return p;
}

// Triangles of the quads of the box's own edges, in the order the region
// found them (deterministic).
void RegionMesher::emit(const glm::ivec3& own_lo, const glm::ivec3& own_hi, ChunkMesh& out,
                        ContourStats& stats, bool order_triangles) {
  std::vector<int32_t>& out_index = out_index_;
  out_index.assign(verts_.size(), -1);
  ContourMesh& m = out.mesh;
  auto add_vertex = [&](size_t vi) {
    out_index[vi] = int32_t(m.positions.size());
    out.vertex_cell.push_back(verts_[vi].cell);
    out.vertex_sheet.push_back(verts_[vi].sheet);
    m.positions.push_back(glm::dvec3(0.0));  // filled by finish_vertices
  };
  for (size_t vi = 0; vi < verts_.size(); ++vi) {  // in cell order (z, y, x), then sheet
    if (in_box(verts_[vi].cell, own_lo, own_hi)) add_vertex(vi);
  }
  out.own_vertices = m.positions.size();
  for (const Region::EdgeRef& e : region_.crossing_edges()) {
    if (!in_box(e.node, own_lo, own_hi)) continue;
    Quad q;
    edge_quad(e.axis, e.node, &q);
    int tri[2][3];
    split(q, tri);
    for (const auto& t : tri) {
      uint32_t idx[3];
      for (int j = 0; j < 3; ++j) {
        const size_t vi = size_t(vertex_index(q.cell[t[j]], q.sheet[t[j]]));
        if (out_index[vi] < 0) add_vertex(vi);
        idx[j] = uint32_t(out_index[size_t(vi)]);
      }
      m.triangles.push_back({idx[0], idx[1], idx[2]});
      m.triangle_material.push_back(q.material);
    }
    ++stats.quads;
  }
  finish_vertices(out, stats);
  if (order_triangles) optimize_triangle_order(m);
}

// Reorders the chunk's triangles for the post-transform vertex cache
// (meshoptimizer's FIFO variant, several times faster than its Forsyth-like
// one; about 0.7 vertices per triangle instead of 1.2 to 1.5 in quad order), carrying each triangle's material along: the
// output triangle is found among the few triangles of its first vertex.
void optimize_triangle_order(ContourMesh& m) {
  const size_t n = m.triangles.size();
  if (n < 2) return;
  std::vector<uint32_t> in(n * 3), out(in.size());
  std::memcpy(in.data(), m.triangles.data(), in.size() * sizeof(uint32_t));
  meshopt_optimizeVertexCacheFifo(out.data(), in.data(), in.size(), m.positions.size(), 16);
  std::vector<uint32_t> first(m.positions.size() + 1, 0), of_vertex(n);
  for (const glm::uvec3& t : m.triangles) ++first[t.x + 1];
  for (size_t v = 0; v + 1 < first.size(); ++v) first[v + 1] += first[v];
  std::vector<uint32_t> fill(first.begin(), first.end() - 1);
  for (uint32_t t = 0; t < n; ++t) of_vertex[fill[m.triangles[t].x]++] = t;
  std::vector<glm::uvec3> triangles(n);
  std::vector<uint16_t> material(n);
  for (size_t t = 0; t < n; ++t) {
    glm::uvec3 tri(out[3 * t], out[3 * t + 1], out[3 * t + 2]);
    triangles[t] = tri;
    for (uint32_t k = first[tri.x]; k < first[tri.x + 1]; ++k) {
      if (m.triangles[of_vertex[k]] == tri) material[t] = m.triangle_material[of_vertex[k]];
    }
  }
  m.triangles = std::move(triangles);
  m.triangle_material = std::move(material);
}

void RegionMesher::finish_vertices(ChunkMesh& out, ContourStats& stats) const {
  const Lattice& lat = world_->lattice();
  ContourMesh& m = out.mesh;
  m.normals.resize(m.positions.size());
  m.vertex_material.resize(m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) {
    const CellVertex& v = *vertex(out.vertex_cell[i], out.vertex_sheet[i]);
    m.positions[i] = lat.to_world(glm::dvec3(v.cell) + v.x);
    m.normals[i] = v.normal;
    m.vertex_material[i] = v.material;
    if (i < out.own_vertices) {
      stats.relaxed_vertices += v.border && config_.relax_iterations > 0;
      stats.untangled_vertices += v.untangled;
      stats.clamped_vertices += v.clamped;
      if (config_.placement == Placement::kQef) ++stats.qef_rank[v.rank];
    }
  }
  stats.cells += out.own_vertices;
}

// Cells [own_lo - low, own_hi + high), and the nodes their corners need.
void RegionMesher::load(const glm::ivec3& own_lo, const glm::ivec3& own_hi, int low, int high) {
  cell_lo_ = own_lo - low;
  cell_hi_ = own_hi + high;
  region_.load(*world_, cell_lo_, cell_hi_ + 1, own_lo, own_hi);
}

// One material in the region: no vertex can sit on a material border.
bool RegionMesher::single_material() const {
  const auto& edges = region_.crossing_edges();
  if (edges.empty()) return true;
  uint16_t first = region_.crossing(edges[0].axis, edges[0].node)->material;
  for (const Region::EdgeRef& e : edges) {
    if (region_.crossing(e.axis, e.node)->material != first) return false;
  }
  return true;
}

void RegionMesher::mesh(const glm::ivec3& own_lo, const glm::ivec3& own_hi, ChunkMesh& out,
                        ContourStats& stats, bool order_triangles) {
  out.mesh = {};
  out.vertex_cell.clear();
  out.vertex_sheet.clear();
  out.own_vertices = 0;
  // Quads need the cells one below, and a cell's sheets its face
  // neighbours' corners: one cell more; untangling untangle_reach cells more
  // on every side; relaxation one more cell per iteration, but only where
  // materials meet.
  // The wide load (a superset) gives the same mesh on one material, so a
  // mesher whose last region had several loads wide at once, saving the
  // narrow load that would be thrown away on a landscape.
  const int untangle_margin = untangle_reach(config_);
  const bool may_relax = config_.relax_iterations > 0;
  const bool wide = may_relax && last_region_mixed_;
  if (wide) load(own_lo, own_hi, 1 + vertex_reach(config_), vertex_reach(config_));
  else load(own_lo, own_hi, 2 + untangle_margin, 1 + untangle_margin);
  last_region_mixed_ = may_relax && !single_material();
  if (last_region_mixed_ && !wide) load(own_lo, own_hi, 1 + vertex_reach(config_), vertex_reach(config_));
  stats.multi_crossing_edges += region_.multi_crossing_edges();
  stats.thin_edges += region_.thin_edges();
  if (region_.uniform()) return;
  place_vertices(own_lo - 1 - untangle_margin, own_hi + untangle_margin);
  relax();
  untangle(own_lo - 1, own_hi);
  emit(own_lo, own_hi, out, stats, order_triangles);
}

}  // namespace ldc::detail
