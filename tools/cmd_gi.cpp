// ldc gi: an image of a world lit by the cone-traced GI of gi_bridge:
// primary visibility by our ray cast, irradiance from the cascades (16
// cones per pixel), albedo and emission from the materials; --reference
// puts the path-traced image (Embree on the contoured mesh) beside it.
// The Vulkan engine and the path tracer are plugins (issue 22), dlopen()ed
// only by --engine vulkan and --reference (gi_bridge/gi_plugin.h).
#include <cmath>
#include <cstdio>
#include <numbers>
#include <memory>
#include <string>
#include <vector>

#include "camera.h"
#include "common.h"
#include "contour/contour.h"
#include "gi_bridge/gi.h"
#include "gi_bridge/gi_plugin.h"
#include "json_inputs.h"
#include "ldc/io.h"
#include "ldc/query.h"
#include "plugin.h"
#include "render/render.h"
#ifdef LDC_HAVE_GI_REFERENCE
#include "gi_bridge/path_trace.h"
#endif

#if defined(LDC_HAVE_VULKAN) && !(defined(LDC_GI_VULKAN_PLUGIN_FILE) && defined(LDC_GI_VULKAN_PLUGIN_ABI))
#error "the Vulkan GI plugin's file name, install path and ABI come from tools/CMakeLists.txt"
#endif
#if defined(LDC_HAVE_GI_REFERENCE) && !(defined(LDC_GI_REFERENCE_PLUGIN_FILE) && defined(LDC_GI_REFERENCE_PLUGIN_ABI))
#error "the path-tracing plugin's file name, install path and ABI come from tools/CMakeLists.txt"
#endif

namespace ldc::tool {
namespace {

struct GiArgs {
  std::string world, output, engine = "vulkan";
  std::string up = "auto";
  CameraArgs camera;
  int levels = 6, resolution = 32, passes = 3, bounces = 3, samples = 16;
  int query_rays = GiConfig{}.query_rays;
  double voxel_size = 0.0;  // 0: 2 h
  float exposure = 1.0f;
  bool reference = false;
  std::vector<std::string> lights;  // "x,y,z,I" or "x,y,z,r,g,b"
  bool light_volume = false;
};

const char* const kGiHelp = R"(Sky: a gradient (zenith 1.0/1.2/1.6, horizon 1.4, ground 0.3) in the 16 lobes, its
zenith up (--up; z unless given: an .ldc world records no up axis); emission from the
materials. The cascades are centred on the camera; --passes lighting passes of
every level (3 give direct light and two bounces). --engine vulkan falls back to the CPU
reference when no Vulkan device exists. Colour: albedo / pi * irradiance + emission,
exposure, x / (1 + x), gamma 2.2. --reference path-traces the same view on the
contoured mesh (--samples paths per pixel) and writes it to the right of the GI image.
--light x,y,z,I (or x,y,z,r,g,b) adds a point light of intensity I at a world point
(irradiance I / r^2 facing it); at most 8, or 65536 with --light-volume, which injects
them into a cascaded light volume as the talk does (less exact, see docs/gi.md).
The image's final gather traces each of the 16 cones as --query-rays narrow rays where
the air is open to the sky (cones darken surfaces they graze); 0 keeps the cones,
about 4 times faster on the CPU engine.
)";

// The engine's configuration the arguments ask for.
GiConfig gi_config_of(const GiArgs& a) {
  GiConfig c;
  c.light_volume = a.light_volume;
  c.query_rays = a.query_rays;
  return c;
}

// The default sky and the --light point lights.
Result<GiLights> parse_lights(const GiArgs& a, int up_axis) {
  GiLights l;
  l.sky = SkyLight::gradient(glm::vec3(1.0f, 1.2f, 1.6f), glm::vec3(1.4f), glm::vec3(0.3f), up_axis);
  for (const std::string& text : a.lights) {
    std::vector<double> v;
    if (!parse_numbers(text, &v) || (v.size() != 4 && v.size() != 6))
      return Status(ErrorCode::kInvalidArgument, "--light " + text + ": want x,y,z,I or x,y,z,r,g,b (finite numbers)");
    const glm::vec3 intensity = v.size() == 4 ? glm::vec3(float(v[3])) : glm::vec3(float(v[3]), float(v[4]), float(v[5]));
    l.points.push_back({glm::dvec3(v[0], v[1], v[2]), intensity});
  }
  if (Status s = check_gi_lights(l, gi_config_of(a)); !s.ok()) return s;
  return l;
}

// --- The plugins (gi_bridge/gi_plugin.h), each loaded once, on first use --

#ifdef LDC_HAVE_VULKAN
struct VulkanPlugin {  // a struct: see VdbPlugin in cmd_voxelize.cpp
  LdcGiVulkanCreateFn create = nullptr;
};

Result<VulkanPlugin> load_vulkan_plugin() {
  const PluginSpec spec{LDC_GI_VULKAN_PLUGIN_FILE, LDC_GI_VULKAN_PLUGIN_INSTALL_REL, "Vulkan GI", "ldc_gi_plugin_abi",
                        LDC_GI_VULKAN_PLUGIN_ABI, {"ldc_gi_vulkan_create"}, "ldc_gi_plugin_layout",
                        gi_plugin_layout()};
  Result<LoadedPlugin> plugin = load_plugin(spec);
  if (plugin.ok()) return VulkanPlugin{reinterpret_cast<LdcGiVulkanCreateFn>(plugin.value().symbols[0])};
  return Status(ErrorCode::kUnsupported, std::string("--engine vulkan needs the Vulkan GI plugin " LDC_GI_VULKAN_PLUGIN_FILE
                                                     ", which did not load (tried ") +
                                             plugin.status().message() + "). --engine cpu needs no plugin");
}

const Result<VulkanPlugin>& vulkan_plugin() {
  static const Result<VulkanPlugin> plugin = load_vulkan_plugin();
  return plugin;
}

// make_vulkan_gi through the plugin: the same engine and the same messages.
Result<std::unique_ptr<GiEngine>> make_vulkan_engine(const GiConfig& config, std::string* device) {
  const Result<VulkanPlugin>& plugin = vulkan_plugin();
  if (!plugin.ok()) return plugin.status();
  std::unique_ptr<GiEngine> engine;
  std::string message = "the Vulkan GI plugin failed without a message";
  const int code = plugin.value().create(&config, &engine, device, &message);
  if (code != 0) return Status(static_cast<ErrorCode>(code), message);
  return engine;
}
#endif

#ifdef LDC_HAVE_GI_REFERENCE
struct ReferencePlugin {
  LdcGiReferenceRadianceFn radiance = nullptr;
};

Result<ReferencePlugin> load_reference_plugin() {
  const PluginSpec spec{LDC_GI_REFERENCE_PLUGIN_FILE, LDC_GI_REFERENCE_PLUGIN_INSTALL_REL, "path-tracing",
                        "ldc_gi_plugin_abi", LDC_GI_REFERENCE_PLUGIN_ABI, {"ldc_gi_reference_radiance"},
                        "ldc_gi_plugin_layout", gi_plugin_layout()};
  Result<LoadedPlugin> plugin = load_plugin(spec);
  if (plugin.ok()) return ReferencePlugin{reinterpret_cast<LdcGiReferenceRadianceFn>(plugin.value().symbols[0])};
  return Status(ErrorCode::kUnsupported, std::string("--reference needs the path-tracing plugin " LDC_GI_REFERENCE_PLUGIN_FILE
                                                     " (Embree), which did not load (tried ") +
                                             plugin.status().message() + ")");
}

const Result<ReferencePlugin>& reference_plugin() {
  static const Result<ReferencePlugin> plugin = load_reference_plugin();
  return plugin;
}
#endif

// A plugin that the arguments need and that does not load: its message
// (naming the paths tried), before the world loads; empty when none.
std::string missing_plugin(const GiArgs& a) {
#ifdef LDC_HAVE_VULKAN
  if (a.engine == "vulkan" && !vulkan_plugin().ok()) return vulkan_plugin().status().message();
#endif
#ifdef LDC_HAVE_GI_REFERENCE
  if (a.reference && !reference_plugin().ok()) return reference_plugin().status().message();
#endif
  (void)a;
  return {};
}

Result<std::unique_ptr<GiEngine>> make_engine(const std::string& name, const GiConfig& config, std::string* device) {
  if (name == "cpu") {
    *device = "cpu reference";
    return make_cpu_gi(config);
  }
  if (name != "vulkan") return Status(ErrorCode::kInvalidArgument, "--engine " + name + ": use vulkan or cpu");
#ifdef LDC_HAVE_VULKAN
  Result<std::unique_ptr<GiEngine>> gi = make_vulkan_engine(config, device);
  if (gi.ok()) return gi;
  std::fprintf(stderr, "gi: %s; using the CPU reference\n", gi.status().message().c_str());
#else
  std::fprintf(stderr, "gi: built without Vulkan (LDC_WITH_VULKAN off); using the CPU reference\n");
#endif
  *device = "cpu reference";
  return make_cpu_gi(config);
}

#ifdef LDC_HAVE_GI_REFERENCE
// The same view path-traced on the contoured mesh (linear radiance).
Result<RadianceImage> reference_image(const World& world, const Camera& cam, const MaterialTable& mats,
                                      const GiLights& lights, int bounces, int samples) {
  Result<ContourMesh> mesh = contour_world(world);
  if (!mesh.ok()) return mesh.status();
  const Result<ReferencePlugin>& plugin = reference_plugin();
  if (!plugin.ok()) return plugin.status();
  RadianceImage img{cam.width(), cam.height(), std::vector<glm::vec3>(size_t(cam.width()) * size_t(cam.height()))};
  std::vector<Ray> rays;
  rays.reserve(img.pixels.size());
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x) rays.push_back(cam.pixel_ray(x, y));
  PathTraceConfig pc;
  pc.samples = samples;
  std::string message = "the path-tracing plugin failed without a message";
  const int code = plugin.value().radiance(&mesh.value(), &mats, &lights, rays.data(), rays.size(), bounces, &pc,
                                           img.pixels.data(), &message);
  if (code != 0) return Status(static_cast<ErrorCode>(code), message);
  return img;
}
#endif

// What the lighting and image took, for the report.
struct GiRun {
  std::string device;
  CascadeConfig cascades;
  GiTimings lighting;
  double voxelize_seconds = 0.0, image_seconds = 0.0, reference_seconds = 0.0;
  int width = 0, height = 0, up_axis = kLdcUpAxis;
};

void print_report(const GiArgs& a, const GiLights& lights, const GiRun& r, bool json) {
  const size_t surface_voxels = r.lighting.surface_voxels / size_t(a.passes);
  if (json) {
    nlohmann::json j{{"device", r.device},
                     {"levels", a.levels},
                     {"resolution", a.resolution},
                     {"voxel_size", r.cascades.voxel_size},
                     {"surface_voxels", surface_voxels},
                     {"passes", a.passes},
                     {"query_rays", a.query_rays},
                     {"up", axis_name(r.up_axis)},
                     {"point_lights", {{"count", lights.points.size()}, {"mode", a.light_volume ? "injected volume" : "exact"}}},
                     {"seconds", {{"voxelize", r.voxelize_seconds}, {"lighting", r.lighting.seconds}, {"lighting_device", r.lighting.device_seconds}, {"image", r.image_seconds}}},
                     {"image", {{"width", r.width}, {"height", r.height}, {"bounces", a.bounces}}},
                     {"output", a.output}};
    if (a.reference) {
      j["reference"] = {{"samples", a.samples}};
      j["seconds"]["reference"] = r.reference_seconds;
    }
    std::printf("%s\n", json_text(with_warnings(j)).c_str());
    return;
  }
  std::printf("gi: %s, %d levels of %d^3 voxels of %.3g m, %zu surface voxels; voxelize %.3f s\n", r.device.c_str(),
              a.levels, a.resolution, r.cascades.voxel_size, surface_voxels, r.voxelize_seconds);
  char device_time[64] = "";  // GPU timestamps (or the CPU engine's kernels); none without timestamps
  if (r.lighting.device_seconds >= 0)
    std::snprintf(device_time, sizeof(device_time), " (device %.3f s each)", r.lighting.device_seconds / a.passes);
  std::printf("gi: %d lighting passes %.3f s (%.3f s each)%s, image %d x %d (%d bounces) %.3f s\n", a.passes,
              r.lighting.seconds, r.lighting.seconds / a.passes, device_time, r.width, r.height, a.bounces,
              r.image_seconds);
  if (a.reference)
    std::printf("gi: path-traced reference, %d paths per pixel, %.3f s (right half)\n", a.samples, r.reference_seconds);
  std::printf("wrote %s\n", a.output.c_str());
}

// Checks what needs no world, so that it fails before the world loads.
Status check_args(const GiArgs& a) {
  if (Status s = check_camera_args(a.camera); !s.ok()) return s;
  // Refused, not replaced: -1 used to mean the default voxel size, and a
  // NaN exposure wrote a black image (issue 24, finding 11).
  if (!(a.voxel_size == 0.0 || (a.voxel_size > 0.0 && std::isfinite(a.voxel_size))))
    return Status(ErrorCode::kInvalidArgument,
                  "--voxel-size " + number_text(a.voxel_size) + ": must be a finite length > 0 (m; default 2 h)");
  if (!(a.exposure > 0.0f && std::isfinite(a.exposure)))
    return Status(ErrorCode::kInvalidArgument, "--exposure " + number_text(a.exposure) + ": must be finite and > 0");
  if (a.passes < 1 || a.passes > 16)
    return Status(ErrorCode::kInvalidArgument, "--passes " + std::to_string(a.passes) + ": must be 1 .. 16");
  if (a.bounces < 1 || a.bounces > 3)
    return Status(ErrorCode::kInvalidArgument, "--bounces " + std::to_string(a.bounces) + ": must be 1 .. 3");
  if (a.query_rays < 0 || a.query_rays > kGiMaxQueryRays)
    return Status(ErrorCode::kInvalidArgument, "--query-rays " + std::to_string(a.query_rays) + ": must be 0 .. " +
                                                   std::to_string(kGiMaxQueryRays));
#ifndef LDC_HAVE_GI_REFERENCE
  if (a.reference)
    return Status(ErrorCode::kUnsupported, "--reference: built without Embree 3 (the path tracer's ray caster)");
#endif
  return parse_up_axis(a.up, kLdcUpAxis).status();
}

// Voxelizes around the camera, lights the cascades and renders the image
// (with the reference on the right).
Result<Image> lit_image(const GiArgs& a, const World& world, const Camera& cam, const GiLights& lights, GiRun& r,
                        Context* ctx) {
  r.cascades.levels = a.levels;
  r.cascades.resolution = a.resolution;
  r.cascades.voxel_size = a.voxel_size > 0.0 ? a.voxel_size : 2.0 * world.lattice().cell_size;
  ScopedTimer t_vox(nullptr, "");
  Result<Cascades> cas = Cascades::create(world.lattice(), r.cascades);
  if (!cas.ok()) return cas.status();
  if (Status s = cas.value().update_all(world, cam.position()); !s.ok()) return s;
  r.voxelize_seconds = t_vox.seconds();
  Result<std::unique_ptr<GiEngine>> gi = make_engine(a.engine, gi_config_of(a), &r.device);
  if (!gi.ok()) return gi.status();
  if (Status s = gi.value()->load(cas.value(), lights); !s.ok()) return s;
  Result<GiTimings> upd = gi.value()->update_all(a.passes);
  if (!upd.ok()) return upd.status();
  r.lighting = upd.value();
  ScopedTimer t_img(nullptr, "");
  Queries queries(world);
  Result<RadianceImage> lit =
      render_gi(queries, cam, *gi.value(),
                {.materials = r.cascades.materials, .sky = lights.sky, .bounces = a.bounces, .ctx = ctx});
  if (!lit.ok()) return lit.status();
  r.image_seconds = t_img.seconds();
  Image image = tone_map(lit.value(), a.exposure);
#ifdef LDC_HAVE_GI_REFERENCE
  if (a.reference) {
    ScopedTimer t_ref(nullptr, "");
    Result<RadianceImage> ref = reference_image(world, cam, r.cascades.materials, lights, a.bounces, a.samples);
    if (!ref.ok()) return ref.status();
    r.reference_seconds = t_ref.seconds();
    return side_by_side(image, tone_map(ref.value(), a.exposure));
  }
#endif
  return image;
}

int run_gi(const GiArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  if (Status s = check_args(a); !s.ok()) return fail("gi", s);
  if (std::string missing = missing_plugin(a); !missing.empty()) return fail("gi", missing);
  const int up_axis = parse_up_axis(a.up, kLdcUpAxis).value();
  Result<GiLights> lights = parse_lights(a, up_axis);
  if (!lights.ok()) return fail("gi", lights.status());
  ProgressBar bar(!common.quiet);
  Result<World> w = load_world_file(a.world, {}, bar.context());
  bar.finish();
  if (!w.ok()) return fail("gi", w.status());
  Result<Camera> cam = make_camera(a.camera, up_axis, &w.value());
  if (!cam.ok()) return fail("gi", cam.status());
  GiLights& scene_lights = lights.value();
  for (size_t i : remove_buried_lights(w.value(), &scene_lights))
    warn("gi", "--light " + a.lights[i] + " lies inside the solid and lights nothing (as in the path tracer); left out");
  GiRun run;
  run.up_axis = up_axis;
  run.width = cam.value().width();
  run.height = cam.value().height();
  ProgressBar image_bar(!common.quiet);
  Result<Image> image = lit_image(a, w.value(), cam.value(), lights.value(), run, image_bar.context());
  image_bar.finish();
  if (!image.ok()) return fail("gi", image.status());
  if (Status s = write_png(image.value(), a.output); !s.ok()) return fail("gi", "-o " + s.message());
  print_report(a, lights.value(), run, common.json);
  return 0;
}

}  // namespace

void add_gi_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<GiArgs>();
  CLI::App* cmd = app.add_subcommand("gi", "Image lit by cone-traced global illumination from the voxel cascades -> PNG");
  cmd->add_option("world", args->world, ".ldc file")->required();
  output_file(cmd->add_option("-o,--output", args->output, "Output .png"))->required();
  add_camera_options(cmd, args->camera, " (default: a view of the whole solid)");
  add_up_option(cmd, args->up, "z (an .ldc world records no up axis)");
  cmd->add_option("--engine", args->engine, "vulkan or cpu")->capture_default_str();
  cmd->add_option("--levels", args->levels, "Cascade levels")->capture_default_str();
  cmd->add_option("--resolution", args->resolution, "Voxels per axis and level")->capture_default_str();
  cmd->add_option("--voxel-size", args->voxel_size, "Level 0 voxel edge in m (default 2 h)");
  cmd->add_option("--passes", args->passes, "Lighting passes of every level")->capture_default_str();
  cmd->add_option("--bounces", args->bounces, "Bounces in the image, 1 .. 3")->capture_default_str();
  cmd->add_option("--query-rays", args->query_rays,
                  "Narrow rays per cone for the image's final gather in open air, 0 .. 16 (0: the cones)")
      ->capture_default_str();
  cmd->add_option("--exposure", args->exposure, "Exposure before tone mapping")->capture_default_str();
  cmd->add_flag("--reference", args->reference, "Also path-trace the view (Embree) and put it on the right");
  cmd->add_option("--samples", args->samples, "Paths per pixel of --reference")->capture_default_str();
  cmd->add_option("--light", args->lights, "Point light x,y,z,I or x,y,z,r,g,b (repeatable)");
  cmd->add_flag("--light-volume", args->light_volume, "Inject the point lights into a cascaded volume (the talk's method)");
  cmd->footer(kGiHelp);
  cmd->callback([args, &common] {
    int code = run_gi(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
