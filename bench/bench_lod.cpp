// Levels of detail (issue 21): a world coarsened to every 2^k-th ray
// (ldc/lod.h) and contoured, per level: the coarsening's and the meshing's
// time, triangles, whether the mesh is closed, and its distance to the level-0
// mesh (bench/meshdist, relative to that mesh's diagonal). Scenes: the default
// landscape (48 m, h = 0.2 m, C = 32) and the shared meshes built at 256
// cells (C = 32), so levels 0, 1, 2. 2 threads unless TBB is told otherwise.
//
// Second table: chunks at mixed levels (contour_levels), each chunk's level
// by its distance to a camera (lod_level), on the same scenes: the time, the
// triangles against level 0, and whether the seams close, by ldc's quality
// report and by CGAL (bench/mesh_validity: the written OBJ as a soup,
// manifold, closed, self-intersecting pairs).
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
#include "mesh_validity.h"
#include "meshdist.h"
#include "meshio/meshio.h"

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

// A camera at `camera`; level 1 from `near` on, level 2 from `far` on.
struct MixedScene {
  std::string name;
  ldc::World world;
  glm::dvec3 camera;
  double near, far;
};

void mixed_row(const MixedScene& s, int reps, size_t samples) {
  const ldc::World& w = s.world;
  const ldc::LodBands bands{.start = {s.near, s.far}, .hysteresis = 0.0};
  int per_level[3] = {0, 0, 0};
  auto level_of = [&](const glm::ivec3& c) {
    return ldc::lod_level(bands, ldc::chunk_distance(w.lattice(), w.chunk_size(), c, s.camera), 0);
  };
  w.for_each_chunk([&](const glm::ivec3& c, ldc::ChunkKind, const ldc::Chunk*) { ++per_level[level_of(c)]; });
  ldc::ContourConfig raw_config;
  raw_config.untangle = false;
  ldc::ContourMesh raw, m;
  const double levels_ms =
      ldc::bench::median_ms(reps, [&] { raw = ldc::contour_levels(w, level_of, raw_config).value(); });
  const double untangle_ms = ldc::bench::median_ms(reps, [&] {
    m = raw;
    if (!ldc::untangle_mesh(m).ok()) std::abort();
  });
  const double level0_ms = ldc::bench::median_ms(reps, [&] { (void)ldc::contour_world(w, raw_config).value(); });
  const ldc::MeshQuality qr = ldc::mesh_quality(raw), q = ldc::mesh_quality(m);
  const ldc::TriangleMesh level0 = as_triangles(mesh_of(w));
  const std::string path = "/tmp/bench_lod_mixed.obj";
  if (!ldc::save_mesh(m, path).ok()) std::abort();
  const ldc::bench::MeshValidity v = ldc::bench::check_mesh_file(path);
  const ldc::bench::MeshDistResult d = ldc::bench::mesh_distance(as_triangles(m), level0, {.samples = samples});
  std::printf("| %s | %d / %d / %d | %.1f | %.1f | %.1f | %zu | %.3f | %zu / %zu / %zu | %s | %s | %zu | %.2e | %.2e |\n",
              s.name.c_str(), per_level[0], per_level[1], per_level[2], levels_ms, untangle_ms, level0_ms, q.triangles,
              double(q.triangles) / double(level0.triangles.size()), qr.boundary_edges, qr.nonmanifold_edges,
              qr.nonmanifold_vertices, q.closed() ? "yes" : "**no**",
              v.read && v.valid && v.closed && v.nonmanifold_edges + v.nonmanifold_vertices == 0 ? "yes" : "**no**",
              v.self_intersections, d.mean_rel, d.hausdorff_rel);
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

  std::printf("\n## Chunks at mixed levels by distance (contour_levels)\n\n"
              "Each chunk's level by lod_level from its box's distance to a camera: level 1 from `near`, level 2 "
              "from `far` (landscape: camera (6, 6, 8) m, 12 and 24 m; meshes: the box's lower corner, 1/3 and "
              "2/3 of the diagonal). levels ms = contour_levels without untangling (each level read in place, nothing coarsened); "
              "untangle ms = untangle_mesh on it; level 0 ms = contour_world of the whole world without untangling, "
              "for scale. Raw = the mesh before untangling: boundary / non-manifold edges / non-manifold "
              "vertices (ldc's mesh_quality). Closed = after untangling, by mesh_quality; CGAL = the written OBJ "
              "valid, closed and manifold by CGAL, with its self-intersecting pairs. Error against the level-0 "
              "mesh (contour_world + untangle_mesh), as above.\n\n");
  std::printf("| scene | chunks at level 0 / 1 / 2 | levels ms | untangle ms | level 0 ms | triangles | / level 0 | raw "
              "boundary / NM edges / NM verts | closed | CGAL | CGAL SI pairs | mean rel | Haus rel |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  mixed_row({"landscape 48 m", ldc::build_terrain({}, 0.2, 32).value(), glm::dvec3(6.0, 6.0, 8.0), 12.0, 24.0}, reps,
            samples);
  for (const std::string& name : args.meshes) {
    ldc::World w = ldc::build_from_mesh(ldc::bench::load(args, name), {.cells = quick ? 128 : 256}).value();
    const ldc::WorldBox box = w.box();
    const double diag = glm::length(box.max - box.min);
    mixed_row({name + (quick ? " 128" : " 256"), std::move(w), box.min, diag / 3.0, 2.0 * diag / 3.0}, reps, samples);
  }
  return 0;
}
