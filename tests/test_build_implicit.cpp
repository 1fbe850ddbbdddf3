// Primitives, heightfields and implicit solids: exact crossings, normals, volumes.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <stb_image_write.h>

#include "ldc/build.h"
#include "test_util.h"

namespace ldc {
namespace {

using test::is_valid;

// Largest distance between each stored point and the primitive's exact surface,
// with the normal error, over every point of the world.
struct SurfaceError {
  double max_distance = 0.0;   // m
  double max_normal_deg = 0.0;
  size_t points = 0;
};

SurfaceError measure(const World& w, const ImplicitSolid& solid, const glm::dvec3& centre_for_normal,
                     bool sphere) {
  SurfaceError e;
  const int c = w.chunk_size();
  w.for_each_chunk([&](const glm::ivec3& ch, ChunkKind, const Chunk* d) {
    if (!d) return;
    for (int a = 0; a < 3; ++a) {
      for (int r = 0; r < c * c; ++r) {
        glm::ivec2 uv(ch[axis_u(a)] * c + r % c, ch[axis_v(a)] * c + r / c);
        for (const PackedPoint& p : d->axis[a].points(r)) {
          SurfacePoint s = decode_point(p, c, ch[a] * c);
          glm::dvec3 q;
          q[a] = s.depth;
          q[axis_u(a)] = uv.x;
          q[axis_v(a)] = uv.y;
          glm::dvec3 world = w.lattice().to_world(q);
          e.max_distance = std::max(e.max_distance, std::abs(solid.value(world)));
          if (sphere) {
            glm::dvec3 exact = glm::normalize(world - centre_for_normal);
            double deg = std::acos(std::min(1.0, glm::dot(exact, glm::dvec3(s.normal)))) * 180.0 / M_PI;
            e.max_normal_deg = std::max(e.max_normal_deg, deg);
          }
          ++e.points;
        }
      }
    }
  });
  return e;
}

TEST(Primitives, SphereCrossingsAreExactToTheDepthStep) {
  Primitive p;
  p.radius = 1.3;
  p.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.31, -0.2, 0.05));
  World w = build_from_primitive(p, {.cells = 64}).value();
  EXPECT_TRUE(is_valid(w));
  auto solid = make_primitive_solid(p);
  SurfaceError e = measure(w, *solid, {0.31, -0.2, 0.05}, true);
  const double h = w.lattice().cell_size;
  EXPECT_GT(e.points, 1000u);
  EXPECT_LT(e.max_distance, h / 1000.0);  // the depth step is h/2048
  EXPECT_LT(e.max_normal_deg, 0.02);
  const double v = 4.0 / 3.0 * M_PI * std::pow(1.3, 3);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(w.volume(a), v, 0.005 * v);
}

TEST(Primitives, EveryShapeUnderARotationAndScaleIsValid) {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(1, 2, 3));
  m = glm::rotate(m, 0.7, glm::normalize(glm::dvec3(1, 2, 3)));
  m = glm::scale(m, glm::dvec3(1.0, 0.5, 1.5));
  for (auto shape : {Primitive::Shape::kSphere, Primitive::Shape::kBox, Primitive::Shape::kCapsule,
                     Primitive::Shape::kCylinder}) {
    Primitive p;
    p.shape = shape;
    p.radius = 0.8;
    p.half_height = 0.6;
    p.half_extents = {0.7, 0.9, 0.5};
    p.transform = m;
    p.material = 3;
    World w = build_from_primitive(p, {.cells = 48}).value();
    EXPECT_TRUE(is_valid(w)) << primitive_shape_name(shape);
    auto solid = make_primitive_solid(p);
    SurfaceError e = measure(w, *solid, {}, false);
    // value() is a distance in local units; the scale is at most 1.5.
    EXPECT_LT(e.max_distance, 1.5 * w.lattice().cell_size / 1000.0) << primitive_shape_name(shape);
    double det = glm::determinant(glm::dmat3(m));
    double local = shape == Primitive::Shape::kSphere ? 4.0 / 3.0 * M_PI * 0.512
                   : shape == Primitive::Shape::kBox  ? 8.0 * 0.7 * 0.9 * 0.5
                   : shape == Primitive::Shape::kCapsule
                       ? M_PI * 0.64 * 1.2 + 4.0 / 3.0 * M_PI * 0.512
                       : M_PI * 0.64 * 1.2;
    EXPECT_NEAR(w.volume(2), local * det, 0.02 * local * det) << primitive_shape_name(shape);
    const glm::dvec3 middle = w.lattice().to_lattice(glm::dvec3(1, 2, 3));  // the transform's translation
    const std::vector<SurfacePoint> centre =
        w.ray_points(2, {int(std::lround(middle.x)), int(std::lround(middle.y))});
    ASSERT_FALSE(centre.empty()) << primitive_shape_name(shape);
    for (const SurfacePoint& q : centre) EXPECT_EQ(q.material, 3) << primitive_shape_name(shape);
  }
}

TEST(Primitives, BoxWithFacesOnLatticePlanesKeepsNodesOnFacesOutside) {
  Primitive p;
  p.shape = Primitive::Shape::kBox;
  p.half_extents = {1.0, 1.0, 1.0};
  GridConfig g;
  g.cell_size = 0.25;
  g.use_origin = true;
  g.origin = glm::dvec3(0.0);
  World w = build_from_primitive(p, g).value();
  EXPECT_TRUE(is_valid(w));
  EXPECT_TRUE(w.inside_node({0, 0, 0}));
  EXPECT_FALSE(w.inside_node({4, 0, 0}));  // on the face x = 1: value 0 is outside
  auto spans = w.ray_spans(0, {0, 0});
  ASSERT_EQ(spans.size(), 1u);
  EXPECT_NEAR(spans[0].enter.depth, -4.0, 1e-3);
  EXPECT_NEAR(spans[0].exit.depth, 4.0, 1e-3);
}

TEST(Primitives, BadParametersAreRefused) {
  Primitive p;
  p.radius = -1.0;
  EXPECT_FALSE(build_from_primitive(p, {}).ok());
  p.radius = 1.0;
  p.transform = glm::dmat4(0.0);
  Result<World> w = build_from_primitive(p, {});
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find("invertible"), std::string::npos);
}

// Issue 24, item 4: a 1e-170 sphere built every chunk solid (its squared
// sizes underflow) and wrote a world its own loader refused.
TEST(Primitives, SizesWhoseSquaresUnderflowAreRefused) {
  Primitive tiny;
  tiny.radius = 1e-170;
  Result<World> w = build_from_primitive(tiny, {});
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().message(), "sphere: smallest half size 1e-170 m (after the transform) is below the limit of 1e-100 m");
  Primitive scaled;  // a unit box scaled below the limit (still invertible in doubles)
  scaled.shape = Primitive::Shape::kBox;
  scaled.transform = glm::scale(glm::dmat4(1.0), glm::dvec3(1e-101));
  EXPECT_EQ(check_primitive(scaled).message(),
            "box: smallest half size 1e-101 m (after the transform) is below the limit of 1e-100 m");
}

// A primitive just above that limit still gets a lattice whose cubes
// underflow at 128 cells: the shared lattice check names the cell size.
TEST(Primitives, CellsBelowTheSmallestCellSizeAreRefused) {
  Primitive small;
  small.radius = 1e-99;
  Result<World> w = build_from_primitive(small, {.cells = 128});
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find("implicit: cell size 1.5625e-101 m is below the limit of 1e-100 m"),
            std::string::npos)
      << w.status().message();
  EXPECT_TRUE(build_from_primitive(small, {.cells = 8}).ok());
}

TEST(Heightfield, ZRaysCrossAtTheSurfaceHeight) {
  auto f = [](double x, double y) { return 2.0 + 0.5 * std::sin(x) * std::cos(0.7 * y); };
  Heightfield hf = heightfield_from_function(65, 65, 0.25, f, 0.0);
  GridConfig g;
  g.cell_size = 0.25;
  g.use_origin = true;
  g.origin = glm::dvec3(0.0);
  World w = build_from_heightfield(hf, g).value();
  EXPECT_TRUE(is_valid(w));
  for (int i : {3, 17, 40}) {
    for (int j : {5, 22, 61}) {
      auto spans = w.ray_spans(2, {i, j});
      ASSERT_EQ(spans.size(), 1u);
      double z = spans[0].exit.depth * 0.25;
      EXPECT_NEAR(z, f(i * 0.25, j * 0.25), 0.25 / 2000.0);
      EXPECT_GT(spans[0].exit.normal.z, 0.0f);
    }
  }
}

TEST(Heightfield, BadFieldsAreRefused) {
  Heightfield hf;
  hf.width = 1;
  hf.height = 5;
  EXPECT_FALSE(build_from_heightfield(hf, {}).ok());
  hf = heightfield_from_function(4, 4, 0.5, [](double, double) { return 1.0; }, 0.0);
  hf.samples[5] = std::nanf("");
  Result<World> w = build_from_heightfield(hf, {});
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find("sample 5"), std::string::npos);
  EXPECT_FALSE(load_heightfield_png("/nonexistent.png", 0.2, 1, 1, 0).ok());
}

// An implicit solid that lies about its bounds: nodes outside them are outside anyway.
class LyingBall final : public ImplicitSolid {
 public:
  double value(const glm::dvec3& p) const override { return glm::length(p) - 1.0; }
  WorldBox bounds() const override { return {glm::dvec3(-0.5), glm::dvec3(0.5)}; }
};

TEST(Implicit, SolidsBreakingTheirBoundsContractStillGiveValidWorlds) {
  LyingBall ball;
  World w = build_from_implicit(ball, {.cells = 16}).value();
  EXPECT_TRUE(is_valid(w));
}

}  // namespace
}  // namespace ldc

namespace ldc {
namespace {

TEST(Heightfield, GrayscalePngLoadsAndBuilds) {
  // A 16 x 8 ramp along x, written with stb and read back through the loader.
  std::vector<unsigned char> pixels(16 * 8);
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 16; ++i) pixels[j * 16 + i] = static_cast<unsigned char>(i * 17);
  std::string path = ::testing::TempDir() + "/ramp.png";
  ASSERT_NE(stbi_write_png(path.c_str(), 16, 8, 1, pixels.data(), 16), 0);
  Result<Heightfield> hf = load_heightfield_png(path, 0.5, 3.0, 1.0, 0.0);
  ASSERT_TRUE(hf.ok()) << hf.status().to_string();
  EXPECT_EQ(hf.value().width, 16);
  EXPECT_FLOAT_EQ(hf.value().samples[15], 1.0f);
  GridConfig g;
  g.cell_size = 0.25;
  g.use_origin = true;
  g.origin = glm::dvec3(0.125);  // rays through cell centres of the footprint: a midpoint rule
  World w = build_from_heightfield(hf.value(), g).value();
  EXPECT_TRUE(is_valid(w));
  // Solid volume: 7.5 m x 3.5 m footprint under a ramp from 1 m to 4 m: mean height 2.5 m.
  EXPECT_NEAR(w.volume(2), 7.5 * 3.5 * 2.5, 0.03 * 7.5 * 3.5 * 2.5);
  EXPECT_FALSE(load_heightfield_png(::testing::TempDir() + "/missing.png", 0.5, 1, 1, 0).ok());
}

TEST(BuildProgress, ReportsFractionsUpToOne) {
  Context ctx;
  double last = 0.0;
  bool monotone = true;
  ctx.set_progress([&](std::string_view, double f) {
    monotone = monotone && f >= 0.0 && f <= 1.0;
    last = f;
  });
  Primitive p;
  ASSERT_TRUE(build_from_primitive(p, {.cells = 64, .chunk_size = 8}, &ctx).ok());
  EXPECT_TRUE(monotone);
  EXPECT_DOUBLE_EQ(last, 1.0);
  EXPECT_GT(ctx.timers().count("build"), 0u);
}

TEST(Inside, ArbitraryPointsMatchNodesAndTheShape) {
  Primitive p;
  p.radius = 1.0;
  World w = build_from_primitive(p, {.cells = 64}).value();
  const double h = w.lattice().cell_size;
  for (int i = 0; i < 2000; ++i) {
    glm::dvec3 q(std::sin(i * 1.7) * 1.2, std::cos(i * 2.3) * 1.2, std::sin(i * 0.37) * 1.2);
    double r = glm::length(q);
    if (std::abs(r - 1.0) < 2.0 * h) continue;  // near the surface the lattice decides
    EXPECT_EQ(w.inside(q), r < 1.0) << q.x << " " << q.y << " " << q.z;
  }
  EXPECT_FALSE(w.inside({std::nan(""), 0, 0}));
  EXPECT_FALSE(w.inside({1e300, 0, 0}));
}

}  // namespace
}  // namespace ldc
