// What CGAL says of a mesh file as a solid, for bench_boolean_process: the
// file read as a polygon soup (CGAL::IO::read_polygon_soup, indices as
// written, nothing welded or repaired), then
// - non-manifold edges and vertices, counted on the soup before anything is
//   oriented or split (orient_polygon_soup's visitor, as tests/cgal counts);
// - whether the soup is a polygon mesh at all (is_polygon_soup_a_polygon_mesh)
//   and, if so, CGAL::is_valid_polygon_mesh and CGAL::is_closed of it;
//   otherwise the soup is oriented (which splits the non-manifold vertices)
//   and is_closed and the border cycles are those of the split mesh;
// - self-intersecting triangle pairs by PMP::self_intersections: on the
//   whole mesh where every triangle can be added to one Surface_mesh by its
//   written indices, otherwise pair by pair over CGAL's box intersection
//   (each candidate pair tested as self_intersections tests it), so that
//   faces a half-edge structure refuses still count. Triangles with collinear
//   corners are counted apart and not tested (self_intersections reports
//   each as the pair (f, f)).
// CGAL stays inside mesh_validity.cpp.
#pragma once

#include <cstddef>
#include <string>

#include "ldc/mesh.h"

namespace ldc::bench {

struct MeshValidity {
  bool read = false;               // the file was read as a soup of polygons
  std::string error;               // why not
  size_t vertices = 0, triangles = 0;  // polygons with k corners count k - 2 triangles
  size_t nonmanifold_edges = 0;    // edges of more than two polygons
  size_t nonmanifold_vertices = 0; // vertices whose polygons form more than one fan
  bool polygon_mesh = false;       // is_polygon_soup_a_polygon_mesh
  bool valid = false;              // is_valid_polygon_mesh of the mesh (false when not a polygon mesh)
  bool closed = false;             // is_closed (after orienting and splitting when not a polygon mesh)
  size_t border_cycles = 0;        // boundary cycles of that mesh
  size_t degenerate = 0;           // triangles with collinear corners (not tested for intersections)
  size_t self_intersections = 0;   // intersecting triangle pairs
  bool pairwise = false;           // counted pair by pair (not one Surface_mesh)
  TriangleMesh mesh;               // the soup as triangles (polygons fanned), for meshdist
};

MeshValidity check_mesh_file(const std::string& path);

}  // namespace ldc::bench
