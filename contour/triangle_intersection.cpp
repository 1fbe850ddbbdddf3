// Exact orientation predicates (filtered, with an expansion-arithmetic
// fallback) and the closed triangle-triangle test built on them. See
// contour/detail/triangle_intersection.h for the rules.
//
// The triangle test uses orientation signs only, so it is exact:
// - each triangle's corners against the other's plane: all strictly on one
//   side, no intersection;
// - all in the plane: a 2D test in a coordinate plane onto which the first
//   triangle projects without degenerating (an affine bijection of the plane,
//   so every incidence is kept): an edge of one crosses an edge of the other,
//   or a corner of one lies in the other;
// - otherwise the two triangles meet along the line where their planes cross
//   iff an edge of one meets the other (the ends of the overlap of the two
//   intervals on that line lie on edges). An edge crossing a plane at one
//   point meets the triangle iff the three signs orient3d(a, b, t_k, t_k+1)
//   are not of mixed sign (Pluecker coordinates; a zero is on an edge).
#include "contour/detail/triangle_intersection.h"

#include <algorithm>
#include <cmath>

namespace ldc::detail {
namespace {

// --- Expansion arithmetic (Shewchuk 1997) ----------------------------------

constexpr double kEpsilon = 0x1p-53;  // half an ulp of 1
constexpr double kOrient2dBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;
constexpr double kOrient3dBound = (7.0 + 56.0 * kEpsilon) * kEpsilon;

// a + b = s + e exactly.
inline void two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  const double bv = s - a;
  e = (a - (s - bv)) + (b - bv);
}

// a * b = p + e exactly (no overflow or underflow).
inline void two_product(double a, double b, double& p, double& e) {
  p = a * b;
  e = std::fma(a, b, -p);
}

// A sum of doubles held exactly: nonoverlapping components, increasing in
// magnitude, zeros dropped. Its sign is the sign of the largest component.
class Expansion {
 public:
  void add(double b) {  // Grow-Expansion, in place
    double q = b;
    int m = 0;
    for (int i = 0; i < n_; ++i) {
      double s, e;
      two_sum(q, c_[i], s, e);
      q = s;
      if (e != 0.0) c_[m++] = e;
    }
    if (q != 0.0) c_[m++] = q;
    n_ = m;
  }
  // Adds sign * x * y * z exactly.
  void add_product(double sign, double x, double y, double z) {
    double p, e, p1, e1, p2, e2;
    two_product(x, y, p, e);
    two_product(p, z, p1, e1);
    add(sign * p1);
    add(sign * e1);
    if (e != 0.0) {
      two_product(e, z, p2, e2);
      add(sign * p2);
      add(sign * e2);
    }
  }
  void add_product(double sign, double x, double y) {
    double p, e;
    two_product(x, y, p, e);
    add(sign * p);
    add(sign * e);
  }
  int sign() const { return n_ == 0 ? 0 : (c_[n_ - 1] > 0.0 ? 1 : -1); }

 private:
  double c_[208];  // at most one component per add: orient3d adds at most 48 * 4
  int n_ = 0;
};

// x - y = hi + lo exactly.
struct Diff {
  double part[2];
};
inline Diff exact_diff(double x, double y) {
  Diff d;
  two_sum(x, -y, d.part[0], d.part[1]);
  return d;
}

int orient3d_exact(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) {
  Diff m[3][3];  // rows b - a, c - a, d - a
  const glm::dvec3* rows[3] = {&b, &c, &d};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) m[r][k] = exact_diff((*rows[r])[k], a[k]);
  // det = sum over permutations p of sign(p) m[0][p0] m[1][p1] m[2][p2]
  constexpr int kPerm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  Expansion sum;
  for (int p = 0; p < 6; ++p) {
    const double sign = p < 3 ? 1.0 : -1.0;
    for (int h = 0; h < 8; ++h) {
      const double x = m[0][kPerm[p][0]].part[h & 1];
      const double y = m[1][kPerm[p][1]].part[(h >> 1) & 1];
      const double z = m[2][kPerm[p][2]].part[(h >> 2) & 1];
      if (x != 0.0 && y != 0.0 && z != 0.0) sum.add_product(sign, x, y, z);
    }
  }
  return sum.sign();
}

int orient2d_exact(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, int i, int j) {
  const Diff ui = exact_diff(b[i], a[i]), uj = exact_diff(b[j], a[j]);
  const Diff vi = exact_diff(c[i], a[i]), vj = exact_diff(c[j], a[j]);
  Expansion sum;  // ui * vj - uj * vi
  for (int h = 0; h < 4; ++h) {
    if (ui.part[h & 1] != 0.0 && vj.part[h >> 1] != 0.0) sum.add_product(1.0, ui.part[h & 1], vj.part[h >> 1]);
    if (uj.part[h & 1] != 0.0 && vi.part[h >> 1] != 0.0) sum.add_product(-1.0, uj.part[h & 1], vi.part[h >> 1]);
  }
  return sum.sign();
}

// --- 2D tests in a coordinate plane (i, j) ----------------------------------

// The coordinate plane onto which triangle t projects without degenerating.
void projection(const glm::dvec3 (&t)[3], int& i, int& j) {
  const glm::dvec3 n = glm::abs(glm::cross(t[1] - t[0], t[2] - t[0]));
  int k = n.x >= n.y && n.x >= n.z ? 0 : n.y >= n.z ? 1 : 2;  // dominant normal axis first
  for (int tries = 0; tries < 3; ++tries, k = (k + 1) % 3) {
    i = (k + 1) % 3;
    j = (k + 2) % 3;
    if (orient2d(t[0], t[1], t[2], i, j) != 0) return;
  }
}

// p lies on the closed segment a-b, given that the three are collinear.
bool between(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& p, int i, int j) {
  return std::min(a[i], b[i]) <= p[i] && p[i] <= std::max(a[i], b[i]) && std::min(a[j], b[j]) <= p[j] &&
         p[j] <= std::max(a[j], b[j]);
}

bool segments_meet_2d(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d, int i,
                      int j) {
  const int o1 = orient2d(a, b, c, i, j), o2 = orient2d(a, b, d, i, j);
  if (o1 * o2 > 0) return false;
  const int o3 = orient2d(c, d, a, i, j), o4 = orient2d(c, d, b, i, j);
  if (o3 * o4 > 0) return false;
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && between(a, b, c, i, j)) || (o2 == 0 && between(a, b, d, i, j)) ||
         (o3 == 0 && between(c, d, a, i, j)) || (o4 == 0 && between(c, d, b, i, j));
}

bool point_in_triangle_2d(const glm::dvec3& p, const glm::dvec3 (&t)[3], int i, int j) {
  const int o0 = orient2d(t[0], t[1], p, i, j), o1 = orient2d(t[1], t[2], p, i, j), o2 = orient2d(t[2], t[0], p, i, j);
  const bool negative = o0 < 0 || o1 < 0 || o2 < 0, positive = o0 > 0 || o1 > 0 || o2 > 0;
  return !(negative && positive);
}

bool segment_meets_triangle_2d(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3 (&t)[3], int i, int j) {
  if (point_in_triangle_2d(a, t, i, j) || point_in_triangle_2d(b, t, i, j)) return true;
  for (int k = 0; k < 3; ++k)
    if (segments_meet_2d(a, b, t[k], t[(k + 1) % 3], i, j)) return true;
  return false;
}

bool coplanar_triangles_meet(const glm::dvec3 (&t)[3], const glm::dvec3 (&u)[3]) {
  int i, j;
  projection(t, i, j);
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l)
      if (segments_meet_2d(t[k], t[(k + 1) % 3], u[l], u[(l + 1) % 3], i, j)) return true;
  return point_in_triangle_2d(u[0], t, i, j) || point_in_triangle_2d(t[0], u, i, j);
}

// --- 3D ---------------------------------------------------------------------

// Segment a-b against triangle t, given the sides sa, sb of a and b against t's plane.
bool segment_meets_triangle(const glm::dvec3& a, const glm::dvec3& b, int sa, int sb, const glm::dvec3 (&t)[3]) {
  if (sa * sb > 0) return false;
  if (sa == 0 && sb == 0) {
    int i, j;
    projection(t, i, j);
    return segment_meets_triangle_2d(a, b, t, i, j);
  }
  const int s0 = orient3d(a, b, t[0], t[1]), s1 = orient3d(a, b, t[1], t[2]), s2 = orient3d(a, b, t[2], t[0]);
  const bool negative = s0 < 0 || s1 < 0 || s2 < 0, positive = s0 > 0 || s1 > 0 || s2 > 0;
  return !(negative && positive);
}

// Floating-point filters, each a proof that two triangles do not meet, with
// a margin (1e-9 of the magnitudes) far above double rounding; when unsure
// they say nothing and the exact tests decide. They spare the exact
// predicates the bulk of neighbouring pairs on flat or gently curved
// surfaces, where everything is nearly coplanar.

// For t = (v, a, b) and u = (v, c, d), projected by (i, j), which is one to
// one on t's plane: a line through v with a and b strictly on one side and c
// and d strictly on the other. The projections then meet only at v, and so
// do the triangles (a common point p != v would project to a common point
// other than v). The line tried is perpendicular to the difference of the
// two corners' bisectors: it parts the two sectors of a fan around v.
bool clearly_apart_at_vertex(const glm::dvec3& v, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                             const glm::dvec3& d, int i, int j) {
  const glm::dvec2 ta(a[i] - v[i], a[j] - v[j]), tb(b[i] - v[i], b[j] - v[j]);
  const glm::dvec2 uc(c[i] - v[i], c[j] - v[j]), ud(d[i] - v[i], d[j] - v[j]);
  const double lta = glm::length(ta), ltb = glm::length(tb), luc = glm::length(uc), lud = glm::length(ud);
  if (!(lta > 0.0 && ltb > 0.0 && luc > 0.0 && lud > 0.0)) return false;
  const glm::dvec2 n = (ta / lta + tb / ltb) - (uc / luc + ud / lud);
  const double ln = glm::length(n);
  auto side = [&](const glm::dvec2& x, double lx) {
    const double s = glm::dot(x, n), tol = 1e-9 * lx * ln;
    return s > tol ? 1 : s < -tol ? -1 : 0;
  };
  return side(ta, lta) > 0 && side(tb, ltb) > 0 && side(uc, luc) < 0 && side(ud, lud) < 0;
}

// Two triangles with no shared corner: an axis on which their projections
// leave a clear gap. Tried: each triangle's normal, and the in-plane normals
// of each triangle's edges (which part any two disjoint coplanar triangles).
bool clearly_apart(const glm::dvec3 (&t)[3], const glm::dvec3 (&u)[3]) {
  auto gap_on = [&](const glm::dvec3& axis) {
    double t_lo = INFINITY, t_hi = -INFINITY, u_lo = INFINITY, u_hi = -INFINITY, size = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double pt = glm::dot(t[k], axis), pu = glm::dot(u[k], axis);
      t_lo = std::min(t_lo, pt), t_hi = std::max(t_hi, pt), u_lo = std::min(u_lo, pu), u_hi = std::max(u_hi, pu);
      size = std::max({size, std::abs(pt), std::abs(pu)});
    }
    const double tol = 1e-9 * size;
    return u_lo > t_hi + tol || t_lo > u_hi + tol;
  };
  for (const auto* tri : {&t, &u}) {
    const glm::dvec3 n = glm::cross((*tri)[1] - (*tri)[0], (*tri)[2] - (*tri)[0]);
    if (gap_on(n)) return true;
    for (int k = 0; k < 3; ++k)
      if (gap_on(glm::cross(n, (*tri)[(k + 1) % 3] - (*tri)[k]))) return true;
  }
  return false;
}

bool same_strict_side(const int (&s)[3]) { return (s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0); }

}  // namespace

int orient3d(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) {
  const double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z;
  const double vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
  const double wx = d.x - a.x, wy = d.y - a.y, wz = d.z - a.z;
  const double vxwy = vx * wy, wxvy = wx * vy;
  const double wxuy = wx * uy, uxwy = ux * wy;
  const double uxvy = ux * vy, vxuy = vx * uy;
  const double det = uz * (vxwy - wxvy) + vz * (wxuy - uxwy) + wz * (uxvy - vxuy);
  const double permanent = (std::abs(vxwy) + std::abs(wxvy)) * std::abs(uz) +
                           (std::abs(wxuy) + std::abs(uxwy)) * std::abs(vz) +
                           (std::abs(uxvy) + std::abs(vxuy)) * std::abs(wz);
  const double bound = kOrient3dBound * permanent;
  if (det > bound) return 1;
  if (-det > bound) return -1;
  // In a plane x, y or z = constant (lattice faces, flat ground): exactly 0.
  if ((ux == 0.0 && vx == 0.0 && wx == 0.0) || (uy == 0.0 && vy == 0.0 && wy == 0.0) ||
      (uz == 0.0 && vz == 0.0 && wz == 0.0))
    return 0;
  return orient3d_exact(a, b, c, d);
}

int orient2d(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, int i, int j) {
  const double left = (b[i] - a[i]) * (c[j] - a[j]);
  const double right = (b[j] - a[j]) * (c[i] - a[i]);
  const double det = left - right;
  const double bound = kOrient2dBound * (std::abs(left) + std::abs(right));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return orient2d_exact(a, b, c, i, j);
}

bool collinear(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  return orient2d(a, b, c, 0, 1) == 0 && orient2d(a, b, c, 1, 2) == 0 && orient2d(a, b, c, 2, 0) == 0;
}

bool segment_meets_triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3 (&t)[3]) {
  return segment_meets_triangle(a, b, orient3d(t[0], t[1], t[2], a), orient3d(t[0], t[1], t[2], b), t);
}

bool triangles_meet(const glm::dvec3 (&t)[3], const glm::dvec3 (&u)[3]) {
  int st[3], su[3];  // t's corners against u's plane, u's against t's
  for (int k = 0; k < 3; ++k) st[k] = orient3d(u[0], u[1], u[2], t[k]);
  if (same_strict_side(st)) return false;
  for (int k = 0; k < 3; ++k) su[k] = orient3d(t[0], t[1], t[2], u[k]);
  if (same_strict_side(su)) return false;
  if (st[0] == 0 && st[1] == 0 && st[2] == 0) return coplanar_triangles_meet(t, u);
  for (int k = 0; k < 3; ++k)
    if (segment_meets_triangle(t[k], t[(k + 1) % 3], st[k], st[(k + 1) % 3], u)) return true;
  for (int k = 0; k < 3; ++k)
    if (segment_meets_triangle(u[k], u[(k + 1) % 3], su[k], su[(k + 1) % 3], t)) return true;
  return false;
}

bool triangle_pair_intersects(const glm::dvec3* positions, const glm::uvec3& t, const glm::uvec3& u) {
  int shared = 0;
  int tk = -1, uk = -1;  // the position in t and u of a shared index
  bool t_shared[3] = {false, false, false};
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l)
      if (t[k] == u[l]) {
        ++shared;
        t_shared[k] = true;
        tk = k;
        uk = l;
      }
  if (shared >= 3) return true;  // the same triangle twice
  if (shared == 2) {
    // Shared edge a-b; c and d are the corners opposite it.
    int free = t_shared[0] ? (t_shared[1] ? 2 : 1) : 0;
    const glm::dvec3& a = positions[t[(free + 1) % 3]];
    const glm::dvec3& b = positions[t[(free + 2) % 3]];
    const glm::dvec3& c = positions[t[free]];
    uint32_t d_index = u[0];
    for (int l = 0; l < 3; ++l)
      if (u[l] != t[0] && u[l] != t[1] && u[l] != t[2]) d_index = u[l];
    const glm::dvec3& d = positions[d_index];
    // In a plane onto which a, b, c project without degenerating: c and d on
    // one side of a-b there (where a coplanar d projects faithfully), then
    // coplanar. The cheap side test first: neighbours rarely fold.
    const glm::dvec3 abc[3] = {a, b, c};
    int i, j;
    projection(abc, i, j);
    if (orient2d(a, b, c, i, j) * orient2d(a, b, d, i, j) <= 0) return false;
    return orient3d(a, b, c, d) == 0;
  }
  const glm::dvec3 pt[3] = {positions[t[0]], positions[t[1]], positions[t[2]]};
  const glm::dvec3 pu[3] = {positions[u[0]], positions[u[1]], positions[u[2]]};
  if (shared == 1) {
    // t = (v, a, b), u = (v, c, d): a-b against u, c-d against t.
    int i, j;
    projection(pt, i, j);
    if (clearly_apart_at_vertex(pt[tk], pt[(tk + 1) % 3], pt[(tk + 2) % 3], pu[(uk + 1) % 3], pu[(uk + 2) % 3], i, j))
      return false;
    return segment_meets_triangle(pt[(tk + 1) % 3], pt[(tk + 2) % 3], pu) ||
           segment_meets_triangle(pu[(uk + 1) % 3], pu[(uk + 2) % 3], pt);
  }
  return !clearly_apart(pt, pu) && triangles_meet(pt, pu);
}

}  // namespace ldc::detail
