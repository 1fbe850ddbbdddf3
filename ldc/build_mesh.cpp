// Triangle mesh -> LDC, watertight by exact predicates (see build.h and detail/exact.h).
//
// Stages:
//   1. snap: vertices to fixed point, welded by exact position; zero-area
//      triangles dropped; edge balance decides whether the mesh is closed.
//   2. rasterize (per axis and chunk column): every ray/triangle crossing with
//      its quantized depth, sorted per ray and merged into winding steps.
//   3. votes (open meshes only, per chunk): the six half-ray votes at every node.
//   4. emit (per axis and chunk column): the points of every chunk's rays.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <new>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "ldc/build.h"
#include "ldc/internal/build_common.h"
#include "ldc/detail/mesh_raster.h"
#include "ldc/internal/ray_math.h"

namespace ldc {
namespace detail {
namespace {

// ---------------------------------------------------------------------------
// Stage 1: snap and weld

Status snap_vertices(const TriangleMesh& mesh, const Lattice& lat, SnappedMesh& out,
                     std::vector<uint32_t>& welded_id) {
  const size_t n = mesh.positions.size();
  std::vector<Vec3i> fixed(n);
  const double scale = double(kFixedOne) / lat.cell_size;
  for (size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      double f = (mesh.positions[i][a] - lat.origin[a]) * scale;
      if (!std::isfinite(f) || std::abs(f) > double(kMaxNodeCoordinate) * kFixedOne) {
        return {ErrorCode::kInvalidArgument,
                "mesh: vertex " + std::to_string(i) + " lies outside the lattice range"};
      }
      fixed[i][a] = std::llround(f);
    }
  }
  // Weld: equal fixed-point positions become one vertex.
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
  tbb::parallel_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return fixed[a] < fixed[b]; });
  welded_id.assign(n, 0);
  out.vertices.clear();
  out.unsnapped.clear();
  for (size_t k = 0; k < n; ++k) {
    if (k == 0 || fixed[order[k]] != fixed[order[k - 1]]) {
      out.vertices.push_back(fixed[order[k]]);
      out.unsnapped.push_back((mesh.positions[order[k]] - lat.origin) * scale);
    }
    welded_id[order[k]] = uint32_t(out.vertices.size() - 1);
  }
  return {};
}

// Edge balance on welded triangles: a mesh is closed when every undirected edge
// is used as often in one direction as in the other (then the winding number
// is well defined everywhere). Edges are bucketed by their smaller vertex
// (a counting sort), so this is linear in the triangle count.
void count_open_edges(const std::vector<std::array<uint32_t, 3>>& tris, size_t vertices,
                      BuildReport& report) {
  std::vector<uint32_t> first(vertices + 1, 0);
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e)
      if (t[e] != t[(e + 1) % 3]) ++first[std::min(t[e], t[(e + 1) % 3]) + 1];
  for (size_t v = 0; v < vertices; ++v) first[v + 1] += first[v];
  std::vector<std::pair<uint32_t, int>> other(first[vertices]);  // (larger vertex, +-1)
  std::vector<uint32_t> fill(first.begin(), first.end() - 1);
  for (const auto& t : tris) {
    for (int e = 0; e < 3; ++e) {
      uint32_t a = t[e], b = t[(e + 1) % 3];
      if (a != b) other[fill[std::min(a, b)]++] = {std::max(a, b), a < b ? 1 : -1};
    }
  }
  size_t unbalanced = 0, boundary = 0;
  for (size_t v = 0; v < vertices; ++v) {
    auto begin = other.begin() + first[v], end = other.begin() + first[v + 1];
    std::sort(begin, end);
    for (auto i = begin; i != end;) {
      auto j = i;
      int balance = 0;
      while (j != end && j->first == i->first) balance += (j++)->second;
      unbalanced += balance != 0;
      boundary += (j - i) == 1;
      i = j;
    }
  }
  report.input_closed = unbalanced == 0;
  report.boundary_edges = boundary;
}

Status snap_mesh(const TriangleMesh& mesh, const Lattice& lat, SnappedMesh& out,
                 BuildReport& report) {
  std::vector<uint32_t> welded;
  Status s = snap_vertices(mesh, lat, out, welded);
  if (!s.ok()) return s;
  const size_t n = mesh.triangles.size();
  std::vector<std::array<uint32_t, 3>> all(n);
  std::vector<std::array<i128, 3>> normals(n);
  tbb::parallel_for(size_t{0}, n, [&](size_t t) {
    all[t] = {welded[mesh.triangles[t][0]], welded[mesh.triangles[t][1]], welded[mesh.triangles[t][2]]};
    normals[t] = triangle_normal(out.vertices, all[t]);
  });
  std::vector<uint32_t> kept;
  kept.reserve(n);
  for (size_t t = 0; t < n; ++t) {
    const auto& nv = normals[t];
    if (nv[0] == 0 && nv[1] == 0 && nv[2] == 0) ++report.degenerate_triangles;
    else kept.push_back(uint32_t(t));
  }
  out.resize(kept.size());
  tbb::parallel_for(size_t{0}, kept.size(), [&](size_t i) {
    size_t t = kept[i];
    out.set_triangle(i, all[t], normals[t], mesh.material_of(t));
  });
  count_open_edges(all, out.vertices.size(), report);
  return {};
}

}  // namespace
}  // namespace detail

Result<World> build_from_mesh(const TriangleMesh& mesh, const GridConfig& grid, Context* ctx,
                              BuildReport* report_out) {
  using namespace detail;
  ScopedTimer total(ctx, "build");
  Status s = check_mesh(mesh, "mesh");
  if (!s.ok()) return s;
  if (mesh.triangles.empty()) return Status(ErrorCode::kInvalidArgument, "mesh: no triangles");
  MeshBounds mb = mesh_bounds(mesh);
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    area += 0.5 * glm::length(glm::cross(mesh.positions[t[1]] - mesh.positions[t[0]],
                                         mesh.positions[t[2]] - mesh.positions[t[0]]));
  }
  Result<WorldConfig> plan = plan_grid({mb.min, mb.max}, grid, area, "mesh");
  if (!plan.ok()) return plan.status();
  try {
    World world = World::create(plan.value()).value();
    BuildReport report;
    report.triangles = mesh.triangles.size();
    SnappedMesh snapped;
    {
      ScopedTimer t(ctx, "build.snap");
      s = snap_mesh(mesh, world.lattice(), snapped, report);
      if (!s.ok()) return s;
    }
    s = rasterize_mesh_into(snapped, world, ctx, report);
    if (!s.ok()) return s;
    report.seconds = total.seconds();
    record_build_report(world, report);
    world.set_metadata("source", "mesh");
    if (report_out) *report_out = report;
    return world;
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, "mesh: out of memory building the LDC; use fewer cells");
  }
}

}  // namespace ldc
