// render(): one ray cast per pixel, shaded, with the overlay drawn on top.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <tuple>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>

#include "ldc/internal/vec_text.h"
#include "ldc/materials.h"
#include "render/detail/up.h"
#include "render/render.h"

namespace ldc {
namespace {

using Rgb = glm::vec3;  // display values in [0, 1]

// The shading's frame: sun and sky of a z-up world, rotated onto the up axis.
struct Light {
  int up_axis = 2;
  glm::vec3 sun{0.0f};  // unit, toward the sun
};

Light light_for(int up_axis) {
  return {up_axis, detail::from_z_up(glm::normalize(glm::vec3(0.55f, -0.35f, 0.75f)), up_axis)};
}

Rgb sky(const Light& light, const glm::dvec3& dir) {
  const float z = float(dir[light.up_axis]);
  const Rgb horizon(0.86f, 0.89f, 0.94f), zenith(0.38f, 0.58f, 0.88f), below(0.66f, 0.71f, 0.78f);
  if (z >= 0.0f) return glm::mix(horizon, zenith, std::sqrt(std::min(z, 1.0f)));
  return glm::mix(horizon, below, std::sqrt(std::min(-z, 1.0f)));
}

const Rgb kInsideColour(0.45f, 0.05f, 0.45f);

// `lit`: 1 in the sun, 0 in shadow.
Rgb shade(const Light& light, const RayHit& h, float lit) {
  if (h.started_inside) return kInsideColour;
  const glm::vec3 n = h.normal;
  const float diffuse = lit * std::max(0.0f, glm::dot(n, light.sun));
  const float ambient = 0.26f + 0.10f * n[light.up_axis];  // a little more light from the sky above
  Rgb c = material_display_colour(h.material) * (ambient + 0.80f * diffuse);
  // A hint of the normal's colour, of the normal in the z-up frame (so that
  // the colours turn with the up axis too).
  return glm::mix(c, 0.5f * detail::to_z_up(n, light.up_axis) + 0.5f, 0.05f);
}

uint8_t to_byte(float v) { return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

Rgb get(const Image& img, int x, int y) {
  const uint8_t* p = &img.rgb[3 * (size_t(y) * size_t(img.width) + size_t(x))];
  return Rgb(p[0], p[1], p[2]) / 255.0f;
}

void set(Image& img, int x, int y, const Rgb& c) {
  uint8_t* p = &img.rgb[3 * (size_t(y) * size_t(img.width) + size_t(x))];
  p[0] = to_byte(c.r), p[1] = to_byte(c.g), p[2] = to_byte(c.b);
}

// Per hit: 1 in the sun, 0 in shadow. Shadow rays start 2 cells off the
// surface: the query's surface lies within kQuerySurfaceTolerance cells of
// the stored one, and must not shadow itself; a start that lands inside the
// solid (a crease) counts as lit.
Status sun_visibility(const Queries& queries, const Light& light, const std::vector<RayHit>& hits,
                      std::vector<float>& lit, RenderStats& stats) {
  const double lift = 2.0 * queries.world().lattice().cell_size;
  std::vector<Ray> rays;
  std::vector<size_t> shadowed;  // pixel of each shadow ray
  for (size_t i = 0; i < hits.size(); ++i) {
    const RayHit& h = hits[i];
    if (!h.hit || h.started_inside || glm::dot(h.normal, light.sun) <= 0.0f) continue;
    Ray r;
    r.origin = h.point + lift * glm::dvec3(h.normal);
    r.direction = glm::dvec3(light.sun);
    rays.push_back(r);
    shadowed.push_back(i);
  }
  std::vector<RayHit> shadow_hits(rays.size());
  if (Status s = queries.ray_cast(rays, shadow_hits, nullptr); !s.ok()) return s;
  for (size_t k = 0; k < shadowed.size(); ++k) {
    if (shadow_hits[k].hit && !shadow_hits[k].started_inside) lit[shadowed[k]] = 0.0f;
  }
  stats.shadow_rays += rays.size();
  return {};
}

// One ray per pixel (and with shadows one toward the sun per lit hit), in
// blocks of rows so that progress moves and the rays of one block only are
// held.
Status shade_image(const Queries& queries, const Camera& cam, const RenderOptions& options, Image& img,
                   RenderStats& stats, Context* ctx) {
  const Light light = light_for(cam.up_axis());
  const int rows = std::max(1, (1 << 16) / img.width);
  // Fog from the target's distance on: far hits fade toward the sky.
  const double near = glm::length(cam.target() - cam.position());
  std::vector<Ray> rays;
  std::vector<RayHit> hits;
  std::vector<float> lit;
  for (int y0 = 0; y0 < img.height; y0 += rows) {
    const int y1 = std::min(img.height, y0 + rows);
    const size_t n = size_t(y1 - y0) * size_t(img.width);
    rays.resize(n);
    hits.resize(n);
    tbb::parallel_for(y0, y1, [&](int y) {
      for (int x = 0; x < img.width; ++x) rays[size_t(y - y0) * size_t(img.width) + size_t(x)] = cam.pixel_ray(x, y);
    });
    ScopedTimer t(nullptr, "");
    if (Status s = queries.ray_cast(rays, hits, nullptr); !s.ok()) return s;
    lit.assign(n, 1.0f);
    if (options.shadows) {
      if (Status s = sun_visibility(queries, light, hits, lit, stats); !s.ok()) return s;
    }
    stats.cast_seconds += t.seconds();
    for (size_t i = 0; i < n; ++i) {
      const int x = int(i % size_t(img.width)), y = y0 + int(i / size_t(img.width));
      const RayHit& h = hits[i];
      stats.hits += h.hit;
      stats.started_inside += h.started_inside;
      const Rgb background = sky(light, rays[i].direction);
      Rgb c = background;
      if (h.hit) {
        c = shade(light, h, lit[i]);
        if (options.fog > 0.0 && !h.started_inside) {
          const double f = std::clamp((h.distance - near) / (2.0 * near), 0.0, 1.0);
          c = glm::mix(c, background, float(options.fog * f));
        }
      }
      set(img, x, y, c);
    }
    stats.rays += n;
    if (ctx) {
      ctx->report_progress("render", double(y1) / double(img.height));
      if (ctx->cancelled()) return Status(ErrorCode::kCancelled, "render cancelled");
    }
  }
  return {};
}

// ---- the overlay ---------------------------------------------------------

// Coverage of one colour, drawn as the maximum of discs so that overlapping
// discs do not darken a translucent layer, then composited. One buffer (one
// byte a pixel) serves every layer in turn; only the box drawn on is visited.
class Layer {
 public:
  explicit Layer(const Image& img) : img_(img), coverage_(size_t(img.width) * size_t(img.height), 0) {}

  void disc(const glm::dvec2& centre, double radius) {
    const int x0 = std::max(0, int(std::floor(centre.x - radius - 1.0)));
    const int x1 = std::min(img_.width - 1, int(std::ceil(centre.x + radius + 1.0)));
    const int y0 = std::max(0, int(std::floor(centre.y - radius - 1.0)));
    const int y1 = std::min(img_.height - 1, int(std::ceil(centre.y + radius + 1.0)));
    if (x0 > x1 || y0 > y1) return;
    lo_ = glm::min(lo_, glm::ivec2(x0, y0));
    hi_ = glm::max(hi_, glm::ivec2(x1, y1));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double d = glm::length(glm::dvec2(x + 0.5, y + 0.5) - centre);
        const auto c = uint8_t(std::lround(255.0 * std::clamp(radius + 0.5 - d, 0.0, 1.0)));
        uint8_t& cov = coverage_[size_t(y) * size_t(img_.width) + size_t(x)];
        cov = std::max(cov, c);
      }
    }
  }

  // Blends `colour` over the image by coverage x opacity and clears the buffer.
  void composite(Image& img, const Rgb& colour, float opacity) {
    for (int y = lo_.y; y <= hi_.y; ++y) {
      for (int x = lo_.x; x <= hi_.x; ++x) {
        uint8_t& cov = coverage_[size_t(y) * size_t(img.width) + size_t(x)];
        if (cov) set(img, x, y, glm::mix(get(img, x, y), colour, opacity * float(cov) / 255.0f));
        cov = 0;
      }
    }
    lo_ = glm::ivec2(std::numeric_limits<int>::max());
    hi_ = glm::ivec2(-1);
  }

 private:
  const Image& img_;
  std::vector<uint8_t> coverage_;
  glm::ivec2 lo_{std::numeric_limits<int>::max()}, hi_{-1};
};

// A point of the overlay as drawn: where it lands and whether the solid hides it.
struct Sample {
  glm::dvec3 point;
  glm::dvec2 pixel;
  double along = 0.0;  // pixels along the polyline (for dashes)
  bool hidden = false;
};

// The part [u0, u1] of the pixel segment pa -> pb inside the box lo .. hi
// (Liang-Barsky), or nothing when it misses the box.
std::optional<std::pair<double, double>> clip_to_box(const glm::dvec2& pa, const glm::dvec2& pb, const glm::dvec2& lo,
                                                     const glm::dvec2& hi) {
  double u0 = 0.0, u1 = 1.0;
  const glm::dvec2 d = pb - pa;
  const double p[4] = {-d.x, d.x, -d.y, d.y};
  const double q[4] = {pa.x - lo.x, hi.x - pa.x, pa.y - lo.y, hi.y - pa.y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return std::nullopt;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0.0) u0 = std::max(u0, t);
    else u1 = std::min(u1, t);
  }
  if (u0 > u1) return std::nullopt;
  return std::pair{u0, u1};
}

// The fraction along a -> b (depths da, db) of the point seen at fraction u
// along its projection: perspective maps a line to a line, but not evenly.
double unproject_fraction(double u, double da, double db) {
  const double w = u * da + (1.0 - u) * db;
  return w > 0.0 ? u * da / w : u;
}

// The part of one path segment that may touch the image: in front of the
// camera, then clipped to the image plus `margin` pixels.
struct SegmentPart {
  glm::dvec3 a, b;           // its ends in the world
  double along = 0.0;        // pixels along the whole segment before a
  double length = 0.0;       // pixels along the whole segment (in front of the camera)
  double part = 0.0;         // pixels from a to b
  int samples = 0;           // steps from a to b, about 0.7 pixels each
  bool clipped_start = false;
};

std::optional<SegmentPart> visible_part(glm::dvec3 a, glm::dvec3 b, const Camera& cam, double near, double margin) {
  const double da = glm::dot(a - cam.position(), cam.forward()), db = glm::dot(b - cam.position(), cam.forward());
  if (da <= near && db <= near) return std::nullopt;
  if (da <= near) a = glm::mix(a, b, (near * 1.001 - da) / (db - da));
  if (db <= near) b = glm::mix(b, a, (near * 1.001 - db) / (da - db));
  auto pa = cam.project(a, near), pb = cam.project(b, near);
  if (!pa || !pb) return std::nullopt;
  SegmentPart s;
  s.length = glm::length(pb->pixel - pa->pixel);
  const glm::dvec2 lo(-margin), hi(cam.width() + margin, cam.height() + margin);
  const auto clip = clip_to_box(pa->pixel, pb->pixel, lo, hi);
  if (!clip) {
    s.samples = -1;  // off the image: only its length counts
    return s;
  }
  const auto [u0, u1] = *clip;
  s.a = glm::mix(a, b, unproject_fraction(u0, pa->depth, pb->depth));
  s.b = glm::mix(a, b, unproject_fraction(u1, pa->depth, pb->depth));
  s.along = s.length * u0;
  s.part = s.length * (u1 - u0);
  s.samples = int(std::clamp(std::ceil(s.part / 0.7), 1.0, 20000.0));
  s.clipped_start = u0 > 0.0;
  return s;
}

// Points along each segment, about 0.7 pixels apart on the image, of the
// part visible_part keeps, so that a segment costs at most about the image's
// diagonal in samples whatever its length in the world (issue 24: a path
// zig-zagging +-10 km at 64 x 64 took 3.7 GB). The samples are counted first:
// more than `budget` in all is refused before they are made.
Status sample_path(const std::vector<glm::dvec3>& path, const Camera& cam, double near, double margin,
                   size_t& budget, std::vector<Sample>& out) {
  if (path.size() == 1) {
    if (auto p = cam.project(path[0], near)) out.push_back({path[0], p->pixel, 0.0, false});
    return {};
  }
  std::vector<std::optional<SegmentPart>> parts(path.size() - 1);
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    parts[i] = visible_part(path[i], path[i + 1], cam, near, margin);
    if (!parts[i] || parts[i]->samples < 0) continue;
    if (size_t(parts[i]->samples) + 1 > budget) {
      return Status(ErrorCode::kTooLarge, "overlay: more than " + std::to_string(kMaxOverlaySamples) +
                                              " samples on the image; draw fewer path vertices");
    }
    budget -= size_t(parts[i]->samples) + 1;
  }
  const size_t first = out.size();
  double along = 0.0;
  for (const auto& s : parts) {
    if (!s) continue;
    // The first sample repeats the previous segment's last unless the start was clipped.
    for (int k = (out.size() == first || s->clipped_start ? 0 : 1); k <= s->samples; ++k) {
      const glm::dvec3 p = glm::mix(s->a, s->b, double(k) / s->samples);
      auto pp = cam.project(p, near);
      if (!pp) continue;
      out.push_back({p, pp->pixel, along + s->along + s->part * k / s->samples, false});
    }
    along += s->length;
  }
  return {};
}

// Hidden: a ray from the point toward the camera hits the solid first (the
// start is moved 2 cells toward the camera so that a point on the surface
// does not hide itself).
Status mark_hidden(const Queries& queries, const Camera& cam, std::vector<Sample>& samples) {
  const double lift = 2.0 * queries.world().lattice().cell_size;
  std::vector<Ray> rays(samples.size());
  std::vector<RayHit> hits(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    const glm::dvec3 to_cam = cam.position() - samples[i].point;
    const double d = glm::length(to_cam);
    rays[i].direction = to_cam / d;
    rays[i].origin = samples[i].point + std::min(lift, 0.5 * d) * rays[i].direction;
    rays[i].max_distance = std::max(0.0, d - std::min(lift, 0.5 * d));
  }
  Status s = queries.ray_cast(rays, hits, nullptr);
  if (!s.ok()) return s;
  for (size_t i = 0; i < samples.size(); ++i) samples[i].hidden = hits[i].hit;
  return {};
}

// The samples of the overlay that may touch the image, marked hidden or not.
Status overlay_samples(const Queries& queries, const Camera& cam, const Overlay& overlay, double r,
                       std::vector<Sample>& line, std::vector<Sample>& dots) {
  const double near = 1e-6 * std::max(1.0, glm::length(cam.target() - cam.position()));
  // Samples wholly off the image need no ray.
  const double m = 3.0 * r + 2.0;
  size_t budget = kMaxOverlaySamples;
  for (const auto& path : overlay.paths) {
    if (Status s = sample_path(path, cam, near, m, budget, line); !s.ok()) return s;
  }
  for (const glm::dvec3& p : overlay.points) {
    if (auto pp = cam.project(p, near)) dots.push_back({p, pp->pixel, 0.0, false});
  }
  auto off_image = [&](const Sample& s) {
    return s.pixel.x < -m || s.pixel.y < -m || s.pixel.x > cam.width() + m || s.pixel.y > cam.height() + m;
  };
  std::erase_if(line, off_image);
  std::erase_if(dots, off_image);
  Status s = mark_hidden(queries, cam, line);
  if (s.ok()) s = mark_hidden(queries, cam, dots);
  return s;
}

Status draw_overlay(const Queries& queries, const Camera& cam, const Overlay& overlay, Image& img,
                    RenderStats& stats) {
  const double r = std::max(1.5, std::min(img.width, img.height) / 280.0);  // line half-width in pixels
  std::vector<Sample> line, dots;
  if (Status s = overlay_samples(queries, cam, overlay, r, line, dots); !s.ok()) return s;
  for (const auto& path : overlay.paths) stats.path_vertices += path.size();
  stats.points += overlay.points.size();

  const Rgb path_colour(1.0f, 0.84f, 0.10f), point_colour(0.95f, 0.15f, 0.45f), outline(0.05f, 0.05f, 0.05f);
  const double R = 2.2 * r;  // dot radius
  Layer layer(img);
  // Hidden parts first (dimmed; the path dashed), then what is seen, outlined.
  for (const Sample& p : line) {
    if (p.hidden && std::fmod(p.along, 6.0 * r) < 3.6 * r) layer.disc(p.pixel, 0.75 * r);
  }
  layer.composite(img, glm::mix(path_colour, Rgb(0.9f), 0.3f), 0.7f);
  for (const Sample& p : dots) {
    if (p.hidden) layer.disc(p.pixel, 0.8 * R);
  }
  layer.composite(img, glm::mix(point_colour, Rgb(0.9f), 0.3f), 0.7f);
  for (const auto& [samples, radius, colour] :
       {std::tuple{&line, r, path_colour}, std::tuple{&dots, R, point_colour}}) {
    for (const Sample& p : *samples) {
      if (!p.hidden) layer.disc(p.pixel, radius + 1.25);
    }
    layer.composite(img, outline, 0.75f);
    for (const Sample& p : *samples) {
      if (!p.hidden) layer.disc(p.pixel, radius);
    }
    layer.composite(img, colour, 1.0f);
  }
  stats.overlay_samples += line.size() + dots.size();
  for (const auto* v : {&line, &dots}) {
    for (const Sample& p : *v) stats.hidden_samples += p.hidden;
  }
  return {};
}

Status check_overlay_points(const std::vector<glm::dvec3>& points, const std::string& where) {
  for (size_t i = 0; i < points.size(); ++i) {
    if (detail::is_finite(points[i])) continue;
    std::ostringstream s;
    s << where << "[" << i << "] " << detail::vec_text(points[i]) << ": must be finite";
    return Status(ErrorCode::kInvalidArgument, s.str());
  }
  return {};
}

}  // namespace

Status check_render_options(const RenderOptions& options) {
  if (!(options.fog >= 0.0 && options.fog <= 1.0)) {
    std::ostringstream s;
    s << "fog " << options.fog << ": must be in 0 .. 1";
    return Status(ErrorCode::kInvalidArgument, s.str());
  }
  for (size_t i = 0; i < options.overlay.paths.size(); ++i) {
    Status s = check_overlay_points(options.overlay.paths[i], "overlay paths[" + std::to_string(i) + "]");
    if (!s.ok()) return s;
  }
  return check_overlay_points(options.overlay.points, "overlay points");
}

Result<Image> render(const Queries& queries, const Camera& camera, const RenderOptions& options,
                     RenderStats* stats, Context* ctx) {
  if (Status s = check_render_options(options); !s.ok()) return s;
  RenderStats local;
  RenderStats& st = stats ? *stats : local;
  Image img;
  img.width = camera.width();
  img.height = camera.height();
  img.rgb.assign(size_t(img.width) * size_t(img.height) * 3, 0);
  if (Status s = shade_image(queries, camera, options, img, st, ctx); !s.ok()) return s;
  if (!options.overlay.paths.empty() || !options.overlay.points.empty()) {
    ScopedTimer t(nullptr, "");
    if (Status s = draw_overlay(queries, camera, options.overlay, img, st); !s.ok()) return s;
    st.overlay_seconds += t.seconds();
  }
  return img;
}

}  // namespace ldc
