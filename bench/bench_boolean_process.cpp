// Mesh booleans as users run them: whole processes, from start to file
// written, on the boolean cases of shared/PEERS.md (bench/boolean_cases.h).
//
// The inputs are written once as plain OBJ files (v and f lines, shortest
// round-trip doubles) into a work folder; then, for each case and op, each
// command is run as a process (posix_spawn, stdout and stderr to log files),
// timed by wall clock from spawn to exit, best of --reps (3):
//   - ldc:  ldc --threads T -q boolean A B --op OP --cells N -o out.obj [ARGS]
//           for N in --cells (64,128,256; --full adds 512) and each --ldc-args
//           variant;
//   - CGAL: cgal_boolean A B --op OP -o out.obj (bench/cgal_boolean_cmd.cpp:
//           CGAL IO, Surface_mesh<Epick>, corefine_and_compute_*; 1 thread);
//   - Manifold native: manifold_boolean ... --threads T (built only with
//           -Dmanifold_DIR=...; skipped otherwise);
//   - manifold-3d (WASM, 1 thread): node bench/js/manifold_boolean.mjs ...
//           (skipped when bench/js/node_modules has no manifold-3d).
// Every output file is then read back by CGAL as a polygon soup
// (bench/mesh_validity.h): triangles, non-manifold edges and vertices, whether
// it is a valid polygon mesh and closed, self-intersecting pairs; and compared
// with CGAL's result by bench/meshdist (mean and Hausdorff distance, divided
// by the bounding-box diagonal of A). Prints a markdown table per case, the
// issue-19 targets at the largest N <= 256, the phase times the peers report,
// and writes bool_process.csv and per case an SVG of error against time and
// one of error against triangles into --plots.
//
// Usage: bench_boolean_process [--cells 64,128,256] [--full] [--reps 3] [--threads 2]
//          [--cases a,b] [--ops subtract,union,intersect] [--ldc-args "ARGS"]...
//          [--plots DIR] [--work DIR] [--keep] [--data DIR]
//          [--ldc PATH] [--cgal PATH] [--manifold PATH] [--node PATH] [--js DIR]
//          [--no-manifold] [--no-node]
#include <spawn.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bench_common.h"
#include "boolean_cases.h"
#include "mesh_validity.h"
#include "meshdist.h"
#include "svg_plot.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using ldc::TriangleMesh;

#ifndef LDC_TOOL_PATH
#define LDC_TOOL_PATH ""
#endif
#ifndef CGAL_BOOLEAN_PATH
#define CGAL_BOOLEAN_PATH ""
#endif
#ifndef MANIFOLD_BOOLEAN_PATH
#define MANIFOLD_BOOLEAN_PATH ""
#endif
#ifndef LDC_TOOL_ASSERTS
#define LDC_TOOL_ASSERTS "?"
#endif
#ifndef LDC_BENCH_JS_DIR
#define LDC_BENCH_JS_DIR ""
#endif

// --- Processes ---------------------------------------------------------------------

struct RunResult {
  bool ok = false;
  std::string status = "ok";
  double best_s = 0;
  std::vector<double> times_s;
  std::string stdout_text, stderr_text;  // of the best run
};

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string last_line(const std::string& text) {
  size_t end = text.find_last_not_of("\r\n ");
  if (end == std::string::npos) return "";
  size_t start = text.find_last_of('\n', end);
  return text.substr(start == std::string::npos ? 0 : start + 1, end + 1 - (start == std::string::npos ? 0 : start + 1));
}

// One process: wall seconds from posix_spawn to waitpid, or -1 if it could not
// start; *code gets the exit status (128 + signal when killed).
double spawn_timed(const std::vector<std::string>& argv, const std::string& out_log, const std::string& err_log,
                   int* code) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, out_log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, err_log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const auto t0 = std::chrono::steady_clock::now();
  int rc = posix_spawnp(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    *code = -1;
    return -1;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  const auto t1 = std::chrono::steady_clock::now();
  *code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return std::chrono::duration<double>(t1 - t0).count();
}

// One more run of a command into `r` (best time and that run's output kept).
// The output file is removed first (outside the timer), so every run creates
// it afresh. A failed run marks `r` failed; a failed command is not run again.
void run_once(const std::vector<std::string>& argv, const std::string& output, RunResult& r) {
  if (!r.status.starts_with("ok")) return;
  const std::string out_log = output + ".stdout", err_log = output + ".stderr";
  std::error_code ec;
  fs::remove(output, ec);
  int code = 0;
  double s = spawn_timed(argv, out_log, err_log, &code);
  if (s < 0 || code != 0 || !fs::exists(output)) {
    r.ok = false;
    std::string msg = last_line(read_text(err_log));
    if (msg.empty()) msg = last_line(read_text(out_log));
    r.status = s < 0 ? "could not start " + argv[0]
                     : "failed (exit " + std::to_string(code) + (msg.empty() ? "" : ": " + msg.substr(0, 160)) + ")";
    return;
  }
  r.times_s.push_back(s);
  if (r.times_s.size() == 1 || s < r.best_s) {
    r.best_s = s;
    r.stdout_text = read_text(out_log);
    r.stderr_text = read_text(err_log);
  }
  r.ok = true;
}

// --- Inputs -----------------------------------------------------------------------

bool write_plain_obj(const TriangleMesh& m, const std::string& path) {
  std::string text;
  text.reserve(m.positions.size() * 80 + m.triangles.size() * 30);
  char buf[40];
  for (const glm::dvec3& p : m.positions) {
    text += 'v';
    for (int k = 0; k < 3; ++k) {
      text += ' ';
      text.append(buf, std::to_chars(buf, buf + sizeof buf, p[k]).ptr);
    }
    text += '\n';
  }
  for (const glm::uvec3& t : m.triangles) {
    text += 'f';
    for (int k = 0; k < 3; ++k) {
      text += ' ';
      text.append(buf, std::to_chars(buf, buf + sizeof buf, t[k] + 1).ptr);
    }
    text += '\n';
  }
  std::ofstream out(path, std::ios::binary);
  out.write(text.data(), std::streamsize(text.size()));
  return bool(out);
}

// --- Measurements -----------------------------------------------------------------

struct Row {
  std::string case_name, op, tool, variant;  // tool: ldc, cgal, manifold, manifold-3d
  int cells = 0;                             // ldc only
  int threads = 1;
  RunResult run;
  ldc::bench::MeshValidity v;
  bool checked = false;
  bool has_err = false;
  double mean_rel = 0, haus_rel = 0;  // against CGAL's result, over A's diagonal
  double tri_ratio = 0;               // triangles / CGAL's triangles
  std::string out_path;
};

std::string label(const Row& r) {
  std::string s = r.tool;
  if (!r.variant.empty()) s += " " + r.variant;
  return s;
}

// A number from a flat JSON object printed by the peers ("key": value).
double json_number(const std::string& text, const std::string& key) {
  size_t at = text.find("\"" + key + "\"");
  if (at == std::string::npos) return NAN;
  at = text.find(':', at);
  if (at == std::string::npos) return NAN;
  return std::strtod(text.c_str() + at + 1, nullptr);
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

struct Options {
  std::vector<int> cells = {64, 128, 256};
  int reps = 3, threads = 2;
  std::vector<std::string> cases, ops = {"subtract", "union", "intersect"};
  std::vector<std::string> ldc_variants;  // extra ldc arguments, one variant each ("" = defaults)
  std::string plots = "docs", work, data = LDC_BENCH_DATA_DIR;
  std::string ldc = LDC_TOOL_PATH, cgal = CGAL_BOOLEAN_PATH, manifold = MANIFOLD_BOOLEAN_PATH, node = "node",
              js = LDC_BENCH_JS_DIR;
  bool keep = false, use_manifold = true, use_node = true;
};

std::vector<std::string> split_args(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string w; std::getline(in, w, ',');)
    if (!w.empty()) out.push_back(w);
  return out;
}

void measure_output(Row& r, const TriangleMesh* reference, size_t reference_tris, double diag_a) {
  if (!r.run.ok) return;
  r.v = ldc::bench::check_mesh_file(r.out_path);
  r.checked = r.v.read;
  if (!r.v.read) {
    r.run.status = "output unreadable: " + r.v.error;
    return;
  }
  if (reference_tris) r.tri_ratio = double(r.v.triangles) / double(reference_tris);
  if (reference && r.tool != "cgal" && !r.v.mesh.triangles.empty()) {
    ldc::bench::MeshDistResult e = ldc::bench::mesh_distance(r.v.mesh, *reference);
    if (e.status.ok()) {
      r.has_err = true;
      r.mean_rel = e.mean_rel * e.diagonal / diag_a;
      r.haus_rel = e.hausdorff_rel * e.diagonal / diag_a;
    }
  } else if (r.tool == "cgal") {
    r.has_err = true;  // the reference itself
  }
}

// --- Tables -----------------------------------------------------------------------

void print_case_table(const std::string& name, const std::vector<Row>& rows, int reps) {
  std::printf("\n### %s\n\n", name.c_str());
  std::printf("| op | tool | cells | threads | s (best of %d) | x CGAL time | triangles | tris / CGAL | mean rel | Haus rel "
              "| NM edges | NM verts | SI pairs | valid mesh | closed |\n",
              reps);
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    if (r.case_name != name) continue;
    const Row* cgal = nullptr;
    for (const Row& c : rows)
      if (c.case_name == r.case_name && c.op == r.op && c.tool == "cgal" && c.run.ok) cgal = &c;
    std::string cells = r.cells ? std::to_string(r.cells) : "—";
    if (!r.run.ok) {
      std::printf("| %s | %s | %s | %d | %s | — | — | — | — | — | — | — | — | — | — |\n", r.op.c_str(), label(r).c_str(),
                  cells.c_str(), r.threads, r.run.status.c_str());
      continue;
    }
    std::string x = cgal ? fmt("%.2f", r.run.best_s / cgal->run.best_s) : "—";
    std::string tris = r.checked ? std::to_string(r.v.triangles) : "—";
    std::string ratio = r.checked && r.tri_ratio > 0 ? fmt("%.2f", r.tri_ratio) : "—";
    std::string mean = r.tool == "cgal" ? "(reference)" : r.has_err ? fmt("%.2e", r.mean_rel) : "—";
    std::string haus = r.tool == "cgal" ? "(reference)" : r.has_err ? fmt("%.2e", r.haus_rel) : "—";
    std::string nme = r.checked ? std::to_string(r.v.nonmanifold_edges) : "—";
    std::string nmv = r.checked ? std::to_string(r.v.nonmanifold_vertices) : "—";
    std::string si = r.checked ? std::to_string(r.v.self_intersections) + (r.v.pairwise ? "*" : "") : "—";
    std::string valid = !r.checked ? "—" : r.v.valid ? "yes" : r.v.polygon_mesh ? "NO" : "NO (not a polygon mesh)";
    std::string closed = !r.checked ? "—"
                         : r.v.closed ? (r.v.polygon_mesh ? "yes" : "yes (after split)")
                                      : "NO (" + std::to_string(r.v.border_cycles) + " border cycles" +
                                            (r.v.polygon_mesh ? "" : " after split") + ")";
    std::printf("| %s | %s | %s | %d | %.3f | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", r.op.c_str(),
                label(r).c_str(), cells.c_str(), r.threads, r.run.best_s, x.c_str(), tris.c_str(), ratio.c_str(),
                mean.c_str(), haus.c_str(), nme.c_str(), nmv.c_str(), si.c_str(), valid.c_str(), closed.c_str());
  }
}

const Row* find_row(const std::vector<Row>& rows, const std::string& c, const std::string& op, const std::string& tool,
                    int cells = 0, const std::string& variant = "") {
  for (const Row& r : rows)
    if (r.case_name == c && r.op == op && r.tool == tool && r.cells == cells && r.variant == variant) return &r;
  return nullptr;
}

void print_targets(const std::vector<Row>& rows, const std::vector<std::string>& cases, const Options& o) {
  int n = 0;
  for (int c : o.cells)
    if (c <= 256) n = std::max(n, c);
  if (n == 0) return;
  std::printf("\n### Issue 19 targets at %d cells (ldc whole process against the peers' whole processes)\n\n", n);
  std::printf("| case | op | ldc | ldc / CGAL time (<= 0.5) | ldc / Manifold time (<= 1) | tris / CGAL (<= 2) "
              "| mean rel (<= 3e-5) | NM edges + verts (0) | SI pairs (0) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  int met[6] = {0, 0, 0, 0, 0, 0}, total[6] = {0, 0, 0, 0, 0, 0};
  auto mark = [&](int k, bool ok) {
    ++total[k];
    met[k] += ok;
    return ok ? " yes" : " **no**";
  };
  const std::vector<std::string> variants = o.ldc_variants.empty() ? std::vector<std::string>{""} : o.ldc_variants;
  for (const std::string& c : cases)
    for (const std::string& op : o.ops)
      for (const std::string& var : variants) {
        const Row* l = find_row(rows, c, op, "ldc", n, var);
        const Row* cg = find_row(rows, c, op, "cgal");
        const Row* mf = find_row(rows, c, op, "manifold");
        if (!l) continue;
        std::string cells[6];
        for (auto& s : cells) s = "—";
        if (l->run.ok && cg && cg->run.ok) {
          double q = l->run.best_s / cg->run.best_s;
          cells[0] = fmt("%.2f", q) + mark(0, q <= 0.5);
        }
        if (l->run.ok && mf && mf->run.ok) {
          double q = l->run.best_s / mf->run.best_s;
          cells[1] = fmt("%.2f", q) + mark(1, q <= 1.0);
        }
        if (l->checked && l->tri_ratio > 0) cells[2] = fmt("%.2f", l->tri_ratio) + mark(2, l->tri_ratio <= 2.0);
        if (l->has_err) cells[3] = fmt("%.2e", l->mean_rel) + mark(3, l->mean_rel <= 3e-5);
        if (l->checked) {
          size_t nm = l->v.nonmanifold_edges + l->v.nonmanifold_vertices;
          cells[4] = std::to_string(nm) + mark(4, nm == 0);
          cells[5] = std::to_string(l->v.self_intersections) + mark(5, l->v.self_intersections == 0);
        }
        if (!l->run.ok) cells[0] = l->run.status;
        std::printf("| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", c.c_str(), op.c_str(),
                    var.empty() ? "defaults" : var.c_str(), cells[0].c_str(), cells[1].c_str(), cells[2].c_str(),
                    cells[3].c_str(), cells[4].c_str(), cells[5].c_str());
      }
  std::printf("\nMet: time <= 0.5x CGAL %d/%d; time <= native Manifold %d/%d; triangles <= 2x CGAL %d/%d; "
              "mean rel <= 3e-5 %d/%d; no non-manifold simplices %d/%d; no self-intersections %d/%d.\n",
              met[0], total[0], met[1], total[1], met[2], total[2], met[3], total[3], met[4], total[4], met[5], total[5]);
}

void print_phases(const std::vector<Row>& rows) {
  auto is_peer = [](const Row& r) { return r.tool == "cgal" || r.tool == "manifold" || r.tool == "manifold-3d"; };
  bool any = false;
  for (const Row& r : rows) any |= r.run.ok && is_peer(r);
  if (!any) return;
  std::printf("\n### Phases the peer commands report (ms, of the best run)\n\n");
  std::printf("| case | op | tool | whole process | node module | load | construct | boolean | write |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    if (!r.run.ok || !is_peer(r)) continue;
    const std::string& j = r.tool == "manifold-3d" ? r.run.stdout_text : r.run.stderr_text;
    auto cell = [&](const char* key) {
      double v = json_number(j, key);
      return std::isnan(v) ? std::string("—") : fmt("%.1f", v);
    };
    std::printf("| %s | %s | %s | %.1f | %s | %s | %s | %s | %s |\n", r.case_name.c_str(), r.op.c_str(), r.tool.c_str(),
                1000 * r.run.best_s, cell("module_ms").c_str(), cell("load_ms").c_str(), cell("construct_ms").c_str(),
                cell("boolean_ms").c_str(), (r.tool == "manifold-3d" ? cell("export_ms") : cell("write_ms")).c_str());
  }
  std::printf("\n(CGAL: load = both OBJ files into Surface_mesh, boolean = corefine_and_compute_*. Manifold: construct = "
              "the two Manifolds from MeshGL; boolean = the op and GetMeshGL (native) or the op and numTri() (WASM); "
              "write = getMesh, OBJ text and the file for the WASM build.)\n");
}

// Seconds `ldc` reports for a phase on its own line ("  contour: 0.352 s").
double ldc_phase(const std::string& text, const std::string& phase) {
  size_t at = text.find("\n  " + phase + ": ");
  if (at == std::string::npos) return NAN;
  return std::strtod(text.c_str() + at + phase.size() + 5, nullptr);
}

void print_ldc_phases(const std::vector<Row>& rows) {
  const std::vector<std::string> phases = {"load",     "build_boolean", "surface_levels", "contour",
                                           "simplify", "untangle",      "quality",        "export"};
  std::printf("\n### Phases `ldc boolean` reports (s, of the best run; rest = the process outside them: start-up, "
              "exit, anything not timed)\n\n");
  std::printf("| case | op | ldc | cells | whole process |");
  for (const std::string& p : phases) std::printf(" %s |", p.c_str());
  std::printf(" rest |\n|---|---|---|---|---|");
  for (size_t k = 0; k < phases.size(); ++k) std::printf("---|");
  std::printf("---|\n");
  for (const Row& r : rows) {
    if (!r.run.ok || r.tool != "ldc") continue;
    std::printf("| %s | %s | %s | %d | %.3f |", r.case_name.c_str(), r.op.c_str(),
                r.variant.empty() ? "defaults" : r.variant.c_str(), r.cells, r.run.best_s);
    double sum = 0;
    for (const std::string& p : phases) {
      double v = ldc_phase(r.run.stdout_text, p);
      std::printf(" %s |", std::isnan(v) ? "—" : fmt("%.3f", v).c_str());
      if (!std::isnan(v)) sum += v;
    }
    std::printf(" %.3f |\n", r.run.best_s - sum);
  }
}

void write_csv(const std::vector<Row>& rows, const std::string& path) {
  std::ofstream out(path);
  out << "case,op,tool,variant,cells,threads,status,best_s,runs_s,triangles,tris_over_cgal,mean_rel,haus_rel,"
         "nm_edges,nm_vertices,si_pairs,si_pairwise,degenerate,polygon_mesh,valid,closed,border_cycles\n";
  for (const Row& r : rows) {
    std::string runs;
    for (double t : r.run.times_s) runs += (runs.empty() ? "" : ";") + fmt("%.4f", t);
    std::string status = r.run.status;
    std::replace(status.begin(), status.end(), '"', '\'');
    out << r.case_name << ',' << r.op << ',' << r.tool << ",\"" << r.variant << "\"," << r.cells << ',' << r.threads
        << ",\"" << status << "\"," << (r.run.ok ? fmt("%.4f", r.run.best_s) : "") << ',' << runs << ',';
    if (r.checked)
      out << r.v.triangles << ',' << fmt("%.4f", r.tri_ratio) << ','
          << (r.has_err && r.tool != "cgal" ? fmt("%.4e", r.mean_rel) : r.tool == "cgal" ? "0" : "") << ','
          << (r.has_err && r.tool != "cgal" ? fmt("%.4e", r.haus_rel) : r.tool == "cgal" ? "0" : "") << ','
          << r.v.nonmanifold_edges << ',' << r.v.nonmanifold_vertices << ',' << r.v.self_intersections << ','
          << (r.v.pairwise ? 1 : 0) << ',' << r.v.degenerate << ',' << (r.v.polygon_mesh ? 1 : 0) << ','
          << (r.v.valid ? 1 : 0) << ',' << (r.v.closed ? 1 : 0) << ',' << r.v.border_cycles << '\n';
    else
      out << ",,,,,,,,,,,,\n";
  }
  std::printf("\ncsv: %s\n", path.c_str());
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void write_plots(const std::vector<Row>& rows, const std::vector<std::string>& cases, const Options& o) {
  const std::map<std::string, std::string> colour = {
      {"subtract", "#d62728"}, {"union", "#1f77b4"}, {"intersect", "#2ca02c"}};
  const std::vector<std::string> variants = o.ldc_variants.empty() ? std::vector<std::string>{""} : o.ldc_variants;
  for (int axis = 0; axis < 2; ++axis) {  // 0: error against time, 1: error against triangles
    for (const std::string& c : cases) {
      std::vector<ldc::bench::PlotSeries> series;
      double y0 = 1e300, y1 = 0;
      auto x_of = [&](const Row& r) { return axis == 0 ? r.run.best_s : double(r.v.triangles); };
      for (const std::string& op : o.ops) {
        for (size_t vi = 0; vi < variants.size(); ++vi) {
          ldc::bench::PlotSeries s;
          s.name = "ldc " + op + (variants[vi].empty() ? "" : " " + variants[vi]);
          s.colour = colour.count(op) ? colour.at(op) : "#000000";
          s.dashed = vi > 0;
          for (const Row& r : rows)
            if (r.case_name == c && r.op == op && r.tool == "ldc" && r.variant == variants[vi] && r.has_err &&
                r.mean_rel > 0) {
              s.points.push_back({x_of(r), r.mean_rel});
              y0 = std::min(y0, r.mean_rel), y1 = std::max(y1, r.mean_rel);
            }
          if (!s.points.empty()) series.push_back(s);
        }
        // The Manifold builds (a colour per build): float positions, so a small error against CGAL's doubles.
        for (const char* tool : {"manifold", "manifold-3d"}) {
          const Row* r = find_row(rows, c, op, tool);
          if (r && r->has_err && r->mean_rel > 0) {
            series.push_back({std::string(tool == std::string("manifold") ? "Manifold native " : "manifold-3d WASM ") + op,
                              tool == std::string("manifold") ? "#9467bd" : "#8c564b", {{x_of(*r), r->mean_rel}},
                              tool != std::string("manifold")});
            y0 = std::min(y0, r->mean_rel), y1 = std::max(y1, r->mean_rel);
          }
        }
      }
      // CGAL is the reference (error 0): a vertical line at its median over the ops.
      std::vector<double> xs;
      for (const Row& r : rows)
        if (r.case_name == c && r.tool == "cgal" && r.run.ok && r.checked) xs.push_back(x_of(r));
      if (!xs.empty() && y1 > 0) series.push_back({"CGAL (reference, 1t)", "#000000", {{median(xs), y0}, {median(xs), y1}}, true});
      const std::string path = o.plots + "/bool_process_" + c + (axis == 0 ? "_time" : "_tris") + ".svg";
      bool ok = ldc::bench::write_loglog_svg(
          path, "Boolean " + c + (axis == 0 ? ": error against whole-process time" : ": error against triangles"),
          axis == 0 ? "whole process, best of " + std::to_string(o.reps) + " [s]" : "output triangles",
          "mean distance to CGAL / diag(A)", series);
      std::printf("plot: %s%s\n", path.c_str(), ok ? "" : " (not written)");
    }
  }
}

// The 1-minute load average: the timings are wall clock on a shared machine.
std::string load_average() {
  std::string s = read_text("/proc/loadavg");
  return s.substr(0, s.find(' '));
}

int usage(const char* argv0) {
  std::fprintf(stderr,
               "usage: %s [--cells 64,128,256] [--full] [--reps 3] [--threads 2] [--cases a,b] "
               "[--ops subtract,union,intersect] [--ldc-args \"ARGS\"]... [--plots DIR] [--work DIR] [--keep] "
               "[--data DIR] [--ldc PATH] [--cgal PATH] [--manifold PATH] [--node PATH] [--js DIR] [--no-manifold] "
               "[--no-node]\n",
               argv0);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  bool full = false;
  for (int i = 1; i < argc; ++i) {
    std::string s = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (s == "--cells") {
      o.cells.clear();
      for (const std::string& c : split_list(next())) o.cells.push_back(std::atoi(c.c_str()));
    } else if (s == "--full") full = true;
    else if (s == "--reps") o.reps = std::max(1, std::atoi(next().c_str()));
    else if (s == "--threads") o.threads = std::max(0, std::atoi(next().c_str()));
    else if (s == "--cases") o.cases = split_list(next());
    else if (s == "--ops") o.ops = split_list(next());
    else if (s == "--ldc-args") o.ldc_variants.push_back(next());
    else if (s == "--plots") o.plots = next();
    else if (s == "--work") o.work = next();
    else if (s == "--keep") o.keep = true;
    else if (s == "--data") o.data = next();
    else if (s == "--ldc") o.ldc = next();
    else if (s == "--cgal") o.cgal = next();
    else if (s == "--manifold") o.manifold = next();
    else if (s == "--node") o.node = next();
    else if (s == "--js") o.js = next();
    else if (s == "--no-manifold") o.use_manifold = false;
    else if (s == "--no-node") o.use_node = false;
    else return usage(argv[0]);
  }
  if (full && std::find(o.cells.begin(), o.cells.end(), 512) == o.cells.end()) o.cells.push_back(512);
  for (const std::string& op : o.ops)
    if (op != "subtract" && op != "union" && op != "intersect") return usage(argv[0]);
  if (o.ldc.empty() || !fs::exists(o.ldc)) {
    std::fprintf(stderr, "bench_boolean_process: the ldc tool was not found (%s); give --ldc PATH\n", o.ldc.c_str());
    return 1;
  }
  if (o.cgal.empty() || !fs::exists(o.cgal)) {
    std::fprintf(stderr, "bench_boolean_process: cgal_boolean was not found (%s); give --cgal PATH\n", o.cgal.c_str());
    return 1;
  }
  std::string manifold_note, node_note;
  if (!o.use_manifold) manifold_note = "skipped (--no-manifold)";
  else if (o.manifold.empty() || !fs::exists(o.manifold))
    manifold_note = "not built (configure with -Dmanifold_DIR=PREFIX/lib/cmake/manifold after "
                    "`bash ../shared/peers/build-manifold.sh PREFIX`)";
  const std::string js_script = o.js + "/manifold_boolean.mjs";
  if (!o.use_node) node_note = "skipped (--no-node)";
  else if (!fs::exists(o.js + "/node_modules/manifold-3d/package.json"))
    node_note = "skipped: no " + o.js + "/node_modules/manifold-3d (run `npm ci` in bench/js)";
  else {
    int code = 0;
    const std::string probe = (fs::temp_directory_path() / "ldc_bench_node_probe").string();
    if (spawn_timed({o.node, "--version"}, probe, probe + ".err", &code) < 0 || code != 0)
      node_note = "skipped: `" + o.node + " --version` failed";
    std::string version = last_line(read_text(probe));
    std::error_code ec;
    fs::remove(probe, ec), fs::remove(probe + ".err", ec);
    if (node_note.empty()) node_note = "node " + version;
  }
  if (!manifold_note.empty()) std::fprintf(stderr, "native Manifold: %s\n", manifold_note.c_str());
  std::fprintf(stderr, "manifold-3d: %s\n", node_note.c_str());
  const bool have_manifold = manifold_note.empty();
  const bool have_node = node_note.rfind("node ", 0) == 0;

  // The work folder.
  bool made_work = false;
  if (o.work.empty()) {
    std::string tmpl = (fs::temp_directory_path() / "ldc-bool-XXXXXX").string();
    if (!mkdtemp(tmpl.data())) {
      std::perror("mkdtemp");
      return 1;
    }
    o.work = tmpl;
    made_work = true;
  } else {
    fs::create_directories(o.work);
  }
  fs::create_directories(o.plots);

  ldc::bench::print_machine();
  std::printf("- load average (1 min) at the start: %s\n", load_average().c_str());
  std::vector<ldc::bench::BooleanCase> cases = ldc::bench::make_boolean_cases(o.data, o.cases, false);
  std::printf("\n### Inputs (shared/PEERS.md cases, written once as plain OBJ, read by every command)\n\n");
  std::printf("| case | A tris | B tris | A diag | A.obj bytes | B.obj bytes |\n|---|---|---|---|---|---|\n");
  std::vector<std::string> case_names;
  for (const auto& c : cases) {
    const std::string a = o.work + "/" + c.name + "_A.obj", b = o.work + "/" + c.name + "_B.obj";
    if (!write_plain_obj(c.a, a) || !write_plain_obj(c.b, b)) {
      std::fprintf(stderr, "cannot write the inputs into %s\n", o.work.c_str());
      return 1;
    }
    case_names.push_back(c.name);
    std::printf("| %s | %zu | %zu | %.4g | %ju | %ju |\n", c.name.c_str(), c.a.triangles.size(), c.b.triangles.size(),
                c.diag, uintmax_t(fs::file_size(a)), uintmax_t(fs::file_size(b)));
  }

  const std::vector<std::string> variants = o.ldc_variants.empty() ? std::vector<std::string>{""} : o.ldc_variants;
  const std::string threads = std::to_string(o.threads);
  std::vector<Row> rows;
  for (const auto& c : cases) {
    const std::string a = o.work + "/" + c.name + "_A.obj", b = o.work + "/" + c.name + "_B.obj";
    for (const std::string& op : o.ops) {
      const auto t0 = std::chrono::steady_clock::now();
      const std::string stem = o.work + "/" + c.name + "_" + op;
      std::vector<Row> here;
      std::vector<std::vector<std::string>> commands;
      auto add = [&](const std::string& tool, const std::string& variant, int cells, int nthreads,
                     const std::vector<std::string>& cmd, const std::string& out) {
        Row r;
        r.case_name = c.name, r.op = op, r.tool = tool, r.variant = variant, r.cells = cells, r.threads = nthreads;
        r.out_path = out;
        here.push_back(std::move(r));
        commands.push_back(cmd);
      };
      add("cgal", "", 0, 1, {o.cgal, a, b, "--op", op, "-o", stem + "_cgal.obj"}, stem + "_cgal.obj");
      for (size_t vi = 0; vi < variants.size(); ++vi)
        for (int n : o.cells) {
          const std::string out = stem + "_ldc" + std::to_string(vi) + "_" + std::to_string(n) + ".obj";
          std::vector<std::string> cmd = {o.ldc, "--threads", threads, "-q", "boolean", a, b, "--op", op,
                                          "--cells", std::to_string(n), "-o", out};
          for (const std::string& w : split_args(variants[vi])) cmd.push_back(w);
          add("ldc", variants[vi], n, o.threads, cmd, out);
        }
      if (have_manifold)
        add("manifold", "", 0, o.threads,
            {o.manifold, a, b, "--op", op, "-o", stem + "_manifold.obj", "--threads", threads}, stem + "_manifold.obj");
      if (have_node)
        add("manifold-3d", "", 0, 1, {o.node, js_script, a, b, "--op", op, "-o", stem + "_manifold3d.obj"},
            stem + "_manifold3d.obj");
      // Round robin: repetition k of every command before repetition k + 1 of any,
      // so a burst of load on the machine does not fall on one tool's runs only.
      for (int rep = 0; rep < o.reps; ++rep)
        for (size_t i = 0; i < here.size(); ++i) run_once(commands[i], here[i].out_path, here[i].run);
      for (const Row& r : here)
        std::fprintf(stderr, "  %s %s %s%s%s: %s\n", c.name.c_str(), op.c_str(), r.tool.c_str(),
                     r.cells ? (" " + std::to_string(r.cells)).c_str() : "",
                     r.variant.empty() ? "" : (" " + r.variant).c_str(),
                     r.run.ok ? fmt("%.3f s", r.run.best_s).c_str() : r.run.status.c_str());

      // Read every output back; CGAL's result is the reference.
      Row& cgal = here.front();
      measure_output(cgal, nullptr, 0, c.diag);
      const TriangleMesh* reference = cgal.checked ? &cgal.v.mesh : nullptr;
      const size_t reference_tris = cgal.checked ? cgal.v.triangles : 0;
      if (cgal.checked) cgal.tri_ratio = 1.0;
      for (size_t i = 1; i < here.size(); ++i) measure_output(here[i], reference, reference_tris, c.diag);
      for (Row& r : here) {
        r.v.mesh = {};  // the meshes are not needed any more
        rows.push_back(std::move(r));
      }
      std::fprintf(stderr, "%s %s done in %.0f s\n", c.name.c_str(), op.c_str(),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      if (!o.keep) {
        std::error_code ec;
        for (const auto& entry : fs::directory_iterator(o.work))
          if (entry.path().filename().string().rfind(c.name + "_" + op + "_", 0) == 0) fs::remove(entry.path(), ec);
      }
    }
  }

  std::printf("- load average (1 min) at the end: %s\n", load_average().c_str());
  for (const std::string& name : case_names) print_case_table(name, rows, o.reps);
  print_targets(rows, case_names, o);
  print_phases(rows);
  print_ldc_phases(rows);
  write_csv(rows, o.plots + "/bool_process.csv");
  write_plots(rows, case_names, o);
  std::printf(
      "\nNotes: every figure is one whole process, from spawn to exit (file written), wall clock, best of %d, in the "
      "same run on the same input files (plain OBJ, v and f lines); the repetitions go round robin over the commands "
      "of a case and op. ldc = `ldc --threads %d -q boolean A B --op OP "
      "--cells N -o out.obj` (N cells along the longest axis of the joint bounds; defaults otherwise%s), built with "
      "the project's flags (asserts %s). CGAL = bench/cgal_boolean_cmd.cpp (CGAL::IO::read_polygon_mesh, "
      "Surface_mesh<Epick>, corefine_and_compute_*, write_polygon_mesh at 17 digits; NDEBUG), 1 thread. Manifold "
      "native = bench/manifold_boolean_cmd.cpp (ldc's OBJ reader, MeshGL float, Merge, a-b / a+b / a^b, GetMeshGL, "
      "plain OBJ writer; TBB capped at %d threads): %s. manifold-3d = node bench/js/manifold_boolean.mjs (WASM, 1 "
      "thread, including node start and module instantiation): %s. Errors: bench/meshdist (200k samples per surface) "
      "of the output against CGAL's output, symmetric mean and sampled Hausdorff distance over diag(A). Validity: "
      "the output file read by CGAL as a polygon soup (bench/mesh_validity.h): NM = non-manifold edges and vertices "
      "counted on the soup before orienting (orient_polygon_soup's visitor); SI pairs = PMP::self_intersections "
      "(* = counted pair by pair, because a Surface_mesh refuses some faces); valid = is_polygon_soup_a_polygon_mesh "
      "and is_valid_polygon_mesh; closed = CGAL::is_closed (after orient_polygon_soup splits non-manifold vertices "
      "where the soup is not a polygon mesh). Work folder: %s%s.\n",
      o.reps, o.threads, o.ldc_variants.empty() ? "" : "; variants add the arguments shown",
      LDC_TOOL_ASSERTS,
      o.threads, have_manifold ? "built" : manifold_note.c_str(), node_note.c_str(), o.work.c_str(),
      o.keep ? " (kept)" : " (removed)");
  if (!o.keep && made_work) {
    std::error_code ec;
    fs::remove_all(o.work, ec);
  }
  return 0;
}
