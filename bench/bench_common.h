// Helpers shared by the benchmark programs.
#pragma once

#include <algorithm>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "ldc/mesh.h"

namespace ldc::bench {

struct Args {
  bool quick = false;               // fewer resolutions and repetitions
  bool accuracy_only = false;       // skip the timing tables
  std::string data_dir;             // where the meshes are
  std::vector<std::string> meshes;  // file names in data_dir
};

Args parse_args(int argc, char** argv, std::vector<std::string> default_meshes);
TriangleMesh load(const Args& args, const std::string& name);  // exits on failure

// Median wall time of `reps` runs of fn, in milliseconds.
inline double median_ms(int reps, const std::function<void()>& fn) {
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    auto a = std::chrono::steady_clock::now();
    fn();
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// CPU, cores, compiler and date, as a markdown list.
void print_machine();

// The mesh with its holes closed by CGAL's triangulate_hole (bench/holefill.cpp).
TriangleMesh fill_holes(const TriangleMesh& mesh, size_t* holes = nullptr);

// Pairs of triangles that intersect other than at a shared edge or vertex
// (CGAL Polygon_mesh_processing::self_intersections).
size_t self_intersections(const TriangleMesh& mesh);

// Depth and normal error of every stored point against the exact mesh (CGAL
// AABB tree), per mesh and resolution, as a markdown table.
void print_accuracy(const Args& args, const std::vector<int>& resolutions);

}  // namespace ldc::bench
