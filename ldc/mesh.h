// Triangle meshes: the in-memory form the builders and brushes take, and
// checks on it. Files are read and written by the meshio module
// (meshio/meshio.h: OBJ, PLY, STL, OFF, GLB, Draco).
//
// Units: positions are in the caller's units (metres for the builders and
// brushes, which take them as world coordinates). Thread safety: the loaders
// and free functions are re-entrant; a TriangleMesh is a plain value.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/status.h"

namespace ldc {

struct TriangleMesh {
  std::vector<glm::dvec3> positions;
  std::vector<glm::uvec3> triangles;        // counter-clockwise seen from outside
  // Empty, or one id per triangle. parse_obj numbers `usemtl` names in the
  // order first seen (id 0 = the first); faces before the first `usemtl` get
  // the name "default", registered only if such faces exist. A file without
  // any `usemtl` leaves both vectors empty, as do the other formats.
  std::vector<uint16_t> triangle_material;
  std::vector<std::string> material_names;  // id -> name (OBJ usemtl), may be empty

  size_t triangle_count() const { return triangles.size(); }
  uint16_t material_of(size_t triangle) const {
    return triangle_material.empty() ? uint16_t{0} : triangle_material[triangle];
  }
};

struct MeshBounds {
  glm::dvec3 min{0.0};
  glm::dvec3 max{0.0};
  glm::dvec3 extent() const { return max - min; }
  double diagonal() const;
};

// Bounds of the vertices referenced by triangles. Requires a non-empty mesh.
MeshBounds mesh_bounds(const TriangleMesh& mesh);

// Signed volume (positive for outward-facing closed meshes).
double mesh_signed_volume(const TriangleMesh& mesh);

// Checks indices, finite coordinates and material ids; names the first bad one.
Status check_mesh(const TriangleMesh& mesh, std::string_view name = "mesh");

// What the topology looks like (vertices welded by exact position).
struct MeshTopology {
  size_t boundary_edges = 0;      // edges used once
  size_t nonmanifold_edges = 0;   // edges used by more than two triangles
  size_t unbalanced_edges = 0;    // edges whose two directions are not used equally often
  size_t degenerate_triangles = 0;
  bool closed() const { return unbalanced_edges == 0; }
};
MeshTopology mesh_topology(const TriangleMesh& mesh);

}  // namespace ldc
