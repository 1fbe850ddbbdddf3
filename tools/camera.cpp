#include "camera.h"

#include <sstream>

#include "common.h"
#include "ldc/internal/vec_text.h"

namespace ldc::tool {

namespace {

Status parse_point(const std::string& option, const std::string& text, glm::dvec3* out) {
  if (parse_vec3(text, out)) return {};
  return {ErrorCode::kInvalidArgument, option + " '" + text + "': expected three finite numbers x,y,z"};
}

}  // namespace

void add_camera_options(CLI::App* cmd, CameraArgs& args, const std::string& what) {
  cmd->add_option("--camera", args.camera, "Camera position x,y,z" + what);
  cmd->add_option("--target", args.target, "Point the camera looks at, x,y,z" + what);
  cmd->add_option("--fov", args.fov, "Vertical field of view in degrees, in (0, 180)")->capture_default_str();
  cmd->add_option("--width", args.width, "Image width in pixels, 1 .. 8192")->capture_default_str();
  cmd->add_option("--height", args.height, "Image height in pixels, 1 .. 8192")->capture_default_str();
}

Status check_camera_args(const CameraArgs& args) {
  for (auto [name, value] : {std::pair<const char*, int>{"--width", args.width}, {"--height", args.height}}) {
    if (value < 1 || value > kMaxImageSide) {
      std::ostringstream s;
      s << name << " " << value << ": must be in 1 .. " << kMaxImageSide;
      return Status(ErrorCode::kInvalidArgument, s.str());
    }
  }
  if (!(args.fov > 0.0 && args.fov < 180.0)) {
    std::ostringstream s;
    s << "--fov " << args.fov << ": must be between 0 and 180 degrees (both excluded)";
    return Status(ErrorCode::kInvalidArgument, s.str());
  }
  glm::dvec3 camera, target;
  if (!args.camera.empty()) {
    Status s = parse_point("--camera", args.camera, &camera);
    if (!s.ok()) return s;
  }
  if (!args.target.empty()) {
    Status s = parse_point("--target", args.target, &target);
    if (!s.ok()) return s;
  }
  if (!args.camera.empty() && !args.target.empty() && camera == target) {
    return Status(ErrorCode::kInvalidArgument,
                  "--camera and --target are the same point " + detail::vec_text(camera) + ": the view has no direction");
  }
  return {};
}

Result<Camera> make_camera(const CameraArgs& args, int up_axis, const World* world) {
  if (Status s = check_camera_args(args); !s.ok()) return s;
  CameraConfig config;
  glm::dvec3 p;
  if (!args.camera.empty() && parse_vec3(args.camera, &p)) config.position = p;
  if (!args.target.empty() && parse_vec3(args.target, &p)) config.target = p;
  config.up_axis = up_axis;
  config.fov_degrees = args.fov;
  config.width = args.width;
  config.height = args.height;
  return Camera::make(config, world);
}

}  // namespace ldc::tool
