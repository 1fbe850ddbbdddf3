// A plain CGAL command-line boolean, as a user would write one from CGAL's
// corefinement examples (the peer of `ldc boolean` in bench_boolean_process):
//
//   cgal_boolean A.obj B.obj --op subtract|union|intersect -o out.obj
//
// Reads both meshes into CGAL::Surface_mesh<Epick> with CGAL's IO (OBJ, OFF,
// PLY, STL), runs PMP::corefine_and_compute_difference / union / intersection
// and writes the result with CGAL's IO at full double precision
// (write_polygon_mesh, stream_precision 17). Single thread (CGAL's corefinement
// is sequential). The reader is CGAL::IO::read_polygon_mesh (the soup straight
// into the mesh), or with --repair PMP::IO::read_polygon_mesh, as CGAL's
// corefinement examples read, which also repairs and orients the soup first
// (slower; the inputs here need neither). Prints the phase times as one JSON
// line on stderr. Exit code 0 on success; 1 with a message on stderr when an
// input does not load, is not closed, or the boolean fails; 2 for bad
// arguments. Built with NDEBUG and CGAL_NDEBUG (bench/CMakeLists.txt), a
// Release build as users would ship it.
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/IO/polygon_mesh_io.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;

namespace {

int usage(const char* argv0) {
  std::fprintf(stderr, "usage: %s A.obj B.obj --op subtract|union|intersect -o out.obj [--repair]\n", argv0);
  return 2;
}

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

bool load(const std::string& path, Mesh& mesh, bool repair) {
  const bool read = repair ? PMP::IO::read_polygon_mesh(path, mesh) : CGAL::IO::read_polygon_mesh(path, mesh);
  if (!read || mesh.is_empty()) {
    std::fprintf(stderr, "cgal_boolean: cannot read a polygon mesh from %s\n", path.c_str());
    return false;
  }
  if (!CGAL::is_triangle_mesh(mesh)) PMP::triangulate_faces(mesh);
  if (!CGAL::is_closed(mesh)) {
    std::fprintf(stderr, "cgal_boolean: %s is not closed; corefinement needs closed inputs\n", path.c_str());
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::string in[2], op, out;
  int n_in = 0;
  bool repair = false;
  for (int i = 1; i < argc; ++i) {
    std::string s = argv[i];
    if (s == "--op" && i + 1 < argc) op = argv[++i];
    else if ((s == "-o" || s == "--output") && i + 1 < argc) out = argv[++i];
    else if (s == "--repair") repair = true;
    else if (!s.empty() && s[0] != '-' && n_in < 2) in[n_in++] = s;
    else return usage(argv[0]);
  }
  if (n_in != 2 || out.empty() || (op != "subtract" && op != "union" && op != "intersect")) return usage(argv[0]);

  auto t0 = Clock::now();
  Mesh a, b, result;
  if (!load(in[0], a, repair) || !load(in[1], b, repair)) return 1;
  const double load_ms = ms_since(t0);
  auto t1 = Clock::now();
  bool ok = false;
  try {
    if (op == "subtract") ok = PMP::corefine_and_compute_difference(a, b, result);
    else if (op == "union") ok = PMP::corefine_and_compute_union(a, b, result);
    else ok = PMP::corefine_and_compute_intersection(a, b, result);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cgal_boolean: corefinement threw: %s\n", e.what());
    return 1;
  }
  if (!ok) {
    std::fprintf(stderr, "cgal_boolean: corefine_and_compute_%s failed (the result is not a closed manifold)\n",
                 op == "subtract" ? "difference" : op == "union" ? "union" : "intersection");
    return 1;
  }
  const double boolean_ms = ms_since(t1);
  auto t2 = Clock::now();
  if (!CGAL::IO::write_polygon_mesh(out, result, CGAL::parameters::stream_precision(17))) {
    std::fprintf(stderr, "cgal_boolean: cannot write %s\n", out.c_str());
    return 1;
  }
  const double write_ms = ms_since(t2);
  std::printf("%s: %zu triangles\n", out.c_str(), size_t(result.number_of_faces()));
  std::fprintf(stderr, "{\"load_ms\": %.3f, \"boolean_ms\": %.3f, \"write_ms\": %.3f, \"triangles\": %zu}\n", load_ms,
               boolean_ms, write_ms, size_t(result.number_of_faces()));
  return 0;
}
