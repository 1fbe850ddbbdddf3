#include "camera.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common.h"
#include "internal/vec_text.h"

namespace ldc::tool {

namespace {

constexpr double kPi = 3.14159265358979323846;

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

Result<Camera> Camera::make(const CameraArgs& args, const World* world) {
  Status checked = check_camera_args(args);
  if (!checked.ok()) return checked;
  Camera c;
  c.width_ = args.width;
  c.height_ = args.height;
  c.fov_deg_ = args.fov;
  c.tan_half_ = std::tan(0.5 * args.fov * kPi / 180.0);

  std::optional<WorldBox> bounds;
  if ((args.camera.empty() || args.target.empty()) && world) bounds = world->solid_bounds();
  if (!args.target.empty()) {
    parse_vec3(args.target, &c.target_);
  } else if (bounds) {
    c.target_ = 0.5 * (bounds->min + bounds->max);
  } else {
    return Status(ErrorCode::kInvalidArgument, "the world holds no solid to aim at: give --target (and --camera)");
  }
  if (!args.camera.empty()) {
    parse_vec3(args.camera, &c.position_);
    if (c.position_ == c.target_) {  // the camera at the default target
      return Status(ErrorCode::kInvalidArgument,
                    "--camera " + detail::vec_text(c.position_) + " is the target (the solid's centre): give --target");
    }
    c.set_basis();
    return c;
  }
  // The default view: from above and to the side, as near as shows the whole
  // solid (its box's eight corners inside the image, with a small margin).
  if (!bounds) {
    if (!world) return Status(ErrorCode::kInvalidArgument, "give --camera");
    bounds = world->solid_bounds();
    if (!bounds) return Status(ErrorCode::kInvalidArgument, "the world holds no solid to frame: give --camera");
  }
  const glm::dvec3 away = glm::normalize(glm::dvec3(0.9, -1.3, 0.9));
  c.position_ = c.target_ + away;  // distance 1 for now: only the basis matters
  c.set_basis();
  const double tan_v = c.tan_half_ / 1.08, tan_h = tan_v * double(c.width_) / double(c.height_);
  double distance = 1e-3;
  for (int i = 0; i < 8; ++i) {
    glm::dvec3 corner((i & 1) ? bounds->max.x : bounds->min.x, (i & 2) ? bounds->max.y : bounds->min.y,
                      (i & 4) ? bounds->max.z : bounds->min.z);
    glm::dvec3 p = corner - c.target_;
    double x = std::abs(glm::dot(p, c.right_)), y = std::abs(glm::dot(p, c.up_)), z = glm::dot(p, c.forward_);
    distance = std::max({distance, x / tan_h - z, y / tan_v - z});
  }
  // Not nearer than the box's radius: the camera stays outside the box.
  distance = std::max(distance, 1.05 * 0.5 * glm::length(bounds->max - bounds->min));
  c.position_ = c.target_ + distance * away;
  c.set_basis();
  return c;
}

void Camera::set_basis() {
  forward_ = glm::normalize(target_ - position_);
  // z up; looking straight up or down, the image's up is +y.
  glm::dvec3 world_up = std::abs(forward_.z) > 0.999 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(0.0, 0.0, 1.0);
  right_ = glm::normalize(glm::cross(forward_, world_up));
  up_ = glm::cross(right_, forward_);
}

Ray Camera::pixel_ray(int x, int y) const {
  const double aspect = double(width_) / double(height_);
  const double u = (2.0 * (x + 0.5) / width_ - 1.0) * tan_half_ * aspect;
  const double v = (1.0 - 2.0 * (y + 0.5) / height_) * tan_half_;
  Ray r;
  r.origin = position_;
  r.direction = glm::normalize(forward_ + u * right_ + v * up_);
  return r;
}

std::optional<Camera::Projected> Camera::project(const glm::dvec3& p, double near) const {
  const glm::dvec3 d = p - position_;
  const double depth = glm::dot(d, forward_);
  if (!(depth > near)) return std::nullopt;
  const double aspect = double(width_) / double(height_);
  const double u = glm::dot(d, right_) / depth / (tan_half_ * aspect);
  const double v = glm::dot(d, up_) / depth / tan_half_;
  return Projected{{0.5 * (u + 1.0) * width_, 0.5 * (1.0 - v) * height_}, depth};
}

}  // namespace ldc::tool
