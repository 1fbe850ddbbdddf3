// ldc raycast: first hits of rays (from a JSON file, a camera or one ray) -> JSON.
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

namespace ldc::tool {
namespace {

const char* const kRaycastHelp = R"(Rays come from exactly one source:
  --rays FILE                   JSON: [{"origin": [x,y,z], "direction": [x,y,z], "max_distance": d}, ...]
                                (or {"rays": [...]}); max_distance is optional (default: unlimited)
  --origin X,Y,Z --direction X,Y,Z   one ray
  --camera X,Y,Z [--target X,Y,Z]    one ray per pixel, as `ldc render` casts them (row by row from the top
                                left; each hit has "pixel": [x, y]); the target defaults to the solid's centre
--max-distance applies to --origin and --camera rays. Output (stdout, or -o FILE):
  {"summary": {"rays", "hits", "seconds", "mrays_per_s", ...},
   "rays": [{"hit": true, "distance", "point", "normal", "material", "started_inside"}, {"hit": false}, ...]}
A ray that starts inside the solid hits at distance 0 with "started_inside": true.
)";

struct RaycastArgs {
  std::string world;
  std::string rays;       // --rays file
  std::string origin;     // --origin
  std::string direction;  // --direction
  double max_distance = std::numeric_limits<double>::infinity();
  CameraArgs camera;
  std::string output;     // -o; empty = stdout
};

// Limit on camera rays: the JSON output takes ~150 bytes a ray.
constexpr size_t kMaxCameraRays = size_t(1) << 24;

struct RaySource {
  std::vector<Ray> rays;
  std::optional<Camera> camera;  // camera rays: pixel i = (i % width, i / width)
  std::string name;              // "file", "ray", "camera"
};

Result<RaySource> make_rays(const RaycastArgs& a, const World& world) {
  const bool from_file = !a.rays.empty();
  const bool single = !a.origin.empty() || !a.direction.empty();
  const bool camera = !a.camera.camera.empty() || !a.camera.target.empty();
  if (int(from_file) + int(single) + int(camera) != 1) {
    return Status(ErrorCode::kInvalidArgument,
                  "give exactly one source of rays: --rays FILE, --origin with --direction, or --camera");
  }
  if (!(a.max_distance >= 0.0)) {
    return Status(ErrorCode::kInvalidArgument, "--max-distance " + number_text(a.max_distance) + ": must be >= 0");
  }
  RaySource src;
  if (from_file) {
    Result<std::vector<Ray>> rays = read_rays(a.rays);
    if (!rays.ok()) return rays.status();
    src.rays = std::move(rays).value();
    src.name = "file";
    return src;
  }
  if (single) {
    if (a.origin.empty() || a.direction.empty()) {
      return Status(ErrorCode::kInvalidArgument, "a single ray needs both --origin and --direction");
    }
    Ray r;
    r.max_distance = a.max_distance;
    if (!parse_vec3(a.origin, &r.origin)) {
      return Status(ErrorCode::kInvalidArgument, "--origin '" + a.origin + "': expected three finite numbers x,y,z");
    }
    if (!parse_vec3(a.direction, &r.direction)) {
      return Status(ErrorCode::kInvalidArgument,
                    "--direction '" + a.direction + "': expected three finite numbers x,y,z");
    }
    if (!(glm::length(r.direction) > 1e-300) || !std::isfinite(glm::length(r.direction))) {
      return Status(ErrorCode::kInvalidArgument,
                    "--direction " + detail::vec_text(r.direction) + " has no usable length (zero or overflowing)");
    }
    src.rays.push_back(r);
    src.name = "ray";
    return src;
  }
  Result<Camera> cam = make_camera(a.camera, kLdcUpAxis, &world);
  if (!cam.ok()) return cam.status();
  const Camera& c = cam.value();
  if (size_t(c.width()) * size_t(c.height()) > kMaxCameraRays) {
    std::ostringstream s;
    s << "--width " << c.width() << " --height " << c.height() << ": at most " << kMaxCameraRays
      << " camera rays (use `ldc render` for bigger images)";
    return Status(ErrorCode::kInvalidArgument, s.str());
  }
  src.rays.resize(size_t(c.width()) * size_t(c.height()));
  for (int y = 0; y < c.height(); ++y) {
    for (int x = 0; x < c.width(); ++x) {
      Ray r = c.pixel_ray(x, y);
      r.max_distance = a.max_distance;
      src.rays[size_t(y) * size_t(c.width()) + size_t(x)] = r;
    }
  }
  src.camera = c;
  src.name = "camera";
  return src;
}

// Casts in blocks so that the progress bar moves.
Status cast_all(const Queries& queries, const std::vector<Ray>& rays, std::vector<RayHit>& hits, Context* ctx) {
  const size_t block = 1 << 16;
  hits.resize(rays.size());
  for (size_t begin = 0; begin < rays.size(); begin += block) {
    const size_t n = std::min(block, rays.size() - begin);
    Status s = queries.ray_cast(std::span<const Ray>(rays).subspan(begin, n), std::span<RayHit>(hits).subspan(begin, n),
                                ctx);
    if (!s.ok()) return Status(s.code(), "rays " + std::to_string(begin) + ".. : " + s.message());
    if (ctx) ctx->report_progress("raycast", double(begin + n) / double(rays.size()));
  }
  return {};
}

void write_vec3(std::FILE* f, double x, double y, double z) { std::fprintf(f, "[%.10g, %.10g, %.10g]", x, y, z); }

// The hits, one ray a line (streamed: a camera's worth of rays would make a
// big JSON tree).
bool write_hits(std::FILE* f, const nlohmann::json& summary, const RaySource& src, const std::vector<RayHit>& hits) {
  std::fprintf(f, "{\"summary\": %s,\n\"rays\": [", json_text(summary, -1).c_str());
  for (size_t i = 0; i < hits.size(); ++i) {
    const RayHit& h = hits[i];
    std::fprintf(f, "%s\n{", i ? "," : "");
    if (src.camera) {
      std::fprintf(f, "\"pixel\": [%zu, %zu], ", i % size_t(src.camera->width()), i / size_t(src.camera->width()));
    }
    if (!h.hit) {
      std::fprintf(f, "\"hit\": false}");
      continue;
    }
    std::fprintf(f, "\"hit\": true, \"distance\": %.10g, \"point\": ", h.distance);
    write_vec3(f, h.point.x, h.point.y, h.point.z);
    // + 0.0: no "-0" in the output.
    std::fprintf(f, ", \"normal\": [%.7g, %.7g, %.7g], \"material\": %u, \"started_inside\": %s}",
                 double(h.normal.x) + 0.0, double(h.normal.y) + 0.0, double(h.normal.z) + 0.0, unsigned(h.material),
                 h.started_inside ? "true" : "false");
  }
  std::fprintf(f, "%s]}\n", hits.empty() ? "" : "\n");
  return std::ferror(f) == 0;
}

void print_summary(std::FILE* f, const nlohmann::json& s, const std::vector<RayHit>& hits) {
  const size_t rays = s["rays"].get<size_t>(), n_hits = s["hits"].get<size_t>();
  std::fprintf(f, "raycast: %zu rays (%s), %zu hits (%.1f%%), %.4f s, %.2f Mrays/s on %d threads\n", rays,
               s["source"].get<std::string>().c_str(), n_hits, rays ? 100.0 * double(n_hits) / double(rays) : 0.0,
               s["seconds"].get<double>(), s["mrays_per_s"].get<double>(), s["threads"].get<int>());
  if (s.contains("camera")) {
    const auto& c = s["camera"];
    auto v = [](const nlohmann::json& a) {
      return detail::vec_text({a[0].get<double>(), a[1].get<double>(), a[2].get<double>()});
    };
    std::fprintf(f, "camera %s -> target %s, fov %g, %d x %d\n", v(c["position"]).c_str(), v(c["target"]).c_str(),
                 c["fov"].get<double>(), c["width"].get<int>(), c["height"].get<int>());
  }
  if (hits.size() == 1) {
    const RayHit& h = hits[0];
    if (!h.hit) {
      std::fprintf(f, "no hit\n");
    } else {
      std::fprintf(f, "hit at distance %.6g: point %s, normal %s, material %u%s\n", h.distance,
                   detail::vec_text(h.point).c_str(), detail::vec_text(glm::dvec3(h.normal)).c_str(), unsigned(h.material),
                   h.started_inside ? " (started inside the solid)" : "");
    }
  }
}

int run_raycast(const RaycastArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  ProgressBar bar(!common.quiet);
  ScopedTimer load(nullptr, "");
  Result<World> w = load_world_file(a.world, {}, bar.context());
  if (!w.ok()) return fail("raycast", w.status());
  const double load_seconds = load.seconds();
  Result<RaySource> src = make_rays(a, w.value());
  if (!src.ok()) return fail("raycast", src.status());

  Queries queries(w.value());
  std::vector<RayHit> hits;
  ScopedTimer cast(nullptr, "");
  Status s = cast_all(queries, src.value().rays, hits, bar.context());
  const double seconds = cast.seconds();
  bar.finish();
  if (!s.ok()) return fail("raycast", s);

  size_t n_hits = 0;
  for (const RayHit& h : hits) n_hits += h.hit;
  nlohmann::json summary = {{"rays", hits.size()}, {"hits", n_hits}, {"seconds", seconds},
                            {"mrays_per_s", seconds > 0.0 ? double(hits.size()) / seconds * 1e-6 : 0.0},
                            {"load_seconds", load_seconds}, {"source", src.value().name},
                            {"threads", thread_count()}};
  if (const auto& c = src.value().camera) {
    summary["camera"] = {{"position", {c->position().x, c->position().y, c->position().z}},
                         {"target", {c->target().x, c->target().y, c->target().z}},
                         {"fov", c->fov()}, {"width", c->width()}, {"height", c->height()}};
  }

  if (a.output.empty()) {
    if (!write_hits(stdout, summary, src.value(), hits)) return fail("raycast", "cannot write to stdout");
    if (!common.json) print_summary(stderr, summary, hits);
    return 0;
  }
  // Streamed into a temp file renamed over -o only once whole (ldc/io.h):
  // a failure or a kill leaves any previous file as it was.
  Result<AtomicFile> out = AtomicFile::create(a.output);
  if (!out.ok()) return fail("raycast", "-o " + out.status().message());
  if (!write_hits(out.value().stream(), summary, src.value(), hits)) {
    return fail("raycast", "-o " + a.output + ": write failed");
  }
  if (Status committed = out.value().commit(); !committed.ok()) return fail("raycast", "-o " + committed.message());
  if (common.json) {
    nlohmann::json report = {{"ok", true}, {"output", a.output}, {"summary", summary}};
    std::printf("%s\n", json_text(report).c_str());
  } else {
    print_summary(stdout, summary, hits);
    std::printf("wrote %s\n", a.output.c_str());
  }
  return 0;
}

}  // namespace

void add_raycast_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<RaycastArgs>();
  CLI::App* cmd = app.add_subcommand("raycast", "First hits of rays from a JSON file, a camera or one ray (JSON out)");
  cmd->add_option("world", args->world, ".ldc file")->required();
  cmd->add_option("--rays", args->rays, "JSON file of rays (format below)");
  cmd->add_option("--origin", args->origin, "One ray: its origin x,y,z");
  cmd->add_option("--direction", args->direction, "One ray: its direction x,y,z (any length > 0)");
  cmd->add_option("--max-distance", args->max_distance, "Longest hit distance for --origin and --camera rays (m)");
  add_camera_options(cmd, args->camera, " (one ray per pixel)");
  output_file(cmd->add_option("-o,--output", args->output, "Write the hits here instead of stdout"));
  cmd->footer(kRaycastHelp);
  cmd->callback([args, &common] {
    int code = run_raycast(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
