// Contouring a world into the output mesh, with the quality report: what
// `ldc contour`, `ldc remesh` and `ldc boolean` share.
#pragma once

#include <functional>
#include <string>

#include "common.h"
#include "contour/contour.h"

namespace ldc::tool {

// The adaptive default of `remesh` and `boolean`: the error bound in cells.
// Measured on the shared meshes at 256 cells (spot, fandisk, stanford-bunny,
// rocker-arm): 0.2 cells keeps the mean distance to the input within 2.7e-5
// of the diagonal (rocker-arm, the worst; 0.3 cells gives 3.1e-5) with 6-38x
// fewer triangles.
constexpr double kAdaptiveMaxErrorCells = 0.2;

struct MeshOutputArgs {
  std::string output;                // .obj .ply .stl .glb .drc
  std::string method = "iterative";  // iterative | qef | masspoint | mc
  ContourConfig config;
  // Adaptive output (simplify_mesh): the bound in cells of h (0 = uniform
  // output) and the triangle target (0 = none). Commands set their default
  // before add_mesh_output_options.
  double max_error_cells = 0.0;
  size_t target_triangles = 0;
  // Adaptive output: chunks meshed at the levels surface_levels allows
  // (contour_levels) where surface_levels_pay_off says it is faster.
  bool surface_levels = true;
  // Set: each chunk meshed at its own level (contour_levels), not with `method`'s placement only.
  std::function<int(const glm::ivec3&)> level_of_chunk;
};

// -o and the contouring options: --method, --iterations, --relax, --slack,
// and the adaptive output's --max-error and --target-triangles.
void add_mesh_output_options(CLI::App* cmd, MeshOutputArgs& args);

// --cells, --cell-size and --chunk-size (deprecated alias --chunk); `cells_of` says
// which bounding box --cells divides.
void add_grid_options(CLI::App* cmd, GridConfig& grid, const std::string& cells_of);

// Refuses an output path whose extension names no mesh format (naming it), and
// a bad --max-error / --target-triangles, so that a typo fails before minutes
// of building rather than after.
Status check_mesh_output(const MeshOutputArgs& args);

// Prints command-specific lines after the quality report (text output only).
using ExtraReportLines = std::function<void(const nlohmann::json& report)>;

// Contours the world, writes the mesh and prints the report: the quality
// report as text, or `report` as JSON with "ok", "output", "method", "quality"
// added and the contour and export times added to report["seconds"]. With
// --max-error > 0 the mesh is simplified before it is written: "simplify" in
// the report (triangles before and after, collapses, refusals) and its time
// in report["seconds"]["simplify"]. Dual-contoured meshes (untangling on)
// then go through untangle_mesh: "untangle" in the report (pairs found and
// left, vertices moved) and report["seconds"]["untangle"].
// Returns the command's exit status.
int contour_and_report(const std::string& command, const World& world, const MeshOutputArgs& args,
                       ProgressBar& bar, nlohmann::json report, const CommonOptions& common,
                       const ExtraReportLines& extra_lines = {});

// untangle_mesh on `mesh`, reported as contour_and_report does.
Status untangle_output(Context* ctx, ContourMesh& mesh, nlohmann::json& report);

// Writes a mesh already made and prints the report, as contour_and_report.
int write_and_report(const std::string& command, const World& world, const ContourMesh& mesh,
                     const ContourStats& stats, const std::string& output, ProgressBar& bar, nlohmann::json report,
                     const CommonOptions& common, const ExtraReportLines& extra_lines = {});

}  // namespace ldc::tool
