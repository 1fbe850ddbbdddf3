// The path-traced reference (ldc::gi_reference, Embree) that bench_gi and
// `ldc gi --reference` measure the cone tracer against: cases whose answer
// is known exactly. In the first ones every path contributes the same light
// (an open sky above a plane, a closed glowing room), so the Monte Carlo
// estimate has no variance and the tolerance is float rounding. The later
// ones (a ball shading the ground from the sky, a glowing square over a
// black one) have variance: their tolerance is 4 standard errors of the
// estimate, stated beside each, plus the mesh's distance from the shape.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "contour/contour.h"
#include "gi/gi_scenes.h"
#include "gi_bridge/path_trace.h"

namespace ldc {
namespace {

using test::GiBox;

constexpr float kPi = std::numbers::pi_v<float>;

std::unique_ptr<PathTracer> tracer(const ContourMesh& mesh, const GiLights& lights) {
  Result<std::unique_ptr<PathTracer>> pt = PathTracer::create(mesh, test::gi_test_materials(), lights);
  EXPECT_TRUE(pt.ok()) << pt.status().message();
  return std::move(pt).value();
}

ContourMesh contoured(const World& world) {
  Result<ContourMesh> mesh = contour_world(world);
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  return std::move(mesh).value();
}

std::unique_ptr<PathTracer> tracer(const std::vector<GiBox>& boxes, const GiLights& lights) {
  return tracer(contoured(test::build_boxes(boxes)), lights);
}

glm::vec3 irradiance_at(const PathTracer& pt, const glm::dvec3& p, const glm::vec3& n, int bounces,
                        int samples = 64) {
  std::vector<glm::vec3> e(1);
  PathTraceConfig c;
  c.samples = samples;
  const Status s = pt.irradiance(std::vector<glm::dvec3>{p}, std::vector<glm::vec3>{n}, bounces, e, c);
  EXPECT_TRUE(s.ok()) << s.message();
  return e[0];
}

const std::vector<GiBox> kGround = {{{-30, -30, -1}, {30, 30, 0}, 0}};

TEST(PathTrace, UniformSkyOverAnOpenPlaneGivesPiTimesItsRadiance) {
  GiLights lights;
  lights.sky = SkyLight::uniform(glm::vec3(1.0f, 0.5f, 0.25f));
  auto pt = tracer(kGround, lights);
  for (int b = 1; b <= 3; ++b) {
    const glm::vec3 e = irradiance_at(*pt, {0.3, 0.1, 0.0}, {0, 0, 1}, b);
    EXPECT_NEAR(e.r, kPi, 1e-4f) << b << " bounces";
    EXPECT_NEAR(e.g, 0.5f * kPi, 1e-4f);
    EXPECT_NEAR(e.b, 0.25f * kPi, 1e-4f);
  }
}

TEST(PathTrace, ClosedRoomWithSkyOutsideIsBlackInside) {
  GiLights lights;
  lights.sky = SkyLight::uniform(glm::vec3(1.0f));
  auto pt = tracer(test::closed_room(), lights);
  EXPECT_EQ(irradiance_at(*pt, {0.1, 0.2, -0.8}, {0, 0, 1}, 3), glm::vec3(0.0f));
  EXPECT_NEAR(irradiance_at(*pt, {0.1, 0.2, 2.4}, {0, 0, 1}, 1).g, kPi, 1e-4f);  // on the roof, outside
}

// Walls of material 2 (albedo 0.7, emission 4): emission seen after at most
// b - 1 reflections, so 4 pi (1 + 0.7 + ... + 0.7^(b-1)).
TEST(PathTrace, GlowingClosedRoomGivesTheFurnaceIrradiance) {
  auto pt = tracer(test::closed_room(2), GiLights{});
  float expected = 0.0f, term = 4.0f * kPi;
  for (int b = 1; b <= 4; ++b) {
    expected += term;
    term *= 0.7f;
    EXPECT_NEAR(irradiance_at(*pt, {0.1, -0.3, 0.2}, {0, 1, 0}, b).g, expected, 1e-4f * expected) << b << " bounces";
  }
}

TEST(PathTrace, PointLightFollowsTheInverseSquareLawAndCastsShadows) {
  GiLights lights;
  lights.points.push_back({glm::dvec3(0.3, 0.1, 2.0), glm::vec3(8.0f)});
  auto pt = tracer(kGround, lights);
  EXPECT_NEAR(irradiance_at(*pt, {0.3, 0.1, 0.0}, {0, 0, 1}, 1).g, 2.0f, 1e-4f);  // 8 / 2^2
  // 2 m to the side: cos 45 deg / (2 sqrt 2)^2.
  EXPECT_NEAR(irradiance_at(*pt, {2.3, 0.1, 0.0}, {0, 0, 1}, 1).g, 8.0f * std::sqrt(0.5f) / 8.0f, 1e-4f);
  std::vector<GiBox> shaded = kGround;
  shaded.push_back({{0.0, -0.2, 0.8}, {0.6, 0.4, 1.2}, 1});  // a black block between light and point
  auto blocked = tracer(shaded, lights);
  EXPECT_EQ(irradiance_at(*blocked, {0.3, 0.1, 0.0}, {0, 0, 1}, 1).g, 0.0f);
}

// --- Scenes with variance ----------------------------------------------------

// Irradiance at points that share one normal, in one call.
std::vector<glm::vec3> irradiance_at(const PathTracer& pt, const std::vector<glm::dvec3>& p, const glm::vec3& n,
                                     int bounces, int samples) {
  std::vector<glm::vec3> e(p.size());
  PathTraceConfig c;
  c.samples = samples;
  const Status s = pt.irradiance(p, std::vector<glm::vec3>(p.size(), n), bounces, e, c);
  EXPECT_TRUE(s.ok()) << s.message();
  return e;
}

// View factor from a horizontal differential patch to a ball of radius r whose
// centre is at height c over the patch's plane and horizontal distance d from
// it, the ball wholly above that plane (c >= r): a cone of half-angle
// asin(r / D) at angle theta from the normal has projected solid angle
// pi sin^2 cos(theta) while it is above the horizon, so F = (r / D)^2 c / D
// (Howell's catalogue, "differential planar element to sphere").
double ball_view_factor(double r, double c, double d) {
  const double dist = std::hypot(d, c);
  return r * r * c / (dist * dist * dist);
}

// Projected solid angle of the triangles of `mesh` above z = z_min that face
// the point p, seen from a horizontal patch at p, by Lambert's formula for a
// polygon (sum over its edges of the angle the edge subtends times the
// vertical component of the unit normal of the plane through p and the edge).
// For a convex closed part this is the part's own view factor times pi.
double projected_solid_angle_of_front_faces(const ContourMesh& mesh, const glm::dvec3& p, double z_min) {
  double sum = 0.0;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 a = mesh.positions[t[0]] - p, b = mesh.positions[t[1]] - p, c = mesh.positions[t[2]] - p;
    if (std::min({a.z, b.z, c.z}) + p.z < z_min || glm::dot(glm::cross(b - a, c - a), a) >= 0.0) continue;
    const glm::dvec3 v[3] = {a, b, c};
    double phi = 0.0;
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 u = glm::normalize(v[k]), w = glm::normalize(v[(k + 1) % 3]);
      phi += std::acos(std::clamp(glm::dot(u, w), -1.0, 1.0)) * glm::normalize(glm::cross(u, w)).z;
    }
    sum += 0.5 * std::abs(phi);
  }
  return sum;
}

// A black ball (radius 0.5 m, 0.1 m over black ground) under a uniform sky of
// radiance 1: a ground point sees sky (1) or ball (0) along each cosine-weighted
// path, so E = pi (1 - F), and each path is a Bernoulli draw with standard error
// pi sqrt(F (1 - F) / N) of the mean: at most 0.0031 with N = 2^18 paths.
// The ball is contoured at h = 0.05 m, so two references: the contoured
// ball's own F (Lambert's formula over its faces towards the point), which the
// estimate must match within 4 standard errors; and the closed form for a
// sphere, which that F must lie between when taken at r_lo (nearest vertex
// less the sag of the longest edge, e^2 / 8r) and r_hi (farthest vertex).
TEST(PathTrace, BallOverTheGroundShadesTheSkyAsItsViewFactorSays) {
  const double r = 0.5, c = 0.6;
  const glm::dvec3 centre(0.0, 0.0, c);
  const ContourMesh mesh = contoured(test::build_ball_over_ground(centre, r, 3.0, 0.05, 1));
  double r_min = 1e9, r_max = 0.0, edge = 0.0;
  for (const glm::uvec3& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3& a = mesh.positions[t[k]];
      if (a.z < 0.05) continue;  // the ground
      r_min = std::min(r_min, glm::length(a - centre));
      r_max = std::max(r_max, glm::length(a - centre));
      edge = std::max(edge, glm::length(a - mesh.positions[t[(k + 1) % 3]]));
    }
  }
  const double r_lo = r_min - edge * edge / (8.0 * r_min), r_hi = r_max;
  std::printf("ball mesh: vertices %.5f .. %.5f from the centre, longest edge %.4f: radius %.5f .. %.5f\n", r_min,
              r_max, edge, r_lo, r_hi);
  ASSERT_GT(r_lo, 0.49);
  ASSERT_LT(r_hi, 0.51);
  GiLights lights;
  lights.sky = SkyLight::uniform(glm::vec3(1.0f));
  auto pt = tracer(mesh, lights);
  const double offset = PathTraceConfig{}.ray_offset;  // paths start this far above the ground
  const int samples = 1 << 18;
  std::vector<glm::dvec3> points;
  const std::vector<double> distances = {0.0, 0.3, 0.6, 1.0, 1.6, 2.5};
  for (size_t i = 0; i < distances.size(); ++i)
    points.push_back({distances[i] * std::cos(0.9 * double(i)), distances[i] * std::sin(0.9 * double(i)), 0.0});
  const std::vector<glm::vec3> e = irradiance_at(*pt, points, {0, 0, 1}, 3, samples);
  for (size_t i = 0; i < points.size(); ++i) {
    const double d = distances[i];
    const double f = projected_solid_angle_of_front_faces(mesh, points[i] + glm::dvec3(0, 0, offset), 0.05) /
                     std::numbers::pi;
    const double f_lo = ball_view_factor(r_lo, c - offset, d), f_hi = ball_view_factor(r_hi, c - offset, d);
    const double sigma = std::numbers::pi * std::sqrt(f * (1.0 - f) / samples);
    std::printf("ball, d = %.1f: E %.5f, mesh's pi (1 - F) %.5f (F %.5f, sphere's %.5f .. %.5f), sigma %.5f\n", d,
                double(e[i].g), std::numbers::pi * (1.0 - f), f, f_lo, f_hi, sigma);
    EXPECT_GE(f, f_lo) << "d = " << d << ": the mesh's view factor is outside the sphere's";
    EXPECT_LE(f, f_hi) << "d = " << d << ": the mesh's view factor is outside the sphere's";
    EXPECT_NEAR(e[i].g, std::numbers::pi * (1.0 - f), 4.0 * sigma) << "d = " << d;
    EXPECT_EQ(e[i].r, e[i].g);  // a grey sky stays grey
  }
}

// Howell's catalogue C-11: two identical, parallel, directly opposed
// rectangles a x b at distance c.
double opposed_rectangles_view_factor(double a, double b, double c) {
  const double x = a / c, y = b / c, x1 = std::sqrt(1.0 + x * x), y1 = std::sqrt(1.0 + y * y);
  return 2.0 / (std::numbers::pi * x * y) *
         (std::log(x1 * y1 / std::sqrt(1.0 + x * x + y * y)) + x * y1 * std::atan(x / y1) +
          y * x1 * std::atan(y / x1) - x * std::atan(x) - y * std::atan(y));
}

// Howell's catalogue B-3: a differential patch facing a parallel rectangle
// a x b at distance c, under one of its corners.
double corner_view_factor(double a, double b, double c) {
  const double x = a / c, y = b / c, x1 = std::sqrt(1.0 + x * x), y1 = std::sqrt(1.0 + y * y);
  return (x / x1 * std::atan(y / x1) + y / y1 * std::atan(x / y1)) / (2.0 * std::numbers::pi);
}

// A 1 m square glowing with radiance 4 (material 2), 1 m over a black 1 m
// square: the irradiance averaged over the receiver is pi 4 F (C-11). The
// mean is taken over the midpoints of a 32 x 32 grid; that quadrature of the
// per-point view factor (B-3, four corners) differs from C-11 by 3e-5, added
// to the tolerance (and checked small: the two closed forms agree). Each
// path is 4 pi times a Bernoulli draw of F_i, so the mean of M points of N
// paths has standard error 4 pi sqrt(sum F_i (1 - F_i) / N) / M: 0.0049
// (0.2%) with M = 1024 and N = 1024. The boxes' faces lie on lattice planes,
// so the mesh is exact (to the builder's nudge of 5e-5 m, a 1e-4 change in F).
TEST(PathTrace, GlowingSquareOverAnOpposedSquareGivesTheirViewFactor) {
  auto pt = tracer({{{-0.5, -0.5, 1.0}, {0.5, 0.5, 1.1}, 2}, {{-0.5, -0.5, -0.1}, {0.5, 0.5, 0.0}, 1}}, GiLights{});
  const double gap = 1.0 - PathTraceConfig{}.ray_offset;  // paths start this far below the emitter
  const int m = 32, samples = 1024;
  std::vector<glm::dvec3> points;
  double quadrature = 0.0, variance = 0.0;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      const double x = -0.5 + (i + 0.5) / m, y = -0.5 + (j + 0.5) / m;
      points.push_back({x, y, 0.0});
      double f = 0.0;
      for (double a : {0.5 - x, 0.5 + x})
        for (double b : {0.5 - y, 0.5 + y}) f += corner_view_factor(a, b, gap);
      quadrature += f / (m * m);
      variance += f * (1.0 - f);
    }
  }
  const double f = opposed_rectangles_view_factor(1.0, 1.0, gap);
  const double emitted = 4.0 * std::numbers::pi;
  const double sigma = emitted * std::sqrt(variance / samples) / (m * m);
  ASSERT_NEAR(quadrature, f, 1e-4);
  const std::vector<glm::vec3> e = irradiance_at(*pt, points, {0, 0, 1}, 1, samples);
  double mean = 0.0;
  for (const glm::vec3& v : e) mean += double(v.g) / double(e.size());
  const double tolerance = 4.0 * sigma + emitted * std::abs(quadrature - f);
  std::printf("opposed squares: mean E %.5f, pi L F %.5f (F %.5f, midpoint rule %.5f), sigma %.5f, tolerance %.5f\n",
              mean, emitted * f, f, quadrature, sigma, tolerance);
  EXPECT_NEAR(mean, emitted * f, tolerance);
}

// A point light of intensity 8 at (0, 0, 2) over grey ground, and a black
// slab (z 1.0 .. 1.2) over x < 0.4: the shadow ray from a ground point
// (X, y), lifted by the ray offset, passes the height z_t of the slab's top
// edge (x_e, z_t) at x = X (2 - z_t) / (2 - offset), so the ground is lit for
// X > x_e (2 - offset) / (2 - z_t) and dark before. Lit points get I cos / r^2 =
// I 2 / r^3; nothing else lights the ground (black sky, black slab, flat
// ground), so every path adds 0 and the answer is exact up to float rounding.
// x_e and z_t are read from the mesh (the slab's faces lie on lattice planes,
// but the edge comes out at (0.39995, 1.19995), nudged off the nodes), and
// points 5e-5 m either side of the shadow edge must be dark and lit: the ray
// offset alone moves the edge by 5e-4 m, each nudge by about 1e-4 m, float
// rays by about 1e-6 m.
TEST(PathTrace, PointLightAndAHalfPlaneBlockerCastAShadowEdgeWhereTheGeometrySays) {
  GiLights lights;
  const glm::dvec3 light(0.0, 0.0, 2.0);
  lights.points.push_back({light, glm::vec3(8.0f)});
  const ContourMesh mesh =
      contoured(test::build_boxes({{{-3, -3, -0.1}, {3, 3, 0}, 0}, {{-3, -3, 1.0}, {0.4, 3, 1.2}, 1}}));
  // The slab's top edge (x_e, z_t), as contoured: its rightmost top vertices.
  double x_edge = -1e9, x_min = 1e9, z_top = -1e9, z_min = 1e9;
  for (const glm::dvec3& p : mesh.positions) {
    if (p.z > 1.1) x_edge = std::max(x_edge, p.x);
    if (p.z > 1.1 && p.x > 0.35) x_min = std::min(x_min, p.x);
    if (p.z > 1.1) z_top = std::max(z_top, p.z), z_min = std::min(z_min, p.z);
  }
  ASSERT_NEAR(x_min, x_edge, 1e-6);  // a straight edge
  ASSERT_NEAR(z_min, z_top, 1e-5);   // a flat top (to 6e-6: the shadow edge moves 1.25 times that)
  // 0.39995 and 1.19995: the builder nudges points off lattice nodes by a depth step.
  ASSERT_NEAR(x_edge, 0.4, 1e-4);
  ASSERT_NEAR(z_top, 1.2, 1e-4);
  const double offset = PathTraceConfig{}.ray_offset;
  const double shadow_edge = x_edge * (2.0 - offset) / (2.0 - z_top);
  auto pt = tracer(mesh, lights);
  auto lit = [&](const glm::dvec3& p) { return 8.0 * 2.0 / std::pow(glm::length(light - p), 3.0); };
  std::vector<glm::dvec3> points;
  std::vector<double> expected;
  for (double y : {-1.0, 0.0, 1.3}) {
    for (double x : {-1.5, 0.0, 0.5, 0.95, shadow_edge - 5e-5}) {  // in the shadow
      points.push_back({x, y, 0.0});
      expected.push_back(0.0);
    }
    for (double x : {shadow_edge + 5e-5, 1.2, 1.6, 2.4}) {  // lit
      points.push_back({x, y, 0.0});
      expected.push_back(lit(points.back()));
    }
  }
  for (int bounces : {1, 2}) {
    const std::vector<glm::vec3> e = irradiance_at(*pt, points, {0, 0, 1}, bounces, 64);
    for (size_t i = 0; i < points.size(); ++i) {
      EXPECT_NEAR(e[i].g, expected[i], 1e-5 * std::max(expected[i], 1.0))
          << "(" << points[i].x << ", " << points[i].y << "), shadow edge at x = " << shadow_edge << ", "
          << bounces << " bounces";
    }
  }
}

TEST(PathTrace, SameSeedSameResultOtherSeedOtherNoise) {
  GiLights lights;
  lights.sky = SkyLight::gradient(glm::vec3(1.0f), glm::vec3(0.5f), glm::vec3(0.1f));
  std::vector<GiBox> boxes = kGround;
  boxes.push_back({{0.6, -1, 0}, {1.0, 1, 2}, 3});  // a red wall beside the point: noisy bounce light
  auto pt = tracer(boxes, lights);
  const std::vector<glm::dvec3> p = {{0.3, 0.1, 0.0}, {-0.5, 0.3, 0.0}};
  const std::vector<glm::vec3> n = {{0, 0, 1}, {0, 0, 1}};
  std::vector<glm::vec3> a(2), b(2), c(2);
  PathTraceConfig cfg;
  cfg.samples = 32;
  ASSERT_TRUE(pt->irradiance(p, n, 2, a, cfg).ok());
  ASSERT_TRUE(pt->irradiance(p, n, 2, b, cfg).ok());
  cfg.seed = 2;
  ASSERT_TRUE(pt->irradiance(p, n, 2, c, cfg).ok());
  EXPECT_EQ(a, b);
  EXPECT_NE(a[0], c[0]);
}

TEST(PathTrace, BadInputIsRefusedNamingTheValue) {
  auto pt = tracer(kGround, GiLights{});
  const std::vector<glm::dvec3> p = {{0, 0, 0}};
  const std::vector<glm::vec3> n = {{0, 0, 1}};
  std::vector<glm::vec3> e(1), two(2);
  auto message = [&](const std::vector<glm::dvec3>& pts, const std::vector<glm::vec3>& nrm, int bounces,
                     std::vector<glm::vec3>& out, const PathTraceConfig& c) {
    const Status s = pt->irradiance(pts, nrm, bounces, out, c);
    EXPECT_FALSE(s.ok());
    return s.message();
  };
  EXPECT_NE(message(p, n, 1, two, {}).find("size"), std::string::npos);
  EXPECT_NE(message(p, n, 0, e, {}).find("bounces 0"), std::string::npos);
  EXPECT_NE(message(p, n, 17, e, {}).find("bounces 17"), std::string::npos);
  PathTraceConfig c;
  c.samples = 0;
  EXPECT_NE(message(p, n, 1, e, c).find("samples 0"), std::string::npos);
  c = {};
  c.ray_offset = -1.0;
  EXPECT_NE(message(p, n, 1, e, c).find("ray_offset"), std::string::npos);
  c.ray_offset = std::nan("");
  EXPECT_NE(message(p, n, 1, e, c).find("ray_offset"), std::string::npos);
  EXPECT_NE(message({{0, std::nan(""), 0}}, n, 1, e, {}).find("point 0"), std::string::npos);
  EXPECT_NE(message(p, {{0, 0, 0}}, 1, e, {}).find("normal 0"), std::string::npos);
  EXPECT_EQ(e[0], glm::vec3(0.0f));  // nothing written
  ContourMesh empty;
  Result<std::unique_ptr<PathTracer>> none = PathTracer::create(empty, test::gi_test_materials(), GiLights{});
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find("no triangles"), std::string::npos);
}

}  // namespace
}  // namespace ldc
