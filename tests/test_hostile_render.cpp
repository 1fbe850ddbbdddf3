// Issue 24, finding 2: the overlay's cost is bounded by the image, not by the
// path's length in the world. A path zig-zagging +-10 km across a 64 x 64 view
// was sampled up to 20,000 times a segment (3.7 GB, then bad_alloc); each
// segment is now clipped to the image before it is sampled.
#include <gtest/gtest.h>

#include <vector>

#include "ldc/build.h"
#include "render/render.h"

namespace ldc {
namespace {

World small_sphere() {
  Primitive p;
  p.shape = Primitive::Shape::kSphere;
  p.radius = 1.0;
  GridConfig g;
  g.cell_size = 0.1;
  g.chunk_size = 16;
  return build_from_primitive(p, g).value();
}

std::vector<glm::dvec3> zigzag(size_t vertices, double reach) {
  std::vector<glm::dvec3> path;
  for (size_t i = 0; i < vertices; ++i) {
    const double s = i % 2 ? reach : -reach;
    path.emplace_back(0.5 * double(i % 4) - 0.75, s, -s);
  }
  return path;
}

TEST(HostileRender, ZigzagOverlayCostsAtMostTheImageDiagonalPerSegment) {
  const World world = small_sphere();
  CameraConfig config;
  config.position = glm::dvec3(-4.0, 0.0, 0.0);
  config.target = glm::dvec3(0.0);
  config.width = config.height = 64;
  const Camera cam = Camera::make(config, &world).value();
  RenderOptions options;
  options.overlay.paths = {zigzag(2000, 1e4)};
  Queries queries(world);
  RenderStats stats;
  Result<Image> img = render(queries, cam, options, &stats);
  ASSERT_TRUE(img.ok()) << img.status().to_string();
  EXPECT_EQ(stats.path_vertices, 2000u);
  // Each segment crosses the image: at most its clipped length / 0.7 + 1 samples,
  // the box being the image plus a margin of a few pixels on each side.
  EXPECT_GT(stats.overlay_samples, 1999u);
  EXPECT_LT(stats.overlay_samples, 1999u * 160u);
}

TEST(HostileRender, TooManyOverlaySamplesAreRefused) {
  const World world = small_sphere();
  CameraConfig config;
  config.position = glm::dvec3(-4.0, 0.0, 0.0);
  config.target = glm::dvec3(0.0);
  config.width = config.height = 512;
  const Camera cam = Camera::make(config, &world).value();
  RenderOptions options;
  options.overlay.paths = {zigzag(8000, 1e4)};  // about 8000 x 1000 samples on the image
  Queries queries(world);
  Result<Image> img = render(queries, cam, options);
  ASSERT_FALSE(img.ok());
  EXPECT_EQ(img.status().code(), ErrorCode::kTooLarge);
  EXPECT_NE(img.status().message().find("overlay: more than 4000000 samples"), std::string::npos)
      << img.status().message();
}

}  // namespace
}  // namespace ldc
