// Mesh booleans (A - B, A u B, A n B) on the cases of shared/PEERS.md:
// ldc (mesh_boolean -> contour_world -> to_triangle_mesh, timed as a whole
// from the two meshes in memory to the output mesh) against CGAL
// corefinement (Epick and Epeck kernels; the Epeck result is the reference
// geometry) and OpenVDB level sets (meshToLevelSet -> csg -> volumeToMesh) at
// the same cell size h = diag(A) / N, in the same run. Times with 1 and 2
// threads; errors by bench/meshdist against the CGAL Epeck result; closedness
// and self-intersections of the ldc output. Writes an SVG of time against
// error per case into the folder given by --plots (default docs/).
//
// Usage: bench_csg [--quick] [--plots DIR] [--cases a,b] [--data DIR]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "bench_common.h"
#include "boolean_cases.h"
#include "contour/contour.h"
#include "meshio/meshio.h"
#include "csg/csg.h"
#include "csg_peers.h"
#include "ldc/build.h"
#include "meshdist.h"
#include "svg_plot.h"

namespace {

using ldc::BooleanOp;
using ldc::TriangleMesh;

const BooleanOp kOps[] = {BooleanOp::kSubtract, BooleanOp::kUnion, BooleanOp::kIntersect};

const char* op_name(BooleanOp op) { return ldc::boolean_op_name(op); }

// --- Inputs (PEERS.md "Booleans": primitives generated, not read; bench/boolean_cases.h) ---

using Case = ldc::bench::BooleanCase;

std::vector<Case> make_cases(const std::string& data, const std::vector<std::string>& only) {
  return ldc::bench::make_boolean_cases(data, only);
}

// --- Measurements -----------------------------------------------------------------

struct Row {
  std::string case_name, method, status = "ok", ref = "cgal-epeck";
  BooleanOp op = BooleanOp::kUnion;
  int res = 0;  // 0: CGAL (no lattice)
  double h = 0, ms[2] = {-1, -1};
  bool ok = true;      // a result exists
  bool invalid = false;  // a result exists but is known garbage (VDB on the open bunny)
  size_t tris = 0;
  int closed = -1;                // -1 not checked
  long self_intersections = -1;   // -1 not counted
  bool has_err = false;
  ldc::bench::MeshDistResult err;
};

// Median wall time of `reps` runs; the output of the last run is kept (its
// destruction is outside the timer, the pipeline's own temporaries inside).
double time_runs(int reps, const std::function<TriangleMesh()>& fn, TriangleMesh* keep) {
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    auto a = std::chrono::steady_clock::now();
    TriangleMesh out = fn();
    auto b = std::chrono::steady_clock::now();
    t.push_back(std::chrono::duration<double, std::milli>(b - a).count());
    if (i + 1 == reps) *keep = std::move(out);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

std::string ldc_error;  // the first failure of the ldc pipeline, if any

TriangleMesh ldc_boolean(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op, double h) {
  ldc::GridConfig grid;
  grid.cell_size = h;
  ldc::Result<ldc::World> w = ldc::mesh_boolean(a, b, op, grid);
  if (!w.ok()) {
    if (ldc_error.empty()) ldc_error = "mesh_boolean: " + w.status().to_string();
    return {};
  }
  ldc::Result<ldc::ContourMesh> m = ldc::contour_world(w.value());
  if (!m.ok()) {
    if (ldc_error.empty()) ldc_error = "contour_world: " + m.status().to_string();
    return {};
  }
  return ldc::to_triangle_mesh(m.value());
}

void add_error(Row& r, const TriangleMesh& out, const TriangleMesh* reference, double near_sharp) {
  if (!reference || out.triangles.empty()) return;
  ldc::bench::MeshDistOptions o;
  o.near_sharp_distance = near_sharp;
  r.err = ldc::bench::mesh_distance(out, *reference, o);
  r.has_err = r.err.status.ok();
}

Row measure_lattice(const Case& c, BooleanOp op, const std::string& method, int res, int reps,
                    const TriangleMesh* reference, const std::string& ref_name, bool count_self) {
  Row r;
  r.case_name = c.name;
  r.method = method;
  r.op = op;
  r.res = res;
  r.h = c.diag / res;
  r.ref = ref_name;
  auto run = [&]() -> TriangleMesh {
    return method == "ldc" ? ldc_boolean(c.a, c.b, op, r.h) : ldc::bench::vdb_boolean(c.a, c.b, op, r.h);
  };
  TriangleMesh out;
  ldc_error.clear();
  for (int t = 0; t < 2; ++t) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(t + 1));
    r.ms[t] = time_runs(reps, run, &out);
  }
  if (!ldc_error.empty()) {
    r.ok = false;
    r.status = "failed: " + ldc_error;
    return r;
  }
  r.tris = out.triangles.size();
  if (r.tris == 0) {
    r.ok = false;
    r.status = "empty output";
    return r;
  }
  r.closed = ldc::mesh_topology(out).closed() ? 1 : 0;
  if (method == "vdb" && c.open_input) {
    r.invalid = true;
    r.status = "INVALID: open input leaks (PEERS.md)";
  }
  add_error(r, out, reference, 2.0 * r.h);
  if (count_self) r.self_intersections = long(ldc::bench::self_intersections(out));
  return r;
}

// --- Tables ---------------------------------------------------------------------

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

void print_inputs(const std::vector<Case>& cases) {
  std::printf("\n### Inputs (generated as shared/PEERS.md defines them)\n\n");
  std::printf("| case | A tris | B tris | PEERS.md A / B tris | match | A diag | A closed | B closed | B volume |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const Case& c : cases) {
    bool match = c.a.triangles.size() == c.expect_a && c.b.triangles.size() == c.expect_b;
    std::printf("| %s | %zu | %zu | %zu / %zu | %s | %.4g | %s | %s | %.4g |\n", c.name.c_str(), c.a.triangles.size(),
                c.b.triangles.size(), c.expect_a, c.expect_b, match ? "yes" : "NO", c.diag,
                ldc::mesh_topology(c.a).closed() ? "yes" : "no", ldc::mesh_topology(c.b).closed() ? "yes" : "no",
                ldc::mesh_signed_volume(c.b));
  }
}

void print_rows(const std::vector<Row>& rows) {
  std::printf("\n### All runs (h = diag(A) / N; errors against the CGAL Epeck result)\n\n");
  std::printf("| case | op | N | h | method | status | ms 1t | ms 2t | tris | closed | self-int pairs | mean rel | Haus rel "
              "| normal mean deg | n>10deg | near-sharp normal deg | vol out/ref | reference |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    const auto& e = r.err;
    std::string n = r.res ? std::to_string(r.res) : "—";
    std::string h = r.res ? fmt("%.3g", r.h) : "—";
    std::string ms1 = r.ok && r.ms[0] >= 0 ? fmt("%.1f", r.ms[0]) : "—";
    std::string ms2 = r.ok && r.ms[1] >= 0 ? fmt("%.1f", r.ms[1]) : "—";
    std::string tris = r.ok ? std::to_string(r.tris) : "—";
    std::string closed = r.closed < 0 ? "—" : r.closed ? "yes" : "NO";
    std::string self = r.self_intersections < 0 ? "—" : std::to_string(r.self_intersections);
    std::string mean = r.has_err ? fmt("%.2e", e.mean_rel) : "—";
    std::string haus = r.has_err ? fmt("%.2e", e.hausdorff_rel) : "—";
    std::string nm = r.has_err ? fmt("%.2f", e.normal_mean_deg) : "—";
    std::string n10 = r.has_err ? fmt("%.1f%%", 100 * e.normal_over10) : "—";
    std::string ns = r.has_err && r.res && e.near_fraction > 0 ? fmt("%.2f", e.near_normal_deg) : "—";
    std::string vol = r.has_err ? fmt("%.4f", e.volume_ratio) : "—";
    std::printf("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n",
                r.case_name.c_str(), op_name(r.op), n.c_str(), h.c_str(), r.method.c_str(), r.status.c_str(),
                ms1.c_str(), ms2.c_str(), tris.c_str(), closed.c_str(), self.c_str(), mean.c_str(), haus.c_str(),
                nm.c_str(), n10.c_str(), ns.c_str(), vol.c_str(), r.has_err ? r.ref.c_str() : "—");
  }
}

const Row* find(const std::vector<Row>& rows, const std::string& c, BooleanOp op, const std::string& method, int res) {
  for (const Row& r : rows)
    if (r.case_name == c && r.op == op && r.method == method && r.res == res) return &r;
  return nullptr;
}

struct Tally {
  int met = 0, total = 0;
  std::string yes(bool ok, bool counted) {
    if (counted) ++total, met += ok;
    return ok ? "yes" : "no";
  }
  std::string str() const { return std::to_string(met) + "/" + std::to_string(total); }
};

void print_targets(const std::vector<Row>& rows, const std::vector<Case>& cases, const std::vector<int>& res) {
  std::printf("\n### Targets per case, op and N (the issue states them at N = 256)\n\n");
  std::printf("Time ratios use the 2-thread ldc pipeline; CGAL is single-threaded. VDB ratios at the same h. "
              "`yes`/`no` is printed at every N; the tally below counts N = 256 only.\n\n");
  std::printf("| case | op | N | ldc mean rel | <= 3e-4 | ldc 2t / CGAL Epick | < 1 | ldc 2t / CGAL Epeck | < 1 "
              "| ldc / VDB time 2t | <= 0.1 | ldc / VDB mean err | <= 1 |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  Tally err, epick, epeck, vtime, verr;
  for (const Case& c : cases)
    for (BooleanOp op : kOps)
      for (int n : res) {
        const Row* l = find(rows, c.name, op, "ldc", n);
        const Row* v = find(rows, c.name, op, "vdb", n);
        const Row* ck = find(rows, c.name, op, "cgal-epick", 0);
        const Row* ce = find(rows, c.name, op, "cgal-epeck", 0);
        if (!l) continue;
        const bool at = n == 256;
        std::string cells[10];
        for (auto& s : cells) s = "—";
        if (l->ok && l->has_err) {
          cells[0] = fmt("%.2e", l->err.mean_rel) + (c.reference_case.empty() ? "" : " (vs filled)");
          cells[1] = err.yes(l->err.mean_rel <= 3e-4, at);
        }
        if (l->ok && ck && ck->ok) {
          double q = l->ms[1] / ck->ms[0];
          cells[2] = fmt("%.2f", q), cells[3] = epick.yes(q < 1, at);
        } else if (ck) {
          cells[2] = "CGAL failed";
        }
        if (l->ok && ce && ce->ok) {
          double q = l->ms[1] / ce->ms[0];
          cells[4] = fmt("%.2f", q), cells[5] = epeck.yes(q < 1, at);
        } else if (ce) {
          cells[4] = "CGAL failed";
        }
        if (l->ok && v && v->ok) {
          double q = l->ms[1] / v->ms[1];
          cells[6] = fmt("%.3f", q), cells[7] = vtime.yes(q <= 0.1, at && !v->invalid);
          if (l->has_err && v->has_err) {
            double e = l->err.mean_rel / v->err.mean_rel;
            cells[8] = fmt("%.2f", e), cells[9] = verr.yes(e <= 1, at && !v->invalid);
          }
          if (v->invalid) cells[6] += " (VDB invalid)", cells[8] += " (VDB invalid)";
        }
        std::printf("| %s | %s | %d | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", c.name.c_str(), op_name(op),
                    n, cells[0].c_str(), cells[1].c_str(), cells[2].c_str(), cells[3].c_str(), cells[4].c_str(),
                    cells[5].c_str(), cells[6].c_str(), cells[7].c_str(), cells[8].c_str(), cells[9].c_str());
      }
  std::printf("\nTargets met at N = 256 (runs with a valid peer): mean error <= 3e-4: %s; faster than CGAL Epick: %s; "
              "faster than CGAL Epeck: %s; VDB >= 10x slower: %s; ldc error <= VDB error: %s.\n",
              err.str().c_str(), epick.str().c_str(), epeck.str().c_str(), vtime.str().c_str(), verr.str().c_str());
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// As PEERS.md's "run-time vs error curve": medians over the closed cases' runs.
void print_summary(const std::vector<Row>& rows, const std::vector<int>& res) {
  std::printf("\n### Medians over the case x op runs with a CGAL reference (the raw bunny left out)\n\n");
  std::printf("| N | ldc ms 1t | ldc ms 2t | ldc tris | ldc mean rel | ldc Haus rel | ldc normal deg | VDB ms 1t | VDB ms 2t "
              "| VDB tris | VDB mean rel | VDB Haus rel | VDB normal deg |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int n : res) {
    std::vector<double> v[2][6];
    for (const Row& r : rows) {
      if (r.res != n || !r.ok || !r.has_err || r.ref != "cgal-epeck") continue;
      int m = r.method == "ldc" ? 0 : 1;
      v[m][0].push_back(r.ms[0]), v[m][1].push_back(r.ms[1]), v[m][2].push_back(double(r.tris));
      v[m][3].push_back(r.err.mean_rel), v[m][4].push_back(r.err.hausdorff_rel), v[m][5].push_back(r.err.normal_mean_deg);
    }
    std::printf("| %d | %.1f | %.1f | %.0f | %.2e | %.2e | %.2f | %.1f | %.1f | %.0f | %.2e | %.2e | %.2f |\n", n,
                median(v[0][0]), median(v[0][1]), median(v[0][2]), median(v[0][3]), median(v[0][4]), median(v[0][5]),
                median(v[1][0]), median(v[1][1]), median(v[1][2]), median(v[1][3]), median(v[1][4]), median(v[1][5]));
  }
  std::vector<double> ck, ce;
  for (const Row& r : rows) {
    if (r.method == "cgal-epick" && r.ok) ck.push_back(r.ms[0]);
    if (r.method == "cgal-epeck" && r.ok) ce.push_back(r.ms[0]);
  }
  std::printf("\nCGAL over the same runs: Epick median %.1f ms (%zu ok runs), Epeck median %.1f ms (%zu ok runs).\n",
              median(ck), ck.size(), median(ce), ce.size());
}

void write_plots(const std::vector<Row>& rows, const std::vector<Case>& cases, const std::string& dir) {
  const char* colour[] = {"#d62728", "#1f77b4", "#2ca02c"};  // difference, union, intersection
  for (const Case& c : cases) {
    std::vector<ldc::bench::PlotSeries> series;
    double y0 = 1e300, y1 = 0;
    for (int m = 0; m < 2; ++m)
      for (int k = 0; k < 3; ++k) {
        ldc::bench::PlotSeries s;
        s.name = std::string(m == 0 ? "ldc " : c.open_input ? "vdb (invalid) " : "vdb ") + op_name(kOps[k]);
        s.colour = colour[k];
        s.dashed = m == 1;
        for (const Row& r : rows)
          if (r.case_name == c.name && r.op == kOps[k] && r.method == (m == 0 ? "ldc" : "vdb") && r.ok && r.has_err &&
              r.err.mean_rel > 0) {
            s.points.push_back({r.ms[1], r.err.mean_rel});
            y0 = std::min(y0, r.err.mean_rel), y1 = std::max(y1, r.err.mean_rel);
          }
        if (!s.points.empty()) series.push_back(s);
      }
    // CGAL is exact (error ~0 against the reference): a vertical line at its
    // time, the median over the three ops.
    for (const char* k : {"cgal-epick", "cgal-epeck"}) {
      std::vector<double> t;
      for (const Row& r : rows)
        if (r.case_name == c.name && r.method == k && r.ok) t.push_back(r.ms[0]);
      if (t.empty() || !(y1 > 0)) continue;
      double x = median(t);
      series.push_back({std::string(k == std::string("cgal-epick") ? "CGAL Epick" : "CGAL Epeck") + " (1t, exact)",
                        "#000000", {{x, y0}, {x, y1}}, k == std::string("cgal-epick")});
    }
    std::string path = dir + "/csg_" + c.name + ".svg";
    bool ok = ldc::bench::write_loglog_svg(path, "Boolean " + c.name + ": time against error (N = 64 .. 512)",
                                           "time, 2 threads [ms]", "mean distance / diagonal (vs CGAL Epeck)", series);
    std::printf("\nplot: %s%s\n", path.c_str(), ok ? "" : " (not written)");
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string plots = "docs", data = LDC_BENCH_DATA_DIR;
  std::vector<std::string> only;
  for (int i = 1; i < argc; ++i) {
    std::string s = argv[i];
    if (s == "--quick") quick = true;
    else if (s == "--plots" && i + 1 < argc) plots = argv[++i];
    else if (s == "--data" && i + 1 < argc) data = argv[++i];
    else if (s == "--cases" && i + 1 < argc) {
      std::stringstream in(argv[++i]);
      for (std::string m; std::getline(in, m, ',');) only.push_back(m);
    } else {
      std::fprintf(stderr, "usage: %s [--quick] [--plots DIR] [--cases a,b] [--data DIR]\n", argv[0]);
      return 2;
    }
  }
  ldc::bench::vdb_initialize();
  ldc::bench::print_machine();
  const std::vector<int> resolutions = quick ? std::vector<int>{64, 128} : std::vector<int>{64, 128, 256, 512};
  const int reps = quick ? 1 : 3;
  std::vector<Case> cases = make_cases(data, only);
  print_inputs(cases);

  std::vector<Row> rows;
  std::map<std::pair<std::string, BooleanOp>, TriangleMesh> references;  // CGAL Epeck results
  for (const Case& c : cases) {
    for (BooleanOp op : kOps) {
      auto t0 = std::chrono::steady_clock::now();
      TriangleMesh epick_mesh;
      for (auto kernel : {ldc::bench::CgalKernel::kEpick, ldc::bench::CgalKernel::kEpeck}) {
        ldc::bench::CgalBooleanResult cr = ldc::bench::cgal_boolean(c.a, c.b, op, kernel, reps);
        Row r;
        r.case_name = c.name;
        r.method = kernel == ldc::bench::CgalKernel::kEpick ? "cgal-epick" : "cgal-epeck";
        r.op = op;
        r.ok = cr.ok;
        r.status = cr.status;
        r.ms[0] = cr.ms;
        r.tris = cr.mesh.triangles.size();
        if (cr.ok) r.closed = ldc::mesh_topology(cr.mesh).closed() ? 1 : 0;
        if (kernel == ldc::bench::CgalKernel::kEpick) epick_mesh = std::move(cr.mesh);
        else if (cr.ok) references[{c.name, op}] = std::move(cr.mesh);
        rows.push_back(std::move(r));
      }
      const std::string ref_case = c.reference_case.empty() ? c.name : c.reference_case;
      auto it = references.find({ref_case, op});
      const TriangleMesh* reference = it == references.end() ? nullptr : &it->second;
      const std::string ref_name = c.reference_case.empty() ? "cgal-epeck" : "cgal-epeck of " + ref_case;
      Row& epick = rows[rows.size() - 2];
      if (epick.ok && it != references.end() && ref_case == c.name) {
        epick.ref = ref_name;
        add_error(epick, epick_mesh, reference, 0.0);
      }
      for (int n : resolutions) {
        rows.push_back(measure_lattice(c, op, "ldc", n, reps, reference, ref_name, n <= 256));
        rows.push_back(measure_lattice(c, op, "vdb", n, reps, reference, ref_name, false));
        std::fprintf(stderr, "  %s %s N=%d: ldc %.1f ms, vdb %.1f ms (2t)\n", c.name.c_str(), op_name(op), n,
                     rows[rows.size() - 2].ms[1], rows.back().ms[1]);
      }
      std::fprintf(stderr, "%s %s done in %.0f s\n", c.name.c_str(), op_name(op),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
  }
  print_rows(rows);
  print_targets(rows, cases, resolutions);
  print_summary(rows, resolutions);
  write_plots(rows, cases, plots);
  std::printf("\nNotes: `ms` = median of %d run(s), wall clock. ldc = mesh_boolean (GridConfig.cell_size = h) -> "
              "contour_world (default ContourConfig) -> to_triangle_mesh, from the two meshes in memory to the output "
              "mesh, 1 and 2 TBB threads; built with asserts on (LDC_ASSERTS). OpenVDB = meshToLevelSet of A and B "
              "(half width 3) -> csgUnion/csgDifference/csgIntersection -> volumeToMesh (iso 0, adaptivity 0), the "
              "whole pipeline, 1 and 2 threads. CGAL = PMP::corefine_and_compute_* alone on fresh Surface_mesh copies, "
              "single thread; the CGAL and OpenVDB code is compiled with NDEBUG, as in PEERS.md. Errors: bench/meshdist "
              "(200k samples per surface) of each output against the CGAL Epeck result of the same case and op "
              "(coordinates rounded to double); `rel` = over the reference result's bounding-box diagonal, as in "
              "PEERS.md; near-sharp = test samples within 2h of a reference edge sharper than 30 degrees. "
              "bunny_sphere_raw (A open): CGAL refuses it, so ldc's output is measured against the CGAL result of "
              "bunny_sphere (the hole-filled bunny); OpenVDB's level set leaks through the holes, its rows are marked "
              "INVALID. Self-intersecting triangle pairs (CGAL) are counted for ldc at N <= 256 only. "
              "`closed` = every edge used equally often in both directions (vertices welded by position).\n",
              reps);
  return 0;
}
