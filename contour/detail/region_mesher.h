// Meshes the cells and edges of one box of the lattice (a chunk, or the whole
// world), reading a margin of neighbouring cells so that vertices, normals
// and relaxation near the box border come out exactly as in any other box.
#pragma once

#include <vector>

#include "contour/contour.h"
#include "contour/detail/cell_sheets.h"
#include "contour/detail/placement.h"
#include "contour/detail/region.h"

namespace ldc::detail {

class RegionMesher {
 public:
  RegionMesher(const World& world, const ContourConfig& config) : world_(&world), config_(config) {}
  // Meshes another world or config next, keeping the buffers (a mesher kept
  // per thread then re-meshes small boxes without allocating).
  void rebind(const World& world, const ContourConfig& config) {
    world_ = &world;
    config_ = config;
  }

  // Cells [own_lo, own_hi) (by their lowest corner) and the edges whose lower
  // node lies there. Vertices of cells outside the box that these quads use
  // are appended after the box's own vertices. With order_triangles, the
  // triangles are reordered for the vertex cache.
  void mesh(const glm::ivec3& own_lo, const glm::ivec3& own_hi, ChunkMesh& out, ContourStats& stats,
            bool order_triangles = true);

  // How many cells away from a vertex the data its final position depends
  // on may lie, beyond its own cell's edges: relaxation reaches one cell
  // further per iteration, untangling untangle_reach cells.
  static int vertex_reach(const ContourConfig& config);
  static int untangle_reach(const ContourConfig& config);

 private:
  struct CellVertex {
    glm::ivec3 cell{0};
    uint8_t sheet = 0;  // which sheet of surface through the cell (detail/cell_sheets.h)
    glm::dvec3 x{0.0};  // lattice coordinates relative to the cell's lowest node
    Qef qef;
    glm::vec3 normal{0.0f};  // mean of its crossings' normals
    uint16_t material = 0;
    bool border = false;  // its quads have different materials
    bool untangled = false;  // moved to its mass point to clear a self-intersection
    bool clamped = false;    // the cell (plus slack) held it back from its planes' optimum
    uint8_t rank = 3;        // kQef: eigenvalues kept
    glm::dvec3 mass{0.0};  // the mean of its crossings: the safe position untangling falls back to
  };
  // The vertices of a quad: a sheet in each of the four cells around an edge.
  struct Quad {
    glm::ivec3 cell[4];  // counter-clockwise seen from outside
    uint8_t sheet[4];
    uint16_t material = 0;
  };

  void load(const glm::ivec3& own_lo, const glm::ivec3& own_hi, int low, int high);
  bool single_material() const;
  void mark_cells_with_vertex();
  unsigned joined_faces(const glm::ivec3& cell, unsigned corners) const;
  const CellSheets& sheets_of(const glm::ivec3& cell) const;
  // The sheet of `cell` that holds the edge from `node` along `axis` (a crossing edge of the cell).
  uint8_t sheet_of(const glm::ivec3& cell, int axis, const glm::ivec3& node) const;
  CellPlanes planes_of(const glm::ivec3& cell, const CellSheets& sheets, int sheet) const;
  void place_vertices(const glm::ivec3& used_lo, const glm::ivec3& used_hi);
  bool has_mixed_crossings(const glm::ivec3& cell) const;
  void add_vertex(const glm::ivec3& cell, int sheet, const CellPlanes& planes);
  void relax();
  void keep_sheets_apart(size_t first, int count);
  void find_border_neighbours();
  // Moves the vertices near self-intersecting triangles to their mass points
  // (see untangle.cpp); `decide_lo/hi` is the cell box whose vertices matter.
  void untangle(const glm::ivec3& decide_lo, const glm::ivec3& decide_hi);
  std::vector<uint8_t> tangled_cells(const glm::ivec3& test_lo, const glm::ivec3& test_hi) const;
  glm::dvec3 relaxed_position(size_t border_index) const;
  bool edge_quad(int axis, const glm::ivec3& node, Quad* quad) const;
  // The quads around one vertex: one per crossing edge of its sheet.
  int vertex_quads(const CellVertex& v, Quad* quads) const;
  // Triangle corners (indices into quad.cell) after the diagonal rule.
  void split(const Quad& q, int tri[2][3]) const;
  int32_t vertex_index(const glm::ivec3& cell, int sheet) const;
  const CellVertex* vertex(const glm::ivec3& cell, int sheet) const;
  size_t cell_index(const glm::ivec3& cell) const;
  bool in_cell_box(const glm::ivec3& cell) const;
  void emit(const glm::ivec3& own_lo, const glm::ivec3& own_hi, ChunkMesh& out, ContourStats& stats,
            bool order_triangles);
  void finish_vertices(ChunkMesh& out, ContourStats& stats) const;

  const World* world_;
  ContourConfig config_;
  Region region_;
  glm::ivec3 cell_lo_{0}, cell_hi_{0};
  std::vector<uint8_t> marked_;       // cells around a crossing edge
  std::vector<int32_t> out_index_;     // emit: verts_ index -> output vertex
  std::vector<int32_t> cell_vertex_;   // index into verts_ of the cell's sheet 0 (its sheets follow), -1 without
  std::vector<uint16_t> cell_sheet_key_;  // of every cell with a vertex: inside corners | joined faces << 8
  std::vector<CellVertex> verts_;
  std::vector<uint32_t> border_;  // vertices on a material border
  // Relaxation: border_[b]'s border neighbours are neighbours_[neighbour_begin_[b] .. neighbour_begin_[b + 1]).
  std::vector<uint32_t> neighbour_begin_, neighbours_;
  std::vector<glm::dvec3> relax_next_;
  bool last_region_mixed_ = false;  // the last region meshed had several materials (a hint for load)
};

}  // namespace ldc::detail
