// Incremental re-meshing: a box of cells meshed once and spliced into the
// chunk meshes it overlaps, so an edit costs the cells it changed (plus the
// relaxation margin), not whole chunks.
//
// Why this is exact: a cell's vertex depends only on the crossings on its 12
// edges and, through material-border relaxation, on vertices at most
// relax_iterations cells away, and through untangling on placed vertices a
// few cells further (R = RegionMesher::vertex_reach in all); a quad depends
// on its edge and its four vertices. So when the crossings change only on
// edges between nodes of a box D, the vertices that can change lie in the
// cells B = [D.lo - 1 - R, D.hi + R) and the quads that can change lie on edges whose lower node is in
// P = [B.lo, B.hi + 1). Everything outside P is kept as it was; P is meshed by
// the same RegionMesher as a full build, which yields the same bits for any
// box (tests compare against fresh builds).
#pragma once

#include <vector>

#include "contour/contour.h"

namespace ldc::detail {

struct MeshPatch {
  glm::ivec3 lo{0}, hi{0};  // the cells and edge nodes it replaces (hi exclusive)
  // Every vertex of the box's cells, sorted by cell (z, y, x) then sheet, and its data.
  std::vector<glm::ivec3> cells;
  std::vector<uint8_t> sheets;
  std::vector<glm::dvec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<uint16_t> materials;
  struct Triangle {
    glm::ivec3 cell[3];
    uint8_t sheet[3];
    uint16_t material = 0;
  };
  std::vector<Triangle> triangles;  // of every edge whose lower node is in the box
};

// The patch box for crossings changed between the nodes of [node_lo, node_hi),
// for vertices whose positions read data `reach` cells beyond their own
// cell (RegionMesher::vertex_reach).
void patch_box(const glm::ivec3& node_lo, const glm::ivec3& node_hi, int reach, glm::ivec3* lo, glm::ivec3* hi);

// Meshes the box, in slabs along z in parallel.
MeshPatch mesh_patch(const World& world, const ContourConfig& config, const glm::ivec3& lo, const glm::ivec3& hi,
                     ContourStats& stats);

// The mesh of `chunk` with the patch's cells and edges replaced; `old` may be
// empty (a chunk that had no mesh).
ChunkMesh splice_patch(const ChunkMesh& old, const MeshPatch& patch, const glm::ivec3& chunk, int chunk_size);

}  // namespace ldc::detail
