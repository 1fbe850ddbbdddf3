// The render module: what the image shows (material colour, sky, overlay),
// the up axis, the checks of bad options and the PNG writer.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>
#include <stb_image.h>

#include "ldc/build.h"
#include "ldc/materials.h"
#include "render/render.h"

namespace ldc {
namespace {

GridConfig grid_at(double h) {
  GridConfig g;
  g.cell_size = h;
  g.chunk_size = 16;
  g.use_origin = true;
  g.origin = glm::dvec3(0.0);
  return g;
}

World sphere_world(const glm::dvec3& centre, double radius, uint16_t material) {
  Primitive p;
  p.shape = Primitive::Shape::kSphere;
  p.radius = radius;
  p.material = material;
  p.transform[3] = glm::dvec4(centre, 1.0);
  return build_from_primitive(p, grid_at(0.05)).value();
}

glm::ivec3 pixel(const Image& img, int x, int y) {
  const uint8_t* p = &img.rgb[3 * (size_t(y) * size_t(img.width) + size_t(x))];
  return {p[0], p[1], p[2]};
}

int max_difference(const glm::ivec3& a, const glm::ivec3& b) {
  const glm::ivec3 d = glm::abs(a - b);
  return std::max({d.x, d.y, d.z});
}

// Looking along +x at the origin from (-4, 0, 0), z up.
CameraConfig view_from_minus_x(int width = 80, int height = 60) {
  CameraConfig c;
  c.position = glm::dvec3(-4.0, 0.0, 0.0);
  c.target = glm::dvec3(0.0);
  c.width = width;
  c.height = height;
  return c;
}

Image render_ok(const World& world, const CameraConfig& config, const RenderOptions& options = {}) {
  Result<Camera> camera = Camera::make(config, &world);
  EXPECT_TRUE(camera.ok()) << camera.status().to_string();
  Queries queries(world);
  Result<Image> img = render(queries, camera.value(), options);
  EXPECT_TRUE(img.ok()) << img.status().to_string();
  return img.ok() ? std::move(img).value() : Image{};
}

TEST(Render, SphereFromOutsideCoversTheCentreWithItsMaterialColourAndTheCornersWithTheSky) {
  const uint16_t red = 5;
  const World sphere = sphere_world(glm::dvec3(0.0), 1.0, red);
  RenderOptions options;
  options.fog = 0.0;
  const Image img = render_ok(sphere, view_from_minus_x(), options);
  ASSERT_EQ(img.rgb.size(), size_t(80 * 60 * 3));
  // The centre faces -x, away from the sun (+x side): ambient light only,
  // 0.26 + 0.10 n.z of the material's display colour, with 5% of the
  // normal's colour.
  const Camera cam = Camera::make(view_from_minus_x(), nullptr).value();
  const RayHit hit = Queries(sphere).ray_cast(cam.pixel_ray(40, 30)).value();
  ASSERT_TRUE(hit.hit);
  const glm::vec3 n = hit.normal;
  const glm::vec3 expected =
      glm::mix(material_display_colour(red) * (0.26f + 0.10f * n.z), 0.5f * n + 0.5f, 0.05f) * 255.0f;
  EXPECT_LE(max_difference(pixel(img, 40, 30), glm::ivec3(glm::round(expected))), 1);
  // The corners show the same sky as a view with the sphere far away.
  const World elsewhere = sphere_world(glm::dvec3(0.0, 0.0, -100.0), 1.0, red);
  const Image sky = render_ok(elsewhere, view_from_minus_x(), options);
  for (auto [x, y] : {std::pair{0, 0}, {79, 0}, {0, 59}, {79, 59}}) {
    EXPECT_EQ(pixel(img, x, y), pixel(sky, x, y)) << x << ", " << y;
    EXPECT_GT(pixel(img, x, y).b, pixel(img, x, y).r) << "the sky is blue";
  }
}

// The axes cycled so that z lands on y: x -> z, y -> x, z -> y.
glm::dvec3 z_up_to_y_up(const glm::dvec3& v) { return {v.y, v.z, v.x}; }

World tilted_capsule(bool y_up) {
  Primitive p;
  p.shape = Primitive::Shape::kCapsule;
  p.radius = 0.35;
  p.half_height = 0.6;
  p.material = 1;
  glm::dmat4 t = glm::translate(glm::dmat4(1.0), glm::dvec3(0.2, -0.1, 0.3)) *
                 glm::rotate(glm::dmat4(1.0), glm::radians(35.0), glm::normalize(glm::dvec3(1.0, 0.5, 0.0)));
  if (y_up) {
    const glm::dmat4 cycle(glm::dvec4(0, 0, 1, 0), glm::dvec4(1, 0, 0, 0), glm::dvec4(0, 1, 0, 0),
                           glm::dvec4(0, 0, 0, 1));
    t = cycle * t;
  }
  p.transform = t;
  return build_from_primitive(p, grid_at(0.05)).value();
}

TEST(Render, UpAxisYRendersAYUpSceneAsUpAxisZRendersItsZUpTwin) {
  const World z_world = tilted_capsule(false), y_world = tilted_capsule(true);
  CameraConfig z_view;
  z_view.position = glm::dvec3(3.0, -4.0, 2.5);
  z_view.target = glm::dvec3(0.2, -0.1, 0.3);
  z_view.width = 96;
  z_view.height = 64;
  CameraConfig y_view = z_view;
  y_view.position = z_up_to_y_up(*z_view.position);
  y_view.target = z_up_to_y_up(*z_view.target);
  y_view.up_axis = 1;
  RenderOptions options;
  options.shadows = true;
  const Image z_img = render_ok(z_world, z_view, options), y_img = render_ok(y_world, y_view, options);
  ASSERT_EQ(z_img.rgb.size(), y_img.rgb.size());
  size_t close = 0, far = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 96; ++x) {
      close += max_difference(pixel(z_img, x, y), pixel(y_img, x, y)) <= 2;
    }
  }
  EXPECT_GE(close, size_t(96 * 64 * 99 / 100));
  // With z up the same y-up scene lies on its side: most of the image differs.
  y_view.up_axis = 2;
  const Image sideways = render_ok(y_world, y_view, options);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 96; ++x) far += max_difference(pixel(z_img, x, y), pixel(sideways, x, y)) > 2;
  }
  EXPECT_GT(far, size_t(96 * 64 / 4));
}

TEST(Render, DefaultViewTurnsWithTheUpAxis) {
  const World z_world = tilted_capsule(false), y_world = tilted_capsule(true);
  CameraConfig config;
  const Camera z_cam = Camera::make(config, &z_world).value();
  config.up_axis = 1;
  const Camera y_cam = Camera::make(config, &y_world).value();
  const glm::dvec3 expected = z_up_to_y_up(z_cam.position());
  EXPECT_LT(glm::length(y_cam.position() - expected), 1e-6) << y_cam.position().x << " " << y_cam.position().y;
  EXPECT_LT(glm::length(y_cam.target() - z_up_to_y_up(z_cam.target())), 1e-9);
  EXPECT_GT(z_cam.position().z, z_cam.target().z) << "from above";
  EXPECT_GT(y_cam.position().y, y_cam.target().y) << "from above, y up";
}

TEST(Render, OverlayPointsAreDrawnWhereTheyProject) {
  const World sphere = sphere_world(glm::dvec3(0.0), 1.0, 0);
  const CameraConfig config = view_from_minus_x(160, 120);
  const Camera cam = Camera::make(config, nullptr).value();
  RenderOptions options;
  const glm::dvec3 seen(-2.0, 0.4, 0.3), hidden(2.0, -0.4, -0.3);  // in front of the sphere, and behind it
  options.overlay.points = {seen, hidden};
  const Image plain = render_ok(sphere, config);
  const Image drawn = render_ok(sphere, config, options);
  const glm::ivec3 pink(242, 38, 115);  // (0.95, 0.15, 0.45)
  const glm::dvec2 at = cam.project(seen)->pixel;
  EXPECT_EQ(pixel(drawn, int(at.x), int(at.y)), pink);
  EXPECT_NE(pixel(plain, int(at.x), int(at.y)), pink);
  // The hidden point is drawn dimmed: changed, but not pink.
  const glm::dvec2 behind = cam.project(hidden)->pixel;
  EXPECT_NE(pixel(drawn, int(behind.x), int(behind.y)), pixel(plain, int(behind.x), int(behind.y)));
  EXPECT_NE(pixel(drawn, int(behind.x), int(behind.y)), pink);
  // Away from both points nothing changes.
  EXPECT_EQ(pixel(drawn, 10, 10), pixel(plain, 10, 10));
  EXPECT_EQ(pixel(drawn, 80, 60), pixel(plain, 80, 60));
}

void expect_refused(const CameraConfig& config, const std::string& message) {
  Result<Camera> camera = Camera::make(config, nullptr);
  ASSERT_FALSE(camera.ok());
  EXPECT_EQ(camera.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(camera.status().message().find(message), std::string::npos) << camera.status().message();
}

TEST(RenderCamera, ZeroWidthIsRefusedNamingIt) {
  CameraConfig c = view_from_minus_x();
  c.width = 0;
  expect_refused(c, "width 0: must be in 1 .. 8192");
}

TEST(RenderCamera, NonFinitePositionIsRefusedNamingIt) {
  CameraConfig c = view_from_minus_x();
  c.position = glm::dvec3(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
  expect_refused(c, "camera position (nan, 0, 0): must be finite");
}

TEST(RenderCamera, PositionAtTheTargetIsRefusedNamingThePoint) {
  CameraConfig c;
  c.position = c.target = glm::dvec3(1.0, 2.0, 3.0);
  expect_refused(c, "the same point (1, 2, 3)");
}

TEST(RenderCamera, UpAxisThreeIsRefusedNamingIt) {
  CameraConfig c = view_from_minus_x();
  c.up_axis = 3;
  expect_refused(c, "up_axis 3");
}

TEST(RenderCamera, FovOf180IsRefusedNamingIt) {
  CameraConfig c = view_from_minus_x();
  c.fov_degrees = 180.0;
  expect_refused(c, "fov 180");
}

TEST(RenderCamera, MissingTargetWithoutAWorldIsRefused) {
  CameraConfig c = view_from_minus_x();
  c.target.reset();
  expect_refused(c, "camera target not given");
}

TEST(Render, FogOutsideZeroToOneIsRefusedNamingIt) {
  RenderOptions options;
  options.fog = 1.5;
  Status s = check_render_options(options);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("fog 1.5"), std::string::npos) << s.message();
}

TEST(Render, NonFiniteOverlayPointIsRefusedNamingIt) {
  const World sphere = sphere_world(glm::dvec3(0.0), 1.0, 0);
  RenderOptions options;
  options.overlay.paths = {{glm::dvec3(0.0), glm::dvec3(1.0, std::numeric_limits<double>::infinity(), 0.0)}};
  Result<Image> img = render(Queries(sphere), Camera::make(view_from_minus_x()).value(), options);
  ASSERT_FALSE(img.ok());
  EXPECT_NE(img.status().message().find("overlay paths[0][1] (1, inf, 0): must be finite"), std::string::npos)
      << img.status().message();
}

Image pattern(int width, int height) {
  Image img{width, height, std::vector<uint8_t>(size_t(width) * size_t(height) * 3)};
  for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = uint8_t(i * 37 % 251);
  return img;
}

TEST(RenderPng, WritePngWritesWhatStbReadsBackAndLeavesNoTmp) {
  const std::string path = ::testing::TempDir() + "/render_pattern.png";
  const Image img = pattern(7, 5);
  ASSERT_TRUE(write_png(img, path).ok());
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  int w = 0, h = 0, channels = 0;
  uint8_t* read = stbi_load(path.c_str(), &w, &h, &channels, 3);
  ASSERT_NE(read, nullptr);
  EXPECT_EQ(w, 7);
  EXPECT_EQ(h, 5);
  EXPECT_EQ(std::vector<uint8_t>(read, read + img.rgb.size()), img.rgb);
  stbi_image_free(read);
}

TEST(RenderPng, UnwritablePathFailsNamingItAndLeavesNothing) {
  const std::string path = ::testing::TempDir() + "/no-such-dir/x.png";
  Status s = write_png(pattern(4, 4), path);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_NE(s.message().find(path), std::string::npos) << s.message();
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}

TEST(RenderPng, ImageWhoseBytesDoNotMatchItsSizeIsRefused) {
  Image img = pattern(4, 4);
  img.rgb.pop_back();
  Status s = write_png(img, ::testing::TempDir() + "/bad.png");
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.message().find("4 x 4 pixels with 47 bytes"), std::string::npos) << s.message();
}

TEST(RenderGiImage, ToneMapTakesZeroToBlackAndExposureScales) {
  RadianceImage r{2, 1, {glm::vec3(0.0f), glm::vec3(1.0f, 3.0f, 1e6f)}};
  const Image img = tone_map(r, 1.0f);
  EXPECT_EQ(pixel(img, 0, 0), glm::ivec3(0));
  // x / (1 + x), then gamma 2.2: 1 -> 0.5^(1/2.2), 3 -> 0.75^(1/2.2).
  EXPECT_EQ(pixel(img, 1, 0), glm::ivec3(186, 224, 255));
  EXPECT_EQ(pixel(tone_map(r, 3.0f), 1, 0).x, 224);
}

TEST(RenderGiImage, SideBySidePutsTheRightImageAfterEachRow) {
  const Image a = pattern(3, 2), b = pattern(2, 2);
  Result<Image> both = side_by_side(a, b);
  ASSERT_TRUE(both.ok());
  EXPECT_EQ(both->width, 5);
  EXPECT_EQ(pixel(*both, 2, 1), pixel(a, 2, 1));
  EXPECT_EQ(pixel(*both, 3, 1), pixel(b, 0, 1));
  EXPECT_FALSE(side_by_side(a, pattern(2, 3)).ok());
}

// --- render_mesh -------------------------------------------------------------------

namespace mesh_image {

// The unit cube [0, 1]^3, 12 triangles counter-clockwise seen from outside.
TriangleMesh cube() {
  TriangleMesh m;
  for (int c = 0; c < 8; ++c) m.positions.emplace_back(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    m.triangles.emplace_back(f[0], f[1], f[2]);
    m.triangles.emplace_back(f[0], f[2], f[3]);
  }
  return m;
}

Camera looking_at_cube_from(const glm::dvec3& position) {
  CameraConfig c;
  c.position = position;
  c.target = glm::dvec3(0.5);
  c.width = 64;
  c.height = 64;
  return Camera::make(c).value();
}

glm::ivec3 pixel(const Image& img, int x, int y) {
  const uint8_t* p = &img.rgb[3 * (size_t(y) * size_t(img.width) + size_t(x))];
  return {p[0], p[1], p[2]};
}

glm::ivec3 background_pixel(const MeshRenderOptions& o) {
  return glm::ivec3(glm::round(glm::clamp(o.background, 0.0, 1.0) * 255.0));
}

}  // namespace mesh_image

TEST(RenderMesh, ACubeCoversTheCentreAndLeavesTheCornersAndItsEdgesAreDarkened) {
  const MeshRenderOptions o;
  const Image img = render_mesh(mesh_image::cube(), mesh_image::looking_at_cube_from({0.5, -3.0, 0.5}), o).value();
  ASSERT_EQ(img.width, 64);
  EXPECT_NE(mesh_image::pixel(img, 32, 32), mesh_image::background_pixel(o));
  EXPECT_EQ(mesh_image::pixel(img, 1, 1), mesh_image::background_pixel(o));
  // The face's diagonal (an edge between its two triangles) is darker than the face beside it.
  const glm::ivec3 face = mesh_image::pixel(img, 26, 32), diagonal = mesh_image::pixel(img, 31, 32);  // x + y = 64
  EXPECT_LT(diagonal.x + diagonal.y + diagonal.z, face.x + face.y + face.z);
}

TEST(RenderMesh, ACrackShowsTheBackgroundThroughIt) {
  TriangleMesh open = mesh_image::cube();
  open.triangles.erase(open.triangles.begin() + 4, open.triangles.begin() + 6);  // the y = 0 face, seen by the camera
  const MeshRenderOptions o;
  const Image img = render_mesh(open, mesh_image::looking_at_cube_from({0.5, -3.0, 0.5}), o).value();
  EXPECT_EQ(mesh_image::pixel(img, 26, 34), mesh_image::background_pixel(o));
}

TEST(RenderMesh, ATriangleReachingBehindTheCameraIsClippedNotDropped) {
  TriangleMesh ground;
  ground.positions = {{-100.0, -100.0, 0.0}, {100.0, -100.0, 0.0}, {0.0, 100.0, 0.0}};
  ground.triangles = {{0, 1, 2}};
  CameraConfig c;
  c.position = glm::dvec3(0.0, -50.0, 2.0);
  c.target = glm::dvec3(0.0, 0.0, 0.0);
  c.width = 32;
  c.height = 32;
  const MeshRenderOptions o;
  const Image img = render_mesh(ground, Camera::make(c).value(), o).value();
  EXPECT_NE(mesh_image::pixel(img, 16, 31), mesh_image::background_pixel(o));  // the ground just below the camera
}

TEST(RenderMesh, BadIndicesAndColourCountsAreRefused) {
  TriangleMesh bad = mesh_image::cube();
  bad.triangles.push_back({0, 1, 8});
  const Camera cam = mesh_image::looking_at_cube_from({0.5, -3.0, 0.5});
  Result<Image> r = render_mesh(bad, cam);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("indexes past the 8 vertices"), std::string::npos) << r.status().message();
  MeshRenderOptions o;
  o.triangle_colour.assign(3, glm::vec3(1.0f));
  r = render_mesh(mesh_image::cube(), cam, o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("3 entries for 12 triangles"), std::string::npos) << r.status().message();
}

}  // namespace
}  // namespace ldc
