// ldc render: a preview image of a world, one ray cast per pixel, with an
// optional overlay of a path and points -> PNG.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <tuple>
#include <vector>

#include <stb_image_write.h>  // the implementation is in libstb (PkgConfig::STB), as stb_image's for the core
#include <tbb/parallel_for.h>

#include "camera.h"
#include "common.h"
#include "internal/vec_text.h"
#include "ldc/io.h"
#include "ldc/query.h"

namespace ldc::tool {
namespace {

const char* const kRenderHelp = R"(Without --camera the view looks at the solid's centre (or --target) from above and
to the side, z up, as near as shows all of it; the camera used is printed. Shading:
lambert from a fixed sun plus ambient, times the material's colour (a fixed palette
by material id: 0 rock, 1 grass, 2 dirt, 3 sand, then distinct colours), with a hint
of the normal's colour; misses show the sky. A camera inside the solid shows purple.
--overlay FILE draws, with the same camera, a polyline and/or points:
  {"path": [[x,y,z], ...], "points": [[x,y,z], ...]}    ("polyline" is taken for "path")
Parts hidden behind the solid (a ray cast toward the camera hits it) are drawn
dimmed and dashed.
)";

struct RenderOptions {
  bool shadows = false;
  double fog = 0.25;  // how much of the sky's colour the farthest hits take [Limit: 0 .. 1]
};

struct RenderArgs {
  std::string world;
  std::string output;
  std::string overlay;
  CameraArgs camera;
  RenderOptions options;
};

using Rgb = glm::vec3;  // display values in [0, 1]

// Material id -> colour: the landscape's materials first (ldc/terrain.h),
// then colours far apart from each other.
Rgb material_colour(uint16_t id) {
  static const Rgb palette[16] = {
      {0.60f, 0.59f, 0.55f},  // 0 rock
      {0.42f, 0.64f, 0.28f},  // 1 grass
      {0.62f, 0.44f, 0.28f},  // 2 dirt
      {0.90f, 0.82f, 0.56f},  // 3 sand
      {0.30f, 0.50f, 0.85f},  // 4 blue
      {0.85f, 0.30f, 0.28f},  // 5 red
      {0.62f, 0.42f, 0.80f},  // 6 violet
      {0.25f, 0.70f, 0.70f},  // 7 teal
      {0.92f, 0.58f, 0.20f},  // 8 orange
      {0.75f, 0.75f, 0.30f},  // 9 olive
      {0.85f, 0.50f, 0.65f},  // 10 pink
      {0.45f, 0.45f, 0.50f},  // 11 slate
      {0.55f, 0.80f, 0.45f},  // 12 light green
      {0.40f, 0.30f, 0.22f},  // 13 umber
      {0.80f, 0.80f, 0.82f},  // 14 white
      {0.20f, 0.35f, 0.55f},  // 15 navy
  };
  return palette[id % 16];
}

Rgb sky(const glm::dvec3& dir) {
  const float z = float(dir.z);
  const Rgb horizon(0.86f, 0.89f, 0.94f), zenith(0.38f, 0.58f, 0.88f), below(0.66f, 0.71f, 0.78f);
  if (z >= 0.0f) return glm::mix(horizon, zenith, std::sqrt(std::min(z, 1.0f)));
  return glm::mix(horizon, below, std::sqrt(std::min(-z, 1.0f)));
}

const glm::vec3 kSun = glm::normalize(glm::vec3(0.55f, -0.35f, 0.75f));  // toward the sun
const Rgb kInsideColour(0.45f, 0.05f, 0.45f);

// `lit`: 1 in the sun, 0 in shadow (--shadows).
Rgb shade(const RayHit& h, float lit) {
  if (h.started_inside) return kInsideColour;
  const glm::vec3 n = h.normal;
  const float diffuse = lit * std::max(0.0f, glm::dot(n, kSun));
  const float ambient = 0.26f + 0.10f * n.z;  // a little more light from the sky above
  Rgb c = material_colour(h.material) * (ambient + 0.80f * diffuse);
  return glm::mix(c, 0.5f * n + 0.5f, 0.05f);  // a hint of the normal's colour
}

uint8_t to_byte(float v) { return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  Rgb get(int x, int y) const {
    const uint8_t* p = &rgb[3 * (size_t(y) * size_t(width) + size_t(x))];
    return Rgb(p[0], p[1], p[2]) / 255.0f;
  }
  void set(int x, int y, const Rgb& c) {
    uint8_t* p = &rgb[3 * (size_t(y) * size_t(width) + size_t(x))];
    p[0] = to_byte(c.r), p[1] = to_byte(c.g), p[2] = to_byte(c.b);
  }
};

struct RenderStats {
  size_t rays = 0, hits = 0, started_inside = 0, shadow_rays = 0;
  double cast_seconds = 0.0;
};

// One ray per pixel (and with shadows one toward the sun per lit hit), in
// blocks of rows so that the progress bar moves and the rays of one block
// only are held.
Status render_image(const Queries& queries, const Camera& cam, const RenderOptions& options, Image& img,
                    RenderStats& stats, Context* ctx) {
  img.width = cam.width();
  img.height = cam.height();
  img.rgb.assign(size_t(img.width) * size_t(img.height) * 3, 0);
  const int rows = std::max(1, (1 << 16) / img.width);
  // Shadow rays start 2 cells off the surface: the query's surface lies within
  // kQuerySurfaceTolerance cells of the stored one, and must not shadow itself.
  const double lift = 2.0 * queries.world().lattice().cell_size;
  // Fog from the target's distance on: far hits fade toward the sky.
  const double near = glm::length(cam.target() - cam.position());
  std::vector<Ray> rays, shadow_rays;
  std::vector<RayHit> hits, shadow_hits;
  std::vector<size_t> shadowed;  // pixel of each shadow ray
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
    Status s = queries.ray_cast(rays, hits, nullptr);
    if (!s.ok()) return s;
    lit.assign(n, 1.0f);
    if (options.shadows) {
      shadow_rays.clear();
      shadowed.clear();
      for (size_t i = 0; i < n; ++i) {
        const RayHit& h = hits[i];
        if (!h.hit || h.started_inside || glm::dot(h.normal, kSun) <= 0.0f) continue;
        Ray r;
        r.origin = h.point + lift * glm::dvec3(h.normal);
        r.direction = glm::dvec3(kSun);
        shadow_rays.push_back(r);
        shadowed.push_back(i);
      }
      shadow_hits.resize(shadow_rays.size());
      s = queries.ray_cast(shadow_rays, shadow_hits, nullptr);
      if (!s.ok()) return s;
      // A start that lands inside the solid (a crease) counts as lit.
      for (size_t k = 0; k < shadowed.size(); ++k) {
        if (shadow_hits[k].hit && !shadow_hits[k].started_inside) lit[shadowed[k]] = 0.0f;
      }
      stats.shadow_rays += shadow_rays.size();
    }
    stats.cast_seconds += t.seconds();
    for (size_t i = 0; i < n; ++i) {
      const int x = int(i % size_t(img.width)), y = y0 + int(i / size_t(img.width));
      const RayHit& h = hits[i];
      stats.hits += h.hit;
      stats.started_inside += h.started_inside;
      const Rgb background = sky(rays[i].direction);
      Rgb c = background;
      if (h.hit) {
        c = shade(h, lit[i]);
        if (options.fog > 0.0 && !h.started_inside) {
          const double f = std::clamp((h.distance - near) / (2.0 * near), 0.0, 1.0);
          c = glm::mix(c, background, float(options.fog * f));
        }
      }
      img.set(x, y, c);
    }
    stats.rays += n;
    if (ctx) ctx->report_progress("render", double(y1) / double(img.height));
  }
  return {};
}

// ---- the overlay ---------------------------------------------------------

struct Overlay {
  std::vector<std::vector<glm::dvec3>> paths;
  std::vector<glm::dvec3> points;
};

Result<std::vector<glm::dvec3>> overlay_points(const nlohmann::json& list, const std::string& where) {
  if (!list.is_array()) return Status(ErrorCode::kParseError, where + " must be an array of [x, y, z]");
  std::vector<glm::dvec3> out;
  for (size_t i = 0; i < list.size(); ++i) {
    const nlohmann::json& p = list[i];
    bool ok = p.is_array() && p.size() == 3;
    glm::dvec3 v(0.0);
    for (int k = 0; ok && k < 3; ++k) {
      ok = p[k].is_number() && std::isfinite(p[k].get<double>());
      if (ok) v[k] = p[k].get<double>();
    }
    if (!ok) {
      std::ostringstream s;
      s << where << "[" << i << "] must be [x, y, z] (three finite numbers), not " << p.dump();
      return Status(ErrorCode::kParseError, s.str());
    }
    out.push_back(v);
  }
  return out;
}

Result<Overlay> read_overlay(const std::string& path) {
  Result<nlohmann::json> read = read_json_file(path);
  if (!read.ok()) return Status(read.status().code(), "--overlay " + read.status().message());
  const nlohmann::json& doc = read.value();
  const std::string usage = " (expected {\"path\": [[x,y,z], ...]} and/or {\"points\": [[x,y,z], ...]}; "
                            "\"polyline\" is taken for \"path\")";
  if (!doc.is_object()) return Status(ErrorCode::kParseError, "--overlay " + path + ": not a JSON object" + usage);
  Overlay overlay;
  bool found = false;
  for (const char* key : {"path", "polyline", "points"}) {
    auto it = doc.find(key);
    if (it == doc.end()) continue;
    found = true;
    Result<std::vector<glm::dvec3>> pts = overlay_points(*it, "--overlay " + path + ": " + key);
    if (!pts.ok()) return pts.status();
    if (std::string(key) == "points") overlay.points = std::move(pts).value();
    else overlay.paths.push_back(std::move(pts).value());
  }
  if (!found) return Status(ErrorCode::kParseError, "--overlay " + path + ": nothing to draw" + usage);
  return overlay;
}

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
        if (cov) img.set(x, y, glm::mix(img.get(x, y), colour, opacity * float(cov) / 255.0f));
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

struct OverlayStats {
  size_t samples = 0, hidden = 0, path_vertices = 0, points = 0;
};

// Points along each segment, about 0.7 pixels apart on the image; segments
// are clipped to the part in front of the camera.
std::vector<Sample> sample_path(const std::vector<glm::dvec3>& path, const Camera& cam, double near) {
  std::vector<Sample> out;
  if (path.size() == 1) {
    if (auto p = cam.project(path[0], near)) out.push_back({path[0], p->pixel, 0.0, false});
    return out;
  }
  double along = 0.0;
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    glm::dvec3 a = path[i], b = path[i + 1];
    const double da = glm::dot(a - cam.position(), cam.forward()), db = glm::dot(b - cam.position(), cam.forward());
    if (da <= near && db <= near) continue;
    if (da <= near) a = glm::mix(a, b, (near * 1.001 - da) / (db - da));
    if (db <= near) b = glm::mix(b, a, (near * 1.001 - db) / (da - db));
    auto pa = cam.project(a, near), pb = cam.project(b, near);
    if (!pa || !pb) continue;
    const double length = glm::length(pb->pixel - pa->pixel);
    const int n = int(std::clamp(std::ceil(length / 0.7), 1.0, 20000.0));
    for (int k = (out.empty() ? 0 : 1); k <= n; ++k) {
      const glm::dvec3 p = glm::mix(a, b, double(k) / n);
      auto pp = cam.project(p, near);
      if (!pp) continue;
      out.push_back({p, pp->pixel, along + length * k / n, false});
    }
    along += length;
  }
  return out;
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

Status draw_overlay(const Queries& queries, const Camera& cam, const Overlay& overlay, Image& img,
                    OverlayStats& stats) {
  const double near = 1e-6 * std::max(1.0, glm::length(cam.target() - cam.position()));
  const double r = std::max(1.5, std::min(img.width, img.height) / 280.0);  // line half-width in pixels
  std::vector<Sample> line, dots;
  for (const auto& path : overlay.paths) {
    std::vector<Sample> s = sample_path(path, cam, near);
    line.insert(line.end(), s.begin(), s.end());
    stats.path_vertices += path.size();
  }
  for (const glm::dvec3& p : overlay.points) {
    if (auto pp = cam.project(p, near)) dots.push_back({p, pp->pixel, 0.0, false});
  }
  stats.points = overlay.points.size();
  // Samples wholly off the image need no ray.
  auto off_image = [&](const Sample& s) {
    const double m = 3.0 * r + 2.0;
    return s.pixel.x < -m || s.pixel.y < -m || s.pixel.x > img.width + m || s.pixel.y > img.height + m;
  };
  std::erase_if(line, off_image);
  std::erase_if(dots, off_image);
  Status s = mark_hidden(queries, cam, line);
  if (s.ok()) s = mark_hidden(queries, cam, dots);
  if (!s.ok()) return s;

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
  stats.samples = line.size() + dots.size();
  for (const auto* v : {&line, &dots}) {
    for (const Sample& p : *v) stats.hidden += p.hidden;
  }
  return {};
}

bool has_png_extension(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png";
}


int run_render(const RenderArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  // What can be checked without the world fails before it loads.
  if (!has_png_extension(a.output)) return fail("render", "-o " + a.output + ": the output must be a .png file");
  Status checked = check_camera_args(a.camera);
  if (!checked.ok()) return fail("render", checked);
  if (!(a.options.fog >= 0.0 && a.options.fog <= 1.0)) {
    std::ostringstream m;
    m << "--fog " << a.options.fog << ": must be in 0 .. 1";
    return fail("render", m.str());
  }
  Overlay overlay;
  if (!a.overlay.empty()) {
    Result<Overlay> o = read_overlay(a.overlay);
    if (!o.ok()) return fail("render", o.status());
    overlay = std::move(o).value();
  }

  ProgressBar bar(!common.quiet);
  ScopedTimer total(nullptr, "");
  Result<World> w = load_world(a.world, {}, bar.context());
  if (!w.ok()) return fail("render", w.status());
  nlohmann::json seconds = {{"load", total.seconds()}};
  Result<Camera> cam = Camera::make(a.camera, &w.value());
  if (!cam.ok()) return fail("render", cam.status());
  const Camera& c = cam.value();

  Queries queries(w.value());
  Image img;
  RenderStats stats;
  ScopedTimer render(nullptr, "");
  Status s = render_image(queries, c, a.options, img, stats, bar.context());
  seconds["render"] = render.seconds();
  seconds["ray_cast"] = stats.cast_seconds;
  bar.finish();
  if (!s.ok()) return fail("render", s);
  OverlayStats ostats;
  if (!a.overlay.empty()) {
    ScopedTimer t(nullptr, "");
    s = draw_overlay(queries, c, overlay, img, ostats);
    seconds["overlay"] = t.seconds();
    if (!s.ok()) return fail("render", s);
  }
  ScopedTimer write(nullptr, "");
  if (!stbi_write_png(a.output.c_str(), img.width, img.height, 3, img.rgb.data(), img.width * 3)) {
    return fail("render", "-o " + a.output + ": cannot write the PNG");
  }
  seconds["write"] = write.seconds();
  seconds["total"] = total.seconds();

  const double hit_fraction = stats.rays ? double(stats.hits) / double(stats.rays) : 0.0;
  const size_t cast = stats.rays + stats.shadow_rays;
  const double mrays = stats.cast_seconds > 0.0 ? double(cast) / stats.cast_seconds * 1e-6 : 0.0;
  nlohmann::json report = {
      {"ok", true}, {"output", a.output}, {"width", img.width}, {"height", img.height}, {"rays", stats.rays},
      {"shadow_rays", stats.shadow_rays}, {"hits", stats.hits}, {"hit_fraction", hit_fraction},
      {"started_inside", stats.started_inside},
      {"mrays_per_s", mrays}, {"threads", thread_count()},
      {"camera", {{"position", vec_json(c.position())}, {"target", vec_json(c.target())}, {"fov", c.fov()}}},
      {"seconds", seconds}};
  if (!a.overlay.empty()) {
    report["overlay"] = {{"file", a.overlay}, {"path_vertices", ostats.path_vertices}, {"points", ostats.points},
                         {"samples", ostats.samples}, {"hidden_samples", ostats.hidden}};
  }
  if (common.json) {
    std::printf("%s\n", report.dump(2).c_str());
    return 0;
  }
  std::ostringstream shadow;
  if (a.options.shadows) shadow << " + " << stats.shadow_rays << " shadow rays";
  std::printf("render: %d x %d, %zu rays%s, %.1f%% hit, ray casts %.3f s (%.2f Mrays/s on %d threads), total %.3f s\n",
              img.width, img.height, stats.rays, shadow.str().c_str(), 100.0 * hit_fraction, stats.cast_seconds, mrays,
              report["threads"].get<int>(), seconds["total"].get<double>());
  std::printf("camera %s -> target %s, fov %g  (--camera %.6g,%.6g,%.6g --target %.6g,%.6g,%.6g)\n",
              detail::vec_text(c.position()).c_str(), detail::vec_text(c.target()).c_str(), c.fov(), c.position().x,
              c.position().y, c.position().z, c.target().x, c.target().y, c.target().z);
  if (stats.started_inside) {
    std::printf("warning: %zu rays started inside the solid (the camera is inside it; shown purple)\n",
                stats.started_inside);
  }
  if (!a.overlay.empty()) {
    std::printf("overlay: %zu path vertices, %zu points; %zu of %zu drawn samples hidden by the solid\n",
                ostats.path_vertices, ostats.points, ostats.hidden, ostats.samples);
  }
  std::printf("wrote %s\n", a.output.c_str());
  return 0;
}

}  // namespace

void add_render_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Preview image of a world (one ray cast per pixel) -> PNG");
  cmd->add_option("world", args->world, ".ldc file")->required();
  cmd->add_option("-o,--output", args->output, "Output .png")->required();
  add_camera_options(cmd, args->camera, " (default: a view of the whole solid)");
  cmd->add_flag("--shadows", args->options.shadows, "Cast a ray toward the sun from each lit hit: shadows");
  cmd->add_option("--fog", args->options.fog, "Fade far hits toward the sky, 0 .. 1")->capture_default_str();
  cmd->add_option("--overlay", args->overlay, "JSON with a \"path\" (or \"polyline\") and/or \"points\" to draw");
  cmd->footer(kRenderHelp);
  cmd->callback([args, &common] {
    int code = run_render(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
