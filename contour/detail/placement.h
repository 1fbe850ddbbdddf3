// Vertex placement from the Hermite planes of a cell.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "contour/contour.h"

namespace ldc::detail {

// The crossings on a cell's edges: at most 12 planes (a point and a normal).
struct CellPlanes {
  int count = 0;
  glm::dvec3 point[12];
  glm::dvec3 normal[12];
  uint16_t material[12];
  uint8_t axis[12];  // of the crossed edge

  void add(const glm::dvec3& p, const glm::dvec3& n, uint16_t m, int edge_axis) {
    point[count] = p;
    normal[count] = n;
    material[count] = m;
    axis[count] = uint8_t(edge_axis);
    ++count;
  }
  glm::dvec3 mass_point() const;
  glm::vec3 mean_normal() const;  // unit; +z when the normals cancel
  uint16_t majority_material() const;
  bool mixed_materials() const;
};

// Sum of squared plane distances, sum_i (n_i . (x - p_i))^2, stored as
// x^T A x - 2 b^T x + c.
struct Qef {
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
  glm::dvec3 b{0.0};
  double c = 0;

  static Qef of(const CellPlanes& planes);
  double error(const glm::dvec3& x) const;
  glm::dvec3 times(const glm::dvec3& x) const;  // A x
};

struct PlacedVertex {
  glm::dvec3 position{0.0};  // same coordinates as the planes
  int rank = 3;              // kQef: eigenvalues kept
  bool clamped = false;      // the cell bound moved it
};

// The meshers' quad split rule. p: the quad's corners in lattice units,
// counter-clockwise seen from `facing`, the unit axis of the quad's edge
// pointing from its inside end to its outside end. First, when only one
// diagonal gives two triangles that face that way, that one: the other folds
// a triangle back over its neighbour. With a vertex in each of the four cells
// around the edge the quad is star-shaped about the edge, so one always does;
// material-border relaxation and sharp placement leave quads where the other
// does not (on the default landscape, this rule took the self-intersecting
// pairs of chunk meshes from 726 to 129). Then along corners 0-2 when that
// diagonal's midpoint fits the Hermite planes of its two end cells better
// (e02 < e13, each the summed QEF error at its diagonal's midpoint); ties,
// to within rounding, go to the shorter diagonal. The margins keep
// degenerate triangles, whose sign is rounding, out of the decision, so
// meshers that sum in another order choose alike.
inline bool split_along_02(double e02, double e13, const glm::dvec3 p[4], const glm::dvec3& facing) {
  auto faces = [&](int a, int b, int c) { return glm::dot(glm::cross(p[b] - p[a], p[c] - p[a]), facing) > 1e-9; };
  const bool ok02 = faces(0, 1, 2) && faces(0, 2, 3), ok13 = faces(0, 1, 3) && faces(1, 2, 3);
  if (ok02 != ok13) return ok02;
  if (std::abs(e02 - e13) > 1e-9 * (1.0 + e02 + e13)) return e02 < e13;
  return glm::length(p[0] - p[2]) <= glm::length(p[1] - p[3]);
}

// The far side of the solid corners a sheet wraps, for planes in the
// coordinates of their cell [0, 1]^3: behind the inside end of every one of
// the sheet's crossed edges (the cell face the edge leaves by, for an edge
// of a finer level), seen along the sum of those edges' directions (inside
// end to outside end; a crossing's normal points to the outside end). A
// vertex there that left its cell has turned its part of the surface inside
// out, with nothing intersecting: with cell_slack, the planes of a sheet
// round a lone inside corner (normals tilted by the neighbouring nodes) can
// meet there, and a cell with four lone inside corners (corner
// configuration 150) came out as a closed surface of negative volume. A
// rotated box's corners, which slack is for, lie ahead of the inside ends.
// Only vertices outside their cell are tested, so nothing changes without
// slack.
struct FarSide {
  glm::dvec3 outward{0.0};
  double nearest = -INFINITY;  // least dot(outward, inside end) (none: nowhere is the far side)
  bool holds(const glm::dvec3& x) const { return glm::dot(outward, x) < nearest; }
};
FarSide far_side(const CellPlanes& planes);
bool left_the_cell(const glm::dvec3& x);  // x in cell coordinates

// Places the vertex of planes given in the coordinates of their cell
// [0, 1]^3, within the cell grown by cell_slack, except that a vertex on the
// sheet's far side (FarSide) is placed again within the cell.
// `qef` is Qef::of(planes), computed once by the caller.
PlacedVertex place_vertex(const CellPlanes& planes, const Qef& qef, const ContourConfig& config);

// How many of the QEF's eigenvalues exceed `truncation` times the largest:
// 1 on a flat piece, 2 on a crease, 3 at a corner.
int qef_rank(const Qef& qef, double truncation);

// Several sheets of surface through one cell (a part of the solid, or a gap
// between parts, thinner than a cell): the vertex x of sheet `sheet` kept on
// its own side of the plane halfway between its mass point and each other
// sheet's (`mass`, `count` sheets, x in the same frame). Placed for sharp
// features, two sheets' vertices can meet at the same crease and cross each
// other's fans: on the default landscape's chunk meshes these cells were in
// nine in ten of the self-intersecting pairs that the quad split rule
// leaves; this took them from 129 to 29 (1,154 to 401 after 300 random
// edits), with no measurable loss of accuracy on the shared meshes.
inline glm::dvec3 keep_to_own_sheet(glm::dvec3 x, int sheet, const glm::dvec3* mass, int count) {
  for (int other = 0; other < count; ++other) {
    const glm::dvec3 d = mass[other] - mass[sheet];
    const double dd = glm::dot(d, d);
    if (other == sheet || dd <= 0.0) continue;
    const double over = glm::dot(x - (mass[sheet] + 0.5 * d), d) / dd;
    if (over > 0.0) x -= over * d;
  }
  return x;
}

// Clamps x into the cell grown by `slack` on every side.
glm::dvec3 clamp_to_cell(const glm::dvec3& x, const glm::dvec3& cell_min, double slack, bool* clamped);

}  // namespace ldc::detail
