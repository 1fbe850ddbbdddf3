// Voxel export (issue 7): solid occupancy against OpenVDB's solid voxelization
// (meshToLevelSet + sdfInteriorMask + copyToDense) in the same run, on meshes
// and the default landscape; one cascade level's full update with the
// six-face G-buffer; the per-frame cost of a camera moving at 10 m/s.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <numeric>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "bench_common.h"
#include "contour/contour.h"
#include "ldc/build.h"
#include "ldc/terrain.h"
#include "voxel_peers.h"
#include "voxelize/voxelize.h"

namespace ldc::bench {
namespace {

struct Timed {
  double wall_ms = 0.0;  // median
  double cpu_ms = 0.0;   // process CPU time of the median-sized share (total / reps)
};

// Median wall time and mean process CPU time of `reps` runs.
Timed time_it(int reps, const std::function<void()>& fn) {
  const std::clock_t c0 = std::clock();
  Timed t;
  t.wall_ms = median_ms(reps, fn);
  t.cpu_ms = 1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC / reps;
  return t;
}

double mesh_volume(const TriangleMesh& m) { return mesh_signed_volume(m); }

struct MeshCase {
  std::string name;
  TriangleMesh mesh;
  double reference_volume = 0.0;  // of the closed (hole-filled) mesh
  bool run_ldc = true;
};

// One row: OpenVDB against LDC (m = 1: LDC cell = voxel; m = 2: LDC at half the voxel size).
void mesh_row(const MeshCase& c, int n, int threads, int reps) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
  const MeshBounds b = mesh_bounds(c.mesh);
  const glm::dvec3 ext = b.extent();
  const double s = std::max({ext.x, ext.y, ext.z}) / n;
  const glm::ivec3 dims(glm::ceil(ext / s - 1e-9));
  VdbSolidResult vdb;
  const Timed vdb_t = time_it(reps, [&] { vdb = vdb_solid_occupancy(c.mesh, s, b.min, dims); });
  const double vdb_vol = double(vdb.occupied) * s * s * s;
  std::printf("| %s | %d | %dx%dx%d | %d | %.1f | %.4f |", c.name.c_str(), n, dims.x, dims.y, dims.z, threads,
              vdb_t.wall_ms, vdb_vol / c.reference_volume);
  if (!c.run_ldc) {
    std::printf(" - | - | - | - | - | - | - | - |\n");
    return;
  }
  double vol[3] = {0, 0, 0};
  Timed build[3], vox[3];
  for (int m : {1, 2}) {
    GridConfig grid;
    grid.cell_size = s / m;
    World world;
    build[m] = time_it(reps, [&] { world = build_from_mesh(c.mesh, grid).value(); });
    VoxelGrid g;
    vox[m] = time_it(reps, [&] { g = voxelize(world, VoxelConfig{.voxel_size = s}).value(); });
    vol[m] = g.volume();
  }
  const double total1 = build[1].wall_ms + vox[1].wall_ms;
  std::printf(" %.1f | %.2f | %.1f (cpu %.1f) | %.0fx | %.0fx | %.4f | %.1f | %.4f |\n", build[1].wall_ms,
              vox[1].wall_ms, total1, build[1].cpu_ms + vox[1].cpu_ms, vdb_t.wall_ms / total1,
              vdb_t.wall_ms / vox[1].wall_ms, vol[1] / c.reference_volume, build[2].wall_ms + vox[2].wall_ms,
              vol[2] / c.reference_volume);
}

void mesh_table(const Args& args) {
  std::printf(
      "Voxel size s = longest bounding-box extent / n. OpenVDB: meshToLevelSet (half width 3) + sdfInteriorMask + "
      "copyToDense into a dense uint8 grid (voxel centres at min + (i + 1/2) s), from triangles. LDC m = 1: the mesh "
      "built into an LDC with h = s (`build`, watertight rasterizer, open meshes repaired), then `voxelize` (occupancy "
      "only, z spans); `total` = build + voxelize, the fair comparison with OpenVDB, which also starts from triangles; "
      "`voxelize`-only is the cost when the LDC already exists (a game's landscape). LDC m = 2: h = s / 2, 4x the rays "
      "per voxel, same voxel grid. `vol / mesh` = occupied volume / volume of the closed mesh (the bunny's holes "
      "closed by CGAL's triangulate_hole for the reference). Times are medians of %d runs; cpu = process CPU time per "
      "run.\n\n",
      args.quick ? 1 : 3);
  std::printf(
      "| mesh | n | dense dims | threads | OpenVDB ms | OpenVDB vol / mesh | LDC build ms | LDC voxelize ms | LDC total "
      "ms | speed-up (total) | speed-up (voxelize only) | LDC vol / mesh | LDC m=2 total ms | m=2 vol / mesh |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<MeshCase> cases;
  for (const std::string& name : args.meshes) {
    MeshCase c{name.substr(0, name.rfind('.')), load(args, name), 0.0, true};
    size_t holes = 0;
    TriangleMesh filled = fill_holes(c.mesh, &holes);
    c.reference_volume = mesh_volume(holes ? filled : c.mesh);
    if (holes) c.name += " (open, " + std::to_string(holes) + " holes)";
    cases.push_back(c);
    if (holes) cases.push_back({c.name.substr(0, c.name.find(' ')) + "-filled", filled, c.reference_volume, true});
  }
  const int reps = args.quick ? 1 : 3;
  for (const MeshCase& c : cases) {
    for (int n : {128, 256}) {
      for (int threads : {1, 2}) mesh_row(c, n, threads, reps);
    }
  }
}

World default_landscape(double* seconds) {
  const auto t = std::chrono::steady_clock::now();
  World w = build_terrain(TerrainConfig{}, 0.2).value();
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  return w;
}

void landscape_table(const World& w, double build_s, const Args& args) {
  ContourMesh cm = contour_world(w).value();
  TriangleMesh mesh;
  mesh.positions = cm.positions;
  mesh.triangles = cm.triangles;
  const double mesh_vol = mesh_volume(mesh);
  std::printf(
      "The default landscape (48 x 48 m, caves, overhangs, arches; LDC h = 0.2 m, built from its implicit function "
      "in %.2f s, not included below). LDC: `voxelize` of the existing LDC (occupancy, z spans), s = 0.4 m (m = 2, "
      "about 128 voxels across) and 0.2 m (m = 1, about 256). OpenVDB: the same pipeline as above on the "
      "dual-contoured mesh of that LDC (%zu triangles; contouring not timed). `vol / mesh` against that mesh's "
      "volume.\n\n",
      build_s, mesh.triangles.size());
  std::printf("| voxel size | dense dims | threads | OpenVDB ms | OpenVDB vol / mesh | LDC voxelize ms | cpu ms | speed-up "
              "| LDC vol / mesh | chunk columns closed / walked |\n|---|---|---|---|---|---|---|---|---|---|\n");
  const int reps = args.quick ? 1 : 3;
  for (double s : {0.4, 0.2}) {
    for (int threads : {1, 2}) {
      tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
      const MeshBounds b = mesh_bounds(mesh);
      const glm::ivec3 dims(glm::ceil(b.extent() / s - 1e-9));
      VdbSolidResult vdb;
      const Timed vt = time_it(reps, [&] { vdb = vdb_solid_occupancy(mesh, s, b.min, dims); });
      VoxelGrid g;
      VoxelStats stats;
      const Timed lt = time_it(reps, [&] {
        stats = {};
        g = voxelize(w, VoxelConfig{.voxel_size = s}, {}, nullptr, &stats).value();
      });
      std::printf("| %.1f m | %dx%dx%d | %d | %.1f | %.4f | %.2f | %.2f | %.0fx | %.4f | %zu / %zu |\n", s, g.box.dims.x,
                  g.box.dims.y, g.box.dims.z, threads, vt.wall_ms, double(vdb.occupied) * s * s * s / mesh_vol,
                  lt.wall_ms, lt.cpu_ms, vt.wall_ms / lt.wall_ms, g.volume() / mesh_vol, stats.chunk_columns_closed,
                  stats.chunk_columns_walked);
    }
  }
}

// Percentile of sorted samples.
double pct(const std::vector<double>& v, double p) { return v[std::min(v.size() - 1, size_t(p * double(v.size())))]; }

void cascade_tables(const World& w, const Args& args) {
  const glm::dvec3 centre(24.0, 24.0, 7.0);
  CascadeConfig cfg;  // 6 levels of 32^3, level 0 voxel 0.2 m
  std::printf("Default landscape, h = 0.2 m; cascades of 6 levels x 32^3, level 0 voxel 0.2 m (level k: 0.2 * 2^k), "
              "camera at (24, 24, 7). Full update = every voxel of one level: occupancy, six-face G-buffer (albedo, "
              "normal, face opacity, emission, all three ray families), first-layer propagation, written into the "
              "packed GPU textures (RGBA8, RGBA8 snorm, R8, R11G11B10F) with toroidal addressing. `pack` = the "
              "camera-centred copy of one level's textures for upload (%.2f MB per level). Medians of %d runs.\n\n",
              double(PackedGBuffer{.resolution = 32, .levels = 1}.bytes()) / 1e6, args.quick ? 20 : 100);
  std::printf("| level | voxel | threads | full update ms | cpu ms | pack ms |\n|---|---|---|---|---|---|\n");
  const int reps = args.quick ? 20 : 100;
  std::vector<double> full_ms[3];
  for (int k = 0; k < cfg.levels; ++k) {
    for (int threads : {1, 2}) {
      tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
      Cascades c = Cascades::create(w.lattice(), cfg).value();
      (void)c.update_level(w, k, centre);  // warm: the storage's pages touched once
      const Timed t = time_it(reps, [&] {
        c.invalidate_level(k);
        (void)c.update_level(w, k, centre);
      });
      PackedGBuffer out;
      c.pack_level(k, &out);
      const Timed p = time_it(reps, [&] { c.pack_level(k, &out); });
      std::printf("| %d | %.1f m | %d | %.3f | %.3f | %.3f |\n", k, cfg.voxel_size * (1 << k), threads, t.wall_ms,
                  t.cpu_ms, p.wall_ms);
      full_ms[threads].push_back(t.wall_ms);
    }
  }
  std::printf("\nCamera moving at 10 m/s at 60 fps (1/6 m per frame) on a circle of 12 m radius around the landscape's "
              "centre, z = 7 m, %d frames after a full update of every level; each frame updates one level on the "
              "talk's schedule (level 0 every 2 frames, level k every 2^(k+1)): scroll, voxelize the exposed slabs, "
              "propagate. `re-voxelize` = the same schedule if each update re-voxelized its level whole (from the full "
              "update medians above).\n\n",
              args.quick ? 300 : 1200);
  std::printf("| threads | mean ms / frame | median | p99 | max | cpu ms / frame | voxels / frame | re-voxelize ms / frame "
              "|\n|---|---|---|---|---|---|---|---|\n");
  const int frames = args.quick ? 300 : 1200;
  for (int threads : {1, 2}) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
    Cascades c = Cascades::create(w.lattice(), cfg).value();
    auto camera = [&](int f) {
      const double angle = double(f) * (10.0 / 60.0) / 12.0;
      return centre + glm::dvec3(12.0 * std::cos(angle), 12.0 * std::sin(angle), 0.0);
    };
    (void)c.update_all(w, camera(0));
    std::vector<double> ms;
    size_t voxels = 0;
    const std::clock_t c0 = std::clock();
    for (int f = 1; f <= frames; ++f) {
      const auto t = std::chrono::steady_clock::now();
      CascadeUpdate up = c.frame(w, camera(f)).value();
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count());
      voxels += up.voxels;
    }
    const double cpu = 1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC / frames;
    const double mean = std::accumulate(ms.begin(), ms.end(), 0.0) / double(frames);
    std::sort(ms.begin(), ms.end());
    double revox = 0.0;
    for (int k = 0; k < cfg.levels; ++k) {
      const double share = k + 1 < cfg.levels ? 1.0 / double(2 << k) : 2.0 / double(1 << cfg.levels);
      revox += share * full_ms[threads][size_t(k)];
    }
    std::printf("| %d | %.3f | %.3f | %.3f | %.3f | %.3f | %.0f | %.3f |\n", threads, mean, pct(ms, 0.5), pct(ms, 0.99),
                ms.back(), cpu, double(voxels) / frames, revox);
  }
}

}  // namespace
}  // namespace ldc::bench

// LDC_BENCH_SECTIONS=meshes,landscape,cascades (default: all) picks the tables.
int main(int argc, char** argv) {
  using namespace ldc::bench;
  Args args = parse_args(argc, argv, {"stanford-bunny.obj", "rocker-arm.obj"});
  const char* env = std::getenv("LDC_BENCH_SECTIONS");
  const std::string sections = env ? env : "meshes,landscape,cascades";
  auto wanted = [&](const char* s) { return sections.find(s) != std::string::npos; };
  print_machine();
  if (wanted("meshes")) {
    std::printf("\n### Solid occupancy from meshes against OpenVDB\n\n");
    mesh_table(args);
  }
  double build_s = 0.0;
  const ldc::World w = default_landscape(&build_s);
  if (wanted("landscape")) {
    std::printf("\n### Solid occupancy of the default landscape\n\n");
    landscape_table(w, build_s, args);
  }
  if (wanted("cascades")) {
    std::printf("\n### Cascades: full level update and per-frame scrolling\n\n");
    cascade_tables(w, args);
  }
  return 0;
}
