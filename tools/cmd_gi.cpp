// ldc gi: an image of a world lit by the cone-traced GI of gi_bridge:
// primary visibility by our ray cast, irradiance from the cascades (16
// cones per pixel), albedo and emission from the materials; --reference
// puts the path-traced image (Embree on the contoured mesh) beside it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <memory>
#include <sstream>
#include <vector>

#include <stb_image_write.h>

#include "camera.h"
#include "common.h"
#include "contour/contour.h"
#include "gi_bridge/gi.h"
#include "ldc/io.h"
#include "ldc/query.h"
#ifdef LDC_HAVE_GI_REFERENCE
#include "gi_bridge/path_trace.h"
#endif

namespace ldc::tool {
namespace {

struct GiArgs {
  std::string world, output, engine = "vulkan";
  CameraArgs camera;
  int levels = 6, resolution = 32, passes = 3, bounces = 3, samples = 16;
  double voxel_size = 0.0;  // 0: 2 h
  float exposure = 1.0f;
  bool reference = false;
  std::vector<std::string> lights;  // "x,y,z,I" or "x,y,z,r,g,b"
  bool light_volume = false;
};

const char* const kGiHelp = R"(Sky: a gradient (zenith 1.0/1.2/1.6, horizon 1.4, ground 0.3) in the 16 lobes; emission
from the materials. The cascades are centred on the camera; --passes lighting passes of
every level (3 give direct light and two bounces). --engine vulkan falls back to the CPU
reference when no Vulkan device exists. Colour: albedo / pi * irradiance + emission,
exposure, x / (1 + x), gamma 2.2. --reference path-traces the same view on the
contoured mesh (--samples paths per pixel) and writes it to the right of the GI image.
--light x,y,z,I (or x,y,z,r,g,b) adds a point light of intensity I at a world point
(irradiance I / r^2 facing it); at most 8, or 65536 with --light-volume, which injects
them into a cascaded light volume as the talk does (less exact, see docs/gi.md).
)";

// The default sky and the --light point lights.
Result<GiLights> parse_lights(const GiArgs& a) {
  GiLights l;
  l.sky = SkyLight::gradient(glm::vec3(1.0f, 1.2f, 1.6f), glm::vec3(1.4f), glm::vec3(0.3f));
  for (const std::string& text : a.lights) {
    std::vector<double> v;
    if (!parse_numbers(text, &v) || (v.size() != 4 && v.size() != 6))
      return Status(ErrorCode::kInvalidArgument, "--light " + text + ": want x,y,z,I or x,y,z,r,g,b (finite numbers)");
    const glm::vec3 intensity = v.size() == 4 ? glm::vec3(float(v[3])) : glm::vec3(float(v[3]), float(v[4]), float(v[5]));
    l.points.push_back({glm::dvec3(v[0], v[1], v[2]), intensity});
  }
  GiConfig config;
  config.light_volume = a.light_volume;
  if (Status s = check_gi_lights(l, config); !s.ok()) return s;
  return l;
}

uint8_t tone(float v, float exposure) {
  v *= exposure;
  v = v / (1.0f + v);
  return uint8_t(std::lround(255.0f * std::pow(std::clamp(v, 0.0f, 1.0f), 1.0f / 2.2f)));
}

Result<std::unique_ptr<GiEngine>> make_engine(const std::string& name, const GiConfig& config, std::string* device) {
  if (name == "cpu") {
    *device = "cpu reference";
    return make_cpu_gi(config);
  }
  if (name != "vulkan") return Status(ErrorCode::kInvalidArgument, "--engine " + name + ": use vulkan or cpu");
#ifdef LDC_HAVE_VULKAN
  Result<std::unique_ptr<GiEngine>> gi = make_vulkan_gi(config, device);
  if (gi.ok()) return gi;
  std::fprintf(stderr, "gi: %s; using the CPU reference\n", gi.status().message().c_str());
#else
  std::fprintf(stderr, "gi: built without Vulkan (LDC_WITH_VULKAN off); using the CPU reference\n");
#endif
  *device = "cpu reference";
  return make_cpu_gi(config);
}

using Pixels = std::vector<glm::vec3>;

// Cone-traced image: ray cast, then one irradiance query per hit.
Status gi_image(const World& world, const Camera& cam, GiEngine& gi, const MaterialTable& mats, const GiLights& lights,
                int bounces, Pixels& out) {
  const size_t n = size_t(cam.width()) * size_t(cam.height());
  std::vector<Ray> rays(n);
  std::vector<RayHit> hits(n);
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x) rays[size_t(y) * size_t(cam.width()) + size_t(x)] = cam.pixel_ray(x, y);
  Queries queries(world);
  if (Status s = queries.ray_cast(rays, hits, nullptr); !s.ok()) return s;
  std::vector<glm::dvec3> p;
  std::vector<glm::vec3> nrm;
  std::vector<size_t> pix;
  out.assign(n, glm::vec3(0.0f));
  for (size_t i = 0; i < n; ++i) {
    if (!hits[i].hit || hits[i].started_inside) {
      out[i] = hits[i].hit ? glm::vec3(0.0f) : lights.sky.radiance(glm::normalize(glm::vec3(rays[i].direction)));
      continue;
    }
    p.push_back(hits[i].point);
    nrm.push_back(hits[i].normal);
    pix.push_back(i);
  }
  std::vector<glm::vec3> e(p.size());
  if (Status s = gi.irradiance(p, nrm, bounces, e); !s.ok()) return s;
  for (size_t k = 0; k < pix.size(); ++k) {
    const VoxelMaterial& m = mats[hits[pix[k]].material];
    out[pix[k]] = m.albedo * e[k] * (1.0f / std::numbers::pi_v<float>) + m.emission;
  }
  return {};
}

#ifdef LDC_HAVE_GI_REFERENCE
Status reference_image(const World& world, const Camera& cam, const MaterialTable& mats, const GiLights& lights,
                       int bounces, int samples, Pixels& out) {
  Result<ContourMesh> mesh = contour_world(world);
  if (!mesh.ok()) return mesh.status();
  Result<std::unique_ptr<PathTracer>> pt = PathTracer::create(mesh.value(), mats, lights);
  if (!pt.ok()) return pt.status();
  const size_t n = size_t(cam.width()) * size_t(cam.height());
  out.assign(n, glm::vec3(0.0f));
  std::vector<glm::dvec3> p;
  std::vector<glm::vec3> nrm;
  std::vector<size_t> pix;
  std::vector<uint16_t> mat;
  for (int y = 0; y < cam.height(); ++y) {
    for (int x = 0; x < cam.width(); ++x) {
      const size_t i = size_t(y) * size_t(cam.width()) + size_t(x);
      const Ray r = cam.pixel_ray(x, y);
      const glm::vec3 d = glm::normalize(glm::vec3(r.direction));
      const PathTracer::Hit h = pt.value()->intersect(r.origin, d);
      if (!std::isfinite(h.distance)) {
        out[i] = lights.sky.radiance(d);
        continue;
      }
      p.push_back(r.origin + h.distance * glm::dvec3(d));
      nrm.push_back(h.normal);
      pix.push_back(i);
      mat.push_back(h.material);
    }
  }
  std::vector<glm::vec3> e(p.size());
  PathTraceConfig pc;
  pc.samples = samples;
  if (Status s = pt.value()->irradiance(p, nrm, bounces, e, pc); !s.ok()) return s;
  for (size_t k = 0; k < pix.size(); ++k)
    out[pix[k]] = mats[mat[k]].albedo * e[k] * (1.0f / std::numbers::pi_v<float>) + mats[mat[k]].emission;
  return {};
}
#endif

int run_gi(const GiArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  if (Status s = check_camera_args(a.camera); !s.ok()) return fail("gi", s);
  if (a.passes < 1 || a.passes > 16) return fail("gi", "--passes " + std::to_string(a.passes) + ": must be 1 .. 16");
  if (a.bounces < 1 || a.bounces > 3) return fail("gi", "--bounces " + std::to_string(a.bounces) + ": must be 1 .. 3");
#ifndef LDC_HAVE_GI_REFERENCE
  if (a.reference) return fail("gi", "--reference: built without Embree 3 (the path tracer's ray caster)");
#endif
  Result<GiLights> parsed_lights = parse_lights(a);
  if (!parsed_lights.ok()) return fail("gi", parsed_lights.status());
  const GiLights& lights = parsed_lights.value();
  GiConfig gi_config;
  gi_config.light_volume = a.light_volume;
  ProgressBar bar(!common.quiet);
  Result<World> w = load_world(a.world, {}, bar.context());
  bar.finish();
  if (!w.ok()) return fail("gi", w.status());
  const World& world = w.value();
  Result<Camera> cam = Camera::make(a.camera, &world);
  if (!cam.ok()) return fail("gi", cam.status());
  CascadeConfig cc;
  cc.levels = a.levels;
  cc.resolution = a.resolution;
  cc.voxel_size = a.voxel_size > 0.0 ? a.voxel_size : 2.0 * world.lattice().cell_size;
  ScopedTimer t_vox(nullptr, "");
  Result<Cascades> cas = Cascades::create(world.lattice(), cc);
  if (!cas.ok()) return fail("gi", cas.status());
  if (Status s = cas.value().update_all(world, cam.value().position()); !s.ok()) return fail("gi", s);
  const double vox_s = t_vox.seconds();
  std::string device;
  Result<std::unique_ptr<GiEngine>> gi = make_engine(a.engine, gi_config, &device);
  if (!gi.ok()) return fail("gi", gi.status());
  if (Status s = gi.value()->load(cas.value(), lights); !s.ok()) return fail("gi", s);
  Result<GiTimings> upd = gi.value()->update_all(a.passes);
  if (!upd.ok()) return fail("gi", upd.status());
  ScopedTimer t_img(nullptr, "");
  Pixels lit;
  if (Status s = gi_image(world, cam.value(), *gi.value(), cc.materials, lights, a.bounces, lit); !s.ok())
    return fail("gi", s);
  const double img_s = t_img.seconds();
  Pixels ref;
  double ref_s = 0.0;
#ifdef LDC_HAVE_GI_REFERENCE
  if (a.reference) {
    ScopedTimer t_ref(nullptr, "");
    if (Status s = reference_image(world, cam.value(), cc.materials, lights, a.bounces, a.samples, ref); !s.ok())
      return fail("gi", s);
    ref_s = t_ref.seconds();
  }
#endif
  const int wdt = cam.value().width(), hgt = cam.value().height(), cols = a.reference ? 2 : 1;
  std::vector<uint8_t> rgb(size_t(wdt * cols) * size_t(hgt) * 3);
  for (int y = 0; y < hgt; ++y) {
    for (int x = 0; x < wdt * cols; ++x) {
      const glm::vec3 c =
          x < wdt ? lit[size_t(y) * size_t(wdt) + size_t(x)] : ref[size_t(y) * size_t(wdt) + size_t(x - wdt)];
      uint8_t* o = &rgb[3 * (size_t(y) * size_t(wdt * cols) + size_t(x))];
      for (int k = 0; k < 3; ++k) o[k] = tone(c[k], a.exposure);
    }
  }
  if (!stbi_write_png(a.output.c_str(), wdt * cols, hgt, 3, rgb.data(), wdt * cols * 3))
    return fail("gi", "-o " + a.output + ": cannot write the PNG");
  if (common.json) {
    nlohmann::json j{{"device", device},
                     {"levels", a.levels},
                     {"resolution", a.resolution},
                     {"voxel_size", cc.voxel_size},
                     {"surface_voxels", upd.value().surface_voxels / size_t(a.passes)},
                     {"passes", a.passes},
                     {"point_lights", {{"count", lights.points.size()}, {"mode", a.light_volume ? "injected volume" : "exact"}}},
                     {"seconds", {{"voxelize", vox_s}, {"lighting", upd.value().seconds}, {"lighting_device", upd.value().device_seconds}, {"image", img_s}}},
                     {"image", {{"width", wdt}, {"height", hgt}, {"bounces", a.bounces}}},
                     {"output", a.output}};
    if (a.reference) {
      j["reference"] = {{"samples", a.samples}};
      j["seconds"]["reference"] = ref_s;
    }
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::printf("gi: %s, %d levels of %d^3 voxels of %.3g m, %zu surface voxels; voxelize %.3f s\n", device.c_str(),
              a.levels, a.resolution, cc.voxel_size, upd.value().surface_voxels / size_t(a.passes), vox_s);
  char device_time[64] = "";  // GPU timestamps (or the CPU engine's kernels); none without timestamps
  if (upd.value().device_seconds >= 0)
    std::snprintf(device_time, sizeof(device_time), " (device %.3f s each)", upd.value().device_seconds / a.passes);
  std::printf("gi: %d lighting passes %.3f s (%.3f s each)%s, image %d x %d (%d bounces) %.3f s\n", a.passes,
              upd.value().seconds, upd.value().seconds / a.passes, device_time, wdt, hgt, a.bounces, img_s);
  if (a.reference) std::printf("gi: path-traced reference, %d paths per pixel, %.3f s (right half)\n", a.samples, ref_s);
  std::printf("wrote %s\n", a.output.c_str());
  return 0;
}

}  // namespace

void add_gi_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<GiArgs>();
  CLI::App* cmd = app.add_subcommand("gi", "Image lit by cone-traced global illumination from the voxel cascades -> PNG");
  cmd->add_option("world", args->world, ".ldc file")->required();
  cmd->add_option("-o,--output", args->output, "Output .png")->required();
  add_camera_options(cmd, args->camera, " (default: a view of the whole solid)");
  cmd->add_option("--engine", args->engine, "vulkan or cpu")->capture_default_str();
  cmd->add_option("--levels", args->levels, "Cascade levels")->capture_default_str();
  cmd->add_option("--resolution", args->resolution, "Voxels per axis and level")->capture_default_str();
  cmd->add_option("--voxel-size", args->voxel_size, "Level 0 voxel edge in m (default 2 h)");
  cmd->add_option("--passes", args->passes, "Lighting passes of every level")->capture_default_str();
  cmd->add_option("--bounces", args->bounces, "Bounces in the image, 1 .. 3")->capture_default_str();
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
