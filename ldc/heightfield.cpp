// Heightfields: the solid between a floor and a bilinear surface over a grid of samples.
#include <algorithm>
#include <cmath>
#include <limits>

#include <stb_image.h>

#include "ldc/build.h"
#include "ldc/internal/build_common.h"

namespace ldc {
namespace {

class HeightfieldSolid final : public ImplicitSolid {
 public:
  explicit HeightfieldSolid(const Heightfield& f) : f_(f) {
    x_max_ = (f.width - 1) * f.spacing;
    y_max_ = (f.height - 1) * f.spacing;
    auto [lo, hi] = std::minmax_element(f.samples.begin(), f.samples.end());
    h_min_ = f.base + f.height_scale * std::min(*lo, *hi);
    h_max_ = f.base + f.height_scale * std::max(*lo, *hi);
  }

  // max of three terms, each negative inside: below the surface, above the
  // floor, inside the footprint.
  double value(const glm::dvec3& p) const override {
    return std::max({p.z - surface(p.x, p.y), f_.floor - p.z, side(p)});
  }

  glm::dvec3 normal(const glm::dvec3& p, double) const override {
    double top = p.z - surface(p.x, p.y), bottom = f_.floor - p.z, s = side(p);
    if (bottom >= top && bottom >= s) return {0.0, 0.0, -1.0};
    if (s >= top) {
      double dx = std::max(-p.x, p.x - x_max_), dy = std::max(-p.y, p.y - y_max_);
      if (dx >= dy) return {p.x < 0.5 * x_max_ ? -1.0 : 1.0, 0.0, 0.0};
      return {0.0, p.y < 0.5 * y_max_ ? -1.0 : 1.0, 0.0};
    }
    glm::dvec2 g = gradient(p.x, p.y);
    return glm::normalize(glm::dvec3(-g.x, -g.y, 1.0));
  }

  uint16_t material(const glm::dvec3&) const override { return f_.material; }

  WorldBox bounds() const override {
    return {{0.0, 0.0, f_.floor}, {x_max_, y_max_, std::max(h_max_, f_.floor)}};
  }

  BoxClass classify(const WorldBox& b) const override {
    if (b.min.z > h_max_ || b.max.z < f_.floor) return BoxClass::kOutside;
    if (b.max.x < 0.0 || b.min.x > x_max_ || b.max.y < 0.0 || b.min.y > y_max_) {
      return BoxClass::kOutside;
    }
    bool in_footprint = b.min.x > 0.0 && b.max.x < x_max_ && b.min.y > 0.0 && b.max.y < y_max_;
    if (in_footprint && b.min.z > f_.floor && b.max.z < h_min_) return BoxClass::kInside;
    return BoxClass::kUnknown;
  }

  // Exact on vertical segments inside the footprint: the surface or the floor,
  // whichever lies on the segment (a segment with one sign change holds one).
  bool segment_root(const glm::dvec3& a, const glm::dvec3& b, double* t) const override {
    if (a.x != b.x || a.y != b.y || a.z == b.z || side(a) >= 0.0) return false;
    for (double z : {surface(a.x, a.y), f_.floor}) {
      double s = (z - a.z) / (b.z - a.z);
      if (s >= 0.0 && s <= 1.0) {
        *t = s;
        return true;
      }
    }
    return false;
  }

 private:
  double sample(int i, int j) const {
    i = std::clamp(i, 0, f_.width - 1);
    j = std::clamp(j, 0, f_.height - 1);
    return f_.samples[size_t(j) * f_.width + i];
  }

  // Cell and fraction of a coordinate along the sample grid.
  std::pair<int, double> locate(double x, int n) const {
    double g = std::clamp(x / f_.spacing, 0.0, double(n - 1));
    int i = std::min(int(g), n - 2);
    return {i, g - i};
  }

  double surface(double x, double y) const {
    auto [i, fx] = locate(x, f_.width);
    auto [j, fy] = locate(y, f_.height);
    double s = (1 - fy) * ((1 - fx) * sample(i, j) + fx * sample(i + 1, j)) +
               fy * ((1 - fx) * sample(i, j + 1) + fx * sample(i + 1, j + 1));
    return f_.base + f_.height_scale * s;
  }

  glm::dvec2 gradient(double x, double y) const {
    auto [i, fx] = locate(x, f_.width);
    auto [j, fy] = locate(y, f_.height);
    double dx = (1 - fy) * (sample(i + 1, j) - sample(i, j)) + fy * (sample(i + 1, j + 1) - sample(i, j + 1));
    double dy = (1 - fx) * (sample(i, j + 1) - sample(i, j)) + fx * (sample(i + 1, j + 1) - sample(i + 1, j));
    return glm::dvec2(dx, dy) * (f_.height_scale / f_.spacing);
  }

  double side(const glm::dvec3& p) const {
    return std::max({-p.x, p.x - x_max_, -p.y, p.y - y_max_});
  }

  Heightfield f_;
  double x_max_, y_max_, h_min_, h_max_;
};

}  // namespace

Status check_heightfield(const Heightfield& f) {
  auto bad = [](const std::string& what) {
    return Status(ErrorCode::kInvalidArgument, "heightfield: " + what);
  };
  if (f.width < 2 || f.height < 2) {
    return bad("size " + std::to_string(f.width) + " x " + std::to_string(f.height) +
               " must be at least 2 x 2");
  }
  if (f.samples.size() != size_t(f.width) * f.height) {
    return bad("has " + std::to_string(f.samples.size()) + " samples, expected width*height = " +
               std::to_string(size_t(f.width) * f.height));
  }
  for (size_t i = 0; i < f.samples.size(); ++i) {
    if (!std::isfinite(f.samples[i])) return bad("sample " + std::to_string(i) + " is not finite");
  }
  if (!(f.spacing > 0.0) || !std::isfinite(f.spacing)) return bad("spacing must be finite and > 0");
  if (!std::isfinite(f.height_scale) || !std::isfinite(f.base) || !std::isfinite(f.floor)) {
    return bad("height_scale, base and floor must be finite");
  }
  if (!(f.floor < f.base)) {
    return bad("floor = " + std::to_string(f.floor) + " must be below base = " + std::to_string(f.base));
  }
  return {};
}

Heightfield heightfield_from_function(int width, int height, double spacing,
                                      const std::function<double(double, double)>& f,
                                      double floor) {
  Heightfield h;
  h.width = width;
  h.height = height;
  h.spacing = spacing;
  h.height_scale = 1.0;
  h.base = 0.0;
  h.floor = floor;
  h.samples.resize(size_t(std::max(width, 0)) * size_t(std::max(height, 0)));
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) h.samples[size_t(j) * width + i] = float(f(i * spacing, j * spacing));
  // Keep floor < base: base is only the zero of the scale here.
  h.base = std::max(h.base, floor + 1e-9);
  return h;
}

Result<Heightfield> load_heightfield_png(const std::string& path, double spacing,
                                         double height_scale, double base, double floor) {
  int w = 0, h = 0, channels = 0;
  Heightfield f;
  if (stbi_is_16_bit(path.c_str())) {
    stbi_us* data = stbi_load_16(path.c_str(), &w, &h, &channels, 1);
    if (!data) return Status(ErrorCode::kParseError, path + ": " + stbi_failure_reason());
    f.samples.assign(size_t(w) * h, 0.0f);
    for (size_t i = 0; i < f.samples.size(); ++i) f.samples[i] = data[i] / 65535.0f;
    stbi_image_free(data);
  } else {
    stbi_uc* data = stbi_load(path.c_str(), &w, &h, &channels, 1);
    if (!data) return Status(ErrorCode::kParseError, path + ": " + stbi_failure_reason());
    f.samples.assign(size_t(w) * h, 0.0f);
    for (size_t i = 0; i < f.samples.size(); ++i) f.samples[i] = data[i] / 255.0f;
    stbi_image_free(data);
  }
  f.width = w;
  f.height = h;
  f.spacing = spacing;
  f.height_scale = height_scale;
  f.base = base;
  f.floor = floor;
  Status s = check_heightfield(f);
  if (!s.ok()) return Status(s.code(), path + ": " + s.message());
  return f;
}

std::unique_ptr<ImplicitSolid> make_heightfield_solid(const Heightfield& field) {
  return std::make_unique<HeightfieldSolid>(field);
}

Result<World> build_from_heightfield(const Heightfield& field, const GridConfig& grid,
                                     Context* ctx, BuildReport* report) {
  Status s = check_heightfield(field);
  if (!s.ok()) return s;
  return detail::build_implicit_as(*make_heightfield_solid(field), grid, ctx, report, "heightfield");
}

}  // namespace ldc
