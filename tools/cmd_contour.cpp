// ldc contour (world -> mesh) and ldc remesh (mesh -> LDC -> mesh).
#include <memory>

#include "common.h"
#include "ldc/io.h"
#include "mesh_output.h"
#include "meshio/meshio.h"

namespace ldc::tool {
namespace {

struct ContourArgs {
  std::string input;
  MeshOutputArgs mesh;
  GridConfig grid;  // remesh only
};

int run_contour(const ContourArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  Status out = check_mesh_output(a.mesh);
  if (!out.ok()) return fail("contour", out);
  ProgressBar bar(!common.quiet);
  ScopedTimer t(nullptr, "");
  Result<World> w = load_world(a.input, {}, bar.context());
  if (!w.ok()) return fail("contour", w.status());
  return contour_and_report("contour", w.value(), a.mesh, bar, {{"seconds", {{"load", t.seconds()}}}}, common);
}

int run_remesh(const ContourArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  Status out = check_mesh_output(a.mesh);
  if (!out.ok()) return fail("remesh", out);
  ProgressBar bar(!common.quiet);
  ScopedTimer t(nullptr, "");
  Result<TriangleMesh> m = load_mesh(a.input);
  if (!m.ok()) return fail("remesh", m.status());
  double load = t.seconds();
  ScopedTimer b(nullptr, "");
  Result<World> w = build_from_mesh(m.value(), a.grid, bar.context());
  if (!w.ok()) return fail("remesh", w.status());
  bar.finish();
  nlohmann::json report = {{"seconds", {{"load", load}, {"build", b.seconds()}}}};
  if (warn_if_rasterized_empty("remesh", w.value(), a.input, BuildMode::kSolid)) report["empty"] = true;
  return contour_and_report("remesh", w.value(), a.mesh, bar, std::move(report), common);
}

}  // namespace

void add_contour_commands(CLI::App& app, CommonOptions& common) {
  auto c = std::make_shared<ContourArgs>();
  CLI::App* contour = app.add_subcommand("contour", "Dual-contour a .ldc world into a mesh, with the quality report");
  contour->add_option("input", c->input, ".ldc file")->required();
  add_mesh_output_options(contour, c->mesh);
  contour->callback([c, &common] {
    int code = run_contour(*c, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
  auto r = std::make_shared<ContourArgs>();
  r->mesh.max_error_cells = kAdaptiveMaxErrorCells;  // adaptive by default; contour stays uniform (engine-like)
  CLI::App* remesh = app.add_subcommand("remesh", "Mesh -> LDC -> mesh: a watertight remesh, with the quality report");
  remesh->add_option("input", r->input, "Mesh file (.obj .ply .stl .off)")->required();
  add_mesh_output_options(remesh, r->mesh);
  add_grid_options(remesh, r->grid, "the input");
  remesh->callback([r, &common] {
    int code = run_remesh(*r, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
