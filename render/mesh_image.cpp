// render_mesh(): a z-buffered rasterizer for triangle meshes (see render.h).
// Written here rather than taken from a library: the project has no
// rasterizer dependency (Vulkan is for compute), and what is needed is small.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "render/render.h"

namespace ldc {
namespace {

constexpr double kNear = 1e-3;  // [Units: m] triangles are clipped to depth > kNear

struct ScreenVertex {
  glm::dvec2 pixel;
  double depth;
};

struct Target {
  Image image;
  std::vector<float> depth;
};

glm::dvec3 colour_of(const MeshRenderOptions& o, size_t t) {
  return t < o.triangle_colour.size() ? glm::dvec3(o.triangle_colour[t]) : glm::dvec3(0.72, 0.72, 0.68);
}

void put(Target& target, int x, int y, const glm::dvec3& c) {
  uint8_t* p = &target.image.rgb[3 * (size_t(y) * size_t(target.image.width) + size_t(x))];
  for (int k = 0; k < 3; ++k) p[k] = uint8_t(std::lround(std::clamp(c[k], 0.0, 1.0) * 255.0));
}

// Fills one projected triangle: depth by 1/z interpolated across the screen,
// pixels within edge_px of an edge darkened.
void fill(Target& target, const ScreenVertex v[3], const glm::dvec3& colour, double edge_px) {
  const glm::dvec2 a = v[0].pixel, b = v[1].pixel, c = v[2].pixel;
  const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (!(std::abs(area) > 1e-12)) return;
  const int w = target.image.width, h = target.image.height;
  const int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x})))),
            x1 = std::min(w - 1, int(std::ceil(std::max({a.x, b.x, c.x})))),
            y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y})))),
            y1 = std::min(h - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
  const double len[3] = {glm::length(c - b), glm::length(a - c), glm::length(b - a)};  // opposite each corner
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const glm::dvec2 p(x + 0.5, y + 0.5);
      const double l0 = ((b.x - p.x) * (c.y - p.y) - (b.y - p.y) * (c.x - p.x)) / area;
      const double l1 = ((c.x - p.x) * (a.y - p.y) - (c.y - p.y) * (a.x - p.x)) / area;
      const double l2 = 1.0 - l0 - l1;
      if (l0 < 0.0 || l1 < 0.0 || l2 < 0.0) continue;
      const double z = 1.0 / (l0 / v[0].depth + l1 / v[1].depth + l2 / v[2].depth);
      float& zbuf = target.depth[size_t(y) * size_t(w) + size_t(x)];
      if (!(z < zbuf)) continue;
      zbuf = float(z);
      // Distance to each edge in pixels: l_i times the height over that edge.
      const double d = std::min({l0 * std::abs(area) / len[0], l1 * std::abs(area) / len[1], l2 * std::abs(area) / len[2]});
      put(target, x, y, d < edge_px ? 0.55 * colour : colour);
    }
  }
}

// The part of a triangle in front of the near plane, as up to two triangles.
int clip_near(const glm::dvec3 in[3], const Camera& camera, glm::dvec3 out[2][3]) {
  double d[3];
  int front = 0;
  for (int i = 0; i < 3; ++i) {
    d[i] = glm::dot(in[i] - camera.position(), camera.forward()) - 2.0 * kNear;
    front += d[i] > 0.0;
  }
  if (front == 0) return 0;
  if (front == 3) {
    std::copy(in, in + 3, out[0]);
    return 1;
  }
  glm::dvec3 poly[4];
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (d[i] > 0.0) poly[n++] = in[i];
    if ((d[i] > 0.0) != (d[j] > 0.0)) poly[n++] = in[i] + (d[i] / (d[i] - d[j])) * (in[j] - in[i]);
  }
  out[0][0] = poly[0], out[0][1] = poly[1], out[0][2] = poly[2];
  if (n == 3) return 1;
  out[1][0] = poly[0], out[1][1] = poly[2], out[1][2] = poly[3];
  return 2;
}

}  // namespace

Result<Image> render_mesh(const TriangleMesh& mesh, const Camera& camera, const MeshRenderOptions& options) {
  for (const glm::uvec3& t : mesh.triangles) {
    if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() || t.z >= mesh.positions.size())
      return Status(ErrorCode::kInvalidArgument, "render_mesh: a triangle indexes past the " +
                                                     std::to_string(mesh.positions.size()) + " vertices");
  }
  if (!options.triangle_colour.empty() && options.triangle_colour.size() != mesh.triangles.size())
    return Status(ErrorCode::kInvalidArgument, "render_mesh: triangle_colour has " +
                                                   std::to_string(options.triangle_colour.size()) + " entries for " +
                                                   std::to_string(mesh.triangles.size()) + " triangles");
  Target target;
  target.image.width = camera.width();
  target.image.height = camera.height();
  target.image.rgb.assign(3 * size_t(camera.width()) * size_t(camera.height()), 0);
  target.depth.assign(size_t(camera.width()) * size_t(camera.height()), std::numeric_limits<float>::infinity());
  for (int y = 0; y < camera.height(); ++y)
    for (int x = 0; x < camera.width(); ++x) put(target, x, y, options.background);
  const glm::dvec3 sun = glm::normalize(options.sun);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::uvec3 tri = mesh.triangles[t];
    const glm::dvec3 p[3] = {mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z]};
    const glm::dvec3 cross = glm::cross(p[1] - p[0], p[2] - p[0]);
    if (glm::dot(cross, p[0] - camera.position()) >= 0.0) continue;  // seen from behind (or edge on)
    const glm::dvec3 n = glm::normalize(cross);
    const glm::dvec3 colour = colour_of(options, t) * (0.35 + 0.65 * std::max(0.0, glm::dot(n, sun)));
    glm::dvec3 parts[2][3];
    const int count = clip_near(p, camera, parts);
    for (int k = 0; k < count; ++k) {
      ScreenVertex v[3];
      bool ok = true;
      for (int i = 0; i < 3 && ok; ++i) {
        const std::optional<Camera::Projected> s = camera.project(parts[k][i], kNear);
        ok = s.has_value();
        if (ok) v[i] = {s->pixel, s->depth};
      }
      if (ok) fill(target, v, colour, options.edge_pixels);
    }
  }
  return std::move(target.image);
}

}  // namespace ldc
