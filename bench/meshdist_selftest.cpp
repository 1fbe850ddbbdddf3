// Self-test of the benchmarks' surface-error measure (meshdist) on cubes whose
// answers are known in closed form. Exits non-zero on a failed check.
//
// Usage: meshdist_selftest [mesh.obj [near_sharp_distance]]
//   With a mesh, also times it against itself and prints the figures.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <tbb/global_control.h>

#include "meshdist.h"
#include "meshio/meshio.h"

namespace {

using ldc::TriangleMesh;
using ldc::bench::MeshDistOptions;
using ldc::bench::MeshDistResult;
using ldc::bench::mesh_distance;

int failures = 0;

void expect(bool ok, const char* what, double value) {
  std::printf("  %-4s %-58s %.6g\n", ok ? "ok" : "FAIL", what, value);
  failures += !ok;
}

// Axis-aligned cube [lo, lo + size]^3, outward and counter-clockwise. Every
// face has its own 4 corners (nothing welded), so the sharp-edge count also
// checks that meshdist welds by position. Each face is split along a diagonal.
TriangleMesh cube(double lo, double size) {
  TriangleMesh m;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // e_u x e_v = e_axis
      const unsigned base = unsigned(m.positions.size());
      const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (const auto& c : corner) {
        glm::dvec3 p(lo);
        p[axis] += side * size;
        p[u] += c[0] * size;
        p[v] += c[1] * size;
        m.positions.push_back(p);
      }
      if (side == 1) {
        m.triangles.push_back({base, base + 1, base + 2});
        m.triangles.push_back({base, base + 2, base + 3});
      } else {  // the low side faces -axis: reverse the winding
        m.triangles.push_back({base, base + 2, base + 1});
        m.triangles.push_back({base, base + 3, base + 2});
      }
    }
  }
  return m;
}

TriangleMesh inverted(TriangleMesh m) {
  for (glm::uvec3& t : m.triangles) std::swap(t.y, t.z);
  return m;
}

void print(const char* name, const MeshDistResult& r) {
  std::printf("%s: diag %.6g mean_rel %.4g haus_rel %.4g normal %.4g deg over10 %.3g%% sharp %zu near %.3g%% "
              "near_normal %.4g near_over10 %.3g%% away %.4g vol %.6g\n",
              name, r.diagonal, r.mean_rel, r.hausdorff_rel, r.normal_mean_deg, 100 * r.normal_over10,
              r.sharp_edges, 100 * r.near_fraction, r.near_normal_deg, 100 * r.near_over10, r.away_normal_deg,
              r.volume_ratio);
}

// A cube against itself: no distance, no normal error, 12 sharp edges, and a
// near band of width w covers 1 - (1 - 2w)^2 of each unit face.
void cube_against_itself() {
  std::printf("cube against itself\n");
  MeshDistOptions o;
  o.near_sharp_distance = 0.02;
  const MeshDistResult r = mesh_distance(cube(0, 1), cube(0, 1), o);
  print("  ", r);
  expect(r.status.ok(), "status ok", 0);
  expect(r.mean_rel < 1e-9, "mean_rel < 1e-9", r.mean_rel);
  expect(r.hausdorff_rel < 1e-9, "hausdorff_rel < 1e-9", r.hausdorff_rel);
  expect(r.normal_mean_deg < 1e-6, "normal_mean_deg ~ 0", r.normal_mean_deg);
  expect(r.normal_over10 == 0, "normal_over10 == 0", r.normal_over10);
  expect(r.sharp_edges == 12, "sharp_edges == 12 (face diagonals are not sharp)", double(r.sharp_edges));
  const double band = 1 - 0.96 * 0.96;
  expect(std::abs(r.near_fraction - band) < 0.003, "near_fraction ~ 1 - 0.96^2 = 0.0784", r.near_fraction);
  expect(std::abs(r.volume_ratio - 1) < 1e-12, "volume_ratio == 1", r.volume_ratio);
}

// A cube scaled by 1.01 about its centre against the unit cube: faces 0.005
// apart, so mean distance ~0.005 (a little more in the edge bands), Hausdorff
// 0.005*sqrt(3) at the corners; volume 1.01^3. In the edge band of the big
// cube the closest point is on a unit-cube edge, where either face may be
// taken: that is the measurement's edge ambiguity, reported here.
void scaled_cube() {
  std::printf("cube scaled by 1.01 about its centre against the unit cube\n");
  MeshDistOptions o;
  o.near_sharp_distance = 0.02;
  const MeshDistResult r = mesh_distance(cube(-0.005, 1.01), cube(0, 1), o);
  print("  ", r);
  const double exact = 0.005 / std::sqrt(3.0);
  expect(std::abs(r.mean_rel / exact - 1) < 0.01, "mean_rel within 1% of 0.005/sqrt(3) = 2.887e-3", r.mean_rel);
  expect(r.hausdorff_rel <= 0.005 + 1e-12 && r.hausdorff_rel > 0.0045, "hausdorff_rel in (0.0045, 0.005]",
         r.hausdorff_rel);
  expect(std::abs(r.volume_ratio - 1.030301) < 1e-9, "volume_ratio == 1.01^3", r.volume_ratio);
  const double edge_band = 4 * 0.005 / 1.01;  // share of the big cube's faces beyond the unit cube's edges
  expect(r.normal_over10 < edge_band, "normal_over10 below the edge-band share 1.98%", r.normal_over10);
  expect(r.away_normal_deg < 1e-6, "away_normal_deg ~ 0 (no ambiguity away from edges)", r.away_normal_deg);
  std::printf("  edge ambiguity: %.3g%% of samples over 10 deg (%.3g%% of the near band), mean %.3g deg overall\n",
              100 * r.normal_over10, 100 * r.near_over10, r.normal_mean_deg);
}

// An inverted cube reads 180 degrees everywhere and has negative volume.
void inverted_cube() {
  std::printf("inverted cube against the cube\n");
  const MeshDistResult r = mesh_distance(inverted(cube(0, 1)), cube(0, 1));
  print("  ", r);
  expect(std::abs(r.normal_mean_deg - 180) < 1e-6, "normal_mean_deg ~ 180", r.normal_mean_deg);
  expect(r.normal_over10 == 1, "normal_over10 == 1", r.normal_over10);
  expect(std::abs(r.volume_ratio + 1) < 1e-12, "volume_ratio == -1", r.volume_ratio);
}

bool same(const MeshDistResult& a, const MeshDistResult& b) {
  return a.mean_rel == b.mean_rel && a.hausdorff_rel == b.hausdorff_rel && a.normal_mean_deg == b.normal_mean_deg &&
         a.normal_over10 == b.normal_over10 && a.near_fraction == b.near_fraction &&
         a.near_normal_deg == b.near_normal_deg && a.away_normal_deg == b.away_normal_deg;
}

// The same inputs give the same figures with 1 thread and with all of them.
void same_result_any_thread_count() {
  std::printf("determinism across thread counts\n");
  MeshDistOptions o;
  o.near_sharp_distance = 0.02;
  const MeshDistResult all = mesh_distance(cube(-0.005, 1.01), cube(0, 1), o);
  MeshDistResult one;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = mesh_distance(cube(-0.005, 1.01), cube(0, 1), o);
  }
  expect(same(all, one), "1 thread == all threads, bit for bit", all.mean_rel - one.mean_rel);
}

// Bad options and empty meshes give an error status, not a crash.
void bad_inputs_are_refused() {
  std::printf("bad inputs\n");
  MeshDistOptions o;
  o.samples = 0;
  expect(!mesh_distance(cube(0, 1), cube(0, 1), o).status.ok(), "samples = 0 refused", 0);
  o = {};
  o.near_sharp_distance = -1;
  expect(!mesh_distance(cube(0, 1), cube(0, 1), o).status.ok(), "negative near_sharp_distance refused", 0);
  expect(!mesh_distance(TriangleMesh{}, cube(0, 1)).status.ok(), "empty test mesh refused", 0);
  TriangleMesh bad = cube(0, 1);
  bad.triangles[0].x = 99;
  expect(!mesh_distance(cube(0, 1), bad).status.ok(), "out-of-range index refused", 0);
}

// Times a mesh against itself (the figures should be ~0 but for edge ties).
int time_mesh(const std::string& path, double near) {
  auto loaded = ldc::load_mesh(path);
  if (!loaded.ok()) {
    std::fprintf(stderr, "%s\n", loaded.status().to_string().c_str());
    return 1;
  }
  MeshDistOptions o;
  o.near_sharp_distance = near;
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const auto start = std::chrono::steady_clock::now();
    const MeshDistResult r = mesh_distance(loaded.value(), loaded.value(), o);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::printf("%s against itself, %d thread(s), %zu tris: %.0f ms\n", path.c_str(), threads,
                loaded.value().triangle_count(), ms);
    print("  ", r);
    if (!r.status.ok()) return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cube_against_itself();
  scaled_cube();
  inverted_cube();
  same_result_any_thread_count();
  bad_inputs_are_refused();
  if (argc > 1 && time_mesh(argv[1], argc > 2 ? std::atof(argv[2]) : 0.0) != 0) return 1;
  std::printf(failures ? "%d check(s) FAILED\n" : "all checks passed\n", failures);
  return failures ? 1 : 0;
}
