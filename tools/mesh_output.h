// Contouring a world into the output mesh, with the quality report: what
// `ldc contour`, `ldc remesh` and `ldc boolean` share.
#pragma once

#include <functional>
#include <string>

#include "common.h"
#include "contour/contour.h"

namespace ldc::tool {

struct MeshOutputArgs {
  std::string output;                // .obj .ply .stl .glb .drc
  std::string method = "iterative";  // iterative | qef | masspoint | mc
  ContourConfig config;
};

// -o and the contouring options: --method, --iterations, --relax, --slack.
void add_mesh_output_options(CLI::App* cmd, MeshOutputArgs& args);

// --cells, --cell-size and --chunk-size (deprecated alias --chunk); `cells_of` says
// which bounding box --cells divides.
void add_grid_options(CLI::App* cmd, GridConfig& grid, const std::string& cells_of);

// Refuses an output path whose extension names no mesh format (naming it), so
// that a typo fails before minutes of building rather than after.
Status check_mesh_output(const MeshOutputArgs& args);

// Prints command-specific lines after the quality report (text output only).
using ExtraReportLines = std::function<void(const nlohmann::json& report)>;

// Contours the world, writes the mesh and prints the report: the quality
// report as text, or `report` as JSON with "ok", "output", "method", "quality"
// added and the contour and export times added to report["seconds"].
// Returns the command's exit status.
int contour_and_report(const std::string& command, const World& world, const MeshOutputArgs& args,
                       ProgressBar& bar, nlohmann::json report, const CommonOptions& common,
                       const ExtraReportLines& extra_lines = {});

// Writes a mesh already made and prints the report, as contour_and_report.
int write_and_report(const std::string& command, const World& world, const ContourMesh& mesh,
                     const ContourStats& stats, const std::string& output, ProgressBar& bar, nlohmann::json report,
                     const CommonOptions& common, const ExtraReportLines& extra_lines = {});

}  // namespace ldc::tool
