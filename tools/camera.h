// The camera options of `ldc raycast`, `ldc render` and `ldc gi`: the same
// options give the same rays in every command (render/render.h, Camera).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "ldc/status.h"
#include "ldc/world.h"
#include "render/render.h"

namespace ldc::tool {

// The camera options as given on the command line (strings until checked).
struct CameraArgs {
  std::string camera;  // "x,y,z"; empty = not given
  std::string target;  // "x,y,z"; empty = not given
  double fov = 50.0;   // vertical field of view [Units: degrees] [Limit: (0, 180)]
  int width = 960;     // [Limit: 1 .. kMaxImageSide]
  int height = 540;    // [Limit: 1 .. kMaxImageSide]
};

// Adds --camera, --target, --fov, --width and --height.
void add_camera_options(CLI::App* cmd, CameraArgs& args, const std::string& what);

// The checks of Camera::make that need no world (sizes, fov, the vectors),
// naming the flags.
Status check_camera_args(const CameraArgs& args);

// The camera of the options (checked first) on `world` (a missing target is
// the centre of its solid, a missing camera a view of all of it), with
// `up_axis` up (0 x, 1 y, 2 z). `world` may be null when both are given.
Result<Camera> make_camera(const CameraArgs& args, int up_axis, const World* world);

}  // namespace ldc::tool
