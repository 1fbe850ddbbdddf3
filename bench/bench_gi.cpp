// GI benchmark (issue 8): the Vulkan cone tracer (lavapipe here: no GPU is
// lent to this machine) on three scenes — a Cornell-like box of primitives
// open to the sky with an emitter and a point light, the default landscape
// with a dug cave, and one shared mesh (spot) on a ground slab — with six
// levels of 32^3 voxels: time per level update and per full update (with
// and without the precombined buffers, and with the near/far split cones;
// the full update also as device time: GPU timestamps, or the CPU engine's
// kernels),
// a staggered frame, and the error (near/far split off and on) of
// the cone-traced irradiance against the path-traced reference (Embree on
// the contoured mesh) at the same points, for 1, 2 and 3 bounces.
// Usage: bench_gi [points (200)] [paths per point (512)] [sources: only the
// error split by light source | timing: only medians of full updates |
// images [DIR]: only whole images against the path tracer (gi_images.cpp),
// paths per pixel, PNGs into DIR | visibility: only the cones' sky against
// exact rays in the same views (gi_images.cpp), the second number the rays
// per cone]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "contour/contour.h"
#include "gi_images.h"
#include "scene_builders.h"
#include "csg/csg.h"
#include "gi_bridge/gi.h"
#include "gi_bridge/path_trace.h"
#include "ldc/build.h"
#include "ldc/mesh.h"
#include "ldc/terrain.h"
#include "meshio/meshio.h"

namespace {

using namespace ldc;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Scene {
  std::string name;
  World world;
  glm::dvec3 camera;
  GiLights lights;
  MaterialTable materials;
};

using bench::add_box;

World build(const TriangleMesh& m, double h) { return bench::build_on_origin(m, h); }

MaterialTable cornell_materials() {
  MaterialTable t;
  t.materials = {{glm::vec3(0.75f), glm::vec3(0.0f)},
                 {glm::vec3(0.75f, 0.15f, 0.12f), glm::vec3(0.0f)},
                 {glm::vec3(0.15f, 0.7f, 0.15f), glm::vec3(0.0f)},
                 {glm::vec3(0.75f), glm::vec3(6.0f)}};
  return t;
}

Scene cornell() {
  TriangleMesh m;
  add_box(m, {-1.6, -1.6, -1.6}, {1.6, 1.6, -0.8}, 0);  // floor
  add_box(m, {-1.6, -1.6, 0.8}, {1.6, 1.6, 1.6}, 0);    // ceiling
  add_box(m, {-1.6, 0.8, -1.6}, {1.6, 1.6, 1.6}, 0);    // back
  add_box(m, {-1.6, -1.6, -1.6}, {-0.8, 1.6, 1.6}, 1);  // red left
  add_box(m, {0.8, -1.6, -1.6}, {1.6, 1.6, 1.6}, 2);    // green right
  add_box(m, {-0.3, -0.3, 0.6}, {0.3, 0.3, 0.8}, 3);    // emitter under the ceiling
  add_box(m, {-0.5, -0.1, -0.8}, {-0.1, 0.3, -0.2}, 0);  // tall block
  add_box(m, {0.1, -0.5, -0.8}, {0.5, -0.1, -0.5}, 0);   // short block
  Scene s{"cornell box (primitives)", build(m, 0.05), {0.0, -0.4, 0.0}, {}, cornell_materials()};
  s.lights.sky = SkyLight::gradient(glm::vec3(0.8f, 0.9f, 1.2f), glm::vec3(1.0f), glm::vec3(0.3f));
  s.lights.points.push_back({glm::dvec3(0.3, 0.2, 0.2), glm::vec3(0.8f, 0.7f, 0.5f)});
  return s;
}

Scene landscape() {
  Result<World> w = build_terrain(TerrainConfig{}, 0.2);
  if (!w.ok()) std::exit(1);
  WorldEditor ed(std::move(w).value());
  // A cave: a chamber dug into the hillside, open at one end.
  (void)ed.apply(Brush::capsule({14, 24, 4.0}, {24, 24, 4.0}, 2.0), EditOp::kSubtract);
  (void)ed.apply(Brush::sphere({24, 24, 4.0}, 3.0), EditOp::kSubtract);
  Scene s{"default landscape, dug cave", ed.world(), {24, 22, 5.0}, {}, default_material_table()};
  s.lights.sky = SkyLight::gradient(glm::vec3(1.0f, 1.2f, 1.6f), glm::vec3(1.4f), glm::vec3(0.3f));
  s.lights.points.push_back({glm::dvec3(24, 24, 4.5), glm::vec3(4.0f, 3.0f, 2.0f)});
  return s;
}

Scene shared_mesh() {
  Result<TriangleMesh> spot = load_mesh(std::string(LDC_BENCH_DATA_DIR) + "/spot.obj");
  if (!spot.ok()) std::exit(1);
  TriangleMesh m = std::move(spot).value();
  for (glm::dvec3& p : m.positions) p = glm::dvec3(p.x * 2.0, p.z * 2.0, p.y * 2.0 + 1.45);  // y up -> z up, 2x
  m.triangle_material.assign(m.triangles.size(), 0);
  add_box(m, {-8, -8, -0.6}, {8, 8, 0.0}, 1);
  Scene s{"shared mesh (spot) on a slab", build(m, 0.05), {0.0, -1.0, 1.0}, {}, cornell_materials()};
  s.lights.sky = SkyLight::gradient(glm::vec3(1.0f, 1.2f, 1.6f), glm::vec3(1.4f), glm::vec3(0.3f));
  return s;
}

// The furnace: a closed box whose walls all glow (emission 1, albedo 0.5),
// so every inside point has irradiance pi (1 bounce), 1.5 pi, 1.75 pi.
Scene furnace() {
  TriangleMesh m;
  add_box(m, {-1.6, -1.6, -1.6}, {1.6, 1.6, -0.8}, 0);
  add_box(m, {-1.6, -1.6, 0.8}, {1.6, 1.6, 1.6}, 0);
  add_box(m, {-1.6, 0.8, -1.6}, {1.6, 1.6, 1.6}, 0);
  add_box(m, {-1.6, -1.6, -1.6}, {1.6, -0.8, 1.6}, 0);
  add_box(m, {-1.6, -1.6, -1.6}, {-0.8, 1.6, 1.6}, 0);
  add_box(m, {0.8, -1.6, -1.6}, {1.6, 1.6, 1.6}, 0);
  Scene s{"furnace (closed glowing box)", build(m, 0.05), {0.0, 0.0, 0.0}, {}, {}};
  s.materials.materials = {{glm::vec3(0.5f), glm::vec3(1.0f)}};
  return s;
}

// Query points: random triangles of the contoured mesh within `radius` of the camera.
void query_points(const ContourMesh& mesh, const glm::dvec3& c, double radius, int count, std::vector<glm::dvec3>& p,
                  std::vector<glm::vec3>& n) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<size_t> pick(0, mesh.triangles.size() - 1);
  for (int tries = 0; int(p.size()) < count && tries < count * 2000; ++tries) {
    const glm::uvec3 t = mesh.triangles[pick(rng)];
    const glm::dvec3 a = mesh.positions[t.x], b = mesh.positions[t.y], d = mesh.positions[t.z];
    const glm::dvec3 x = (a + b + d) / 3.0;
    const glm::dvec3 cr = glm::cross(b - a, d - a);
    if (glm::length(x - c) > radius || glm::length(cr) <= 1e-12) continue;
    p.push_back(x);
    n.emplace_back(glm::normalize(cr));
  }
}

float lum(const glm::vec3& v) { return (v.x + v.y + v.z) / 3.0f; }

struct Stats {
  double mean = 0, p95 = 0;
};
Stats rel_error(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& ref) {
  std::vector<double> e;
  double scale = 0;
  for (const glm::vec3& r : ref) scale += lum(r);
  scale /= double(std::max<size_t>(1, ref.size()));
  for (size_t i = 0; i < a.size(); ++i) {
    // Relative to the point's reference, floored at 5% of the scene's mean (dark corners).
    const double d = std::max(double(lum(ref[i])), 0.05 * scale);
    e.push_back(std::abs(double(lum(a[i]) - lum(ref[i]))) / d);
  }
  std::sort(e.begin(), e.end());
  Stats st;
  for (double x : e) st.mean += x / double(e.size());
  st.p95 = e.empty() ? 0 : e[std::min(e.size() - 1, size_t(0.95 * double(e.size())))];
  return st;
}

// Six levels of 32^3 voxels of about 0.1 m (a whole number of cells),
// centred on the scene's camera.
Result<Cascades> bench_cascades(const Scene& s, const MaterialTable& materials) {
  CascadeConfig cc;
  cc.levels = 6;
  cc.resolution = 32;
  cc.voxel_size = s.world.lattice().cell_size * std::max(1.0, std::round(0.1 / s.world.lattice().cell_size));
  cc.materials = materials;
  Result<Cascades> cas = Cascades::create(s.world.lattice(), cc);
  if (!cas.ok()) return cas;
  if (Status st = cas.value().update_all(s.world, s.camera); !st.ok()) return st;
  return cas;
}

// The CPU engine, or the Vulkan one (its device's name into *device);
// null, with a message, when no Vulkan device exists.
std::unique_ptr<GiEngine> make_engine(bool cpu, const GiConfig& config, std::string* device) {
  if (cpu) return make_cpu_gi(config);
  Result<std::unique_ptr<GiEngine>> gi = make_vulkan_gi(config, device);
  if (!gi.ok()) {
    std::printf("no Vulkan device: %s\n", gi.status().message().c_str());
    return nullptr;
  }
  return std::move(gi).value();
}

void run(const Scene& s, int points, int paths) {
  std::printf("\n## %s\n", s.name.c_str());
  Result<Cascades> cas = bench_cascades(s, s.materials);
  if (!cas.ok()) {
    std::printf("cascades failed: %s\n", cas.status().message().c_str());
    return;
  }
  const double voxel_size = cas.value().voxel_size(0);
  std::string device;
  std::vector<glm::vec3> gi_e[2][3];  // [near/far split off, on][bounces - 1]
  Result<ContourMesh> mesh = contour_world(s.world);
  if (!mesh.ok()) return;
  std::vector<glm::dvec3> p;
  std::vector<glm::vec3> n;
  query_points(mesh.value(), s.camera, 1.5, points, p, n);
  std::printf("cascades: 6 levels of 32^3, level 0 voxel %.3g m; %zu query points within 1.5 m of the camera\n",
              voxel_size, p.size());
  std::printf("| engine | precombined | near/far split | load s | level 0 s | level 1 s | level 2 s | level 3 s | level 4 s | level 5 s | full update s | full update device s | staggered frame s (mean of 16) | surface voxels |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  // Vulkan (lavapipe here) with and without the precombined buffers and
  // with the near/far split cones, then the CPU engine for reference.
  std::vector<std::string> queries;
  for (int run_i = 0; run_i < 5; ++run_i) {
    const bool pre = run_i != 1, cpu = run_i >= 3, split = run_i == 2 || run_i == 4;
    GiConfig gc;
    gc.precombined = pre;
    gc.near_far = split;
    std::unique_ptr<GiEngine> engine = make_engine(cpu, gc, &device);
    if (!engine) return;
    GiEngine& g = *engine;
    auto t0 = Clock::now();
    if (!g.load(cas.value(), s.lights).ok()) return;
    const double load_s = since(t0);
    std::printf("| %s | %s | %s | %.3f |", cpu ? "cpu" : device.c_str(), pre ? "on" : "off", split ? "on" : "off",
                load_s);
    size_t surf = 0;
    for (int l = 0; l < 6; ++l) {
      Result<GiTimings> t = g.update_level(l);
      std::printf(" %.4f |", t.ok() ? t.value().seconds : -1.0);
      if (t.ok()) surf += t.value().surface_voxels;
    }
    Result<GiTimings> full = g.update_all(1);
    (void)g.update_all(1);
    double frames = 0;
    for (int f = 0; f < 16; ++f) {
      Result<GiTimings> t = g.frame();
      if (t.ok()) frames += t.value().seconds / 16.0;
    }
    std::printf(" %.4f | %.4f | %.4f | %zu |\n", full.ok() ? full.value().seconds : -1.0,
                full.ok() ? full.value().device_seconds : -1.0, frames, surf);
    if (pre && !cpu) {
      (void)g.update_all(3);
      for (int b = 1; b <= 3; ++b) {
        gi_e[split][b - 1].resize(p.size());
        (void)g.irradiance(p, n, b, gi_e[split][b - 1]);
      }
      t0 = Clock::now();
      std::vector<glm::vec3> tmp(p.size());
      (void)g.irradiance(p, n, 3, tmp);
      // Printed after the table: a line inside it would split it for readers
      // (tests/docs/readme_figures reads these rows).
      queries.push_back("(irradiance query of " + std::to_string(p.size()) + " points, near/far split " +
                        (split ? "on" : "off") + ": " + std::to_string(since(t0)) + " s)");
    }
  }
  for (const std::string& q : queries) std::printf("%s\n", q.c_str());
  std::printf("device: %s\n", device.c_str());
  Result<std::unique_ptr<PathTracer>> pt = PathTracer::create(mesh.value(), s.materials, s.lights);
  if (!pt.ok()) return;
  std::printf("| near/far split | bounces | mean rel. error | p95 rel. error | mean cone-traced | mean path-traced | path tracer s | path samples |\n|---|---|---|---|---|---|---|---|\n");
  for (int b = 1; b <= 3; ++b) {
    std::vector<glm::vec3> ref(p.size());
    PathTraceConfig pc;
    pc.samples = paths;
    const auto t0 = Clock::now();
    (void)pt.value()->irradiance(p, n, b, ref, pc);
    const double pt_s = since(t0);
    for (int split = 0; split < 2; ++split) {
      const Stats st = rel_error(gi_e[split][b - 1], ref);
      double mg = 0, mr = 0;
      for (size_t i = 0; i < p.size(); ++i)
        mg += lum(gi_e[split][b - 1][i]) / double(p.size()), mr += lum(ref[i]) / double(p.size());
      std::printf("| %s | %d | %.1f%% | %.1f%% | %.3f | %.3f | %.2f | %d paths x %zu points |\n", split ? "on" : "off", b,
                  100 * st.mean, 100 * st.p95, mg, mr, pt_s, paths, p.size());
    }
  }
}

// The error split by light source (sky, point light exact and injected,
// emitter alone), each with 1..3 bounces, on the CPU engine: says which
// term the error comes from; then all the scene's sources together (the
// main table's figures from the CPU engine). A source the scene has but the
// query points never receive (spot's unused emissive material) is skipped.
void by_source(const Scene& s, int points, int paths) {
  std::printf("\n### %s: error by light source (cpu engine)\n", s.name.c_str());
  Result<ContourMesh> mesh = contour_world(s.world);
  if (!mesh.ok()) return;
  std::vector<glm::dvec3> p;
  std::vector<glm::vec3> n;
  query_points(mesh.value(), s.camera, 1.5, points, p, n);
  std::printf("| source | bounces | mean rel. error | p95 rel. error | mean cone-traced | mean path-traced |\n|---|---|---|---|---|---|\n");
  for (int src = 0; src < 5; ++src) {
    GiLights lights;
    MaterialTable mats = s.materials;
    if (src == 0 || src == 4) lights.sky = s.lights.sky;
    if (src == 1 || src == 3 || src == 4) lights.points = s.lights.points;
    if (src != 2 && src != 4) {
      for (VoxelMaterial& m : mats.materials) m.emission = glm::vec3(0.0f);
    }
    bool present = src == 1 || src == 3 ? !lights.points.empty() : src == 4;
    for (int i = 0; i < kGiDirections && src == 0; ++i) present = present || lum(lights.sky.amplitude[size_t(i)]) > 0;
    for (const VoxelMaterial& m : mats.materials) present = present || (src == 2 && lum(m.emission) > 0);
    if (!present) continue;
    Result<Cascades> cas = bench_cascades(s, mats);
    if (!cas.ok()) return;
    GiConfig gc;
    gc.light_volume = src == 3;
    std::unique_ptr<GiEngine> g = make_cpu_gi(gc);
    if (!g->load(cas.value(), lights).ok() || !g->update_all(3).ok()) return;
    Result<std::unique_ptr<PathTracer>> pt = PathTracer::create(mesh.value(), mats, lights);
    if (!pt.ok()) return;
    for (int b = 1; b <= 3; ++b) {
      std::vector<glm::vec3> e(p.size()), ref(p.size());
      (void)g->irradiance(p, n, b, e);
      PathTraceConfig pc;
      pc.samples = paths;
      (void)pt.value()->irradiance(p, n, b, ref, pc);
      const Stats st = rel_error(e, ref);
      double mg = 0, mr = 0;
      for (size_t i = 0; i < p.size(); ++i) mg += lum(e[i]) / double(p.size()), mr += lum(ref[i]) / double(p.size());
      const char* names[] = {"sky", "point light (exact)", "emission", "point light (injected volume)", "all together"};
      if (mr <= 0.0) break;
      std::printf("| %s | %d | %.1f%% | %.1f%% | %.3f | %.3f |\n", names[src], b, 100 * st.mean, 100 * st.p95, mg, mr);
    }
  }
}

// Timing only (`bench_gi 0 0 timing`): per scene and engine (default
// config), the median and the minimum of 9 full updates after 3 passes, wall
// and device time, and each stage's median device time (single runs are
// noisy: lavapipe shares the cores).
void timing(const Scene& s) {
  Result<Cascades> cas = bench_cascades(s, s.materials);
  if (!cas.ok()) return;
  for (int cpu = 0; cpu < 2; ++cpu) {
    std::string device = "cpu";
    std::unique_ptr<GiEngine> engine = make_engine(cpu, {}, &device);
    if (!engine) continue;
    if (!engine->load(cas.value(), s.lights).ok() || !engine->update_all(3).ok()) return;
    std::vector<double> wall, dev, cones, update, copy, precombine;
    for (int r = 0; r < 9; ++r) {
      Result<GiTimings> t = engine->update_all(1);
      if (!t.ok()) return;
      const GiTimings::Stages& st = t.value().stage_device_seconds;
      wall.push_back(t.value().seconds);
      dev.push_back(t.value().device_seconds);
      cones.push_back(st.cones);
      update.push_back(st.update);
      copy.push_back(st.copy);
      precombine.push_back(st.precombine);
    }
    for (std::vector<double>* v : {&wall, &dev, &cones, &update, &copy, &precombine}) std::sort(v->begin(), v->end());
    std::printf("| %s | %s | %.4f | %.4f | %.4f | %.4f | %.3f | %.3f | %.3f | %.3f |\n", s.name.c_str(), device.c_str(),
                wall[4], wall[0], dev[4], dev[0], 1e3 * cones[4], 1e3 * update[4], 1e3 * copy[4], 1e3 * precombine[4]);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int points = argc > 1 ? std::atoi(argv[1]) : 200;
  const int paths = argc > 2 ? std::atoi(argv[2]) : 512;
  std::printf("# bench_gi: cone-traced GI (Vulkan engine rows name their device; llvmpipe = Mesa's lavapipe on the CPU) vs path-traced reference\n");
  if (argc > 3 && std::string(argv[3]) == "timing") {
    std::printf("| scene | engine | full update s (median of 9) | min | device s (median) | min | cones ms (median) | update "
                "ms | copy ms | precombine ms |\n|---|---|---|---|---|---|---|---|---|---|\n");
    timing(cornell());
    timing(landscape());
    timing(shared_mesh());
    return 0;
  }
  if (argc > 3 && std::string(argv[3]) == "images") {
    ldc::bench::gi_images(paths, argc > 4 ? argv[4] : nullptr, true);
    return 0;
  }
  if (argc > 3 && std::string(argv[3]) == "visibility") {
    ldc::bench::gi_sky_visibility(paths);
    return 0;
  }
  if (argc > 3 && std::string(argv[3]) == "sources") {
    by_source(cornell(), points, paths);
    by_source(landscape(), points, paths);
    by_source(shared_mesh(), points, paths);
    by_source(furnace(), points, paths);
    return 0;
  }
  run(cornell(), points, paths);
  run(landscape(), points, paths);
  run(shared_mesh(), points, paths);
  return 0;
}
