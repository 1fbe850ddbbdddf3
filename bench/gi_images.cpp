// `bench_gi 0 PATHS images [DIR]` (issue 25): the cone tracer's images
// against the path tracer's, whole images rather than points near the
// camera. Per view and engine (CPU; Vulkan where a device exists), over the
// pixels whose camera ray hits the contoured mesh, in linear radiance:
//   rel. L1     = sum |cone - path| / sum path (luminance), all hit pixels,
//                 and over the darkest fifth of them (by the path tracer);
//   brightness  = sum cone / sum path.
// The reference is the mean of two path-traced images of PATHS paths per
// pixel (seeds 1 and 2); their own rel. L1 against each other says how
// noisy one of them is. Views where the path tracer sees no light at all
// (the closed room with the sky outside) report the cone tracer's mean
// radiance instead, which must be 0. With DIR, each view is written as
// DIR/gi_<view>.png: the cone tracer (CPU engine) on the left, the
// reference on the right. BENCH_GI_VIEW picks views by substring,
// BENCH_GI_BOUNCES=1 or 2 compares the first bounces alone (both sides) and
// BENCH_GI_QUERY_RAYS sets GiConfig::query_rays (0: the cones themselves).
#include "gi_images.h"
#include "scene_builders.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "contour/contour.h"
#include "csg/csg.h"
#include "gi_bridge/path_trace.h"
#include "ldc/build.h"
#include "ldc/query.h"
#include "ldc/terrain.h"
#include "render/render.h"

namespace ldc::bench {
namespace {

constexpr int kWidth = 160;
constexpr int kHeight = 90;

struct View {
  std::string name;      // also the PNG's name
  const World* world;
  glm::dvec3 camera, target;
  double fov;
  GiLights lights;
  MaterialTable materials;
};

// A closed room of 4 x 4 x 3 m inside, walls 0.4 m thick, on a lattice of
// 0.1 m: thin enough that the coarse levels hold wall and room in one voxel.
World closed_room() {
  TriangleMesh m;
  const double x = 2.0, y = 2.0, z = 1.5, t = 0.4;
  add_box(m, {-x - t, -y - t, -z - t}, {x + t, y + t, -z}, 0);
  add_box(m, {-x - t, -y - t, z}, {x + t, y + t, z + t}, 0);
  add_box(m, {-x - t, -y - t, -z}, {-x, y + t, z}, 1);
  add_box(m, {x, -y - t, -z}, {x + t, y + t, z}, 2);
  add_box(m, {-x, -y - t, -z}, {x, -y, z}, 0);
  add_box(m, {-x, y, -z}, {x, y + t, z}, 0);
  add_box(m, {-0.6, -0.2, -z}, {0.2, 0.6, -0.7}, 0);  // a block on the floor
  return build_on_origin(m, 0.1);
}

MaterialTable room_materials(float emission) {
  MaterialTable t;
  t.materials = {{glm::vec3(0.7f), glm::vec3(emission)},
                 {glm::vec3(0.7f, 0.15f, 0.12f), glm::vec3(emission)},
                 {glm::vec3(0.15f, 0.7f, 0.15f), glm::vec3(emission)}};
  return t;
}

SkyLight default_sky() { return SkyLight::gradient(glm::vec3(1.0f, 1.2f, 1.6f), glm::vec3(1.4f), glm::vec3(0.3f)); }

// BENCH_GI_BOUNCES: 1 or 2 to compare the first bounces alone (both sides), 3 when unset.
int bounces() {
  const char* b = std::getenv("BENCH_GI_BOUNCES");
  const int n = b ? std::atoi(b) : 3;
  return n >= 1 && n <= 3 ? n : 3;
}

// BENCH_GI_QUERY_RAYS: GiConfig::query_rays (the default when unset).
GiConfig engine_config() {
  GiConfig c;
  if (const char* r = std::getenv("BENCH_GI_QUERY_RAYS")) c.query_rays = std::clamp(std::atoi(r), 0, kGiMaxQueryRays);
  return c;
}

float lum(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

struct ImageError {
  double l1 = 0, l1_dark = 0, brightness = 0, mean_cone = 0, mean_path = 0;
};

ImageError compare(const std::vector<glm::vec3>& cone, const std::vector<glm::vec3>& path,
                   const std::vector<uint8_t>& hit) {
  std::vector<size_t> px;
  for (size_t i = 0; i < hit.size(); ++i)
    if (hit[i]) px.push_back(i);
  ImageError e;
  if (px.empty()) return e;
  std::sort(px.begin(), px.end(), [&](size_t a, size_t b) { return lum(path[a]) < lum(path[b]); });
  const size_t dark = std::max<size_t>(1, px.size() / 5);
  double diff = 0, diff_dark = 0, sum_c = 0, sum_p = 0, sum_p_dark = 0;
  for (size_t k = 0; k < px.size(); ++k) {
    const double c = lum(cone[px[k]]), p = lum(path[px[k]]);
    diff += std::abs(c - p), sum_c += c, sum_p += p;
    if (k < dark) diff_dark += std::abs(c - p), sum_p_dark += p;
  }
  e.l1 = sum_p > 0 ? diff / sum_p : 0;
  e.l1_dark = sum_p_dark > 0 ? diff_dark / sum_p_dark : 0;
  e.brightness = sum_p > 0 ? sum_c / sum_p : 0;
  e.mean_cone = sum_c / double(px.size());
  e.mean_path = sum_p / double(px.size());
  return e;
}

void print_row(const View& v, const std::string& engine, const ImageError& e, double noise, int paths) {
  if (e.mean_path <= 0.0) {
    std::printf("| %s | %s | — | — | — | mean %.2e (path %.2e) | %d x 2 |\n", v.name.c_str(), engine.c_str(),
                e.mean_cone, e.mean_path, paths);
    return;
  }
  std::printf("| %s | %s | %.3f | %.3f | %.3f | %.3f | %d x 2 |\n", v.name.c_str(), engine.c_str(), e.l1, e.l1_dark,
              e.brightness, noise, paths);
}

struct Reference {
  std::vector<glm::vec3> mean;
  std::vector<uint8_t> hit;
  double noise = 0;  // rel. L1 of seed 2 against seed 1
};

Result<Reference> reference(const View& v, const std::vector<Ray>& rays, int paths) {
  Result<ContourMesh> mesh = contour_world(*v.world);
  if (!mesh.ok()) return mesh.status();
  Result<std::unique_ptr<PathTracer>> pt = PathTracer::create(mesh.value(), v.materials, v.lights);
  if (!pt.ok()) return pt.status();
  Reference r;
  std::vector<glm::vec3> a(rays.size()), b(rays.size());
  r.hit.resize(rays.size());
  PathTraceConfig pc;
  pc.samples = paths;
  if (Status s = pt.value()->radiance_along(rays, bounces(), a, pc, r.hit); !s.ok()) return s;
  pc.seed = 2;
  if (Status s = pt.value()->radiance_along(rays, bounces(), b, pc); !s.ok()) return s;
  r.noise = compare(b, a, r.hit).l1;
  r.mean.resize(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) r.mean[i] = 0.5f * (a[i] + b[i]);
  return r;
}

// The cone tracer's image of the view (3 passes, 3 bounces), or an error.
Result<RadianceImage> cone_image(const View& v, const Camera& cam, GiEngine& gi) {
  CascadeConfig cc;
  cc.voxel_size = 2.0 * v.world->lattice().cell_size;
  cc.materials = v.materials;
  Result<Cascades> cas = Cascades::create(v.world->lattice(), cc);
  if (!cas.ok()) return cas.status();
  if (Status s = cas.value().update_all(*v.world, cam.position()); !s.ok()) return s;
  if (Status s = gi.load(cas.value(), v.lights); !s.ok()) return s;
  if (Result<GiTimings> t = gi.update_all(3); !t.ok()) return t.status();
  Queries queries(*v.world);
  return render_gi(queries, cam, gi, {.materials = v.materials, .sky = v.lights.sky, .bounces = bounces()});
}

Result<Camera> view_camera(const View& v) {
  CameraConfig cc;
  cc.position = v.camera;
  cc.target = v.target;
  cc.fov_degrees = v.fov;
  cc.width = kWidth;
  cc.height = kHeight;
  return Camera::make(cc, v.world);
}

void run_view(const View& v, int paths, const char* dir, bool with_vulkan) {
  Result<Camera> cam = view_camera(v);
  if (!cam.ok()) return;
  std::vector<Ray> rays;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) rays.push_back(cam.value().pixel_ray(x, y));
  Result<Reference> ref = reference(v, rays, paths);
  if (!ref.ok()) {
    std::printf("| %s | reference failed: %s |\n", v.name.c_str(), ref.status().message().c_str());
    return;
  }
  for (int engine = 0; engine < (with_vulkan ? 2 : 1); ++engine) {
    std::string device = "cpu";
    std::unique_ptr<GiEngine> gi;
    if (engine == 0) {
      gi = make_cpu_gi(engine_config());
    } else {
      Result<std::unique_ptr<GiEngine>> vk = make_vulkan_gi(engine_config(), &device);
      if (!vk.ok()) continue;
      gi = std::move(vk).value();
    }
    Result<RadianceImage> img = cone_image(v, cam.value(), *gi);
    if (!img.ok()) {
      std::printf("| %s | %s | failed: %s |\n", v.name.c_str(), device.c_str(), img.status().message().c_str());
      continue;
    }
    print_row(v, device, compare(img.value().pixels, ref.value().mean, ref.value().hit), ref.value().noise, paths);
    if (dir && engine == 0) {
      const RadianceImage path{kWidth, kHeight, ref.value().mean};
      Result<Image> both = side_by_side(tone_map(img.value(), 1.0f), tone_map(path, 1.0f));
      if (both.ok()) (void)write_png(both.value(), std::string(dir) + "/gi_" + v.name + ".png");
    }
  }
}

// The worlds the views look at (built once) and the views.
struct Scenes {
  World tunnel, room;
  std::vector<View> views;
};

Result<std::unique_ptr<Scenes>> issue25_scenes() {
  Result<World> dug = main_job_tunnel();
  if (!dug.ok()) return Status(dug.status().code(), "main job's tunnel: " + dug.status().message());
  auto sc = std::make_unique<Scenes>(Scenes{std::move(dug).value(), closed_room(), {}});
  const World* tunnel = &sc->tunnel;
  const World* room = &sc->room;
  GiLights sky;
  sky.sky = default_sky();
  GiLights chamber_light = sky;
  chamber_light.points.push_back({glm::dvec3(25.5, 9, 4.2), glm::vec3(3.0f)});
  GiLights light_only;
  light_only.points = chamber_light.points;
  GiLights room_light;
  room_light.points.push_back({glm::dvec3(0.8, -0.6, 0.9), glm::vec3(3.0f)});
  const MaterialTable terrain = default_material_table();
  sc->views = {
      {"landscape", tunnel, {61, -5, 10}, {45, 11, 3.4}, 55, sky, terrain},
      {"tunnel_near_mouth", tunnel, {44, 10.4, 3.4}, {37, 11, 3.4}, 70, sky, terrain},
      {"tunnel_far_from_mouths", tunnel, {8, 9.8, 3.6}, {14, 10, 3.6}, 70, sky, terrain},
      {"chamber_sky_and_light", tunnel, {20, 9.2, 4.0}, {26, 9, 3.6}, 70, chamber_light, terrain},
      {"chamber_light_only", tunnel, {20, 9.2, 4.0}, {26, 9, 3.6}, 70, light_only, terrain},
      {"chamber_sky_only", tunnel, {20, 9.2, 4.0}, {26, 9, 3.6}, 70, sky, terrain},
      {"closed_room_light", room, {-1.4, -1.6, 0.8}, {1.0, 1.2, -0.8}, 75, room_light, room_materials(0.0f)},
      {"closed_room_sky_outside", room, {-1.4, -1.6, 0.8}, {1.0, 1.2, -0.8}, 75, sky, room_materials(0.0f)},
      {"furnace", room, {-1.4, -1.6, 0.8}, {1.0, 1.2, -0.8}, 75, GiLights{}, room_materials(1.0f)}};
  return sc;
}

// --- Sky visibility per cone: the cone tracer's against exact rays ------------------

struct SurfacePoint {
  glm::dvec3 p;
  glm::vec3 n;
};

// Every `stride`-th pixel's first hit on the view's solid.
std::vector<SurfacePoint> sample_pixels(const View& v, const Camera& cam, int stride) {
  Queries q(*v.world);
  std::vector<SurfacePoint> out;
  for (int y = stride / 2; y < kHeight; y += stride)
    for (int x = stride / 2; x < kWidth; x += stride) {
      Result<RayHit> h = q.ray_cast(cam.pixel_ray(x, y));
      if (h.ok() && h.value().hit && !h.value().started_inside) out.push_back({h.value().point, h.value().normal});
    }
  return out;
}

// The part of cone i's rays (gi_cone_ray: spread evenly within its
// half-angle) from the point that leave the world without meeting the solid.
double exact_escape(const Queries& q, const SurfacePoint& sp, int cone, int rays) {
  int escaped = 0;
  for (int k = 0; k < rays; ++k) {
    Result<RayHit> h = q.ray_cast(Ray{sp.p + 1e-3 * glm::dvec3(sp.n), gi_cone_ray(cone, k, rays)});
    if (h.ok() && !h.value().hit) ++escaped;
  }
  return double(escaped) / rays;
}

// The view's cascades with every material black, so that a query sees
// nothing but the sky.
Result<Cascades> black_cascades(const View& v, const Camera& cam) {
  MaterialTable black = v.materials;
  for (VoxelMaterial& m : black.materials) m = VoxelMaterial{glm::vec3(0.0f), glm::vec3(0.0f)};
  black.fallback = VoxelMaterial{glm::vec3(0.0f), glm::vec3(0.0f)};
  CascadeConfig cc;
  cc.voxel_size = 2.0 * v.world->lattice().cell_size;
  cc.materials = black;
  Result<Cascades> cas = Cascades::create(v.world->lattice(), cc);
  if (!cas.ok()) return cas.status();
  if (Status s = cas.value().update_all(*v.world, cam.position()); !s.ok()) return s;
  return cas;
}

// The cone tracer's sky transmittance of each point's cone i (0 where the
// point's air is sealed): irradiance under a sky of 1 in lobe i alone, on
// black cascades, times sum_j c_j / (pi c_i).
Result<std::vector<double>> cone_sky(const Cascades& black, GiEngine& gi, const std::vector<SurfacePoint>& pts,
                                     int i) {
  GiLights lobe;
  lobe.sky.amplitude[size_t(i)] = glm::vec3(1.0f);
  if (Status s = gi.load(black, lobe); !s.ok()) return s;
  std::vector<glm::dvec3> p(pts.size());
  std::vector<glm::vec3> n(pts.size()), e(pts.size());
  for (size_t k = 0; k < pts.size(); ++k) p[k] = pts[k].p, n[k] = pts[k].n;
  if (Status s = gi.irradiance(p, n, 1, e); !s.ok()) return s;
  std::vector<double> t(pts.size(), 0.0);
  const glm::vec3 axis = gi_directions()[size_t(i)];
  for (size_t k = 0; k < pts.size(); ++k) {
    double sum = 0.0;
    for (const glm::vec3& dj : gi_directions()) sum += std::max(0.0f, glm::dot(n[k], dj));
    const double c = glm::dot(n[k], axis);
    if (c > 0.0) t[k] = double(e[k].y) * sum / (std::numbers::pi * c);
  }
  return t;
}

void visibility_row(const View& v, int rays) {
  Result<Camera> cam = view_camera(v);
  if (!cam.ok()) return;
  const std::vector<SurfacePoint> pts = sample_pixels(v, cam.value(), 4);
  Queries q(*v.world);
  std::unique_ptr<GiEngine> gi = make_cpu_gi(engine_config());
  Result<Cascades> black = black_cascades(v, cam.value());
  if (!black.ok()) {
    std::printf("| %s | failed: %s |\n", v.name.c_str(), black.status().message().c_str());
    return;
  }
  double cone = 0, exact = 0, over = 0, leak = 0, weight = 0;
  for (int i = 0; i < kGiDirections; ++i) {
    Result<std::vector<double>> t = cone_sky(black.value(), *gi, pts, i);
    if (!t.ok()) {
      std::printf("| %s | failed: %s |\n", v.name.c_str(), t.status().message().c_str());
      return;
    }
    const glm::vec3 axis = gi_directions()[size_t(i)];
    for (size_t k = 0; k < pts.size(); ++k) {
      const double c = glm::dot(pts[k].n, axis);
      if (c <= 0.0) continue;
      const double e = exact_escape(q, pts[k], i, rays), tc = t.value()[k];
      cone += c * tc, exact += c * e, weight += c;
      over += c * std::max(e - tc, 0.0), leak += c * std::max(tc - e, 0.0);
    }
  }
  if (exact <= 0.0) {
    std::printf("| %s | %zu | %.4f | 0 | — | — | %.4f |\n", v.name.c_str(), pts.size(), cone / weight, leak / weight);
    return;
  }
  std::printf("| %s | %zu | %.4f | %.4f | %.3f | %.3f | %.3f |\n", v.name.c_str(), pts.size(), cone / weight,
              exact / weight, cone / exact, over / exact, leak / exact);
}

// BENCH_GI_VIEW: a substring of the views to run (all when unset).
bool view_wanted(const View& v) {
  const char* only = std::getenv("BENCH_GI_VIEW");
  return !only || v.name.find(only) != std::string::npos;
}

}  // namespace

void gi_sky_visibility(int rays) {
  Result<std::unique_ptr<Scenes>> sc = issue25_scenes();
  if (!sc.ok()) {
    std::printf("%s\n", sc.status().message().c_str());
    return;
  }
  std::printf("\n## Sky visibility per cone: the cone tracer against exact rays (issue 25)\n");
  std::printf("Every 4th pixel's first hit in x and y; per point and cone i with c = n . d_i > 0: the cone tracer's sky "
              "transmittance (CPU engine, 6 levels of 32^3 voxels of 2 h centred on the camera) against the part of "
              "%d rays spread over the cone that leave the world (ldc ray casts), weighted by c. Too dark = sum c "
              "max(exact - cone, 0) / sum c exact; leaked = sum c max(cone - exact, 0) / sum c exact (by the cone "
              "weight's sum where no ray escapes).\n",
              rays);
  std::printf("| view | points | cone sky | exact sky | cone / exact | too dark | leaked |\n|---|---|---|---|---|---|---|\n");
  // One row per camera: the lights do not change what the sky reaches.
  std::vector<glm::dvec3> cameras;
  for (const View& v : sc.value()->views) {
    if (std::find(cameras.begin(), cameras.end(), v.camera) != cameras.end()) continue;
    cameras.push_back(v.camera);
    if (view_wanted(v)) visibility_row(v, rays);
  }
}

void gi_images(int paths, const char* dir, bool with_vulkan) {
  Result<std::unique_ptr<Scenes>> sc = issue25_scenes();
  if (!sc.ok()) {
    std::printf("%s\n", sc.status().message().c_str());
    return;
  }
  std::printf("\n## Whole images against the path tracer (issue 25)\n");
  std::printf("%d x %d pixels, %d bounces, cascades of 6 levels of 32^3 voxels of 2 h centred on the camera, 3 passes, "
              "final gather from open air: %d rays per cone (GiConfig::query_rays; 0: the cones); "
              "reference: mean of 2 path-traced images of %d paths per pixel (seeds 1, 2)\n",
              kWidth, kHeight, bounces(), engine_config().query_rays, paths);
  std::printf("| view | engine | rel. L1 | rel. L1, darkest fifth | brightness | reference noise (seed 2 vs 1) | paths |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const View& v : sc.value()->views)
    if (view_wanted(v)) run_view(v, paths, dir, with_vulkan);
}

}  // namespace ldc::bench
