// Small hand-made meshes with known quality counts, shared by tests/test_quality.cpp
// (the counts worked out by hand) and tests/cgal/test_cgal_reference.cpp (the
// same counts from CGAL).
#pragma once

#include <string>
#include <vector>

#include "contour/contour.h"

namespace ldc::test {

// Appends the box [lo, hi]: 8 corners (index bits x, y, z), 12 triangles
// counter-clockwise seen from outside. Each face quad (a, b, c, d) splits
// along a-c: the faces x = const along y = z, y = const along x = z, and
// z = const along x = y (in the box's own coordinates).
inline void add_box(ContourMesh& m, const glm::dvec3& lo, const glm::dvec3& hi) {
  const uint32_t base = uint32_t(m.positions.size());
  for (int c = 0; c < 8; ++c)
    m.positions.push_back({(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z});
  constexpr uint32_t kFaces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : kFaces) {
    m.triangles.push_back(glm::uvec3(f[0], f[1], f[2]) + base);
    m.triangles.push_back(glm::uvec3(f[0], f[2], f[3]) + base);
  }
}

inline ContourMesh box_pair(const glm::dvec3& lo_b, const glm::dvec3& hi_b) {
  ContourMesh m;
  add_box(m, glm::dvec3(0.0), glm::dvec3(1.0));
  add_box(m, lo_b, hi_b);
  return m;
}

// The unit cube whose top face is a fan of four triangles around an apex
// (vertex 8): below the top but above the bottom it is a dent; below the
// bottom (z < 0) the fan pierces the bottom face.
inline ContourMesh cube_with_fan_top(const glm::dvec3& apex) {
  ContourMesh m;
  add_box(m, glm::dvec3(0.0), glm::dvec3(1.0));
  m.triangles.erase(m.triangles.end() - 2, m.triangles.end());  // the top face {4, 5, 7, 6}
  m.positions.push_back(apex);
  for (const glm::uvec3& t : {glm::uvec3(4, 5, 8), glm::uvec3(5, 7, 8), glm::uvec3(7, 6, 8), glm::uvec3(6, 4, 8)})
    m.triangles.push_back(t);
  return m;
}

// The unit cube's edge 0-1 split at its midpoint (vertex 8) in the bottom
// face, the gap closed by the flat triangle (0, 8, 1): watertight with every
// fan a disc, but the side triangle (0, 1, 5), still on the whole edge,
// overlaps the bottom's (0, 3, 8) along 0-8 and (8, 3, 1) along 8-1: 2 pairs,
// and 1 triangle of zero area.
inline ContourMesh cube_with_flat_triangle() {
  ContourMesh m;
  add_box(m, glm::dvec3(0.0), glm::dvec3(1.0));
  m.positions.push_back({0.5, 0.0, 0.0});
  for (glm::uvec3& t : m.triangles)
    if (t == glm::uvec3(0, 3, 1)) t = {0, 3, 8};
  m.triangles.push_back({8, 3, 1});
  m.triangles.push_back({0, 8, 1});
  return m;
}

inline ContourMesh triangles(std::vector<glm::dvec3> positions, std::vector<glm::uvec3> tris) {
  ContourMesh m;
  m.positions = std::move(positions);
  m.triangles = std::move(tris);
  return m;
}

struct QualityCase {
  std::string name;
  ContourMesh mesh;
  // Counts worked out by hand.
  size_t boundary_edges, nonmanifold_edges, nonmanifold_vertices, self_intersecting_pairs;
};

inline std::vector<QualityCase> quality_cases() {
  std::vector<QualityCase> cases;
  cases.push_back({"two disjoint cubes", box_pair({2, 0, 0}, {3, 1, 1}), 0, 0, 0, 0});
  // A cube of side 0.2 through the face x = 1 of the unit cube, inside its
  // triangle z >= y: each of its four side faces crosses x = 1 in both of its
  // triangles, each meeting that one triangle: 8 pairs.
  cases.push_back({"interpenetrating cubes", box_pair({0.9, 0.1, 0.6}, {1.1, 0.3, 0.8}), 0, 0, 0, 8});
  // The fan's apex below the bottom: the fan crosses z = 0 in the rectangle
  // [0.2667, 0.6] x [0.3, 0.6333]; of its sides, y = 0.3 and x = 0.6 cross the
  // bottom's diagonal x = y (2 + 2 pairs), the other two stay in y > x (1 + 1).
  cases.push_back({"cube with its top folded through the bottom", cube_with_fan_top({0.4, 0.45, -0.5}), 0, 0, 0, 6});
  cases.push_back({"cube with a dent in its top", cube_with_fan_top({0.4, 0.45, 0.5}), 0, 0, 0, 0});
  // Two triangles on the edge 0-1 with their third corners on the same side, in one plane.
  cases.push_back({"two triangles folded flat onto each other",
                   triangles({{0, 0, 0}, {1, 0, 0}, {0.3, 1, 0}, {0.7, 0.5, 0}}, {{0, 1, 2}, {1, 0, 3}}), 4, 0, 0, 1});
  cases.push_back({"two triangles on an edge, unfolded",
                   triangles({{0, 0, 0}, {1, 0, 0}, {0.3, 1, 0}, {0.7, -0.5, 0}}, {{0, 1, 2}, {1, 0, 3}}), 4, 0, 0, 0});
  cases.push_back({"bow-tie vertex",
                   triangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0.5}, {0, -1, 0.5}}, {{0, 1, 2}, {0, 3, 4}}), 6,
                   0, 1, 0});
  // Sharing vertex 0, the edge 3-4 of the second passes through the first at (0.75, 0.75, 0).
  cases.push_back({"triangle through a triangle it shares a vertex with",
                   triangles({{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {1, 0.5, 1}, {0.5, 1, -1}}, {{0, 1, 2}, {0, 3, 4}}), 6,
                   0, 1, 1});
  cases.push_back({"three triangles on one edge",
                   triangles({{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, 0, 1}, {0.5, -1, -1}},
                             {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}),
                   6, 1, 2, 0});
  cases.push_back({"cube with a flat triangle on an edge", cube_with_flat_triangle(), 0, 0, 0, 2});
  ContourMesh open_box;
  add_box(open_box, glm::dvec3(0.0), glm::dvec3(1.0));
  open_box.triangles.erase(open_box.triangles.end() - 2, open_box.triangles.end());
  cases.push_back({"open box", open_box, 4, 0, 0, 0});
  return cases;
}

}  // namespace ldc::test
