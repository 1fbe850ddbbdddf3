// ldc boolean: two meshes -> one lattice -> union, difference or intersection -> mesh.
#include <cstdio>
#include <memory>

#include "common.h"
#include "csg/csg.h"
#include "mesh_output.h"

namespace ldc::tool {
namespace {

struct BooleanArgs {
  std::string first, second;  // mesh files
  std::string op;
  GridConfig grid;
  BooleanConfig config;
  MeshOutputArgs mesh;
};

Result<BooleanOp> parse_boolean_op(const std::string& name) {
  for (BooleanOp op : {BooleanOp::kUnion, BooleanOp::kDifference, BooleanOp::kIntersection}) {
    if (name == boolean_op_name(op)) return op;
  }
  return Status(ErrorCode::kInvalidArgument, "--op '" + name + "': use union, difference or intersection");
}

// An input as its build saw it: open inputs are decided by the repair's
// half-ray votes, and the rays it repaired are counted.
nlohmann::json input_json(const std::string& file, const TriangleMesh& mesh, const BuildReport& build) {
  return {{"file", file},
          {"triangles", mesh.triangle_count()},
          {"closed", build.input_closed},
          {"boundary_edges", build.boundary_edges},
          {"repaired_rays", build.repaired_rays},
          {"degenerate_triangles", build.degenerate_triangles}};
}

void print_inputs(const nlohmann::json& report) {
  for (const auto& in : report["inputs"]) {
    std::printf("  input %s: %zu triangles, ", in["file"].get<std::string>().c_str(), in["triangles"].get<size_t>());
    if (in["closed"].get<bool>()) {
      std::printf("closed\n");
    } else {
      std::printf("open (%zu boundary edges): %zu rays repaired by the half-ray votes\n",
                  in["boundary_edges"].get<size_t>(), in["repaired_rays"].get<size_t>());
    }
  }
}

int run_boolean(const BooleanArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  Result<BooleanOp> op = parse_boolean_op(a.op);
  if (!op.ok()) return fail("boolean", op.status());
  Status out = check_mesh_output(a.mesh);
  if (!out.ok()) return fail("boolean", out);
  ProgressBar bar(!common.quiet);
  ScopedTimer t(nullptr, "");
  Result<TriangleMesh> first = load_mesh(a.first);
  if (!first.ok()) return fail("boolean", first.status());
  Result<TriangleMesh> second = load_mesh(a.second);
  if (!second.ok()) return fail("boolean", second.status());
  double load = t.seconds();
  ScopedTimer b(nullptr, "");
  std::array<BuildReport, 2> builds;
  Result<World> w = mesh_boolean(first.value(), second.value(), op.value(), a.grid, a.config, bar.context(), &builds);
  if (!w.ok()) return fail("boolean", w.status());
  nlohmann::json report = {
      {"op", a.op},
      {"inputs", nlohmann::json::array({input_json(a.first, first.value(), builds[0]), input_json(a.second, second.value(), builds[1])})},
      {"seconds", {{"load", load}, {"build_boolean", b.seconds()}}}};
  return contour_and_report("boolean", w.value(), a.mesh, bar, std::move(report), common, print_inputs);
}

}  // namespace

void add_boolean_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<BooleanArgs>();
  CLI::App* cmd = app.add_subcommand(
      "boolean", "Union, difference or intersection of two meshes on one lattice -> mesh, with the quality report");
  cmd->add_option("first", args->first, "Mesh file A (.obj .ply .stl .off)")->required();
  cmd->add_option("second", args->second, "Mesh file B (.obj .ply .stl .off)")->required();
  cmd->add_option("--op", args->op, "union | difference (A minus B) | intersection")->required();
  add_grid_options(cmd, args->grid, "both meshes' joint bounds");
  cmd->add_option("--sliver", args->config.sliver, "Remove spans and gaps thinner than this (cells, 0 .. 0.5)")
      ->capture_default_str();
  cmd->add_option("--cut-material", args->config.cut_material,
                  "Material of surfaces a difference exposes (-1 = the material cut into)")
      ->capture_default_str();
  add_mesh_output_options(cmd, args->mesh);
  cmd->callback([args, &common] {
    int code = run_boolean(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
