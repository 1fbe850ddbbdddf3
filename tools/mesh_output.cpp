#include "mesh_output.h"

#include <cmath>
#include <cstdio>

#include "ldc/lod.h"
#include "meshio/meshio.h"
#include "plugin.h"

namespace ldc::tool {
namespace {

// Adaptive output meshes at the levels the surface allows (surface_levels
// at a tenth of the bound) where that pays off.
bool wants_surface_levels(const MeshOutputArgs& a) {
  return a.surface_levels && a.max_error_cells > 0.0 && a.method != "mc" && !a.level_of_chunk;
}

// report["surface_levels"]: the chunks per level and what was done with them.
nlohmann::json surface_levels_json(const World& w, const SurfaceLevelChoice& c, double tolerance) {
  nlohmann::json chunks = nlohmann::json::array();
  for (int k = 0; k <= max_lod_level(w.chunk_size()); ++k) chunks.push_back(c.levels.surface_chunks(k));
  return {{"tolerance_cells", tolerance},
          {"chunks_by_level", chunks},
          {"several_materials", c.levels.several_materials},
          {"borders_relaxed", c.borders_relaxed},
          {"fell_back", c.fell_back},
          {"used", c.used}};
}

Result<ContourMesh> run_method(const World& w, const MeshOutputArgs& a, Context* ctx, ContourStats* stats,
                               nlohmann::json& report) {
  if (a.method == "mc" && a.level_of_chunk) {
    return Status(ErrorCode::kInvalidArgument, "--method mc has no levels of detail: leave out --lod-bands");
  }
  if (a.method == "mc") return marching_cubes(w, ctx);
  ContourConfig c = a.config;
  if (a.method == "iterative") c.placement = Placement::kIterative;
  else if (a.method == "qef") c.placement = Placement::kQef;
  else if (a.method == "masspoint") c.placement = Placement::kMassPoint;
  else return Status(ErrorCode::kInvalidArgument, "--method '" + a.method + "': use iterative, qef, masspoint or mc");
  // One piece: untangle_mesh clears self-intersections after simplification
  // (mesh_world), moving only the vertices that cross. Contouring's own local
  // round would move every vertex near a fold to its mass point first, which
  // blunts sharp features (fandisk's Hausdorff error 4x larger) and triples
  // the contouring time.
  c.untangle = false;
  if (a.level_of_chunk) return contour_levels(w, a.level_of_chunk, c, ctx, stats);
  if (!wants_surface_levels(a)) return contour_world(w, c, ctx, stats);
  const double tolerance = surface_level_tolerance(a.max_error_cells);
  SurfaceLevelChoice choice;
  Result<ContourMesh> mesh = contour_at_surface_levels(w, tolerance, c, ctx, stats, &choice);
  if (!mesh.ok()) return mesh;
  report["surface_levels"] = surface_levels_json(w, choice, tolerance);
  report["seconds"]["surface_levels"] = choice.levels_seconds;
  return mesh;
}

ExportOptions export_options(const World& w) {
  ExportOptions o;
  for (int id = 0; id < 256; ++id) {
    std::string name = w.metadata_value("material." + std::to_string(id));
    if (name.empty()) break;
    o.material_names.push_back(name);
  }
  return o;
}

nlohmann::json quality_json(const MeshQuality& q, const ContourStats& s) {
  // A mesh with no triangles bounds nothing: neither closed nor watertight (issue 24).
  const bool empty = q.triangles == 0;
  return {{"triangles", q.triangles},
          {"vertices", q.vertices},
          {"closed", !empty && q.closed()},  // a closed 2-manifold without self-intersections
          {"watertight", !empty && q.watertight()},
          {"failures", empty ? std::string("empty (no triangles)") : quality_failures(q)},
          {"boundary_edges", q.boundary_edges},
          {"nonmanifold_edges", q.nonmanifold_edges},
          {"nonmanifold_vertices", q.nonmanifold_vertices},
          {"self_intersecting_pairs", q.self_intersecting_pairs},
          {"unpaired_edges", q.unpaired_edges},
          {"degenerate_triangles", q.degenerate_triangles},
          {"min_angle_deg", q.min_angle_deg},
          {"min_angle_histogram_10deg", q.min_angle_histogram},
          {"area", q.area},
          {"volume", q.volume},
          {"multi_crossing_edges", s.multi_crossing_edges},
          {"thin_edges", s.thin_edges},
          {"clamped_vertices", s.clamped_vertices},
          {"relaxed_vertices", s.relaxed_vertices},
          {"qef_rank", s.qef_rank},
          {"chunks_meshed", s.chunks_meshed}};
}

nlohmann::json simplify_json(const SimplifyStats& s, double max_error, double cells) {
  return {{"max_error", max_error},
          {"max_error_cells", cells},
          {"triangles_before", s.triangles_before},
          {"triangles_after", s.triangles_after},
          {"collapses", s.collapses},
          {"locked_vertices", s.locked_vertices},
          {"rejected_topology", s.rejected_topology},
          {"rejected_flip", s.rejected_flip},
          {"rejected_sliver", s.rejected_sliver},
          {"rejected_intersection", s.rejected_intersection},
          {"max_error_reached", s.max_error_reached}};
}

// --max-error (cells of h) and --target-triangles as simplify_mesh takes them.
SimplifyOptions simplify_options(const World& w, const MeshOutputArgs& a) {
  return {.max_error = a.max_error_cells * w.lattice().cell_size, .target_triangles = a.target_triangles};
}

// Simplifies within --max-error, timed.
Status simplify_output(const World& w, const MeshOutputArgs& a, Context* ctx, ContourMesh& mesh,
                       nlohmann::json& report) {
  const SimplifyOptions options = simplify_options(w, a);
  ScopedTimer s(nullptr, "");
  Result<SimplifyStats> simple = simplify_mesh(mesh, options, ctx);
  report["seconds"]["simplify"] = s.seconds();
  if (!simple.ok()) return simple.status();
  report["simplify"] = simplify_json(simple.value(), options.max_error, a.max_error_cells);
  return {};
}

nlohmann::json untangle_json(const UntangleMeshStats& s) {
  return {{"pairs_before", s.pairs_before},
          {"pairs_after", s.pairs_after},
          {"vertices_moved", s.vertices_moved},
          {"rounds", s.rounds},
          {"specks_removed", s.specks_removed},
          {"speck_triangles_removed", s.speck_triangles_removed}};
}

// simplify_and_untangle (contour/contour.h) within --max-error, with
// untangling's moves capped at one cell h; report["untangle_retry"] when
// the first way left pairs.
Status simplify_and_untangle_output(const World& w, const MeshOutputArgs& a, Context* ctx, ContourMesh& mesh,
                                    nlohmann::json& report) {
  const SimplifyOptions options = simplify_options(w, a);
  Result<SimplifyUntangleStats> done = simplify_and_untangle(mesh, options, {.max_move = w.lattice().cell_size}, ctx);
  if (!done.ok()) return done.status();
  const SimplifyUntangleStats& s = done.value();
  report["seconds"]["simplify"] = s.simplify_seconds;
  report["seconds"]["untangle"] = s.untangle_seconds;
  report["simplify"] = simplify_json(s.simplify, options.max_error, a.max_error_cells);
  report["untangle"] = untangle_json(s.untangle);
  if (s.retried)
    report["untangle_retry"] = {{"uniform_pairs_before", s.uniform_untangle.pairs_before},
                                {"uniform_pairs_after", s.uniform_untangle.pairs_after},
                                {"pairs_after", s.untangle.pairs_after},
                                {"used", s.retry_used},
                                {"simplified_pairs_after", s.first_pairs_after}};
  return {};
}

// Contours, simplifies (with --max-error > 0) and untangles (dual
// contouring with untangling on), timing each step.
Result<ContourMesh> mesh_world(const World& w, const MeshOutputArgs& a, Context* ctx, ContourStats& stats,
                               nlohmann::json& report) {
  ScopedTimer t(nullptr, "");
  Result<ContourMesh> mesh = run_method(w, a, ctx, &stats, report);
  report["seconds"]["contour"] = t.seconds() - report["seconds"].value("surface_levels", 0.0);  // reported on its own
  if (!mesh.ok()) return mesh;
  const bool untangle = a.method != "mc" && a.config.untangle;
  if (a.max_error_cells > 0.0 && untangle) {
    if (Status s = simplify_and_untangle_output(w, a, ctx, mesh.value(), report); !s.ok()) return s;
  } else if (a.max_error_cells > 0.0) {
    if (Status s = simplify_output(w, a, ctx, mesh.value(), report); !s.ok()) return s;
  } else if (untangle) {
    if (Status s = untangle_output(ctx, mesh.value(), report); !s.ok()) return s;
  }
  return mesh;
}

void print_report(const nlohmann::json& j) {
  const auto& q = j["quality"];
  // "closed" only for a closed 2-manifold without self-intersections; otherwise what fails.
  const std::string verdict =
      q["closed"].get<bool>() ? "closed" : "NOT closed: " + q["failures"].get<std::string>();
  std::printf("%s: %zu triangles, %zu vertices, %s\n", j["output"].get<std::string>().c_str(),
              q["triangles"].get<size_t>(), q["vertices"].get<size_t>(), verdict.c_str());
  std::printf("  %s; boundary edges %zu, non-manifold edges %zu / vertices %zu, self-intersecting pairs %zu, "
              "degenerate triangles %zu\n",
              q["watertight"].get<bool>() ? "watertight" : "NOT watertight", q["boundary_edges"].get<size_t>(),
              q["nonmanifold_edges"].get<size_t>(), q["nonmanifold_vertices"].get<size_t>(),
              q["self_intersecting_pairs"].get<size_t>(), q["degenerate_triangles"].get<size_t>());
  if (j.contains("simplify")) {
    const auto& s = j["simplify"];
    std::printf("  adaptive: %zu -> %zu triangles within %g cells (%g m); %zu collapses\n",
                s["triangles_before"].get<size_t>(), s["triangles_after"].get<size_t>(),
                s["max_error_cells"].get<double>(), s["max_error"].get<double>(), s["collapses"].get<size_t>());
  }
  if (j.contains("surface_levels")) {
    const auto& l = j["surface_levels"];
    std::string counts;
    for (const auto& n : l["chunks_by_level"]) counts += (counts.empty() ? "" : " / ") + std::to_string(n.get<size_t>());
    const char* why = l["used"].get<bool>()              ? "meshed at these levels"
                      : l["fell_back"].get<bool>()       ? "one level: a seam between levels came out non-manifold"
                      : l["borders_relaxed"].get<bool>() ? "one level: material borders are relaxed there"
                                                         : "one level: the levels would not pay off";
    std::printf("  surface levels: chunks with surface at level 0 / 1 / ...: %s (%s)\n", counts.c_str(), why);
  }
  if (j.contains("untangle") && j["untangle"]["pairs_before"].get<size_t>() > 0) {
    const auto& u = j["untangle"];
    std::printf("  untangled: %zu self-intersecting pairs -> %zu, %zu vertices moved",
                u["pairs_before"].get<size_t>(), u["pairs_after"].get<size_t>(), u["vertices_moved"].get<size_t>());
    if (u["specks_removed"].get<size_t>() > 0)
      std::printf("; tangled specks removed: %zu (%zu triangles)", u["specks_removed"].get<size_t>(),
                  u["speck_triangles_removed"].get<size_t>());
    std::printf("\n");
  }
  if (j.contains("untangle_retry")) {
    const auto& r = j["untangle_retry"];
    std::printf("  %s: the simplified mesh kept %zu pairs; untangled before simplifying (%zu -> %zu), then %zu\n",
                r["used"].get<bool>() ? "retried" : "retried in vain", r["simplified_pairs_after"].get<size_t>(),
                r["uniform_pairs_before"].get<size_t>(), r["uniform_pairs_after"].get<size_t>(),
                r["pairs_after"].get<size_t>());
  }
  // %.3g: a sliver of 0.004 degrees (not degenerate) must not read "0.0".
  std::printf("  min angle %.3g deg; histogram (10 deg bins):", q["min_angle_deg"].get<double>());
  for (const auto& b : q["min_angle_histogram_10deg"]) std::printf(" %zu", b.get<size_t>());
  std::printf("\n  area %.6g, volume %.6g\n", q["area"].get<double>(), q["volume"].get<double>());
  print_seconds(j["seconds"]);
}

}  // namespace

Status untangle_output(Context* ctx, ContourMesh& mesh, nlohmann::json& report) {
  ScopedTimer u(nullptr, "");
  Result<UntangleMeshStats> untangled = untangle_mesh(mesh, {}, ctx);
  report["seconds"]["untangle"] = u.seconds();
  if (!untangled.ok()) return untangled.status();
  report["untangle"] = untangle_json(untangled.value());
  return {};
}

void add_mesh_output_options(CLI::App* cmd, MeshOutputArgs& a) {
  output_file(cmd->add_option("-o,--output", a.output, "Output mesh (.obj .ply .stl .glb .drc)"))->required();
  cmd->add_option("--method", a.method, "iterative | qef | masspoint | mc")->capture_default_str();
  cmd->add_option("--iterations", a.config.iterations, "Iterative placement: steps")->capture_default_str();
  cmd->add_option("--relax", a.config.relax_iterations, "Material-border relaxation steps (0 = off)")->capture_default_str();
  cmd->add_option("--slack", a.config.cell_slack, "How far vertices may leave their cell (fraction of h)")->capture_default_str();
  cmd->add_option("--max-error", a.max_error_cells,
                  "Adaptive output: simplify within this distance, in cells of h (0 = uniform output)")
      ->capture_default_str();
  cmd->add_flag("--surface-levels,!--no-surface-levels", a.surface_levels,
                "Adaptive output: mesh chunks whose surface is plain (flat faces, creases) from every 2nd or 4th ray "
                "before simplifying, when the cost model says it is faster (default on; off: one level everywhere)");
  cmd->add_option("--target-triangles", a.target_triangles,
                  "Adaptive output: stop simplifying at this many triangles (0 = no target; the bound still holds)")
      ->capture_default_str();
}

void add_grid_options(CLI::App* cmd, GridConfig& grid, const std::string& cells_of) {
  cmd->add_option("--cells", grid.cells, "Cells along the longest axis of " + cells_of)->capture_default_str();
  cmd->add_option("--cell-size", grid.cell_size, "Cell size h (m); overrides --cells");
  cmd->add_option("--chunk-size,--chunk", grid.chunk_size, "Chunk size in cells: 8, 16, 32 or 64")->capture_default_str();
}

Status check_mesh_output(const MeshOutputArgs& args) {
  Result<MeshFormat> format = mesh_format_from_path(args.output);
  if (!format.ok()) return format.status();
  if (format.value() == MeshFormat::kDraco) {  // the plugin, before the work (issue 22)
    if (Status s = check_draco_plugin(args.output); !s.ok()) return s;
  }
  if (!(args.max_error_cells >= 0.0 && std::isfinite(args.max_error_cells)))
    return Status(ErrorCode::kInvalidArgument,
                  "--max-error " + std::to_string(args.max_error_cells) + ": must be a finite number of cells >= 0");
  if (args.target_triangles > 0 && args.max_error_cells == 0.0)
    return Status(ErrorCode::kInvalidArgument,
                  "--target-triangles " + std::to_string(args.target_triangles) +
                      " needs --max-error > 0 (with --max-error 0 the output is uniform)");
  return {};
}

int contour_and_report(const std::string& command, const World& w, const MeshOutputArgs& a, ProgressBar& bar,
                       nlohmann::json report, const CommonOptions& common, const ExtraReportLines& extra_lines) {
  ContourStats stats;
  Result<ContourMesh> mesh = mesh_world(w, a, bar.context(), stats, report);
  if (!mesh.ok()) return fail(command, mesh.status());
  report["method"] = a.method;
  return write_and_report(command, w, mesh.value(), stats, a.output, bar, std::move(report), common, extra_lines);
}

int write_and_report(const std::string& command, const World& w, const ContourMesh& mesh, const ContourStats& stats,
                     const std::string& output, ProgressBar& bar, nlohmann::json report, const CommonOptions& common,
                     const ExtraReportLines& extra_lines) {
  ScopedTimer e(nullptr, "");
  Status s = save_mesh(mesh, output, export_options(w));
  report["seconds"]["export"] = e.seconds();
  bar.finish();
  if (!s.ok()) return fail(command, s);
  report["ok"] = true;
  report["output"] = output;
  ScopedTimer q(nullptr, "");
  // After untangle_mesh its exact pair count stands in for a second search.
  QualityOptions quality_options;
  if (report.contains("untangle"))
    quality_options.known_self_intersecting_pairs = report["untangle"]["pairs_after"].get<size_t>();
  report["quality"] = quality_json(mesh_quality(mesh, quality_options), stats);
  report["seconds"]["quality"] = q.seconds();  // the report's own cost (self-intersection test included)
  if (common.json) {
    std::printf("%s\n", json_text(with_warnings(std::move(report))).c_str());
    return 0;
  }
  print_report(report);
  if (extra_lines) extra_lines(report);
  return 0;
}

}  // namespace ldc::tool
