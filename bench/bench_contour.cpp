// Remeshing benchmark: mesh -> LDC -> dual contouring (each placement method,
// and marching cubes) against OpenVDB meshToLevelSet + volumeToMesh
// (adaptivity 0) at the same cell size h = diagonal / N, in the same run.
// Time with 1 and 2 threads, error against the input mesh (meshdist: symmetric
// mean and max distance over the diagonal, normal error, and the normal error
// within 2h of the input's sharp edges). Writes an SVG of time against error
// per mesh into the folder given by --plots (default docs/).
//
// A second section (issue 19) asks, at equal mean error, who needs fewer
// triangles: `ldc remesh` as it runs by default (adaptive) against OpenVDB
// volumeToMesh with adaptivity 0 .. 1 (see measure_adaptive); its CSV and
// plots are written only when --plots is given.
//
// Usage: bench_contour [--quick] [--meshes a.obj,b.obj] [--plots DIR]
//                      [--adaptive-only | --no-adaptive] [--adaptive-n 64,128,256]
//                      [--vdb-n LIST (default: N, 2N, 4N of each --adaptive-n)]
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <sstream>
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

// The adaptive default of `ldc remesh`: tools/mesh_output.h's
// kAdaptiveMaxErrorCells (the bench does not link the tool; keep in step).
constexpr double kRemeshMaxErrorCells = 0.2;

// As `ldc remesh --max-error <max_error_cells>` does it (tools/mesh_output.cpp,
// mesh_world): when max_error_cells > 0, contour_at_surface_levels at a
// tenth of the bound (otherwise contour_world); dual contouring without
// the local untangling round, then simplify_mesh within max_error_cells * h
// when that is > 0, then untangle_mesh on the whole mesh (all timed
// together). `stats`, when given, receives the simplification's figures.
ldc::TriangleMesh ldc_remesh(const ldc::TriangleMesh& in, double h, ldc::ContourConfig config, bool mc,
                             double max_error_cells = 0.0, ldc::SimplifyStats* stats = nullptr) {
  ldc::GridConfig grid;
  grid.cell_size = h;
  ldc::World w = ldc::build_from_mesh(in, grid).value();
  if (mc) return ldc::to_triangle_mesh(ldc::marching_cubes(w).value());
  config.untangle = false;
  ldc::ContourMesh m = max_error_cells > 0.0
                           ? ldc::contour_at_surface_levels(w, ldc::surface_level_tolerance(max_error_cells), config).value()
                           : ldc::contour_world(w, config).value();
  if (max_error_cells > 0.0) {
    ldc::SimplifyStats s =
        ldc::simplify_mesh(m, {.max_error = max_error_cells * w.lattice().cell_size}).value();
    if (stats) *stats = s;
  }
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

// --- Adaptive remesh against OpenVDB with adaptivity (issue 19) -------------
//
// At equal mean error, who needs fewer triangles? ldc as `ldc remesh` runs by
// default (adaptive, --max-error 0.2 cells) at N; OpenVDB meshToLevelSet +
// volumeToMesh with adaptivity in kVdbAdaptivity at N, 2N and 4N (the level set
// built once per resolution, meshed once per adaptivity). OpenVDB's triangles
// at ldc's mean error come from the Pareto front of all of its points for the
// mesh (every resolution and adaptivity measured), interpolated log-log.

const double kVdbAdaptivity[] = {0.0, 0.1, 0.25, 0.5, 0.75, 1.0};

struct AdaptiveRow {
  std::string mesh, who;  // who: "ldc" or "vdb"
  int res = 0;
  double adaptivity = 0;  // vdb only
  double ms = 0;          // one run, 2 threads (vdb: level set + volumeToMesh)
  size_t tris = 0;
  size_t uniform_tris = 0;  // ldc only: before simplify_mesh
  size_t self_intersections = 0;
  ldc::MeshTopology topo;
  ldc::bench::MeshDistResult err;
  bool pareto = false;        // vdb only: on the front
  bool pareto_clean = false;  // vdb only: on the front of the outputs free of self-intersections
};

void measure_output(AdaptiveRow& r, const ldc::TriangleMesh& out, const ldc::TriangleMesh& in, double h) {
  r.tris = out.triangles.size();
  ldc::bench::MeshDistOptions o;
  o.near_sharp_distance = 2.0 * h;
  r.err = ldc::bench::mesh_distance(out, in, o);
  r.self_intersections = ldc::bench::self_intersections(out);
  r.topo = ldc::mesh_topology(out);
}

std::vector<AdaptiveRow> measure_adaptive(const std::string& name, const ldc::TriangleMesh& in,
                                          const std::vector<int>& ldc_res, const std::vector<int>& vdb_res_given) {
  std::vector<AdaptiveRow> rows;
  const double diag = ldc::mesh_bounds(in).diagonal();
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
  for (int res : ldc_res) {
    AdaptiveRow r;
    r.mesh = name;
    r.who = "ldc";
    r.res = res;
    const double h = diag / res;
    ldc::SimplifyStats stats;
    ldc::TriangleMesh out;
    r.ms = median_ms(1, [&] {
      out = ldc_remesh(in, h, {.placement = ldc::Placement::kIterative}, false, kRemeshMaxErrorCells, &stats);
    });
    r.uniform_tris = stats.triangles_before;
    measure_output(r, out, in, h);
    rows.push_back(r);
    std::fprintf(stderr, "  %s ldc %d: %zu tris, mean %.2e\n", name.c_str(), res, r.tris, r.err.mean_rel);
  }
  // OpenVDB at N, 2N and 4N of every ldc N unless given: at equal N its error
  // is several times ldc's, so its front needs the finer grids to reach it.
  std::set<int> vdb_res(vdb_res_given.begin(), vdb_res_given.end());
  if (vdb_res.empty())
    for (int res : ldc_res) vdb_res.insert(res), vdb_res.insert(2 * res), vdb_res.insert(4 * res);
  for (int res : vdb_res) {
    const double h = diag / res;
    openvdb::FloatGrid::Ptr grid;
    const double level_set_ms = median_ms(1, [&] {
      auto xform = openvdb::math::Transform::createLinearTransform(h);
      grid = ldc::bench::vdb_level_set(in, *xform);
    });
    for (double a : kVdbAdaptivity) {
      AdaptiveRow r;
      r.mesh = name;
      r.who = "vdb";
      r.res = res;
      r.adaptivity = a;
      ldc::TriangleMesh out;
      r.ms = level_set_ms + median_ms(1, [&] { out = ldc::bench::vdb_to_mesh(*grid, a); });
      measure_output(r, out, in, h);
      rows.push_back(r);
    }
    std::fprintf(stderr, "  %s vdb %d done\n", name.c_str(), res);
  }
  // The front: sorted by mean error, each point with fewer triangles than
  // every more accurate one.
  std::vector<AdaptiveRow*> vdb;
  for (AdaptiveRow& r : rows)
    if (r.who == "vdb") vdb.push_back(&r);
  std::sort(vdb.begin(), vdb.end(), [](const AdaptiveRow* a, const AdaptiveRow* b) {
    return a->err.mean_rel != b->err.mean_rel ? a->err.mean_rel < b->err.mean_rel : a->tris < b->tris;
  });
  size_t fewest = SIZE_MAX, fewest_clean = SIZE_MAX;
  for (AdaptiveRow* r : vdb) {
    if (r->tris < fewest) r->pareto = true, fewest = r->tris;
    if (r->self_intersections == 0 && r->tris < fewest_clean) r->pareto_clean = true, fewest_clean = r->tris;
  }
  return rows;
}

std::string closed_text(const AdaptiveRow& r) {
  const auto& t = r.topo;
  if (t.closed() && t.boundary_edges == 0 && t.nonmanifold_edges == 0) return "yes";
  return "no (" + std::to_string(t.boundary_edges) + " bd, " + std::to_string(t.nonmanifold_edges) + " nm, " +
         std::to_string(t.unbalanced_edges) + " unbal)";
}

void print_adaptive_rows(const std::vector<AdaptiveRow>& rows) {
  std::printf("\n### Adaptive remesh: `ldc remesh` (default --max-error %.1f cells) against OpenVDB volumeToMesh with "
              "adaptivity (h = diagonal / N)\n\n",
              kRemeshMaxErrorCells);
  std::printf("| mesh | method | N | adaptivity | ms 2t (1 run) | tris | ldc tris before simplifying | mean rel | Haus rel | "
              "near-sharp normal deg | closed (welded) | self-intersecting pairs | on OpenVDB front |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const AdaptiveRow& r : rows) {
    const bool l = r.who == "ldc";
    std::printf("| %s | %s | %d | %s | %.0f | %zu | %s | %.2e | %.2e | %.2f | %s | %zu | %s |\n", r.mesh.c_str(),
                l ? "ldc remesh" : "vdb", r.res, l ? "-" : std::to_string(r.adaptivity).substr(0, 4).c_str(), r.ms,
                r.tris, l ? std::to_string(r.uniform_tris).c_str() : "-", r.err.mean_rel, r.err.hausdorff_rel,
                r.err.near_normal_deg, closed_text(r).c_str(), r.self_intersections, l ? "-" : r.pareto ? "yes" : "");
  }
}

std::string vdb_label(const AdaptiveRow& r) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%d/%g", r.res, r.adaptivity);
  return buf;
}

// clean_only: OpenVDB's front from its outputs without self-intersections.
void print_adaptive_summary(const std::vector<AdaptiveRow>& rows, bool clean_only) {
  std::printf("\n### Adaptive remesh: OpenVDB's triangles at ldc's mean error (target: ldc/OpenVDB < 1)%s\n\n",
              clean_only ? ", OpenVDB outputs without self-intersecting pairs only" : "");
  std::printf("| mesh | N | ldc mean rel | ldc tris | OpenVDB tris at that error | ldc/OpenVDB | ldc / T_b "
              "(OpenVDB-favourable) | bracketing OpenVDB points (N/adaptivity: mean rel, tris) |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const AdaptiveRow& l : rows) {
    if (l.who != "ldc") continue;
    std::vector<const AdaptiveRow*> front;
    for (const AdaptiveRow& r : rows)
      if (r.who == "vdb" && r.mesh == l.mesh && (clean_only ? r.pareto_clean : r.pareto)) front.push_back(&r);
    std::sort(front.begin(), front.end(),
              [](const AdaptiveRow* a, const AdaptiveRow* b) { return a->err.mean_rel < b->err.mean_rel; });
    const double e = l.err.mean_rel;
    std::string vdb_tris, ratio, ratio_b = "-", bracket;
    char buf[128];
    if (front.empty() || e < front.front()->err.mean_rel) {
      vdb_tris = "not reached";
      ratio = "-";
      if (!front.empty()) {
        std::snprintf(buf, sizeof buf, "most accurate: %s, %.2e, %zu tris", vdb_label(*front.front()).c_str(),
                      front.front()->err.mean_rel, front.front()->tris);
        bracket = buf;
      }
    } else if (e >= front.back()->err.mean_rel) {
      // Even OpenVDB's coarsest front point is as accurate: no extrapolation.
      const AdaptiveRow& b = *front.back();
      std::snprintf(buf, sizeof buf, "<= %zu", b.tris);
      vdb_tris = buf;
      std::snprintf(buf, sizeof buf, ">= %.3g", double(l.tris) / double(b.tris));
      ratio = buf;
      std::snprintf(buf, sizeof buf, "coarsest: %s (%.2e)", vdb_label(b).c_str(), b.err.mean_rel);
      bracket = buf;
    } else {
      size_t i = 0;
      while (!(front[i]->err.mean_rel <= e && e < front[i + 1]->err.mean_rel)) ++i;
      const AdaptiveRow& a = *front[i];
      const AdaptiveRow& b = *front[i + 1];
      const double t = std::log(e / a.err.mean_rel) / std::log(b.err.mean_rel / a.err.mean_rel);
      const double tris = std::exp(std::log(double(a.tris)) + t * std::log(double(b.tris) / double(a.tris)));
      std::snprintf(buf, sizeof buf, "%.0f", tris);
      vdb_tris = buf;
      std::snprintf(buf, sizeof buf, "%.3g", double(l.tris) / tris);
      ratio = buf;
      std::snprintf(buf, sizeof buf, "%.3g", double(l.tris) / double(b.tris));
      ratio_b = buf;
      std::snprintf(buf, sizeof buf, "%s (%.2e, %zu) - %s (%.2e, %zu)", vdb_label(a).c_str(), a.err.mean_rel, a.tris,
                    vdb_label(b).c_str(), b.err.mean_rel, b.tris);
      bracket = buf;
    }
    std::printf("| %s | %d | %.2e | %zu | %s | %s | %s | %s |\n", l.mesh.c_str(), l.res, e, l.tris, vdb_tris.c_str(),
                ratio.c_str(), ratio_b.c_str(), bracket.c_str());
  }
}

void write_adaptive_outputs(const std::vector<AdaptiveRow>& rows, const std::string& dir) {
  const std::string csv_path = dir + "/contour_adaptive.csv";
  if (std::FILE* f = std::fopen(csv_path.c_str(), "w")) {
    std::fprintf(f, "mesh,method,N,adaptivity,triangles,mean_rel,hausdorff_rel,near_sharp_normal_deg,boundary_edges,"
                    "nonmanifold_edges,unbalanced_edges,self_intersecting_pairs,pareto,pareto_clean,ms_2t\n");
    for (const AdaptiveRow& r : rows)
      std::fprintf(f, "%s,%s,%d,%g,%zu,%.6e,%.6e,%.4f,%zu,%zu,%zu,%zu,%d,%d,%.1f\n", r.mesh.c_str(), r.who.c_str(), r.res,
                   r.adaptivity, r.tris, r.err.mean_rel, r.err.hausdorff_rel, r.err.near_normal_deg,
                   r.topo.boundary_edges, r.topo.nonmanifold_edges, r.topo.unbalanced_edges, r.self_intersections,
                   r.pareto ? 1 : 0, r.pareto_clean ? 1 : 0, r.ms);
    std::fclose(f);
    std::printf("\ncsv: %s\n", csv_path.c_str());
  }
  const char* vdb_colours[] = {"#bbbbbb", "#888888", "#555555", "#222222", "#000000"};
  std::map<std::string, std::vector<ldc::bench::PlotSeries>> per_mesh;
  std::map<std::string, std::map<int, ldc::bench::PlotSeries>> vdb;
  for (const AdaptiveRow& r : rows) {
    if (r.who == "ldc") {
      auto& s = per_mesh[r.mesh];
      if (s.empty()) s.push_back({"ldc remesh (default)", "#d62728", {}, false});
      s[0].points.push_back({double(r.tris), r.err.mean_rel});
    } else {
      auto& s = vdb[r.mesh][r.res];
      s.name = "vdb N=" + std::to_string(r.res);
      s.dashed = true;
      s.points.push_back({double(r.tris), r.err.mean_rel});
    }
  }
  for (auto& [mesh, by_res] : vdb) {
    size_t i = 0;
    for (auto& [res, s] : by_res) {
      s.colour = vdb_colours[std::min<size_t>(i++, 4)];
      per_mesh[mesh].push_back(s);
    }
  }
  for (const auto& [mesh, series] : per_mesh) {
    std::string path = dir + "/contour_adaptive_" + mesh.substr(0, mesh.find('.')) + ".svg";
    ldc::bench::write_loglog_svg(path,
                                 "Adaptive remesh " + mesh + ": triangles against error (vdb: adaptivity 0 .. 1)",
                                 "triangles", "mean distance / diagonal", series);
    std::printf("plot: %s\n", path.c_str());
  }
}

void print_adaptive_notes(const std::vector<AdaptiveRow>& rows) {
  std::set<int> ldc_n, vdb_n;
  for (const AdaptiveRow& r : rows) (r.who == "ldc" ? ldc_n : vdb_n).insert(r.res);
  auto list = [](const std::set<int>& v) {
    std::string t;
    for (int n : v) t += (t.empty() ? "" : ", ") + std::to_string(n);
    return t;
  };
  std::printf("\nldc N: %s; OpenVDB N: %s.\n", list(ldc_n).c_str(), list(vdb_n).c_str());
  std::printf(
      "\nNotes: ldc rows are the remesh as `ldc remesh` runs it by default (tools/mesh_output.cpp, mesh_world): "
      "build_from_mesh at h = diagonal / N (the tool's default grid is --cells along the longest axis instead), "
      "surface_levels at a tenth of the bound and, where surface_levels_pay_off says so, contour_levels at those "
      "levels (otherwise contour_world), with iterative placement and without the local untangling round, "
      "simplify_mesh within %.1f h (the default --max-error), then untangle_mesh; \"ldc tris before simplifying\" "
      "is the count before simplify_mesh (the uniform mesh where one level was kept). "
      "OpenVDB rows: meshToLevelSet (half width 3 voxels) at h = diagonal / N, then volumeToMesh(isovalue 0, "
      "adaptivity) with relaxDisorientedTriangles on (the default), quads split into two triangles and re-wound "
      "outward, at the N listed above (by default N, 2N and 4N of every ldc N; one front per mesh from all of them). Errors from bench/meshdist (200k samples per surface, "
      "symmetric mean and sampled Hausdorff distance over the input's diagonal), against the input (the bunny after "
      "CGAL hole filling). \"closed (welded)\": ldc::mesh_topology with vertices welded by position, no boundary, "
      "non-manifold or unbalanced edge; self-intersecting triangle pairs counted by CGAL. "
      "Interpolation: per mesh, OpenVDB's front is the set of its points (all N and adaptivities) that no other "
      "OpenVDB point beats with both lower-or-equal mean error and fewer triangles; along it, sorted by mean error, "
      "triangles fall. For ldc's mean error e, the two front points with e_a <= e < e_b give OpenVDB's triangles "
      "T = exp(log T_a + (log e - log e_a) / (log e_b - log e_a) * (log T_b - log T_a)), i.e. linear in log "
      "triangles against log error. Between measured settings OpenVDB's true front may lie below that line, so "
      "\"ldc / T_b\" also divides ldc's triangles by T_b, the triangles of the bracketing OpenVDB point that is "
      "less accurate than ldc (a comparison that favours OpenVDB). The second summary table does the same with OpenVDB's front built only "
      "from its outputs with no self-intersecting pair (ldc's outputs have none: untangle_mesh). \"not reached\": e is below the most accurate OpenVDB point measured (no "
      "extrapolation); \"<= T\": e is at or above the least accurate front point, whose triangles are then an "
      "upper bound. Times are one run each on a shared, busy machine (2 threads): not comparable, not the point.\n",
      kRemeshMaxErrorCells);
}

}  // namespace

int main(int argc, char** argv) {
  std::string plots = "docs";
  bool plots_given = false, adaptive_only = false, no_adaptive = false;
  std::vector<int> adaptive_res, vdb_res;
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--plots" && i + 1 < argc) plots = argv[++i], plots_given = true;
    else if (a == "--adaptive-only") adaptive_only = true;
    else if (a == "--no-adaptive") no_adaptive = true;
    else if (a == "--adaptive-n" && i + 1 < argc) {
      std::stringstream list(argv[++i]);
      for (std::string n; std::getline(list, n, ',');) adaptive_res.push_back(std::stoi(n));
    } else if (a == "--vdb-n" && i + 1 < argc) {
      std::stringstream list(argv[++i]);
      for (std::string n; std::getline(list, n, ',');) vdb_res.push_back(std::stoi(n));
    } else rest.push_back(argv[i]);
  }
  ldc::bench::Args args = ldc::bench::parse_args(int(rest.size()), rest.data(),
                                                 {"fandisk.obj", "rocker-arm.obj", "spot.obj", "stanford-bunny.obj"});
  if (adaptive_res.empty()) adaptive_res = args.quick ? std::vector<int>{64, 128} : std::vector<int>{64, 128, 256};
  openvdb::initialize();
  ldc::bench::print_machine();
  std::vector<int> resolutions = args.quick ? std::vector<int>{64, 128} : std::vector<int>{64, 128, 256, 512};
  std::vector<Row> rows;
  std::vector<AdaptiveRow> adaptive_rows;
  for (const std::string& file : args.meshes) {
    ldc::TriangleMesh in = ldc::bench::load(args, file);
    std::string name = file;
    if (file == "stanford-bunny.obj") {  // measured closed, as the peers are
      size_t holes = 0;
      in = ldc::bench::fill_holes(in, &holes);
      name = "stanford-bunny-filled.obj";
      std::fprintf(stderr, "  filled %zu holes in the bunny\n", holes);
    }
    if (!adaptive_only) {
      for (int res : resolutions) {
        int reps = args.quick ? 2 : (res >= 512 ? 2 : res >= 256 ? 3 : 5);
        for (const Method& m : methods()) rows.push_back(measure(name, in, m, res, reps));
        std::fprintf(stderr, "  %s %d done\n", name.c_str(), res);
      }
    }
    if (!no_adaptive) {
      std::vector<AdaptiveRow> a = measure_adaptive(name, in, adaptive_res, vdb_res);
      adaptive_rows.insert(adaptive_rows.end(), a.begin(), a.end());
    }
  }
  if (!adaptive_only) {
    print_rows(rows);
    print_targets(rows);
    write_plots(rows, plots);
    std::printf("\nNotes: median wall time of repeated runs of the whole remesh (mesh in memory -> mesh in memory), "
                "1 and 2 threads. Errors from bench/meshdist (200k samples per surface, CGAL AABB trees), against the "
                "input mesh (the bunny after CGAL hole filling). OpenVDB polygons are re-wound outward before measuring. "
                "Self-intersecting triangle pairs counted by CGAL.\n");
  }
  if (!no_adaptive) {
    print_adaptive_rows(adaptive_rows);
    print_adaptive_summary(adaptive_rows, false);
    print_adaptive_summary(adaptive_rows, true);
    if (plots_given) write_adaptive_outputs(adaptive_rows, plots);  // CSV and plots only where asked
    print_adaptive_notes(adaptive_rows);
  }
  return 0;
}
