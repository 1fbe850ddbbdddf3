// Marching cubes on LDC data, the baseline: vertices at the edge crossings,
// normals unused for placement. Each cube's polygons are the loops of its
// sheets (detail/cell_sheets.h, the table dual contouring uses too: faces
// with two diagonal inside corners separate them, the same from both cubes
// sharing the face, except where both cubes would link the face's two
// segments: that face is joined from both sides, as dual contouring does),
// fanned into triangles.
//
// Welding: a vertex is a lattice edge's crossing, so it is named by the edge
// (its lower node and axis). Chunks are meshed in parallel, each keeping the
// edges its vertices lie on; the edge belongs to the chunk that holds its
// lower node. When the parts are joined, a chunk's own vertices are numbered
// chunk by chunk in a fixed order and a vertex on a neighbour's edge takes
// the neighbour's number: every crossing is one vertex, the same for any
// thread count.
#include <array>
#include <atomic>
#include <mutex>
#include <unordered_map>

#include <tbb/parallel_for.h>

#include "contour/contour.h"
#include "contour/detail/cell_sheets.h"
#include "contour/detail/region.h"

namespace ldc {
namespace {

glm::ivec3 corner(int c) { return {c & 1, (c >> 1) & 1, (c >> 2) & 1}; }

// A lattice edge relative to a chunk's first node (offsets 0 .. chunk size).
uint32_t edge_key(const glm::ivec3& offset, int axis) {
  return uint32_t(offset.x) | uint32_t(offset.y) << 7 | uint32_t(offset.z) << 14 | uint32_t(axis) << 21;
}

// One chunk's mesh, with the lattice edge of each vertex.
struct Part {
  ContourMesh mesh;
  std::vector<glm::ivec3> vertex_node;  // the edge's lower node
  std::vector<uint8_t> vertex_axis;
  std::unordered_map<uint32_t, uint32_t> ids;  // edge_key (relative to the chunk) -> vertex
};

class CubeMesher {
 public:
  CubeMesher(const World& w, const detail::Region& r, const glm::ivec3& cell_lo, Part& out)
      : w_(w), r_(r), cell_lo_(cell_lo), part_(out), out_(out.mesh), ids_(out.ids) {}

  void cube(const glm::ivec3& cell) {
    const unsigned inside = r_.cell_corners(cell);
    const detail::CellSheets& sheets = detail::cell_sheets(inside, joined_faces(cell, inside));
    for (int s = 0; s < sheets.count; ++s) {
      uint32_t loop[12];
      const int n = sheets.loop_size[s];
      for (int i = 0; i < n; ++i) loop[i] = vertex(cell, sheets.loop[s][i]);
      for (int i = 1; i + 1 < n; ++i) {
        out_.triangles.push_back({loop[0], loop[i], loop[i + 1]});
        out_.triangle_material.push_back(out_.vertex_material[loop[0]]);
      }
    }
  }

 private:
  // The faces both cubes would link through both segments, joined from both
  // sides as dual contouring joins them (detail::joined_faces). Otherwise both
  // cubes' loops pass through both segments, and their fans can both use the
  // chord between the same two crossings: an edge of four triangles. The
  // region holds one node more on every side than the cubes read, for the
  // cubes across.
  unsigned joined_faces(const glm::ivec3& cell, unsigned inside) const {
    return detail::joined_faces(cell, inside, [&](const glm::ivec3& c) { return int(r_.cell_corners(c)); });
  }

  uint32_t vertex(const glm::ivec3& cell, int slot) {
    const int axis = detail::cell_edge_axis(slot);
    const glm::ivec3 node = cell + detail::cell_edge_offset(slot);
    const uint32_t key = edge_key(node - cell_lo_, axis);
    auto it = ids_.find(key);
    if (it != ids_.end()) return it->second;
    const detail::EdgeCrossing* x = r_.crossing(axis, node);
    glm::dvec3 p(node);
    p[axis] += x->t;
    uint32_t id = uint32_t(out_.positions.size());
    out_.positions.push_back(w_.lattice().to_world(p));
    out_.normals.push_back(x->normal);
    out_.vertex_material.push_back(x->material);
    part_.vertex_node.push_back(node);
    part_.vertex_axis.push_back(uint8_t(axis));
    ids_.emplace(key, id);
    return id;
  }

  const World& w_;
  const detail::Region& r_;
  glm::ivec3 cell_lo_;
  Part& part_;
  ContourMesh& out_;
  std::unordered_map<uint32_t, uint32_t>& ids_;
};

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

Result<ContourMesh> marching_cubes(const World& world, Context* ctx) {
  if (Status s = check_box_faces_outside(world); !s.ok()) return s;
  const int c = world.chunk_size();
  std::vector<glm::ivec3> chunks;
  const glm::ivec3 lo = world.chunk_origin() - 1, hi = world.chunk_origin() + world.chunk_dims();
  for (int z = lo.z; z < hi.z; ++z)
    for (int y = lo.y; y < hi.y; ++y)
      for (int x = lo.x; x < hi.x; ++x) chunks.emplace_back(x, y, z);
  std::vector<Part> parts(chunks.size());
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t i) {
    if (ctx && ctx->cancelled()) return;
    glm::ivec3 cell_lo = chunks[i] * c, cell_hi = cell_lo + c;
    bool quiet = true;  // the chunk and its upper neighbours, whose nodes its cells read
    for (int k = 0; k < 8; ++k) quiet = quiet && world.chunk_kind(chunks[i] + corner(k)) == world.chunk_kind(chunks[i]);
    if (quiet && world.chunk_kind(chunks[i]) != ChunkKind::kMixed) return;
    detail::Region region;
    region.load(world, cell_lo - 1, cell_hi + 2, cell_lo, cell_hi);
    if (region.uniform()) return;
    CubeMesher mesher(world, region, cell_lo, parts[i]);
    for (int z = cell_lo.z; z < cell_hi.z; ++z)
      for (int y = cell_lo.y; y < cell_hi.y; ++y)
        for (int x = cell_lo.x; x < cell_hi.x; ++x) mesher.cube({x, y, z});
  });
  if (ctx && ctx->cancelled()) return Status(ErrorCode::kCancelled, "marching cubes: cancelled");

  // Weld: each vertex resolves to the part owning its edge (the chunk of its
  // lower node), where the edge's cube made it too; own vertices are numbered
  // part by part.
  const glm::ivec3 dims = hi - lo;
  constexpr uint32_t kOwn = UINT32_MAX;
  std::vector<std::vector<uint32_t>> owner_vertex(parts.size());  // kOwn, or the vertex in the owner part
  std::vector<std::vector<uint32_t>> owner_part(parts.size());
  std::vector<size_t> own_count(parts.size() + 1, 0);
  tbb::parallel_for(size_t{0}, parts.size(), [&](size_t i) {
    const Part& p = parts[i];
    owner_vertex[i].assign(p.mesh.vertex_count(), kOwn);
    owner_part[i].assign(p.mesh.vertex_count(), uint32_t(i));
    size_t own = 0;
    for (size_t v = 0; v < p.mesh.vertex_count(); ++v) {
      const glm::ivec3 node = p.vertex_node[v];
      const glm::ivec3 owner(floor_div(node.x, c), floor_div(node.y, c), floor_div(node.z, c));
      if (owner != chunks[i] && glm::all(glm::greaterThanEqual(owner, lo)) && glm::all(glm::lessThan(owner, hi))) {
        const glm::ivec3 r = owner - lo;
        const size_t j = (size_t(r.z) * size_t(dims.y) + size_t(r.y)) * size_t(dims.x) + size_t(r.x);
        auto it = parts[j].ids.find(edge_key(node - owner * c, p.vertex_axis[v]));
        if (it != parts[j].ids.end()) {
          owner_vertex[i][v] = it->second;
          owner_part[i][v] = uint32_t(j);
          continue;
        }
      }
      ++own;  // on its own edge (or, never expected, an edge its owner did not mesh)
    }
    own_count[i + 1] = own;
  });
  for (size_t i = 0; i < parts.size(); ++i) own_count[i + 1] += own_count[i];
  // Global ids of every part's own vertices.
  std::vector<std::vector<uint32_t>> global(parts.size());
  tbb::parallel_for(size_t{0}, parts.size(), [&](size_t i) {
    global[i].assign(parts[i].mesh.vertex_count(), kOwn);
    uint32_t next = uint32_t(own_count[i]);
    for (size_t v = 0; v < global[i].size(); ++v)
      if (owner_vertex[i][v] == kOwn) global[i][v] = next++;
  });
  ContourMesh out;
  const size_t vertex_total = own_count.back();
  out.positions.resize(vertex_total);
  out.normals.resize(vertex_total);
  out.vertex_material.resize(vertex_total);
  std::vector<size_t> triangle_base(parts.size() + 1, 0);
  for (size_t i = 0; i < parts.size(); ++i) triangle_base[i + 1] = triangle_base[i] + parts[i].mesh.triangle_count();
  out.triangles.resize(triangle_base.back());
  out.triangle_material.resize(triangle_base.back());
  tbb::parallel_for(size_t{0}, parts.size(), [&](size_t i) {
    const ContourMesh& m = parts[i].mesh;
    for (size_t v = 0; v < m.vertex_count(); ++v) {
      if (owner_vertex[i][v] != kOwn) {
        global[i][v] = global[owner_part[i][v]][owner_vertex[i][v]];
        continue;
      }
      out.positions[global[i][v]] = m.positions[v];
      out.normals[global[i][v]] = m.normals[v];
      out.vertex_material[global[i][v]] = m.vertex_material[v];
    }
  });
  tbb::parallel_for(size_t{0}, parts.size(), [&](size_t i) {
    const ContourMesh& m = parts[i].mesh;
    for (size_t t = 0; t < m.triangle_count(); ++t) {
      const glm::uvec3& tri = m.triangles[t];
      out.triangles[triangle_base[i] + t] = {global[i][tri.x], global[i][tri.y], global[i][tri.z]};
      out.triangle_material[triangle_base[i] + t] = m.triangle_material[t];
    }
  });
  return out;
}

}  // namespace ldc
