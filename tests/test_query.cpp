// Queries: ray casts, sphere casts, overlaps and closest points against
// analytic shapes and against the contoured mesh.
#include <algorithm>
#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/build.h"
#include "ldc/query.h"
#include "test_util.h"

namespace ldc {
namespace {

World build_primitive(const Primitive& p, double h) {
  GridConfig grid;
  grid.cell_size = h;
  grid.chunk_size = 16;
  auto world = build_from_primitive(p, grid);
  EXPECT_TRUE(world.ok()) << world.status().to_string();
  return std::move(world).value();
}

Primitive sphere(double radius, const glm::dvec3& centre) {
  Primitive p;
  p.shape = Primitive::Shape::kSphere;
  p.radius = radius;
  p.transform[3] = glm::dvec4(centre, 1.0);
  return p;
}

glm::dvec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> n;
  glm::dvec3 v(n(rng), n(rng), n(rng));
  return glm::normalize(v);
}

// Exact first hit of a ray with a sphere, or -1.
double sphere_hit(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& c, double r) {
  const glm::dvec3 oc = o - c;
  const double b = glm::dot(oc, d), q = glm::dot(oc, oc) - r * r, disc = b * b - q;
  if (disc < 0.0) return -1.0;
  const double t = -b - std::sqrt(disc);
  return t >= 0.0 ? t : -1.0;
}

double point_triangle_distance2(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  // Ericson, Real-Time Collision Detection 5.1.5.
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  auto d2of = [&](const glm::dvec3& q) { return glm::dot(p - q, p - q); };
  if (d1 <= 0 && d2 <= 0) return d2of(a);
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return d2of(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return d2of(a + ab * (d1 / (d1 - d3)));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return d2of(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return d2of(a + ac * (d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return d2of(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const double denom = 1.0 / (va + vb + vc);
  return d2of(a + ab * (vb * denom) + ac * (vc * denom));
}

// Distance from p to the nearest triangle of the mesh within `reach`, or reach.
double distance_to_mesh(const ContourMesh& mesh, const glm::dvec3& p, double reach) {
  double best = reach * reach;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 &a = mesh.positions[t.x], &b = mesh.positions[t.y], &c = mesh.positions[t.z];
    const glm::dvec3 lo = glm::min(a, glm::min(b, c)) - reach, hi = glm::max(a, glm::max(b, c)) + reach;
    if (glm::any(glm::lessThan(p, lo)) || glm::any(glm::greaterThan(p, hi))) continue;
    best = std::min(best, point_triangle_distance2(p, a, b, c));
  }
  return std::sqrt(best);
}

TEST(RayCast, SphereHitsLieOnTheAnalyticSurface) {
  const double h = 0.1;
  const glm::dvec3 centre(0.031, 0.017, -0.023);
  World world = build_primitive(sphere(1.0, centre), h);
  Queries queries(world);
  std::mt19937 rng(7);
  double worst = 0.0;
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::dvec3 o = centre + 2.5 * random_unit(rng);
    const glm::dvec3 target = centre + 0.95 * random_unit(rng);
    const glm::dvec3 d = glm::normalize(target - o);
    Result<RayHit> hit = queries.ray_cast({o, d});
    ASSERT_TRUE(hit.ok()) << hit.status().to_string();
    ASSERT_TRUE(hit->hit) << "ray " << i << " aimed inside the sphere missed";
    const double exact = sphere_hit(o, d, centre, 1.0);
    worst = std::max(worst, std::abs(hit->distance - exact));
    EXPECT_NEAR(glm::length(glm::dvec3(hit->normal)), 1.0, 1e-3);
    ++hits;
  }
  std::printf("sphere r=1 h=%.2f: %d hits, worst distance error %.4f h\n", h, hits, worst / h);
  EXPECT_LT(worst, 0.1 * h);
}

TEST(RayCast, HitsLieOnTheContouredSurface) {
  const double h = 0.1;
  struct Case {
    const char* name;
    Primitive shape;
  };
  Primitive box;
  box.shape = Primitive::Shape::kBox;
  box.half_extents = glm::dvec3(0.8, 0.6, 0.5);
  box.transform = glm::rotate(glm::dmat4(1.0), 0.4, glm::dvec3(0.3, 0.5, 0.8));
  Primitive cylinder;
  cylinder.shape = Primitive::Shape::kCylinder;
  cylinder.radius = 0.7;
  cylinder.half_height = 0.8;
  cylinder.transform = glm::rotate(glm::dmat4(1.0), 0.7, glm::dvec3(1.0, 0.2, 0.0));
  for (const Case& c : {Case{"sphere", sphere(1.0, glm::dvec3(0.03, 0.01, -0.02))}, Case{"box", box},
                        Case{"cylinder", cylinder}}) {
    World world = build_primitive(c.shape, h);
    Result<ContourMesh> mesh = contour_world(world);
    ASSERT_TRUE(mesh.ok());
    Queries queries(world);
    std::mt19937 rng(11);
    std::vector<double> errors;
    int agree = 0, total = 0;
    for (int i = 0; i < 1000; ++i) {
      const glm::dvec3 o = 2.5 * random_unit(rng), target = 0.9 * random_unit(rng);
      Result<RayHit> hit = queries.ray_cast({o, target - o});
      ASSERT_TRUE(hit.ok());
      ++total;
      if (!hit->hit) continue;
      ++agree;
      errors.push_back(distance_to_mesh(mesh.value(), hit->point, 2 * h) / h);
    }
    std::sort(errors.begin(), errors.end());
    const double median = errors[errors.size() / 2], p99 = errors[errors.size() * 99 / 100], worst = errors.back();
    std::printf("%s: %d/%d hit, distance to contoured mesh median %.3f h, p99 %.3f h, worst %.3f h\n", c.name, agree,
                total, median, p99, worst);
    EXPECT_LT(p99, kQuerySurfaceTolerance) << c.name;
  }
}

}  // namespace
}  // namespace ldc
