// ldc boolean: two meshes -> one lattice -> union, subtract or intersect -> mesh.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "common.h"
#include "csg/csg.h"
#include "mesh_output.h"
#include "meshio/meshio.h"

namespace ldc::tool {
namespace {

struct BooleanArgs {
  std::string first, second;  // mesh files
  std::string op;
  GridConfig grid;
  BooleanConfig config;
  MeshOutputArgs mesh;
  std::string translate_b;  // --translate-b x,y,z; empty = not given
  std::string scale_b;      // --scale-b s; empty = not given
};

// B's placement from --scale-b and --translate-b: v -> scale * v + offset
// (scaled about the origin, then moved).
struct Placement {
  double scale = 1.0;
  glm::dvec3 offset{0.0};
};

// Errors name the option and the text given.
Result<Placement> parse_placement(const BooleanArgs& a) {
  Placement p;
  if (!a.scale_b.empty()) {
    std::vector<double> v;
    if (!parse_numbers(a.scale_b, &v) || v.size() != 1 || !(v[0] > 0.0)) {
      return Status(ErrorCode::kInvalidArgument,
                    "--scale-b '" + a.scale_b + "': must be one finite number > 0 (a uniform scale)");
    }
    p.scale = v[0];
  }
  if (!a.translate_b.empty() && !parse_vec3(a.translate_b, &p.offset)) {
    return Status(ErrorCode::kInvalidArgument,
                  "--translate-b '" + a.translate_b + "': expected three finite numbers x,y,z");
  }
  return p;
}

Status place(const Placement& p, TriangleMesh* mesh) {
  for (glm::dvec3& v : mesh->positions) {
    v = p.scale * v + p.offset;
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
      return Status(ErrorCode::kInvalidArgument,
                    "--scale-b / --translate-b move a vertex of mesh B past the largest finite number");
    }
  }
  return {};
}

// Why an empty result is empty, for the warning.
std::string empty_reason(BooleanOp op) {
  switch (op) {
    case BooleanOp::kIntersect: return "A and B do not overlap on the lattice";
    case BooleanOp::kSubtract: return "B covers all of A on the lattice";
    case BooleanOp::kUnion: return "neither A nor B holds any solid on the lattice";
  }
  return "no solid is left";
}

Result<BooleanOp> parse_boolean_op(const std::string& name) {
  if (std::optional<BooleanOp> op = boolean_op_from_name(name)) return *op;
  return Status(ErrorCode::kInvalidArgument, "--op '" + name + "': use union, subtract or intersect");
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
  Result<Placement> placement = parse_placement(a);
  if (!placement.ok()) return fail("boolean", placement.status());
  ProgressBar bar(!common.quiet);
  ScopedTimer t(nullptr, "");
  Result<TriangleMesh> first = load_mesh(a.first);
  if (!first.ok()) return fail("boolean", first.status());
  Result<TriangleMesh> second = load_mesh(a.second);
  if (!second.ok()) return fail("boolean", second.status());
  Status placed = place(placement.value(), &second.value());
  if (!placed.ok()) return fail("boolean", placed);
  double load = t.seconds();
  ScopedTimer b(nullptr, "");
  std::array<BuildReport, 2> builds;
  Result<World> w = mesh_boolean(first.value(), second.value(), op.value(),
                                 {.grid = a.grid, .boolean = a.config, .ctx = bar.context(), .reports = &builds});
  if (!w.ok()) return fail("boolean", w.status());
  // No surface point and no solid chunk: the mesh written will have no triangles.
  const bool empty = !w.value().solid_bounds().has_value();
  if (empty) {
    bar.finish();
    warn("boolean", "the result is empty: " + empty_reason(op.value()) + "; writing a mesh with no triangles to " +
                        a.mesh.output);
  }
  nlohmann::json report = {
      {"op", a.op},
      {"empty", empty},
      {"inputs", nlohmann::json::array({input_json(a.first, first.value(), builds[0]), input_json(a.second, second.value(), builds[1])})},
      {"seconds", {{"load", load}, {"build_boolean", b.seconds()}, {"stages", stage_seconds(*bar.context())}}}};
  return contour_and_report("boolean", w.value(), a.mesh, bar, std::move(report), common, print_inputs);
}

}  // namespace

void add_boolean_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<BooleanArgs>();
  args->mesh.max_error_cells = kAdaptiveMaxErrorCells;  // adaptive by default
  CLI::App* cmd = app.add_subcommand(
      "boolean", "Union, subtraction or intersection of two meshes on one lattice -> mesh, with the quality report");
  cmd->add_option("first", args->first, "Mesh file A (.obj .ply .stl .off)")->required();
  cmd->add_option("second", args->second, "Mesh file B (.obj .ply .stl .off)")->required();
  cmd->add_option("--op", args->op, "union | subtract (A minus B) | intersect (0.2's difference and intersection still work)")->required();
  cmd->add_option("--translate-b", args->translate_b,
                  "Move mesh B by x,y,z (m) after --scale-b, before the boolean (default 0,0,0)");
  cmd->add_option("--scale-b", args->scale_b,
                  "Scale mesh B uniformly about the origin by this factor (> 0) before the boolean (default 1)");
  add_grid_options(cmd, args->grid, "both meshes' joint bounds (B as placed)");
  cmd->add_option("--sliver", args->config.sliver, "Remove spans and gaps thinner than this (cells, 0 .. 0.5)")
      ->capture_default_str();
  cmd->add_option("--cut-material", args->config.cut_material,
                  "Material of surfaces a subtraction exposes (-1 = the material cut into)")
      ->capture_default_str();
  add_mesh_output_options(cmd, args->mesh);
  cmd->callback([args, &common] {
    int code = run_boolean(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
