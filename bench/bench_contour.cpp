// Remeshing benchmark: mesh -> LDC -> dual contouring (each placement method,
// and marching cubes) against OpenVDB meshToLevelSet + volumeToMesh
// (adaptivity 0) at the same cell size h = diagonal / N, in the same run.
// Time with 1 and 2 threads, error against the input mesh (meshdist: symmetric
// mean and max distance over the diagonal, normal error, and the normal error
// within 2h of the input's sharp edges). Writes an SVG of time against error
// per mesh into the folder given by --plots (default docs/).
//
// Usage: bench_contour [--quick] [--meshes a.obj,b.obj] [--plots DIR]
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <tbb/global_control.h>

#include "bench_common.h"
#include "contour/contour.h"
#include "meshio/meshio.h"
#include "ldc/build.h"
#include "meshdist.h"
#include "svg_plot.h"
#include "vdb_mesh.h"

namespace {

using ldc::bench::median_ms;

struct Method {
  std::string name;
  std::string colour;
  std::function<ldc::TriangleMesh(const ldc::TriangleMesh&, double)> remesh;  // input, h -> output
};

// As `ldc remesh --max-error 0` does it: dual contouring without the local
// untangling round, then untangle_mesh on the whole mesh (timed with it).
ldc::TriangleMesh ldc_remesh(const ldc::TriangleMesh& in, double h, ldc::ContourConfig config, bool mc) {
  ldc::GridConfig grid;
  grid.cell_size = h;
  ldc::World w = ldc::build_from_mesh(in, grid).value();
  if (mc) return ldc::to_triangle_mesh(ldc::marching_cubes(w).value());
  config.untangle = false;
  ldc::ContourMesh m = ldc::contour_world(w, config).value();
  ldc::untangle_mesh(m).value();
  return ldc::to_triangle_mesh(m);
}

ldc::TriangleMesh vdb_remesh(const ldc::TriangleMesh& in, double h) {
  auto xform = openvdb::math::Transform::createLinearTransform(h);
  return ldc::bench::vdb_to_mesh(*ldc::bench::vdb_level_set(in, *xform));
}

std::vector<Method> methods() {
  std::vector<Method> m;
  m.push_back({"vdb", "#888888", [](const ldc::TriangleMesh& in, double h) { return vdb_remesh(in, h); }});
  m.push_back({"ldc-iterative", "#d62728", [](const ldc::TriangleMesh& in, double h) {
                 return ldc_remesh(in, h, {.placement = ldc::Placement::kIterative}, false);
               }});
  m.push_back({"ldc-iterative-16", "#ff7f0e", [](const ldc::TriangleMesh& in, double h) {
                 return ldc_remesh(in, h, {.placement = ldc::Placement::kIterative, .iterations = 16}, false);
               }});
  m.push_back({"ldc-qef", "#1f77b4", [](const ldc::TriangleMesh& in, double h) {
                 return ldc_remesh(in, h, {.placement = ldc::Placement::kQef}, false);
               }});
  m.push_back({"ldc-masspoint", "#2ca02c", [](const ldc::TriangleMesh& in, double h) {
                 return ldc_remesh(in, h, {.placement = ldc::Placement::kMassPoint}, false);
               }});
  m.push_back({"ldc-mc", "#9467bd", [](const ldc::TriangleMesh& in, double h) { return ldc_remesh(in, h, {}, true); }});
  return m;
}

struct Row {
  std::string mesh, method;
  int res = 0;
  double h = 0, ms[2] = {0, 0};
  size_t tris = 0;
  size_t self_intersections = 0;
  ldc::bench::MeshDistResult err;
};

Row measure(const std::string& name, const ldc::TriangleMesh& in, const Method& method, int res, int reps) {
  Row r;
  r.mesh = name;
  r.method = method.name;
  r.res = res;
  r.h = ldc::mesh_bounds(in).diagonal() / res;
  for (int t = 0; t < 2; ++t) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(t + 1));
    r.ms[t] = median_ms(reps, [&] { (void)method.remesh(in, r.h); });
  }
  ldc::TriangleMesh out = method.remesh(in, r.h);
  r.tris = out.triangles.size();
  ldc::bench::MeshDistOptions o;
  o.near_sharp_distance = 2.0 * r.h;
  r.err = ldc::bench::mesh_distance(out, in, o);
  r.self_intersections = ldc::bench::self_intersections(out);
  return r;
}

void print_rows(const std::vector<Row>& rows) {
  std::printf("\n### Remesh: mesh -> LDC -> mesh against OpenVDB meshToLevelSet + volumeToMesh (h = diagonal / N)\n\n");
  std::printf("| mesh | N | method | ms 1t | ms 2t | tris | mean rel | Haus rel | normal mean deg | n>10deg | near-sharp frac "
              "| near-sharp normal deg | away normal deg | vol out/in | self-intersecting pairs |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    const auto& e = r.err;
    std::printf("| %s | %d | %s | %.1f | %.1f | %zu | %.2e | %.2e | %.2f | %.1f%% | %.1f%% | %.2f | %.2f | %.4f | %zu |\n",
                r.mesh.c_str(), r.res, r.method.c_str(), r.ms[0], r.ms[1], r.tris, e.mean_rel, e.hausdorff_rel,
                e.normal_mean_deg, 100 * e.normal_over10, 100 * e.near_fraction, e.near_normal_deg, e.away_normal_deg,
                e.volume_ratio, r.self_intersections);
  }
}

// The targets for the default method against OpenVDB at the same h.
void print_targets(const std::vector<Row>& rows) {
  std::printf("\n### Default method (ldc-iterative) against OpenVDB: ratios (target)\n\n");
  std::printf("| mesh | N | mean distance ratio (<= 0.5) | near-sharp normal ratio (<= 0.33) | remesh time ratio 2t (<= 0.2) |\n");
  std::printf("|---|---|---|---|---|\n");
  std::map<std::pair<std::string, int>, const Row*> vdb;
  for (const Row& r : rows)
    if (r.method == "vdb") vdb[{r.mesh, r.res}] = &r;
  for (const Row& r : rows) {
    if (r.method != "ldc-iterative") continue;
    const Row* v = vdb[{r.mesh, r.res}];
    if (!v) continue;
    std::printf("| %s | %d | %.2f | %.2f | %.3f |\n", r.mesh.c_str(), r.res, r.err.mean_rel / v->err.mean_rel,
                v->err.near_normal_deg > 0 ? r.err.near_normal_deg / v->err.near_normal_deg : 0.0, r.ms[1] / v->ms[1]);
  }
}

void write_plots(const std::vector<Row>& rows, const std::string& dir) {
  std::map<std::string, std::vector<ldc::bench::PlotSeries>> per_mesh;
  for (const Method& m : methods()) {
    std::map<std::string, ldc::bench::PlotSeries> s;
    for (const Row& r : rows) {
      if (r.method != m.name) continue;
      auto& series = s[r.mesh];
      series.name = m.name;
      series.colour = m.colour;
      series.dashed = m.name == "vdb";
      series.points.push_back({r.ms[1], r.err.mean_rel});
    }
    for (auto& [mesh, series] : s) per_mesh[mesh].push_back(series);
  }
  for (const auto& [mesh, series] : per_mesh) {
    std::string path = dir + "/contour_" + mesh.substr(0, mesh.find('.')) + ".svg";
    ldc::bench::write_loglog_svg(path, "Remesh " + mesh + ": time against error (N = 64, 128, 256, 512)",
                                 "time, 2 threads [ms]", "mean distance / diagonal", series);
    std::printf("\nplot: %s\n", path.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string plots = "docs";
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    if (std::string(argv[i]) == "--plots" && i + 1 < argc) plots = argv[++i];
    else rest.push_back(argv[i]);
  }
  ldc::bench::Args args = ldc::bench::parse_args(int(rest.size()), rest.data(),
                                                 {"fandisk.obj", "rocker-arm.obj", "spot.obj", "stanford-bunny.obj"});
  openvdb::initialize();
  ldc::bench::print_machine();
  std::vector<int> resolutions = args.quick ? std::vector<int>{64, 128} : std::vector<int>{64, 128, 256, 512};
  std::vector<Row> rows;
  for (const std::string& file : args.meshes) {
    ldc::TriangleMesh in = ldc::bench::load(args, file);
    std::string name = file;
    if (file == "stanford-bunny.obj") {  // measured closed, as the peers are
      size_t holes = 0;
      in = ldc::bench::fill_holes(in, &holes);
      name = "stanford-bunny-filled.obj";
      std::fprintf(stderr, "  filled %zu holes in the bunny\n", holes);
    }
    for (int res : resolutions) {
      int reps = args.quick ? 2 : (res >= 512 ? 2 : res >= 256 ? 3 : 5);
      for (const Method& m : methods()) rows.push_back(measure(name, in, m, res, reps));
      std::fprintf(stderr, "  %s %d done\n", name.c_str(), res);
    }
  }
  print_rows(rows);
  print_targets(rows);
  write_plots(rows, plots);
  std::printf("\nNotes: median wall time of repeated runs of the whole remesh (mesh in memory -> mesh in memory), "
              "1 and 2 threads. Errors from bench/meshdist (200k samples per surface, CGAL AABB trees), against the "
              "input mesh (the bunny after CGAL hole filling). OpenVDB polygons are re-wound outward before measuring. "
              "Self-intersecting triangle pairs counted by CGAL.\n");
  return 0;
}
