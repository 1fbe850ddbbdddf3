// render_gi(): primary hits lit by a GI engine's irradiance; tone mapping
// and images side by side.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include "ldc/context.h"

#include "render/render.h"

namespace ldc {

namespace {

// The engine's irradiance in blocks of at least 4096 points, about 32 in
// all, so that a long final gather (seconds on lavapipe) reports progress
// and can be cancelled. Each point's answer does not depend on its block.
Status irradiance_in_blocks(GiEngine& gi, std::span<const glm::dvec3> p, std::span<const glm::vec3> n, int bounces,
                            std::span<glm::vec3> e, Context* ctx) {
  const size_t block = std::max<size_t>(4096, (p.size() + 31) / 32);
  for (size_t first = 0; first < p.size(); first += block) {
    if (ctx && ctx->cancelled()) return Status(ErrorCode::kCancelled, "gi image: cancelled");
    const size_t count = std::min(block, p.size() - first);
    if (Status s = gi.irradiance(p.subspan(first, count), n.subspan(first, count), bounces, e.subspan(first, count));
        !s.ok())
      return s;
    if (ctx) ctx->report_progress("gi image", double(first + count) / double(p.size()));
  }
  return {};
}

}  // namespace

Result<RadianceImage> render_gi(const Queries& queries, const Camera& cam, GiEngine& gi,
                                const GiImageOptions& options) {
  const MaterialTable& materials = options.materials;
  const SkyLight& sky = options.sky;
  const int bounces = options.bounces;
  if (bounces < 1 || bounces > 3) {
    return Status(ErrorCode::kInvalidArgument, "bounces " + std::to_string(bounces) + ": must be 1 .. 3");
  }
  const size_t n = size_t(cam.width()) * size_t(cam.height());
  std::vector<Ray> rays(n);
  std::vector<RayHit> hits(n);
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x) rays[size_t(y) * size_t(cam.width()) + size_t(x)] = cam.pixel_ray(x, y);
  if (Status s = queries.ray_cast(rays, hits, nullptr); !s.ok()) return s;
  std::vector<glm::dvec3> p;
  std::vector<glm::vec3> nrm;
  std::vector<size_t> pix;
  RadianceImage out{cam.width(), cam.height(), std::vector<glm::vec3>(n, glm::vec3(0.0f))};
  for (size_t i = 0; i < n; ++i) {
    if (!hits[i].hit || hits[i].started_inside) {
      out.pixels[i] = hits[i].hit ? glm::vec3(0.0f) : sky.radiance(glm::normalize(glm::vec3(rays[i].direction)));
      continue;
    }
    p.push_back(hits[i].point);
    nrm.push_back(hits[i].normal);
    pix.push_back(i);
  }
  std::vector<glm::vec3> e(p.size());
  if (Status s = irradiance_in_blocks(gi, p, nrm, bounces, e, options.ctx); !s.ok()) return s;
  for (size_t k = 0; k < pix.size(); ++k) {
    const VoxelMaterial& m = materials[hits[pix[k]].material];
    out.pixels[pix[k]] = m.albedo * e[k] * (1.0f / std::numbers::pi_v<float>) + m.emission;
  }
  return out;
}

namespace {

uint8_t tone(float v, float exposure) {
  v *= exposure;
  if (!(v > 0.0f)) return 0;
  v = v / (1.0f + v);
  return uint8_t(std::lround(255.0f * std::pow(std::clamp(v, 0.0f, 1.0f), 1.0f / 2.2f)));
}

}  // namespace

Image tone_map(const RadianceImage& radiance, float exposure) {
  Image img{radiance.width, radiance.height, std::vector<uint8_t>(radiance.pixels.size() * 3)};
  for (size_t i = 0; i < radiance.pixels.size(); ++i) {
    for (int k = 0; k < 3; ++k) img.rgb[3 * i + size_t(k)] = tone(radiance.pixels[i][k], exposure);
  }
  return img;
}

Result<Image> side_by_side(const Image& left, const Image& right) {
  if (left.height != right.height) {
    return Status(ErrorCode::kInvalidArgument, "side_by_side: heights " + std::to_string(left.height) + " and " +
                                                   std::to_string(right.height) + " differ");
  }
  Image out{left.width + right.width, left.height, {}};
  out.rgb.reserve(left.rgb.size() + right.rgb.size());
  for (int y = 0; y < out.height; ++y) {
    const auto row = [y](const Image& img) { return img.rgb.begin() + 3 * ptrdiff_t(y) * img.width; };
    out.rgb.insert(out.rgb.end(), row(left), row(left) + 3 * ptrdiff_t(left.width));
    out.rgb.insert(out.rgb.end(), row(right), row(right) + 3 * ptrdiff_t(right.width));
  }
  return out;
}

}  // namespace ldc
