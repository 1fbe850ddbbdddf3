// ldc contour (world -> mesh) and ldc remesh (mesh -> LDC -> mesh).
#include <cstdio>
#include <memory>

#include "common.h"
#include "contour/contour.h"
#include "contour/export.h"
#include "ldc/io.h"

namespace ldc::tool {
namespace {

struct ContourArgs {
  std::string input;
  std::string output;
  std::string method = "iterative";
  ContourConfig config;
  GridConfig grid;  // remesh only
};

Result<ContourMesh> run_method(const World& w, const ContourArgs& a, Context* ctx, ContourStats* stats) {
  if (a.method == "mc") return marching_cubes(w, ctx);
  ContourConfig c = a.config;
  if (a.method == "iterative") c.placement = Placement::kIterative;
  else if (a.method == "qef") c.placement = Placement::kQef;
  else if (a.method == "masspoint") c.placement = Placement::kMassPoint;
  else return Status(ErrorCode::kInvalidArgument, "--method '" + a.method + "': use iterative, qef, masspoint or mc");
  return contour_world(w, c, ctx, stats);
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
  return {{"triangles", q.triangles},
          {"vertices", q.vertices},
          {"closed", q.closed()},
          {"boundary_edges", q.boundary_edges},
          {"nonmanifold_edges", q.nonmanifold_edges},
          {"nonmanifold_vertices", q.nonmanifold_vertices},
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

void print_report(const nlohmann::json& j) {
  const auto& q = j["quality"];
  std::printf("%s: %zu triangles, %zu vertices, %s\n", j["output"].get<std::string>().c_str(),
              q["triangles"].get<size_t>(), q["vertices"].get<size_t>(),
              q["closed"].get<bool>() ? "closed" : "NOT closed");
  std::printf("  boundary edges %zu, non-manifold edges %zu / vertices %zu, degenerate triangles %zu\n",
              q["boundary_edges"].get<size_t>(), q["nonmanifold_edges"].get<size_t>(),
              q["nonmanifold_vertices"].get<size_t>(), q["degenerate_triangles"].get<size_t>());
  std::printf("  min angle %.1f deg; histogram (10 deg bins):", q["min_angle_deg"].get<double>());
  for (const auto& b : q["min_angle_histogram_10deg"]) std::printf(" %zu", b.get<size_t>());
  std::printf("\n  area %.6g, volume %.6g\n", q["area"].get<double>(), q["volume"].get<double>());
  for (const auto& [k, v] : j["seconds"].items()) std::printf("  %s: %.3f s\n", k.c_str(), v.get<double>());
}

int finish(const char* command, const World& w, const ContourArgs& a, ProgressBar& bar, nlohmann::json timings,
           const CommonOptions& common) {
  ScopedTimer t(nullptr, "");
  ContourStats stats;
  Result<ContourMesh> mesh = run_method(w, a, bar.context(), &stats);
  timings["contour"] = t.seconds();
  if (!mesh.ok()) return fail(command, mesh.status());
  ScopedTimer e(nullptr, "");
  Status s = save_contour_mesh(mesh.value(), a.output, export_options(w));
  timings["export"] = e.seconds();
  bar.finish();
  if (!s.ok()) return fail(command, s);
  nlohmann::json out = {{"output", a.output}, {"method", a.method}, {"seconds", timings},
                        {"quality", quality_json(mesh_quality(mesh.value()), stats)}};
  if (common.json) std::printf("%s\n", out.dump(2).c_str());
  else print_report(out);
  return 0;
}

int run_contour(const ContourArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  ProgressBar bar(!common.quiet);
  ScopedTimer t(nullptr, "");
  Result<World> w = load_world(a.input, {}, bar.context());
  if (!w.ok()) return fail("contour", w.status());
  return finish("contour", w.value(), a, bar, {{"load", t.seconds()}}, common);
}

int run_remesh(const ContourArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  ProgressBar bar(!common.quiet);
  ScopedTimer t(nullptr, "");
  Result<TriangleMesh> m = load_mesh(a.input);
  if (!m.ok()) return fail("remesh", m.status());
  double load = t.seconds();
  ScopedTimer b(nullptr, "");
  Result<World> w = build_from_mesh(m.value(), a.grid, bar.context());
  if (!w.ok()) return fail("remesh", w.status());
  return finish("remesh", w.value(), a, bar, {{"load", load}, {"build", b.seconds()}}, common);
}

void add_contour_options(CLI::App* cmd, ContourArgs& a) {
  cmd->add_option("-o,--output", a.output, "Output mesh (.obj .ply .stl .glb .drc)")->required();
  cmd->add_option("--method", a.method, "iterative | qef | masspoint | mc")->capture_default_str();
  cmd->add_option("--iterations", a.config.iterations, "Iterative placement: steps")->capture_default_str();
  cmd->add_option("--relax", a.config.relax_iterations, "Material-border relaxation steps (0 = off)")->capture_default_str();
  cmd->add_option("--slack", a.config.cell_slack, "How far vertices may leave their cell (fraction of h)")->capture_default_str();
}

}  // namespace

void add_contour_commands(CLI::App& app, CommonOptions& common) {
  auto c = std::make_shared<ContourArgs>();
  CLI::App* contour = app.add_subcommand("contour", "Dual-contour a .ldc world into a mesh, with the quality report");
  contour->add_option("input", c->input, ".ldc file")->required();
  add_contour_options(contour, *c);
  contour->callback([c, &common] {
    int code = run_contour(*c, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
  auto r = std::make_shared<ContourArgs>();
  CLI::App* remesh = app.add_subcommand("remesh", "Mesh -> LDC -> mesh: a watertight remesh, with the quality report");
  remesh->add_option("input", r->input, "Mesh file (.obj .ply .stl .off)")->required();
  add_contour_options(remesh, *r);
  remesh->add_option("--cells", r->grid.cells, "Cells along the longest axis")->capture_default_str();
  remesh->add_option("--cell-size", r->grid.cell_size, "Cell size h (overrides --cells)");
  remesh->add_option("--chunk", r->grid.chunk_size, "Chunk size in cells")->capture_default_str();
  remesh->callback([r, &common] {
    int code = run_remesh(*r, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
