// ldc voxelize: solid occupancy and the six-face G-buffer of a world -> .vdb, or raw arrays + JSON header.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "common.h"
#include "plugin.h"
#include "ldc/internal/vec_text.h"
#include "ldc/io.h"
#include "voxelize/vdb_plugin.h"
#include "voxelize/voxelize.h"

#if !defined(LDC_VDB_PLUGIN_FILE) || !defined(LDC_VDB_PLUGIN_INSTALL_REL) || !defined(LDC_VDB_PLUGIN_ABI)
#error "the OpenVDB plugin's file name, install path and ABI come from tools/CMakeLists.txt"
#endif

namespace ldc::tool {
namespace {

const char* const kVoxelizeHelp = R"(Without --cascades: one dense grid over the world's solid at --voxel-size (a whole
number of cells h). With --cascades K: K camera-centred levels of N^3 voxels (--resolution, default 32), level k of
voxel size s * 2^k, around --camera (default: the centre of the solid). Voxels have no up; --up sets the
default ray family (--ray-axis): the vertical rays, so that a y-up level gives the voxels of its z-up twin.
Output by extension: .vdb (OpenVDB grids occupancy, normal, albedo; per cascade level _L<k>), or .json / .raw
(both files are written: little-endian arrays in .raw, their names, types, shapes and offsets in .json).)";

struct VoxelizeArgs {
  std::string world;
  std::string output;
  double voxel_size = 0.0;
  int cascades = 0;
  int resolution = 32;
  std::string camera;
  std::string up = "auto";
  std::string axis;  // empty: the up axis
  bool occupancy_only = false;
};

enum class Format { kVdb, kRaw };

Result<Format> output_format(const std::string& path) {
  if (path.ends_with(".vdb")) return Format::kVdb;
  if (path.ends_with(".json") || path.ends_with(".raw")) return Format::kRaw;
  return Status(ErrorCode::kInvalidArgument, "-o " + path + ": unknown output format (use .vdb, .json or .raw)");
}

// The ray family: --ray-axis, or the up axis (the library's default, z, is
// the vertical of a z-up world: a y-up level then voxelizes as its z-up twin).
Result<int> ray_axis(const VoxelizeArgs& a) {
  Result<int> up = parse_up_axis(a.up, kLdcUpAxis);
  if (!up.ok() || a.axis.empty()) return up;
  if (a.axis == "x" || a.axis == "y" || a.axis == "z") return a.axis[0] - 'x';
  return Status(ErrorCode::kInvalidArgument, "--ray-axis '" + a.axis + "': use x, y or z");
}

// --- The OpenVDB plugin ----------------------------------------------------
// OpenVDB is not linked into the tool: relocating libopenvdb cost every
// command ~60 ms at start-up. It is dlopen()ed here, only for a .vdb output.

// The loaded plugin (a struct: GCC's -Wshadow flags Result<> of a bare
// function pointer, whose constructor argument "value" may be called).
struct VdbPlugin {
  LdcVdbWriteFn write = nullptr;
};

// Beside the tool (the build tree), then the install layout (<libdir>/ldc):
// tools/plugin.h.
Result<VdbPlugin> load_vdb_plugin() {
  const PluginSpec spec{LDC_VDB_PLUGIN_FILE, LDC_VDB_PLUGIN_INSTALL_REL, "OpenVDB", "ldc_vdb_plugin_abi",
                        LDC_VDB_PLUGIN_ABI, {"ldc_vdb_plugin_write"}, nullptr, 0};
  Result<LoadedPlugin> plugin = load_plugin(spec);
  if (plugin.ok()) return VdbPlugin{reinterpret_cast<LdcVdbWriteFn>(plugin.value().symbols[0])};
  return Status(ErrorCode::kUnsupported, std::string("a .vdb output needs the OpenVDB plugin " LDC_VDB_PLUGIN_FILE
                                                     ", which did not load (tried ") +
                                             plugin.status().message() +
                                             "). Write .json or .raw instead: they need no OpenVDB");
}

// Loaded once, on the first .vdb output.
const Result<VdbPlugin>& vdb_plugin() {
  static const Result<VdbPlugin> plugin = load_vdb_plugin();
  return plugin;
}

void keep_message(void* user, const char* message) noexcept {
  try {
    *static_cast<std::string*>(user) = message;
  } catch (...) {  // out of memory: the caller's fallback message stands
  }
}

// ldc::save_vdb through the plugin: the same files and the same messages.
Status write_vdb(const std::vector<LdcVdbGrid>& grids, const std::string& path, const std::string& source) {
  const Result<VdbPlugin>& plugin = vdb_plugin();
  if (!plugin.ok()) return plugin.status();
  std::string message = path + ": the OpenVDB plugin failed without a message";
  const int code = plugin.value().write(grids.data(), grids.size(), sizeof(VoxelGrid), path.c_str(),
                                        source.c_str(), keep_message, &message);
  return code == 0 ? Status() : Status(static_cast<ErrorCode>(code), message);
}

Status write_vdb(const VoxelGrid& grid, const std::string& path, const std::string& source) {
  const LdcVdbGrid one{&grid, ""};
  return write_vdb(std::vector<LdcVdbGrid>{one}, path, source);
}

// Every valid level as occupancy_L<k>, normal_L<k>, albedo_L<k> (as
// ldc::save_vdb(const Cascades&, ...)).
Status write_vdb(const Cascades& cascades, const std::string& path, const std::string& source) {
  const std::vector<NamedLevelGrid> levels = valid_level_grids(cascades);
  std::vector<LdcVdbGrid> grids;
  for (const NamedLevelGrid& l : levels) grids.push_back({&l.grid, l.suffix.c_str()});
  return write_vdb(grids, path, source);
}

nlohmann::json box_json(const VoxelBox& b) {
  return {{"lo", {b.lo.x, b.lo.y, b.lo.z}}, {"dims", {b.dims.x, b.dims.y, b.dims.z}}};
}

Result<nlohmann::json> run_dense(const VoxelizeArgs& a, const World& world, int axis, Format format, Context* ctx) {
  VoxelizeOptions opt;
  opt.faces = !a.occupancy_only;
  VoxelStats stats;
  Result<VoxelGrid> g = voxelize(world, VoxelConfig{.voxel_size = a.voxel_size, .axis = axis}, opt, ctx, &stats);
  if (!g.ok()) return g.status();
  Status s = format == Format::kVdb ? write_vdb(g.value(), a.output, a.world) : save_raw(g.value(), a.output);
  if (!s.ok()) return s;
  return nlohmann::json{{"mode", "dense"},
                        {"voxel_size", a.voxel_size},
                        {"box", box_json(g.value().box)},
                        {"voxels", stats.voxels},
                        {"surface_voxels", stats.surface_voxels},
                        {"volume_m3", g.value().volume()},
                        {"world_volume_m3", world.volume(axis)},
                        {"chunk_columns_closed", stats.chunk_columns_closed},
                        {"chunk_columns_walked", stats.chunk_columns_walked},
                        {"rays_walked", stats.rays_walked},
                        {"voxelize_seconds", stats.seconds}};
}

Result<nlohmann::json> run_cascades(const VoxelizeArgs& a, const World& world, int axis, Format format, Context* ctx) {
  glm::dvec3 camera(0.0);
  if (!a.camera.empty()) {
    if (!parse_vec3(a.camera, &camera)) {
      return Status(ErrorCode::kInvalidArgument, "--camera '" + a.camera + "': expected three finite numbers x,y,z");
    }
  } else if (auto b = world.solid_bounds()) {
    camera = 0.5 * (b->min + b->max);
  }
  CascadeConfig cfg;
  cfg.levels = a.cascades;
  cfg.resolution = a.resolution;
  cfg.voxel_size = a.voxel_size;
  cfg.axis = axis;
  Result<Cascades> c = Cascades::create(world.lattice(), cfg);
  if (!c.ok()) return c.status();
  const auto start = std::chrono::steady_clock::now();
  Status s = c.value().update_all(world, camera, ctx);
  if (!s.ok()) return s;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  s = format == Format::kVdb ? write_vdb(c.value(), a.output, a.world) : save_raw(c.value(), a.output);
  if (!s.ok()) return s;
  nlohmann::json levels = nlohmann::json::array();
  for (int k = 0; k < c.value().levels(); ++k) {
    levels.push_back({{"voxel_size", c.value().voxel_size(k)}, {"box", box_json(c.value().level_box(k))}});
  }
  return nlohmann::json{{"mode", "cascades"},
                        {"camera", {camera.x, camera.y, camera.z}},
                        {"resolution", a.resolution},
                        {"levels", levels},
                        {"texture_bytes", c.value().texture().bytes()},
                        {"voxelize_seconds", seconds}};
}

void print_text(const nlohmann::json& j) {
  if (j["mode"] == "dense") {
    const auto& b = j["box"]["dims"];
    std::printf("voxelize: %d x %d x %d voxels of %g m, %zu surface voxels, volume %.6g m^3 (spans: %.6g), %.3f s\n",
                b[0].get<int>(), b[1].get<int>(), b[2].get<int>(), j["voxel_size"].get<double>(),
                j["surface_voxels"].get<size_t>(), j["volume_m3"].get<double>(), j["world_volume_m3"].get<double>(),
                j["voxelize_seconds"].get<double>());
    std::printf("chunk columns: %zu closed form or empty, %zu walked (%zu rays)\n",
                j["chunk_columns_closed"].get<size_t>(), j["chunk_columns_walked"].get<size_t>(),
                j["rays_walked"].get<size_t>());
  } else {
    std::printf("voxelize: %zu cascade levels of %d^3 voxels around %s, %.3f s\n", j["levels"].size(),
                j["resolution"].get<int>(), detail::vec_text({j["camera"][0].get<double>(), j["camera"][1].get<double>(),
                                                               j["camera"][2].get<double>()}).c_str(),
                j["voxelize_seconds"].get<double>());
    for (size_t k = 0; k < j["levels"].size(); ++k) {
      std::printf("  level %zu: voxel %g m\n", k, j["levels"][k]["voxel_size"].get<double>());
    }
  }
  std::printf("wrote %s\n", j["output"].get<std::string>().c_str());
}

int run_voxelize(const VoxelizeArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  Result<Format> format = output_format(a.output);
  if (!format.ok()) return fail("voxelize", format.status());
  Result<int> axis = ray_axis(a);
  if (!axis.ok()) return fail("voxelize", axis.status());
  if (a.cascades < 0) return fail("voxelize", "--cascades " + std::to_string(a.cascades) + ": must be >= 0 (0: one dense grid)");
  if (a.cascades == 0 && !a.camera.empty()) return fail("voxelize", "--camera needs --cascades K");
  // A missing plugin is found before the (maybe long) voxelization.
  if (format.value() == Format::kVdb && !vdb_plugin().ok()) return fail("voxelize", vdb_plugin().status().message());
  Result<World> world = load_world_file(a.world);
  if (!world.ok()) return fail("voxelize", world.status());
  ProgressBar bar(!common.quiet);
  Result<nlohmann::json> j = a.cascades > 0 ? run_cascades(a, world.value(), axis.value(), format.value(), bar.context())
                                            : run_dense(a, world.value(), axis.value(), format.value(), bar.context());
  bar.finish();
  if (!j.ok()) return fail("voxelize", j.status());
  j.value()["ok"] = true;
  j.value()["input"] = a.world;
  j.value()["output"] = a.output;
  j.value()["threads"] = thread_count();
  j.value()["ray_axis"] = axis_name(axis.value());
  if (common.json) {
    std::printf("%s\n", json_text(j.value()).c_str());
  } else {
    print_text(j.value());
  }
  return 0;
}

}  // namespace

void add_voxelize_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<VoxelizeArgs>();
  CLI::App* cmd = app.add_subcommand("voxelize", "Solid occupancy and the six-face G-buffer -> .vdb or raw + JSON");
  cmd->footer(kVoxelizeHelp);
  cmd->add_option("world", args->world, "Input .ldc file")->required();
  output_file(cmd->add_option("-o,--output", args->output, "Output .vdb, .json or .raw"))->required();
  cmd->add_option("--voxel-size", args->voxel_size, "Voxel edge (m): a whole number of cells h")->required();
  cmd->add_option("--cascades", args->cascades, "Camera-centred cascade levels K (0 = one dense grid)");
  cmd->add_option("--resolution", args->resolution, "Voxels per axis of each cascade level")->capture_default_str();
  cmd->add_option("--camera", args->camera, "Cascade centre x,y,z (m); default: the centre of the solid");
  add_up_option(cmd, args->up, "z (an .ldc world records no up axis)");
  cmd->add_option("--ray-axis,--axis", args->axis, "Ray family integrated for the occupancy: x, y or z (default: the up axis)");
  cmd->add_flag("--occupancy-only", args->occupancy_only, "Dense grid: occupancy only, no normal/albedo (faster)");
  cmd->callback([args, &common] {
    int code = run_voxelize(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
