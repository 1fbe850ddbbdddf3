// Exact orientation predicates and the triangle-pair test that mesh_quality
// counts self-intersections with (contour/triangle_intersection.cpp).
//
// Predicates: the determinant is evaluated in double arithmetic with
// Shewchuk's forward error bound (1997); only when its magnitude is below
// the bound is it recomputed exactly, as a sum of floating-point expansions
// (two_diff / two_product / grow-expansion, also Shewchuk's). The sign is
// exact for every finite input whose products neither overflow nor
// underflow.
//
// Triangles are closed sets; two triangles intersect when they share a
// point. A pair that shares mesh vertices (by index) counts only when it
// meets beyond what it shares, with the rules CGAL's self_intersections uses:
// - three shared indices (the same triangle twice): counted;
// - two (an edge a-b; third vertices c and d): counted when a, b, c, d are
//   coplanar and c, d lie strictly on the same side of the line a-b (the two
//   triangles overlap; folded onto each other);
// - one (a vertex v; t = (v, a, b), u = (v, c, d)): counted when the segment
//   c-d meets t or the segment a-b meets u (if two triangles meet at a point
//   p other than v, the ray from v through p leaves one of them first, on its
//   edge opposite v, at a point of the other);
// - none: counted when the closed triangles meet (touching counts).
// Degenerate triangles (repeated indices, or collinear corners) are not
// tested; mesh_quality counts them apart, as CGAL reports them apart.
#pragma once

#include <glm/glm.hpp>

namespace ldc::detail {

// Sign (-1, 0, 1) of det[b - a, c - a, d - a]: positive when d lies on the
// side of the plane a, b, c that (b - a) x (c - a) points to.
int orient3d(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d);

// Sign of the orientation of a, b, c projected onto coordinates i and j:
// det[(b - a)_ij, (c - a)_ij], positive when counter-clockwise.
int orient2d(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, int i, int j);

// Whether a, b and c lie on one line (exactly).
bool collinear(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

// Whether the closed segment a-b meets the closed triangle t (not degenerate).
bool segment_meets_triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3 (&t)[3]);

// Whether two closed, non-degenerate triangles meet.
bool triangles_meet(const glm::dvec3 (&t)[3], const glm::dvec3 (&u)[3]);

// Whether mesh triangles t and u (vertex indices into positions; neither
// degenerate) intersect beyond the vertices they share, by the rules above.
bool triangle_pair_intersects(const glm::dvec3* positions, const glm::uvec3& t, const glm::uvec3& u);

}  // namespace ldc::detail
