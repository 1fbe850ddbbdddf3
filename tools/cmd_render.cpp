// ldc render: a preview image of a world, one ray cast per pixel, with an
// optional overlay of a path and points -> PNG.
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <vector>

#include "camera.h"
#include "common.h"
#include "json_inputs.h"
#include "ldc/internal/vec_text.h"
#include "ldc/io.h"
#include "ldc/query.h"
#include "render/render.h"

namespace ldc::tool {
namespace {

const char* const kRenderHelp = R"(Without --camera the view looks at the solid's centre (or --target) from above and
to the side, --up up (z unless given: an .ldc world records no up axis), as near as
shows all of it; the camera used is printed. Shading (render/render.h): lambert from a
fixed sun plus ambient, times the material's colour (the one palette, ldc/materials.h:
0 rock, 1 grass, 2 dirt, 3 sand, then distinct colours), with a hint of the normal's
colour; misses show the sky. Sun, sky and view turn with --up. A camera inside the
solid shows purple.
--overlay FILE draws, with the same camera, a polyline and/or points:
  {"path": [[x,y,z], ...], "points": [[x,y,z], ...]}    ("polyline" is taken for "path")
(at most 1,000,000 entries in each list; the path is drawn only where it crosses the image).
Parts hidden behind the solid (a ray cast toward the camera hits it) are drawn
dimmed and dashed.
)";

struct RenderArgs {
  std::string world;
  std::string output;
  std::string overlay;
  std::string up = "auto";
  CameraArgs camera;
  RenderOptions options;  // the overlay is read from `overlay`
};

bool has_png_extension(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png";
}

// Checks what needs no world, so that it fails before the world loads.
Status check_args(const RenderArgs& a) {
  if (!has_png_extension(a.output))
    return Status(ErrorCode::kInvalidArgument, "-o " + a.output + ": the output must be a .png file");
  if (Status s = check_camera_args(a.camera); !s.ok()) return s;
  if (!(a.options.fog >= 0.0 && a.options.fog <= 1.0)) {
    std::ostringstream m;
    m << "--fog " << a.options.fog << ": must be in 0 .. 1";
    return Status(ErrorCode::kInvalidArgument, m.str());
  }
  return parse_up_axis(a.up, kLdcUpAxis).status();
}

nlohmann::json report_json(const RenderArgs& a, const Image& img, const Camera& c, const RenderStats& stats,
                           const nlohmann::json& seconds) {
  const double hit_fraction = stats.rays ? double(stats.hits) / double(stats.rays) : 0.0;
  const size_t cast = stats.rays + stats.shadow_rays;
  const double mrays = stats.cast_seconds > 0.0 ? double(cast) / stats.cast_seconds * 1e-6 : 0.0;
  nlohmann::json report = {
      {"ok", true}, {"output", a.output}, {"width", img.width}, {"height", img.height}, {"rays", stats.rays},
      {"shadow_rays", stats.shadow_rays}, {"hits", stats.hits}, {"hit_fraction", hit_fraction},
      {"started_inside", stats.started_inside},
      {"mrays_per_s", mrays}, {"threads", thread_count()}, {"up", axis_name(c.up_axis())},
      {"camera", {{"position", vec_json(c.position())}, {"target", vec_json(c.target())}, {"fov", c.fov()}}},
      {"seconds", seconds}};
  if (!a.overlay.empty()) {
    report["overlay"] = {{"file", a.overlay}, {"path_vertices", stats.path_vertices}, {"points", stats.points},
                         {"samples", stats.overlay_samples}, {"hidden_samples", stats.hidden_samples}};
  }
  return report;
}

void print_report(const RenderArgs& a, const Camera& c, const RenderStats& stats, const nlohmann::json& report) {
  std::ostringstream shadow;
  if (a.options.shadows) shadow << " + " << stats.shadow_rays << " shadow rays";
  std::printf("render: %d x %d, %zu rays%s, %.1f%% hit, ray casts %.3f s (%.2f Mrays/s on %d threads), total %.3f s\n",
              c.width(), c.height(), stats.rays, shadow.str().c_str(), 100.0 * report["hit_fraction"].get<double>(),
              stats.cast_seconds, report["mrays_per_s"].get<double>(), report["threads"].get<int>(),
              report["seconds"]["total"].get<double>());
  std::printf("camera %s -> target %s, fov %g  (--camera %.6g,%.6g,%.6g --target %.6g,%.6g,%.6g)\n",
              detail::vec_text(c.position()).c_str(), detail::vec_text(c.target()).c_str(), c.fov(), c.position().x,
              c.position().y, c.position().z, c.target().x, c.target().y, c.target().z);
  if (!a.overlay.empty()) {
    std::printf("overlay: %zu path vertices, %zu points; %zu of %zu drawn samples hidden by the solid\n",
                stats.path_vertices, stats.points, stats.hidden_samples, stats.overlay_samples);
  }
  std::printf("wrote %s\n", a.output.c_str());
}

int run_render(const RenderArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  if (Status s = check_args(a); !s.ok()) return fail("render", s);
  RenderOptions options = a.options;
  if (!a.overlay.empty()) {
    Result<Overlay> o = read_overlay(a.overlay);
    if (!o.ok()) return fail("render", o.status());
    options.overlay = std::move(o).value();
  }

  ProgressBar bar(!common.quiet);
  ScopedTimer total(nullptr, "");
  Result<World> w = load_world_file(a.world, {}, bar.context());
  if (!w.ok()) return fail("render", w.status());
  nlohmann::json seconds = {{"load", total.seconds()}};
  Result<Camera> cam = make_camera(a.camera, parse_up_axis(a.up, kLdcUpAxis).value(), &w.value());
  if (!cam.ok()) return fail("render", cam.status());
  const Camera& c = cam.value();

  Queries queries(w.value());
  RenderStats stats;
  ScopedTimer render_timer(nullptr, "");
  Result<Image> img = render(queries, c, options, &stats, bar.context());
  seconds["render"] = render_timer.seconds() - stats.overlay_seconds;
  seconds["ray_cast"] = stats.cast_seconds;
  bar.finish();
  if (!img.ok()) return fail("render", img.status());
  if (!a.overlay.empty()) seconds["overlay"] = stats.overlay_seconds;
  ScopedTimer write(nullptr, "");
  if (Status s = write_png(img.value(), a.output); !s.ok()) return fail("render", "-o " + s.message());
  seconds["write"] = write.seconds();
  seconds["total"] = total.seconds();

  if (stats.started_inside) {
    warn("render", std::to_string(stats.started_inside) +
                       " rays started inside the solid (the camera is inside it; shown purple)");
  }
  const nlohmann::json report = report_json(a, img.value(), c, stats, seconds);
  if (common.json) {
    std::printf("%s\n", json_text(with_warnings(report)).c_str());
    return 0;
  }
  print_report(a, c, stats, report);
  return 0;
}

}  // namespace

void add_render_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Preview image of a world (one ray cast per pixel) -> PNG");
  cmd->add_option("world", args->world, ".ldc file")->required();
  output_file(cmd->add_option("-o,--output", args->output, "Output .png"))->required();
  add_camera_options(cmd, args->camera, " (default: a view of the whole solid)");
  add_up_option(cmd, args->up, "z (an .ldc world records no up axis)");
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
