// Levels of detail (issue 21): a world coarsened to every 2^k-th ray
// (ldc/lod.h) and contoured, per level: the coarsening's and the meshing's
// time, triangles, whether the mesh is closed, and its distance to the level-0
// mesh (bench/meshdist, relative to that mesh's diagonal). Scenes: the default
// landscape (48 m, h = 0.2 m, C = 32) and the shared meshes built at 256
// cells (C = 32), so levels 0, 1, 2. 2 threads unless TBB is told otherwise.
//
// Usage: bench_lod [--quick]
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bench_common.h"
#include "contour/contour.h"
#include "ldc/build.h"
#include "ldc/lod.h"
#include "ldc/terrain.h"
#include "meshdist.h"

namespace {

ldc::TriangleMesh as_triangles(const ldc::ContourMesh& m) {
  ldc::TriangleMesh t;
  t.positions = m.positions;
  t.triangles = m.triangles;
  return t;
}

// The tools' pipeline for a uniform mesh: contour, then untangle_mesh.
ldc::ContourMesh mesh_of(const ldc::World& w) {
  ldc::ContourMesh m = ldc::contour_world(w).value();
  if (!ldc::untangle_mesh(m).ok()) std::abort();
  return m;
}

void scene_rows(const char* name, const ldc::World& world, int reps, size_t samples) {
  ldc::TriangleMesh level0;
  for (int level = 0; level <= ldc::max_lod_level(world.chunk_size()); ++level) {
    ldc::World coarse;
    const double coarsen_ms = ldc::bench::median_ms(reps, [&] { coarse = ldc::coarsen(world, level).value(); });
    ldc::ContourMesh m;
    const double mesh_ms = ldc::bench::median_ms(reps, [&] { m = mesh_of(coarse); });
    const ldc::MeshQuality q = ldc::mesh_quality(m);
    if (level == 0) level0 = as_triangles(m);
    const ldc::bench::MeshDistResult d =
        ldc::bench::mesh_distance(as_triangles(m), level0, {.samples = samples});
    std::printf("| %s | %d | %.4g | %zu | %.2f | %.1f | %.1f | %zu | %.3f | %s | %.2e | %.2e |\n", name, level,
                coarse.lattice().cell_size, coarse.stats().points, coarsen_ms, mesh_ms, coarsen_ms + mesh_ms,
                q.triangles, double(q.triangles) / double(level0.triangles.size()), q.closed() ? "yes" : "**no**",
                d.mean_rel, d.hausdorff_rel);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const int reps = quick ? 1 : 5;
  const size_t samples = quick ? 20000 : 200000;
  std::printf("# Levels of detail: every 2^k-th ray (issue 21)\n\n");
  ldc::bench::print_machine();
  std::printf("\nTimes: median of %d runs, ms. Mesh = contour_world + untangle_mesh (uniform, as `ldc contour "
              "--lod K` writes it). Error: meshdist of level k's mesh against level 0's (mean and sampled "
              "Hausdorff over its diagonal, %zu samples a side).\n\n",
              reps, samples);
  std::printf("| scene | level | cell m | points | coarsen ms | mesh ms | total ms | triangles | / level 0 | closed "
              "| mean rel | Haus rel |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  scene_rows("landscape 48 m", ldc::build_terrain({}, 0.2, 32).value(), reps, samples);
  ldc::bench::Args args = ldc::bench::parse_args(1, argv, {"spot.obj", "fandisk.obj", "rocker-arm.obj"});
  for (const std::string& name : args.meshes) {
    const ldc::World w = ldc::build_from_mesh(ldc::bench::load(args, name), {.cells = quick ? 128 : 256}).value();
    scene_rows((name + (quick ? " 128" : " 256")).c_str(), w, reps, samples);
  }
  return 0;
}
