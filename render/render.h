// Preview images of a World, in memory, and a PNG writer.
//
// A pinhole Camera casts one ray per pixel (Queries::ray_cast, through the
// pixel's centre). render() shades the hits: the material's display colour
// (ldc/materials.h) times a fixed sun's lambert term plus ambient light,
// with a hint of the normal's colour; optional shadows (a ray toward the sun
// from each lit hit) and fog (far hits fade toward the sky); misses show a
// sky gradient; a camera inside the solid shows purple. An overlay of
// polylines and points in world coordinates is drawn on top with the same
// camera; parts the solid hides are drawn dimmed (the polylines dashed).
//
// render_gi() lights the same primary hits by a GI engine's irradiance
// (gi_bridge/gi.h: the CPU engine, or the Vulkan one when the caller links
// ldc::gi; this module needs no Vulkan), tone mapped into an image.
//
// Up. Sun, sky, ambient light and the default view are those of a z-up
// world rotated onto CameraConfig::up_axis (the rotation that cycles the
// axes, x -> y -> z -> x, until z lands on the up axis): a y-up level
// rendered with up_axis 1 looks as its z-up twin does with up_axis 2.
//
//   CameraConfig cam;                 // no position or target: frame the solid
//   cam.width = 640;
//   cam.height = 360;
//   Result<Camera> camera = Camera::make(cam, &world);
//   if (!camera) return camera.status();
//   Queries queries(world);
//   Result<Image> image = render(queries, *camera, RenderOptions{});
//   if (image) (void)write_png(*image, "preview.png");
//
// Thread safety: every call is const on its inputs; a Camera is an immutable
// value. render() runs its ray casts in parallel (TBB) and gives the same
// bytes for any thread count. Target ldc::render.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi_bridge/gi.h"
#include "ldc/context.h"
#include "ldc/mesh.h"
#include "ldc/query.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {

inline constexpr int kMaxImageSide = 8192;

// An 8-bit sRGB image: rows from the top, 3 bytes a pixel (r, g, b).
struct Image {
  int width = 0;             // [Units: pixels]
  int height = 0;            // [Units: pixels]
  std::vector<uint8_t> rgb;  // 3 * width * height bytes
};

struct CameraConfig {
  // Where the camera stands. [Units: m] [Limit: finite, not the target]
  // [Default: a view of the world's solid from above and to the side (the
  // direction (0.9, -1.3, 0.9) from the target, z up), as near as shows all
  // of its box]
  std::optional<glm::dvec3> position;
  // The point the camera looks at. [Units: m] [Limit: finite]
  // [Default: the centre of the world's solid box]
  std::optional<glm::dvec3> target;
  // The world axis pointing up: 0 x, 1 y, 2 z. The image's up is its part
  // normal to the view (+y, rotated as above, when looking along it).
  // [Limit: 0, 1, 2] [Default: 2 (z)]
  int up_axis = 2;
  double fov_degrees = 50.0;  // vertical field of view [Units: degrees] [Limit: (0, 180)] [Default: 50]
  int width = 960;            // [Units: pixels] [Limit: 1 .. kMaxImageSide] [Default: 960]
  int height = 540;           // [Units: pixels] [Limit: 1 .. kMaxImageSide] [Default: 540]
};

// The checks of Camera::make that need no world: sizes, fov, up axis,
// finite points, position != target. The error names the field and value.
Status check_camera_config(const CameraConfig& config);

class Camera {
 public:
  // Checks the config and fills in a missing target or position from the
  // world's solid box; `world` may be null when both are given. Fails when
  // one is missing and the world holds no solid, or when the position is
  // the default target.
  static Result<Camera> make(const CameraConfig& config, const World* world = nullptr);

  int width() const { return width_; }
  int height() const { return height_; }
  int up_axis() const { return up_axis_; }
  const glm::dvec3& position() const { return position_; }
  const glm::dvec3& target() const { return target_; }
  double fov() const { return fov_deg_; }  // [Units: degrees]

  // The ray through the centre of pixel (x, y); y = 0 is the top row.
  Ray pixel_ray(int x, int y) const;

  // Where p lands on the image, in pixels (x right, y down, pixel centres at
  // +0.5), and its depth along the view axis; nullopt when p is not in front
  // of the camera (depth at most `near`).
  struct Projected {
    glm::dvec2 pixel;
    double depth;
  };
  std::optional<Projected> project(const glm::dvec3& p, double near = 1e-6) const;

  // Unit, from the position toward the target.
  const glm::dvec3& forward() const { return forward_; }

 private:
  void set_basis();
  void frame(const WorldBox& box, const glm::dvec3& away);

  glm::dvec3 position_{0.0}, target_{0.0};
  double fov_deg_ = 50.0;
  int width_ = 1, height_ = 1, up_axis_ = 2;
  glm::dvec3 forward_{0.0}, right_{0.0}, up_{0.0};
  double tan_half_ = 1.0;  // tan(fov / 2): the image's half height at distance 1
};

// Bounds on the overlay (issue 24): the vertices and points one overlay may
// give, and the samples drawn along its paths. Each path segment is clipped to
// the image (plus the line's width) before it is sampled about 0.7 pixels
// apart, so a segment costs at most about (width + height) samples however
// long it is in the world; more than kMaxOverlaySamples in all is refused with
// kTooLarge rather than run out of memory.
inline constexpr size_t kMaxOverlayVertices = 1'000'000;
inline constexpr size_t kMaxOverlaySamples = 4'000'000;

// What is drawn over the shaded image, in world coordinates.
struct Overlay {
  std::vector<std::vector<glm::dvec3>> paths;  // polylines, yellow [Units: m] [Limit: finite] [Default: none]
  std::vector<glm::dvec3> points;              // dots, pink [Units: m] [Limit: finite] [Default: none]
};

struct RenderOptions {
  bool shadows = false;  // a ray toward the sun from each lit hit [Default: off]
  // How much of the sky's colour the farthest hits take (from the target's
  // distance on, full at three times it). [Limit: 0 .. 1] [Default: 0.25]
  double fog = 0.25;
  Overlay overlay;  // [Default: nothing drawn]
};

struct RenderStats {
  size_t rays = 0;            // primary rays, one per pixel
  size_t hits = 0;
  size_t started_inside = 0;  // rays whose start is inside the solid (shown purple)
  size_t shadow_rays = 0;
  double cast_seconds = 0.0;  // in Queries::ray_cast, primary and shadow rays
  // The overlay: vertices and points given, samples drawn, of them hidden.
  size_t path_vertices = 0, points = 0, overlay_samples = 0, hidden_samples = 0;
  double overlay_seconds = 0.0;
};

// An error naming the bad field (fog, an overlay point), or ok.
Status check_render_options(const RenderOptions& options);

// The shaded image of queries.world() seen by `camera`, with the overlay.
// ctx reports progress ("render") and may cancel; stats may be null.
Result<Image> render(const Queries& queries, const Camera& camera, const RenderOptions& options,
                     RenderStats* stats = nullptr, Context* ctx = nullptr);

// Linear radiance per pixel, rows from the top (what render_gi tone maps).
struct RadianceImage {
  int width = 0, height = 0;
  std::vector<glm::vec3> pixels;  // width * height [Units: radiance]
};

// How render_gi shades its hits.
struct GiImageOptions {
  MaterialTable materials = default_material_table();  // albedo and emission per material id
  SkyLight sky;                                        // what misses show
  int bounces = 1;  // as GiEngine::irradiance [Limit: 1 .. 3]
  // Progress (stage "gi image", after each block of queries) and
  // cancellation (checked between blocks: kCancelled, no image). nullptr: none.
  Context* ctx = nullptr;
};

// Primary hits by ray cast, one irradiance query per hit: albedo / pi *
// irradiance + emission from the materials; misses show the sky, a start
// inside the solid black. The engine must be loaded and lit
// (GiEngine::load, update_all).
Result<RadianceImage> render_gi(const Queries& queries, const Camera& camera, GiEngine& gi,
                                const GiImageOptions& options);

// Per channel: times `exposure`, then x / (1 + x), then gamma 2.2, to 8 bits;
// a product that is not > 0 (negative, NaN) gives 0.
Image tone_map(const RadianceImage& radiance, float exposure);

// --- Triangle meshes -------------------------------------------------------------

// How render_mesh draws: flat shading by each triangle's normal under a
// sun, its edges darkened so that the tessellation shows (levels of detail),
// and triangles seen from behind left out, so that a crack in a closed mesh
// shows the background through it.
struct MeshRenderOptions {
  // Per triangle, linear 0..1; empty: all grey. [Limit: empty or one per triangle] [Default: empty]
  std::vector<glm::vec3> triangle_colour;
  double edge_pixels = 0.6;                     // edges within this of a pixel centre are darkened; 0: none [Units: pixels]
  glm::dvec3 sun{0.55, -0.35, 0.75};            // toward the sun, any length but zero [Default: as render's, z up]
  glm::dvec3 background{0.86, 0.89, 0.94};      // what no triangle covers [Default: render's horizon colour]
};

// The mesh seen by `camera`, z-buffered, clipped at 1 mm in front of it.
// kInvalidArgument for a triangle index past the vertices or a colour count
// that is not one per triangle. Single-threaded: meant for pictures (about
// 10 million small triangles a second).
Result<Image> render_mesh(const TriangleMesh& mesh, const Camera& camera, const MeshRenderOptions& options = {});

// `right` placed to the right of `left`; fails unless the heights agree.
Result<Image> side_by_side(const Image& left, const Image& right);

// Writes an 8-bit RGB PNG atomically: to path + ".tmp", then renamed over
// `path`; on failure neither is left behind. Errors name the path.
Status write_png(const Image& image, const std::string& path);

}  // namespace ldc
