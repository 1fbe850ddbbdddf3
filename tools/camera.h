// A pinhole camera for `ldc raycast` and `ldc render`: the same options give
// the same rays in both commands (one per pixel, through the pixel's centre).
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>

#include "ldc/query.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc::tool {

// The camera options as given on the command line (strings until checked).
struct CameraArgs {
  std::string camera;  // "x,y,z"; empty = not given
  std::string target;  // "x,y,z"; empty = not given
  double fov = 50.0;   // vertical field of view [Units: degrees] [Limit: (0, 180)]
  int width = 960;     // [Limit: 1 .. kMaxImageSide]
  int height = 540;    // [Limit: 1 .. kMaxImageSide]
};

inline constexpr int kMaxImageSide = 8192;

// Adds --camera, --target, --fov, --width and --height.
void add_camera_options(CLI::App* cmd, CameraArgs& args, const std::string& what);

// The checks of Camera::make that need no world: sizes, fov, the vectors.
Status check_camera_args(const CameraArgs& args);

class Camera {
 public:
  // Checks the options (width, height, fov, finite vectors, camera != target).
  // A missing target is the centre of the world's solid, a missing camera a view
  // of it from above and to the side (the direction (0.9, -1.3, 0.9), z up), as
  // near as shows all of it. `world` may be null when both are given.
  static Result<Camera> make(const CameraArgs& args, const World* world);

  int width() const { return width_; }
  int height() const { return height_; }
  const glm::dvec3& position() const { return position_; }
  const glm::dvec3& target() const { return target_; }
  double fov() const { return fov_deg_; }

  // The ray through the centre of pixel (x, y); y = 0 is the top row.
  Ray pixel_ray(int x, int y) const;

  // Where p lands on the image, in pixels (x right, y down, pixel centres at
  // +0.5), and its depth along the view axis; nullopt when p is not in front
  // of the camera (depth below `near`).
  struct Projected {
    glm::dvec2 pixel;
    double depth;
  };
  std::optional<Projected> project(const glm::dvec3& p, double near = 1e-6) const;

  // Forward (unit, toward the target) and the image's right and up axes.
  const glm::dvec3& forward() const { return forward_; }

 private:
  void set_basis();

  glm::dvec3 position_{0.0}, target_{0.0};
  double fov_deg_ = 50.0;
  int width_ = 1, height_ = 1;
  glm::dvec3 forward_{0.0}, right_{0.0}, up_{0.0};
  double tan_half_ = 1.0;  // tan(fov / 2): the image's half height at distance 1
};


}  // namespace ldc::tool
