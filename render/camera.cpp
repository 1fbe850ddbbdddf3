// The pinhole camera of render/render.h: checks, the default view, rays and projection.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "ldc/internal/vec_text.h"
#include "render/detail/up.h"
#include "render/render.h"

namespace ldc {

namespace {

constexpr double kPi = 3.14159265358979323846;

Status bad(const std::string& message) { return Status(ErrorCode::kInvalidArgument, message); }

Status check_point(const char* name, const std::optional<glm::dvec3>& p) {
  if (!p || detail::is_finite(*p)) return {};
  return bad(std::string("camera ") + name + " " + detail::vec_text(*p) + ": must be finite");
}

}  // namespace

Status check_camera_config(const CameraConfig& config) {
  for (auto [name, value] : {std::pair<const char*, int>{"width", config.width}, {"height", config.height}}) {
    if (value < 1 || value > kMaxImageSide) {
      std::ostringstream s;
      s << "camera " << name << " " << value << ": must be in 1 .. " << kMaxImageSide;
      return bad(s.str());
    }
  }
  if (!(config.fov_degrees > 0.0 && config.fov_degrees < 180.0)) {
    std::ostringstream s;
    s << "camera fov " << config.fov_degrees << ": must be between 0 and 180 degrees (both excluded)";
    return bad(s.str());
  }
  if (config.up_axis < 0 || config.up_axis > 2) {
    return bad("camera up_axis " + std::to_string(config.up_axis) + ": must be 0 (x), 1 (y) or 2 (z)");
  }
  if (Status s = check_point("position", config.position); !s.ok()) return s;
  if (Status s = check_point("target", config.target); !s.ok()) return s;
  if (config.position && config.target && *config.position == *config.target) {
    return bad("camera position and target are the same point " + detail::vec_text(*config.target) +
               ": the view has no direction");
  }
  return {};
}

Result<Camera> Camera::make(const CameraConfig& config, const World* world) {
  if (Status s = check_camera_config(config); !s.ok()) return s;
  Camera c;
  c.width_ = config.width;
  c.height_ = config.height;
  c.up_axis_ = config.up_axis;
  c.fov_deg_ = config.fov_degrees;
  c.tan_half_ = std::tan(0.5 * config.fov_degrees * kPi / 180.0);

  std::optional<WorldBox> bounds;
  if ((!config.position || !config.target) && world) bounds = world->solid_bounds();
  if (config.target) {
    c.target_ = *config.target;
  } else if (bounds) {
    c.target_ = 0.5 * (bounds->min + bounds->max);
  } else {
    return bad("camera target not given and the world holds no solid to aim at");
  }
  if (config.position) {
    c.position_ = *config.position;
    if (c.position_ == c.target_) {  // the position at the default target
      return bad("camera position " + detail::vec_text(c.position_) +
                 " is the target (the solid's centre): give a target");
    }
    c.set_basis();
    return c;
  }
  if (!bounds) return bad("camera position not given and the world holds no solid to frame");
  const glm::dvec3 away = detail::from_z_up(glm::normalize(glm::dvec3(0.9, -1.3, 0.9)), c.up_axis_);
  c.frame(*bounds, away);
  return c;
}

// From the target along `away`, as near as shows the whole box (its eight
// corners inside the image, with a small margin) but not nearer than the
// box's radius: the camera stays outside the box.
void Camera::frame(const WorldBox& box, const glm::dvec3& away) {
  position_ = target_ + away;  // distance 1 for now: only the basis matters
  set_basis();
  const double tan_v = tan_half_ / 1.08, tan_h = tan_v * double(width_) / double(height_);
  double distance = 1e-3;
  for (int i = 0; i < 8; ++i) {
    glm::dvec3 corner((i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y,
                      (i & 4) ? box.max.z : box.min.z);
    glm::dvec3 p = corner - target_;
    double x = std::abs(glm::dot(p, right_)), y = std::abs(glm::dot(p, up_)), z = glm::dot(p, forward_);
    distance = std::max({distance, x / tan_h - z, y / tan_v - z});
  }
  distance = std::max(distance, 1.05 * 0.5 * glm::length(box.max - box.min));
  position_ = target_ + distance * away;
  set_basis();
}

void Camera::set_basis() {
  forward_ = glm::normalize(target_ - position_);
  // Looking straight up or down, the image's up is +y (rotated onto the up axis).
  const glm::dvec3 axis_up = detail::from_z_up(glm::dvec3(0.0, 0.0, 1.0), up_axis_);
  const glm::dvec3 world_up =
      std::abs(forward_[up_axis_]) > 0.999 ? detail::from_z_up(glm::dvec3(0.0, 1.0, 0.0), up_axis_) : axis_up;
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

}  // namespace ldc
