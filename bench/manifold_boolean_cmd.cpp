// A plain command-line boolean on native Manifold (C++, TBB), the peer of
// `ldc boolean` in bench_boolean_process. Built only when CMake is given
// -Dmanifold_DIR=PREFIX/lib/cmake/manifold (shared/peers/build-manifold.sh
// builds that prefix; no Manifold code is in this repository).
//
//   manifold_boolean A.obj B.obj --op subtract|union|intersect -o out.obj [--threads N]
//
// Reads both meshes with ldc's mesh reader (meshio: OBJ, PLY, STL, OFF), builds
// a manifold::MeshGL (numProp = 3, float positions, as Manifold's users
// usually do) and calls Merge(), constructs the two Manifolds, computes a - b,
// a + b or a ^ b, takes GetMeshGL() and writes a plain OBJ (v and f lines,
// shortest round-trip floats) in one write. --threads N caps TBB (0 = all
// cores). Prints the phase times on stderr. Exit code 0 on success; 1 with a
// message when an input does not load or is not a manifold, or the result
// has an error; 2 for bad arguments.
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <manifold/manifold.h>
#include <tbb/global_control.h>

#include "meshio/meshio.h"

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Manifold's own ToString is compiled only with MANIFOLD_DEBUG.
std::string error_name(manifold::Manifold::Error e) {
  using E = manifold::Manifold::Error;
  switch (e) {
    case E::NoError: return "no error";
    case E::NonFiniteVertex: return "non-finite vertex";
    case E::NotManifold: return "not manifold";
    case E::VertexOutOfBounds: return "vertex out of bounds";
    case E::ResultTooLarge: return "result too large";
    default: return "error " + std::to_string(int(e));
  }
}

int usage(const char* argv0) {
  std::fprintf(stderr, "usage: %s A.obj B.obj --op subtract|union|intersect -o out.obj [--threads N]\n", argv0);
  return 2;
}

bool load(const std::string& path, manifold::MeshGL& out) {
  ldc::Result<ldc::TriangleMesh> m = ldc::load_mesh(path);
  if (!m.ok()) {
    std::fprintf(stderr, "manifold_boolean: %s\n", m.status().to_string().c_str());
    return false;
  }
  const ldc::TriangleMesh& mesh = m.value();
  out.numProp = 3;
  out.vertProperties.reserve(3 * mesh.positions.size());
  for (const glm::dvec3& p : mesh.positions)
    for (int k = 0; k < 3; ++k) out.vertProperties.push_back(float(p[k]));
  out.triVerts.reserve(3 * mesh.triangles.size());
  for (const glm::uvec3& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) out.triVerts.push_back(t[k]);
  out.Merge();
  return true;
}

bool write_obj(const manifold::MeshGL& mesh, const std::string& path) {
  const size_t nv = mesh.NumVert(), nt = mesh.NumTri();
  std::string text;
  text.resize(nv * 3 * 18 + nt * 3 * 12 + 64);
  char* at = text.data();
  char* const end = text.data() + text.size();
  for (size_t v = 0; v < nv; ++v) {
    *at++ = 'v';
    for (int k = 0; k < 3; ++k) {
      *at++ = ' ';
      at = std::to_chars(at, end, mesh.vertProperties[v * mesh.numProp + k]).ptr;
    }
    *at++ = '\n';
  }
  for (size_t t = 0; t < nt; ++t) {
    *at++ = 'f';
    for (int k = 0; k < 3; ++k) {
      *at++ = ' ';
      at = std::to_chars(at, end, mesh.triVerts[3 * t + k] + 1).ptr;
    }
    *at++ = '\n';
  }
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  const size_t n = size_t(at - text.data());
  const bool ok = std::fwrite(text.data(), 1, n, f) == n;
  return std::fclose(f) == 0 && ok;
}

}  // namespace

int main(int argc, char** argv) {
  std::string in[2], op, out;
  int n_in = 0, threads = 0;
  for (int i = 1; i < argc; ++i) {
    std::string s = argv[i];
    if (s == "--op" && i + 1 < argc) op = argv[++i];
    else if ((s == "-o" || s == "--output") && i + 1 < argc) out = argv[++i];
    else if (s == "--threads" && i + 1 < argc) threads = std::atoi(argv[++i]);
    else if (!s.empty() && s[0] != '-' && n_in < 2) in[n_in++] = s;
    else return usage(argv[0]);
  }
  if (n_in != 2 || out.empty() || threads < 0 || (op != "subtract" && op != "union" && op != "intersect"))
    return usage(argv[0]);
  std::unique_ptr<tbb::global_control> cap;
  if (threads > 0) cap = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

  auto t0 = Clock::now();
  manifold::MeshGL ma, mb;
  if (!load(in[0], ma) || !load(in[1], mb)) return 1;
  const double load_ms = ms_since(t0);

  auto t1 = Clock::now();
  manifold::Manifold a(ma), b(mb);
  for (const auto& [m, path] : {std::pair{&a, &in[0]}, std::pair{&b, &in[1]}})
    if (m->Status() != manifold::Manifold::Error::NoError) {
      std::fprintf(stderr, "manifold_boolean: %s: %s\n", path->c_str(), error_name(m->Status()).c_str());
      return 1;
    }
  const double construct_ms = ms_since(t1);

  auto t2 = Clock::now();
  manifold::Manifold r = op == "subtract" ? a - b : op == "union" ? a + b : a ^ b;
  if (r.Status() != manifold::Manifold::Error::NoError) {
    std::fprintf(stderr, "manifold_boolean: the boolean failed: %s\n", error_name(r.Status()).c_str());
    return 1;
  }
  manifold::MeshGL result = r.GetMeshGL();
  const double boolean_ms = ms_since(t2);

  auto t3 = Clock::now();
  if (!write_obj(result, out)) {
    std::fprintf(stderr, "manifold_boolean: cannot write %s\n", out.c_str());
    return 1;
  }
  const double write_ms = ms_since(t3);
  std::fprintf(stderr, "{\"load_ms\": %.3f, \"construct_ms\": %.3f, \"boolean_ms\": %.3f, \"write_ms\": %.3f, \"triangles\": %zu}\n",
               load_ms, construct_ms, boolean_ms, write_ms, size_t(result.NumTri()));
  return 0;
}
