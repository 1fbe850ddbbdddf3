// ldc build: mesh, primitive, heightfield or landscape -> .ldc
#include <cstdio>
#include <memory>
#include <optional>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "common.h"
#include "ldc/io.h"
#include "ldc/terrain.h"
#include "meshio/meshio.h"

namespace ldc::tool {
namespace {

struct BuildArgs {
  std::string input;       // mesh file
  std::string primitive;   // sphere | box | capsule | cylinder
  std::string heightfield; // PNG
  bool terrain = false;
  std::string output;
  GridConfig grid;
  MeshReadingArgs reading;  // mesh input
  std::string up = "auto";  // the floor side of shells
  // primitive
  double radius = 1.0, half_height = 1.0;
  std::string half_extents = "1,1,1", translate = "0,0,0", scale = "1,1,1", axis = "0,0,1";
  double rotate_deg = 0.0;
  // heightfield
  double spacing = 0.2, height_scale = 10.0, base = 1.0, floor = 0.0;
  // terrain
  uint32_t seed = 1;
  std::string size = "48,48";
  bool validate = false;
};

Result<Primitive> primitive_from(const BuildArgs& a) {
  Primitive p;
  if (a.primitive == "sphere") p.shape = Primitive::Shape::kSphere;
  else if (a.primitive == "box") p.shape = Primitive::Shape::kBox;
  else if (a.primitive == "capsule") p.shape = Primitive::Shape::kCapsule;
  else if (a.primitive == "cylinder") p.shape = Primitive::Shape::kCylinder;
  else return Status(ErrorCode::kInvalidArgument, "unknown primitive '" + a.primitive + "' (sphere, box, capsule, cylinder)");
  p.radius = a.radius;
  p.half_height = a.half_height;
  glm::dvec3 t, s, ax;
  if (!parse_vec3(a.half_extents, &p.half_extents) || !parse_vec3(a.translate, &t) ||
      !parse_vec3(a.scale, &s) || !parse_vec3(a.axis, &ax)) {
    return Status(ErrorCode::kInvalidArgument, "vectors take the form x,y,z with finite numbers");
  }
  if (glm::length(ax) == 0.0) return Status(ErrorCode::kInvalidArgument, "--axis must not be zero");
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), t);
  m = glm::rotate(m, glm::radians(a.rotate_deg), glm::normalize(ax));
  p.transform = glm::scale(m, s);
  Status st = check_primitive(p);
  if (!st.ok()) return st;
  return p;
}

Result<World> build_world(const BuildArgs& a, Context* ctx, BuildReport* report) {
  int sources = !a.input.empty() + !a.primitive.empty() + !a.heightfield.empty() + a.terrain;
  if (sources != 1) {
    return Status(ErrorCode::kInvalidArgument,
                  "give exactly one input: a mesh file, --primitive, --heightfield or --terrain");
  }
  if (!a.input.empty()) {
    Result<int> up = parse_up_axis(a.up, 1);  // meshes: the Recast convention, y up
    if (!up.ok()) return up.status();
    Result<BuildConfig> config = mesh_build_config(a.reading, up.value());
    if (!config.ok()) return config.status();
    Result<TriangleMesh> mesh = load_mesh(a.input);
    if (!mesh.ok()) return mesh.status();
    Result<World> w = build_from_mesh(mesh.value(), a.grid, config.value(), ctx, report);
    if (w.ok()) w.value().set_metadata("source.file", a.input);
    return w;
  }
  if (!a.primitive.empty()) {
    Result<Primitive> p = primitive_from(a);
    if (!p.ok()) return p.status();
    return build_from_primitive(p.value(), a.grid, ctx, report);
  }
  if (!a.heightfield.empty()) {
    Result<Heightfield> f = load_heightfield_png(a.heightfield, a.spacing, a.height_scale, a.base, a.floor);
    if (!f.ok()) return f.status();
    return build_from_heightfield(f.value(), a.grid, ctx, report);
  }
  TerrainConfig tc;
  tc.seed = a.seed;
  std::vector<double> size;
  if (!parse_numbers(a.size, &size) || size.size() != 2) {
    return Status(ErrorCode::kInvalidArgument, "--size '" + a.size + "': expected two finite numbers X,Y (m)");
  }
  tc.size_x = size[0];
  tc.size_y = size[1];
  double h = a.grid.cell_size > 0.0 ? a.grid.cell_size : 0.2;
  return build_terrain(tc, h, a.grid.chunk_size, ctx, report);
}

nlohmann::json report_json(const BuildReport& r) {
  return {{"seconds", r.seconds},
          {"triangles", r.triangles},
          {"degenerate_triangles", r.degenerate_triangles},
          {"input_closed", r.input_closed},
          {"boundary_edges", r.boundary_edges},
          {"crossings", r.crossings},
          {"repaired_rays", r.repaired_rays},
          {"synthesized_points", r.synthesized_points},
          {"dropped_crossings", r.dropped_crossings},
          {"normal_flips", r.normal_flips},
          {"nudged_points", r.nudged_points},
          {"solid_components", r.solid_components},
          {"surface_components", r.surface_components},
          {"shell_triangles", r.shell_triangles}};
}

// What the build read, for the empty-result warning; the mesh's build mode.
std::string input_name(const BuildArgs& a) {
  if (!a.input.empty()) return a.input;
  if (!a.primitive.empty()) return "the " + a.primitive;
  if (!a.heightfield.empty()) return a.heightfield;
  return "the landscape";
}

std::optional<BuildMode> mesh_mode(const BuildArgs& a) {
  if (a.input.empty()) return std::nullopt;
  Result<BuildConfig> config = mesh_build_config(a.reading, 1);
  return config.ok() ? std::optional<BuildMode>(config.value().mode) : std::nullopt;
}

void print_text(const BuildArgs& a, const BuildReport& report, const nlohmann::json& out) {
  std::printf("built %s in %.3f s (%zu repaired rays)\n", a.output.c_str(), report.seconds,
              report.repaired_rays);
  if (report.surface_components) {
    std::printf("read %zu components as solids and %zu as shells (%zu triangles)\n",
                report.solid_components, report.surface_components, report.shell_triangles);
  }
  std::printf("%s", world_info_text(out["info"]).c_str());
}

int run_build(const BuildArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  ProgressBar bar(!common.quiet);
  BuildReport report;
  Result<World> w = build_world(a, bar.context(), &report);
  bar.finish();
  if (!w.ok()) return fail("build", w.status());
  // Validated before the save: an invalid world is never written (exit 2).
  nlohmann::json info = world_info_json(w.value(), a.validate, bar.context());
  if (refuse_invalid_world("build", info, a.output)) return kExitInvalid;
  const bool empty = warn_if_rasterized_empty("build", w.value(), input_name(a), mesh_mode(a));
  Status s = save_world(w.value(), a.output, {}, bar.context());
  bar.finish();
  if (!s.ok()) return fail("build", s);
  nlohmann::json out = {{"output", a.output}, {"empty", empty}, {"build", report_json(report)}, {"info", info}};
  out["build"]["stages"] = stage_seconds(*bar.context());
  if (common.json) std::printf("%s\n", json_text(with_warnings(out)).c_str());
  else print_text(a, report, out);
  return kExitSuccess;
}

}  // namespace

void add_build_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<BuildArgs>();
  CLI::App* cmd = app.add_subcommand("build", "Build an LDC from a mesh, primitive, heightfield or the landscape");
  cmd->add_option("input", args->input, "Mesh file (.obj .ply .stl .off)");
  output_file(cmd->add_option("-o,--output", args->output, "Output .ldc file"))->required();
  CLI::Option* cells =
      cmd->add_option("--cells", args->grid.cells, "Cells along the longest axis of the input")->capture_default_str();
  cmd->add_option("--cell-size", args->grid.cell_size, "Cell size h (m); overrides --cells");
  cmd->add_option("--chunk-size,--chunk", args->grid.chunk_size, "Chunk size in cells: 8, 16, 32 or 64")->capture_default_str();
  CLI::Option* padding =
      cmd->add_option("--padding", args->grid.padding, "Empty cells around the input")->capture_default_str();
  add_mesh_reading_options(cmd, args->reading, "solid");
  add_up_option(cmd, args->up, "y for a mesh (the Recast convention); sets which side of a shell is its floor");
  cmd->add_option("--primitive", args->primitive, "sphere | box | capsule | cylinder");
  cmd->add_option("--radius", args->radius, "Primitive radius (m)")->capture_default_str();
  cmd->add_option("--half-height", args->half_height, "Capsule/cylinder half height (m)")->capture_default_str();
  cmd->add_option("--half-extents", args->half_extents, "Box half extents x,y,z (m)")->capture_default_str();
  cmd->add_option("--translate", args->translate, "Primitive translation x,y,z (m)")->capture_default_str();
  cmd->add_option("--scale", args->scale, "Primitive scale x,y,z")->capture_default_str();
  cmd->add_option("--rotate", args->rotate_deg, "Primitive rotation about --axis (degrees)")->capture_default_str();
  cmd->add_option("--axis", args->axis, "Rotation axis x,y,z of --rotate")->capture_default_str();
  cmd->add_option("--heightfield", args->heightfield, "Grayscale PNG heightfield");
  cmd->add_option("--spacing", args->spacing, "Heightfield sample spacing (m)")->capture_default_str();
  cmd->add_option("--height-scale", args->height_scale, "Heightfield height of white (m)")->capture_default_str();
  cmd->add_option("--base", args->base, "Heightfield height of black (m)")->capture_default_str();
  cmd->add_option("--floor", args->floor, "Heightfield floor (m)")->capture_default_str();
  cmd->add_flag("--terrain", args->terrain, "The procedural landscape (default scene)");
  cmd->add_option("--seed", args->seed, "Landscape seed")->capture_default_str();
  cmd->add_option("--size", args->size, "Landscape size X,Y (m)")->capture_default_str();
  cmd->add_flag("--validate", args->validate, "Validate the result before writing it (exit 2 and no file if invalid)");
  cmd->callback([args, &common, cells, padding] {
    // The landscape's extent is --size and its cells --cell-size: say so
    // rather than ignore the options meant for meshes and primitives.
    if (args->terrain && (cells->count() > 0 || padding->count() > 0)) {
      throw CLI::RuntimeError(fail("build", std::string(cells->count() > 0 ? "--cells" : "--padding") +
                                                " does not apply to --terrain (its extent is --size X,Y and its "
                                                "cell size --cell-size)"));
    }
    int code = run_build(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
