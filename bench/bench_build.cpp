// Build benchmark: LDC from a triangle mesh against OpenVDB's meshToLevelSet at
// the same cell size, in the same run, 1 and 2 threads; memory of both; and the
// accuracy of the stored points (depth and normal against the exact mesh, via CGAL).
//
// Usage: bench_build [--quick] [--meshes a.obj,b.obj] [--data DIR]
// Prints markdown tables on stdout.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/global_control.h>

#include "bench_common.h"
#include "ldc/build.h"

namespace {

using ldc::bench::median_ms;

struct VdbInput {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
};

VdbInput to_vdb(const ldc::TriangleMesh& m) {
  VdbInput in;
  for (const auto& p : m.positions) in.points.emplace_back(float(p.x), float(p.y), float(p.z));
  for (const auto& t : m.triangles) in.triangles.emplace_back(t[0], t[1], t[2]);
  return in;
}

openvdb::FloatGrid::Ptr vdb_level_set(const VdbInput& in, double h) {
  auto xform = openvdb::math::Transform::createLinearTransform(h);
  std::vector<openvdb::Vec4I> quads;
  return openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, in.points, in.triangles, quads, 3.0f);
}

struct Row {
  std::string mesh;
  int cells = 0;
  double h = 0;
  double ours_ms[2] = {0, 0}, vdb_ms[2] = {0, 0};
  size_t ours_bytes = 0, vdb_bytes = 0, points = 0, repaired = 0;
  bool valid = false;
};

Row run_one(const std::string& name, const ldc::TriangleMesh& mesh, const VdbInput& vin, int cells, int reps) {
  Row r;
  r.mesh = name;
  r.cells = cells;
  ldc::MeshBounds b = ldc::mesh_bounds(mesh);
  glm::dvec3 e = b.extent();
  r.h = std::max(e.x, std::max(e.y, e.z)) / cells;
  ldc::GridConfig grid;
  grid.cells = cells;
  for (int t = 0; t < 2; ++t) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(t + 1));
    r.ours_ms[t] = median_ms(reps, [&] { (void)ldc::build_from_mesh(mesh, grid); });
    r.vdb_ms[t] = median_ms(reps, [&] { (void)vdb_level_set(vin, r.h); });
  }
  ldc::BuildReport report;
  ldc::World w = ldc::build_from_mesh(mesh, grid, nullptr, &report).value();
  ldc::WorldStats s = w.stats();
  r.ours_bytes = s.memory_bytes;
  r.points = s.points;
  r.repaired = report.repaired_rays;
  r.valid = ldc::validate(w).ok;
  r.vdb_bytes = vdb_level_set(vin, r.h)->memUsage();
  return r;
}

void print_build_table(const std::vector<Row>& rows) {
  std::printf("\n### Build: LDC vs OpenVDB meshToLevelSet (half width 3), same cell size\n\n");
  std::printf("| mesh | cells | h | LDC ms 1t | LDC ms 2t | VDB ms 1t | VDB ms 2t | speed-up 1t | speed-up 2t "
              "| LDC MiB | VDB MiB | memory ratio | points | bytes/point | repaired rays | valid |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    std::printf("| %s | %d | %.3g | %.2f | %.2f | %.1f | %.1f | %.1fx | %.1fx | %.2f | %.2f | %.2f | %zu | %.2f | %zu | %s |\n",
                r.mesh.c_str(), r.cells, r.h, r.ours_ms[0], r.ours_ms[1], r.vdb_ms[0], r.vdb_ms[1],
                r.vdb_ms[0] / r.ours_ms[0], r.vdb_ms[1] / r.ours_ms[1], r.ours_bytes / 1048576.0,
                r.vdb_bytes / 1048576.0, double(r.ours_bytes) / double(r.vdb_bytes), r.points,
                double(r.ours_bytes) / double(std::max<size_t>(r.points, 1)), r.repaired, r.valid ? "yes" : "NO");
  }
}

}  // namespace

int main(int argc, char** argv) {
  ldc::bench::Args args = ldc::bench::parse_args(argc, argv, {"stanford-bunny.obj", "fandisk.obj", "rocker-arm.obj", "spot.obj"});
  openvdb::initialize();
  ldc::bench::print_machine();
  std::vector<int> resolutions = args.quick ? std::vector<int>{64, 128} : std::vector<int>{64, 128, 256, 512};
  std::vector<Row> rows;
  if (args.accuracy_only) {
    ldc::bench::print_accuracy(args, {128, 256});
    return 0;
  }
  for (const std::string& name : args.meshes) {
    ldc::TriangleMesh mesh = ldc::bench::load(args, name);
    VdbInput vin = to_vdb(mesh);
    for (int cells : resolutions) {
      int reps = cells >= 512 ? 3 : (cells >= 256 ? 5 : 9);
      if (args.quick) reps = 3;
      rows.push_back(run_one(name, mesh, vin, cells, reps));
      std::fprintf(stderr, "  %s %d done\n", name.c_str(), cells);
    }
  }
  print_build_table(rows);
  if (!args.quick) ldc::bench::print_accuracy(args, {128, 256});
  std::printf("\nNotes: median wall time of repeated runs, inputs in memory, file I/O excluded. "
              "LDC memory = everything the World holds; VDB memory = FloatGrid::memUsage(). "
              "OpenVDB's level set of the open stanford-bunny loses its interior (see PEERS.md); its time is still "
              "a fair measure of the build cost.\n");
  return 0;
}
