// The path-traced reference (ldc::gi_reference, Embree) that bench_gi and
// `ldc gi --reference` measure the cone tracer against: cases whose answer
// is known exactly. In each of them every path contributes the same light
// (an open sky above a plane, a closed glowing room), so the Monte Carlo
// estimate has no variance and the tolerance is float rounding.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "contour/contour.h"
#include "gi/gi_scenes.h"
#include "gi_bridge/path_trace.h"

namespace ldc {
namespace {

using test::GiBox;

constexpr float kPi = std::numbers::pi_v<float>;

std::unique_ptr<PathTracer> tracer(const std::vector<GiBox>& boxes, const GiLights& lights) {
  const World world = test::build_boxes(boxes);
  Result<ContourMesh> mesh = contour_world(world);
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  Result<std::unique_ptr<PathTracer>> pt = PathTracer::create(mesh.value(), test::gi_test_materials(), lights);
  EXPECT_TRUE(pt.ok()) << pt.status().message();
  return std::move(pt).value();
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
