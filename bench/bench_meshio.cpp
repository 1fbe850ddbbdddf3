// Mesh file speed: writing and reading a contoured landscape of about a
// million triangles in every format (meshio/meshio.h), median of 5 runs.
// Usage: bench_meshio [--threads N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "contour/contour.h"
#include "ldc/terrain.h"
#include "meshio/meshio.h"

namespace {

using Clock = std::chrono::steady_clock;

template <class Fn>
double median_seconds(int runs, Fn&& fn) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto start = Clock::now();
    if (!fn()) std::exit(1);
    t.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 0;
  if (argc == 3 && std::strcmp(argv[1], "--threads") == 0) threads = std::atoi(argv[2]);
  tbb::global_control cap(tbb::global_control::max_allowed_parallelism,
                          threads > 0 ? size_t(threads) : size_t(tbb::this_task_arena::max_concurrency()));
  ldc::TerrainConfig terrain;
  terrain.size_x = terrain.size_y = 96.0;  // about a million triangles at h = 0.2 m
  ldc::Result<ldc::World> world = ldc::build_terrain(terrain, 0.2);
  if (!world) return std::fprintf(stderr, "%s\n", world.status().to_string().c_str()), 1;
  ldc::Result<ldc::ContourMesh> mesh = ldc::contour_world(*world);
  if (!mesh) return std::fprintf(stderr, "%s\n", mesh.status().to_string().c_str()), 1;
  const std::string dir = std::filesystem::temp_directory_path() / "ldc_bench_meshio";
  std::filesystem::create_directories(dir);
  std::printf("# bench_meshio: %zu triangles, %zu vertices, %d threads\n\n", mesh->triangle_count(),
              mesh->vertex_count(), tbb::this_task_arena::max_concurrency());
  std::printf("| format | write s | read s | file MB | write M triangles/s |\n|---|---:|---:|---:|---:|\n");
  for (const char* ext : {"obj", "ply", "stl", "off", "glb", "drc"}) {
    const std::string path = dir + "/landscape." + ext;
    const double write = median_seconds(5, [&] { return ldc::save_mesh(*mesh, path).ok(); });
    const double read = median_seconds(5, [&] { return ldc::load_contour_mesh(path).ok(); });
    const double mb = double(std::filesystem::file_size(path)) / 1e6;
    std::printf("| %s | %.3f | %.3f | %.1f | %.2f |\n", ext, write, read, mb,
                double(mesh->triangle_count()) / write / 1e6);
  }
  std::filesystem::remove_all(dir);
  return 0;
}
