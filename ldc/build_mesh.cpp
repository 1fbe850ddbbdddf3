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
#include "ldc/detail/mesh_shells.h"
#include "ldc/internal/ray_math.h"

namespace ldc {
namespace detail {

// ---------------------------------------------------------------------------
// Stage 1: snap and weld

namespace {

// Which positions a triangle uses: the others do not size the lattice and are not snapped.
std::vector<uint8_t> referenced_vertices(const TriangleMesh& mesh) {
  std::vector<uint8_t> used(mesh.positions.size(), 0);
  for (const glm::uvec3& t : mesh.triangles)
    for (int corner = 0; corner < 3; ++corner)
      if (t[corner] < used.size()) used[t[corner]] = 1;  // check_mesh names bad indices
  return used;
}

}  // namespace

Status snap_vertices(const TriangleMesh& mesh, const Lattice& lat, SnappedMesh& out,
                     std::vector<uint32_t>& welded_id) {
  const size_t n = mesh.positions.size();
  const std::vector<uint8_t> used = referenced_vertices(mesh);
  std::vector<Vec3i> fixed(n);
  std::vector<uint32_t> order;
  order.reserve(n);
  const double scale = double(kFixedOne) / lat.cell_size;
  for (size_t i = 0; i < n; ++i) {
    if (!used[i]) continue;
    for (int a = 0; a < 3; ++a) {
      double f = (mesh.positions[i][a] - lat.origin[a]) * scale;
      if (!std::isfinite(f) || std::abs(f) > double(kMaxNodeCoordinate) * kFixedOne) {
        return {ErrorCode::kInvalidArgument,
                "mesh: vertex " + std::to_string(i + 1) + " (1-based) lies outside the lattice range"};
      }
      fixed[i][a] = std::llround(f);
    }
    order.push_back(uint32_t(i));
  }
  // Weld: equal fixed-point positions become one vertex. Unused positions
  // keep welded id 0; no triangle reads it.
  tbb::parallel_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return fixed[a] < fixed[b]; });
  welded_id.assign(n, 0);
  out.vertices.clear();
  out.unsnapped.clear();
  for (size_t k = 0; k < order.size(); ++k) {
    if (k == 0 || fixed[order[k]] != fixed[order[k - 1]]) {
      out.vertices.push_back(fixed[order[k]]);
      out.unsnapped.push_back((mesh.positions[order[k]] - lat.origin) * scale);
    }
    welded_id[order[k]] = uint32_t(out.vertices.size() - 1);
  }
  return {};
}

namespace {

// Edge balance on welded triangles: a mesh is closed when every undirected
// edge is used as often in one direction as in the other (then the winding
// number is well defined everywhere).
void count_open_edges(const std::vector<std::array<uint32_t, 3>>& tris, size_t vertices,
                      BuildReport& report) {
  size_t unbalanced = 0, boundary = 0;
  for_each_undirected_edge(tris, vertices, [&](uint32_t, uint32_t, int balance, size_t uses) {
    unbalanced += balance != 0;
    boundary += uses == 1;
  });
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

namespace {

// The shell thickness for cell size h, or an error naming the field.
Result<double> shell_thickness(const BuildConfig& config, double h) {
  const double t = config.shell_thickness;
  if (!std::isfinite(t) || t < 0.0) {
    return Status(ErrorCode::kInvalidArgument, "shell_thickness " + std::to_string(t) +
                                                   ": must be 0 (one cell) or a finite length > 0");
  }
  if (t == 0.0) return h * 65.0 / 64.0;
  if (t < h / 16.0 || t > 16.0 * h) {
    return Status(ErrorCode::kInvalidArgument,
                  "shell_thickness " + std::to_string(t) + " m: must lie between h/16 and 16 h (h = " +
                      std::to_string(h) + " m)");
  }
  return t;
}

Status check_build_config(const BuildConfig& config) {
  if (config.mode != BuildMode::kSolid && config.mode != BuildMode::kSurface &&
      config.mode != BuildMode::kAuto) {
    return {ErrorCode::kInvalidArgument, "mode: not one of solid, surface, auto"};
  }
  if (config.up_axis < 0 || config.up_axis > 2) {
    return {ErrorCode::kInvalidArgument,
            "up_axis " + std::to_string(config.up_axis) + ": must be 0, 1 or 2"};
  }
  return {};
}

// The mesh as the rasterizer reads it: the input, or (surface and auto
// modes) its sheets turned into shells. Welds on the lattice's fixed-point
// grid first, so components join where the build's vertices do.
Result<TriangleMesh> mesh_to_rasterize(const TriangleMesh& mesh, const Lattice& lat,
                                       const BuildConfig& config, double thickness,
                                       BuildReport& report) {
  SnappedMesh welded;
  std::vector<uint32_t> welded_id;
  Status s = snap_vertices(mesh, lat, welded, welded_id);
  if (!s.ok()) return s;
  const MeshComponents components = mesh_components(mesh, welded_id, welded.vertices.size());
  report.input_closed =
      std::all_of(components.closed.begin(), components.closed.end(), [](uint8_t c) { return c != 0; });
  report.boundary_edges = components.boundary_edges;
  report.degenerate_triangles =
      size_t(std::count(components.of_triangle.begin(), components.of_triangle.end(), MeshComponents::kNone));
  return shelled_mesh(mesh, components, config.mode, thickness, config.up_axis, report);
}

// Plans the lattice; shells reach below the input, so surface readings grow
// the box by the shell thickness (at the cell size the input alone gives).
Result<WorldConfig> plan_mesh_grid(const TriangleMesh& mesh, const GridConfig& grid,
                                   const BuildConfig& config, double* thickness) {
  MeshBounds mb = mesh_bounds(mesh);
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    area += 0.5 * glm::length(glm::cross(mesh.positions[t[1]] - mesh.positions[t[0]],
                                         mesh.positions[t[2]] - mesh.positions[t[0]]));
  }
  Result<WorldConfig> plan = plan_grid({mb.min, mb.max}, grid, area, "mesh");
  if (!plan.ok() || config.mode == BuildMode::kSolid) return plan;
  const double h = plan.value().lattice.cell_size;
  Result<double> t = shell_thickness(config, h);
  if (!t.ok()) return t.status();
  *thickness = t.value();
  GridConfig fixed = grid;
  fixed.cell_size = h;
  // Prisms double the surface at most (top and bottom; sides are thin).
  return plan_grid({mb.min - glm::dvec3(*thickness), mb.max + glm::dvec3(*thickness)}, fixed,
                   2.0 * area, "mesh");
}

}  // namespace
}  // namespace detail

const char* build_mode_name(BuildMode mode) {
  switch (mode) {
    case BuildMode::kSolid: return "solid";
    case BuildMode::kSurface: return "surface";
    case BuildMode::kAuto: return "auto";
  }
  return "unknown";
}

Result<World> build_from_mesh(const TriangleMesh& mesh, const GridConfig& grid, Context* ctx,
                              BuildReport* report_out) {
  return build_from_mesh(mesh, grid, BuildConfig{}, ctx, report_out);
}

Result<World> build_from_mesh(const TriangleMesh& mesh, const GridConfig& grid,
                              const BuildConfig& config, Context* ctx, BuildReport* report_out) {
  using namespace detail;
  ScopedTimer total(ctx, "build");
  Status s = check_mesh(mesh, "mesh");
  if (!s.ok()) return s;
  if (mesh.triangles.empty()) return Status(ErrorCode::kInvalidArgument, "mesh: no triangles");
  s = check_build_config(config);
  if (!s.ok()) return s;
  double thickness = 0.0;
  Result<WorldConfig> plan = plan_mesh_grid(mesh, grid, config, &thickness);
  if (!plan.ok()) return plan.status();
  try {
    World world = World::create(plan.value()).value();
    BuildReport report;
    report.triangles = mesh.triangles.size();
    SnappedMesh snapped;
    BuildReport input;  // surface readings: the input's closedness, for the report
    {
      ScopedTimer t(ctx, "build.snap");
      if (config.mode == BuildMode::kSolid) {
        s = snap_mesh(mesh, world.lattice(), snapped, report);
      } else {
        Result<TriangleMesh> read = mesh_to_rasterize(mesh, world.lattice(), config, thickness, report);
        if (!read.ok()) return read.status();
        input = report;
        // The rasterizer repairs by votes only what the shells left open.
        s = snap_mesh(read.value(), world.lattice(), snapped, report);
        report.degenerate_triangles += input.degenerate_triangles;
      }
      if (!s.ok()) return s;
    }
    s = rasterize_mesh_into(snapped, world, ctx, report);
    if (!s.ok()) return s;
    if (config.mode != BuildMode::kSolid) {
      report.input_closed = input.input_closed;
      report.boundary_edges = input.boundary_edges;
    }
    report.seconds = total.seconds();
    record_build_report(world, report);
    world.set_metadata("source", "mesh");
    if (config.mode != BuildMode::kSolid) world.set_metadata("build.mode", build_mode_name(config.mode));
    // The materials' names (OBJ usemtl), as the landscape records its own:
    // material.<id> = name, so tools can name materials (ldc path --filter).
    for (size_t id = 0; id < mesh.material_names.size(); ++id) {
      world.set_metadata("material." + std::to_string(id), mesh.material_names[id]);
    }
    if (report_out) *report_out = report;
    return world;
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, "mesh: out of memory building the LDC; use fewer cells");
  }
}

}  // namespace ldc
