// Mass point, QEF with a truncated pseudo-inverse (Ju et al. 2002), and the
// iterative particle method (Schmitz, Dietrich & Comba 2009).
#include <algorithm>
#include <cmath>
#include <utility>

#include "contour/detail/placement.h"

namespace ldc::detail {

glm::dvec3 CellPlanes::mass_point() const {
  glm::dvec3 sum(0.0);
  for (int i = 0; i < count; ++i) sum += point[i];
  return count ? sum / double(count) : sum;
}

glm::vec3 CellPlanes::mean_normal() const {
  glm::dvec3 sum(0.0);
  for (int i = 0; i < count; ++i) sum += normal[i];
  double len = glm::length(sum);
  return len > 1e-12 ? glm::vec3(sum / len) : glm::vec3(0.0f, 0.0f, 1.0f);
}

uint16_t CellPlanes::majority_material() const {
  if (!mixed_materials()) return count ? material[0] : 0;
  uint16_t best = count ? material[0] : 0;
  int best_n = 0;
  for (int i = 0; i < count; ++i) {
    int n = 0;
    for (int j = 0; j < count; ++j) n += material[j] == material[i];
    if (n > best_n || (n == best_n && material[i] < best)) {
      best = material[i];
      best_n = n;
    }
  }
  return best;
}

bool CellPlanes::mixed_materials() const {
  for (int i = 1; i < count; ++i)
    if (material[i] != material[0]) return true;
  return false;
}

Qef Qef::of(const CellPlanes& planes) {
  Qef q;
  for (int i = 0; i < planes.count; ++i) {
    const glm::dvec3& n = planes.normal[i];
    double d = glm::dot(n, planes.point[i]);
    q.a00 += n.x * n.x;
    q.a01 += n.x * n.y;
    q.a02 += n.x * n.z;
    q.a11 += n.y * n.y;
    q.a12 += n.y * n.z;
    q.a22 += n.z * n.z;
    q.b += n * d;
    q.c += d * d;
  }
  return q;
}

glm::dvec3 Qef::times(const glm::dvec3& x) const {
  return {a00 * x.x + a01 * x.y + a02 * x.z, a01 * x.x + a11 * x.y + a12 * x.z,
          a02 * x.x + a12 * x.y + a22 * x.z};
}

double Qef::error(const glm::dvec3& x) const {
  return std::max(0.0, glm::dot(x, times(x)) - 2.0 * glm::dot(b, x) + c);
}

glm::dvec3 clamp_to_cell(const glm::dvec3& x, const glm::dvec3& cell_min, double slack, bool* clamped) {
  glm::dvec3 lo = cell_min - slack, hi = cell_min + 1.0 + slack;
  glm::dvec3 y = glm::clamp(x, lo, hi);
  if (clamped) *clamped = y != x;
  return y;
}

namespace {

// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations:
// m = V diag(w) V^T, the columns of v are the eigenvectors.
void jacobi_eigen(double m[3][3], double w[3], double v[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) v[i][j] = i == j;
  const double scale = m[0][0] * m[0][0] + m[1][1] * m[1][1] + m[2][2] * m[2][2] + 1e-300;
  for (int sweep = 0; sweep < 8; ++sweep) {
    double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    if (off < 1e-24 * scale) break;  // converges quadratically: 3 to 5 sweeps
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (std::abs(m[p][q]) < 1e-300) continue;
        double theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
        double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 3; ++k) {  // m = J^T m J
          double mkp = m[k][p], mkq = m[k][q];
          m[k][p] = c * mkp - s * mkq;
          m[k][q] = s * mkp + c * mkq;
        }
        for (int k = 0; k < 3; ++k) {
          double mpk = m[p][k], mqk = m[q][k];
          m[p][k] = c * mpk - s * mqk;
          m[q][k] = s * mpk + c * mqk;
        }
        for (int k = 0; k < 3; ++k) {
          double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  for (int i = 0; i < 3; ++i) w[i] = m[i][i];
}

// Eigen-decomposition of a symmetric 3x3 matrix: eigenvalues in closed form
// (the trigonometric solution of the characteristic cubic), eigenvectors from
// cross products of rows of A - lambda I (Kopp 2008, "Efficient numerical
// diagonalization of hermitian 3x3 matrices"). Where two eigenvalues are too
// close for cross products, the cyclic Jacobi method takes over.
void symmetric_eigen(double m[3][3], double w[3], double v[3][3]) {
  const double p1 = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
  const double q = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
  const double d0 = m[0][0] - q, d1 = m[1][1] - q, d2 = m[2][2] - q;
  const double p2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * p1;
  const double scale = std::abs(q) + std::sqrt(p2) + 1e-300;
  if (p2 < 1e-18 * scale * scale) {  // a multiple of the identity: any basis
    for (int i = 0; i < 3; ++i) {
      w[i] = m[i][i];
      for (int j = 0; j < 3; ++j) v[i][j] = i == j;
    }
    return;
  }
  const double p = std::sqrt(p2 / 6.0);
  double b[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) b[i][j] = (m[i][j] - (i == j ? q : 0.0)) / p;
  double r = (b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) - b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
              b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0])) / 2.0;
  double phi = std::acos(std::clamp(r, -1.0, 1.0)) / 3.0;
  w[0] = q + 2.0 * p * std::cos(phi);
  w[2] = q + 2.0 * p * std::cos(phi + 2.0943951023931953);  // + 2 pi / 3
  w[1] = 3.0 * q - w[0] - w[2];
  // An eigenvector of a distinct eigenvalue is the longest cross product of
  // two rows of A - lambda I. Two close eigenvalues (a flat or gently curved
  // cell: two near-zero ones) share an eigenspace, where any orthonormal
  // pair will do.
  const double gap = 1e-5 * scale;
  const bool top_apart = w[0] - w[1] >= gap, bottom_apart = w[1] - w[2] >= gap;
  auto vector_of = [&](double lambda) {
    glm::dvec3 r0(m[0][0] - lambda, m[0][1], m[0][2]), r1(m[1][0], m[1][1] - lambda, m[1][2]),
        r2(m[2][0], m[2][1], m[2][2] - lambda);
    glm::dvec3 c[3] = {glm::cross(r0, r1), glm::cross(r0, r2), glm::cross(r1, r2)};
    int best = 0;
    for (int i = 1; i < 3; ++i)
      if (glm::dot(c[i], c[i]) > glm::dot(c[best], c[best])) best = i;
    return glm::normalize(c[best]);
  };
  auto any_perpendicular = [](const glm::dvec3& a) {
    glm::dvec3 t = std::abs(a.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    return glm::normalize(glm::cross(a, t));
  };
  glm::dvec3 e[3];
  if (top_apart) {
    e[0] = vector_of(w[0]);
    e[2] = bottom_apart ? vector_of(w[2]) : any_perpendicular(e[0]);
    e[1] = glm::normalize(glm::cross(e[2], e[0]));
  } else if (bottom_apart) {
    e[2] = vector_of(w[2]);
    e[0] = any_perpendicular(e[2]);
    e[1] = glm::normalize(glm::cross(e[2], e[0]));
  } else {
    jacobi_eigen(m, w, v);  // all three close but not equal: rare
    return;
  }
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) v[i][k] = e[k][i];
}

// Minimiser of the QEF nearest the mass point: x = c + A^+ (b - A c), with
// eigenvalues below truncation * largest dropped.
glm::dvec3 solve_qef(const Qef& q, const glm::dvec3& mass, double truncation, int* rank) {
  double m[3][3] = {{q.a00, q.a01, q.a02}, {q.a01, q.a11, q.a12}, {q.a02, q.a12, q.a22}};
  double w[3], v[3][3];
  symmetric_eigen(m, w, v);
  double largest = std::max({std::abs(w[0]), std::abs(w[1]), std::abs(w[2])});
  glm::dvec3 r = q.b - q.times(mass);
  glm::dvec3 x = mass;
  *rank = 0;
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs(w[i]) > truncation * largest) || largest == 0.0) continue;
    glm::dvec3 e(v[0][i], v[1][i], v[2][i]);
    x += e * (glm::dot(e, r) / w[i]);
    ++*rank;
  }
  return x;
}

// The particle method: each step moves the vertex by `step` times the mean
// pull sum_i n_i (n_i . (p_i - x)) / N of the planes. That pull is b - A x
// with the QEF's A and b, so a step costs one 3x3 product, not a pass over
// the planes. Each step is clamped to the box [lo, hi]: projected gradient
// descent, which settles on the best point inside the box when the planes
// meet outside it. *constrained reports whether the box ever stopped it.
glm::dvec3 iterate_particle(const Qef& q, int planes, glm::dvec3 x, int iterations, double step,
                            const glm::dvec3& lo, const glm::dvec3& hi, bool* constrained) {
  const double s = step / planes;
  for (int it = 0; it < iterations; ++it) {
    glm::dvec3 free = x + (q.b - q.times(x)) * s;
    glm::dvec3 next = glm::clamp(free, lo, hi);
    *constrained = *constrained || next != free;
    // Settled: a step below 1e-6 cell changes nothing a mesh can show.
    bool settled = glm::dot(next - x, next - x) < 1e-12;
    x = next;
    if (settled) break;
  }
  return x;
}

// base^k by squaring (k >= 0).
double power(double base, int k) {
  double result = 1.0;
  for (; k > 0; k >>= 1, base *= base)
    if (k & 1) result *= base;
  return result;
}

// The particle method's k unconstrained steps in closed form. The steps are
// linear, x <- x + s/N (b - A x), so in A's eigenbasis each component of the
// residual shrinks by (1 - s lambda / N) per step: after k steps x0 has moved
// by sum_i g(lambda_i) e_i (e_i . r0), g(lambda) = (1 - (1 - s lambda/N)^k) / lambda.
// One eigen-decomposition replaces k passes: many steps cost as little as few.
glm::dvec3 particle_closed_form(const Qef& q, int planes, const glm::dvec3& x0, int iterations, double step) {
  double m[3][3] = {{q.a00, q.a01, q.a02}, {q.a01, q.a11, q.a12}, {q.a02, q.a12, q.a22}};
  double w[3], v[3][3];
  symmetric_eigen(m, w, v);
  const double s = step / planes;
  const glm::dvec3 r = q.b - q.times(x0);
  glm::dvec3 x = x0;
  for (int i = 0; i < 3; ++i) {
    double lambda = std::max(w[i], 0.0);
    double g = lambda * s < 1e-12 ? iterations * s : (1.0 - power(1.0 - s * lambda, iterations)) / lambda;
    glm::dvec3 e(v[0][i], v[1][i], v[2][i]);
    x += e * (g * glm::dot(e, r));
  }
  return x;
}

}  // namespace

int qef_rank(const Qef& q, double truncation) {
  double m[3][3] = {{q.a00, q.a01, q.a02}, {q.a01, q.a11, q.a12}, {q.a02, q.a12, q.a22}};
  double w[3], v[3][3];
  symmetric_eigen(m, w, v);
  const double largest = std::max({std::abs(w[0]), std::abs(w[1]), std::abs(w[2])});
  int rank = 0;
  for (double lambda : w) rank += largest > 0.0 && std::abs(lambda) > truncation * largest;
  return rank;
}

namespace {

PlacedVertex place_in_box(const CellPlanes& planes, const Qef& qef, const glm::dvec3& lo, const glm::dvec3& hi,
                          const ContourConfig& config) {
  PlacedVertex out;
  glm::dvec3 mass = planes.mass_point();
  switch (config.placement) {
    case Placement::kMassPoint:
      out.position = mass;  // inside the cell: a mean of points on its edges
      break;
    case Placement::kIterative: {
      glm::dvec3 x = particle_closed_form(qef, planes.count, mass, config.iterations, config.step);
      out.position = x;
      if (glm::any(glm::lessThan(x, lo)) || glm::any(glm::greaterThan(x, hi))) {
        // It leaves the cell: take steps one by one, each projected into the
        // cell (at most 64: this point is off the planes anyway).
        out.position = iterate_particle(qef, planes.count, mass, std::min(config.iterations, 64), config.step,
                                        lo, hi, &out.clamped);
      }
      break;
    }
    case Placement::kQef: {
      glm::dvec3 x = solve_qef(qef, mass, config.qef_truncation, &out.rank);
      out.position = x;
      if (glm::any(glm::lessThan(x, lo)) || glm::any(glm::greaterThan(x, hi))) {
        // The planes meet outside the cell: settle on the best point inside it.
        out.clamped = true;
        bool unused = false;
        out.position = iterate_particle(qef, planes.count, glm::clamp(x, lo, hi), 32, 1.0, lo, hi, &unused);
      }
      break;
    }
  }
  return out;
}

}  // namespace

FarSide far_side(const CellPlanes& planes) {
  FarSide f;
  glm::dvec3 inside_end[12];
  for (int i = 0; i < planes.count; ++i) {
    const int a = planes.axis[i];
    const bool plus = planes.normal[i][a] > 0.0;  // the normal points to the outside end
    inside_end[i] = planes.point[i];
    inside_end[i][a] = plus ? 0.0 : 1.0;
    f.outward[a] += plus ? 1.0 : -1.0;
  }
  double nearest = INFINITY;
  for (int i = 0; i < planes.count; ++i) nearest = std::min(nearest, glm::dot(f.outward, inside_end[i]));
  if (planes.count > 0) f.nearest = nearest;
  return f;
}

bool left_the_cell(const glm::dvec3& x) {
  return glm::any(glm::lessThan(x, glm::dvec3(0.0))) || glm::any(glm::greaterThan(x, glm::dvec3(1.0)));
}

PlacedVertex place_vertex(const CellPlanes& planes, const Qef& qef, const ContourConfig& config) {
  const double slack = config.cell_slack;
  // 0.0 - slack: +0 without slack, the bound the placement always had.
  PlacedVertex out = place_in_box(planes, qef, glm::dvec3(0.0 - slack), glm::dvec3(1.0 + slack), config);
  if (left_the_cell(out.position) && far_side(planes).holds(out.position)) {  // then no slack
    out = place_in_box(planes, qef, glm::dvec3(0.0), glm::dvec3(1.0), config);
    out.clamped = true;
  }
  return out;
}

}  // namespace ldc::detail
