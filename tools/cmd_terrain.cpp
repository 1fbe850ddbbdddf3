// ldc terrain: write the built-in default landscape, as a .ldc world or as a .ldcs store.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cmd_store.h"
#include "common.h"
#include "ldc/io.h"
#include "ldc/terrain.h"

namespace ldc::tool {
namespace {

struct TerrainArgs {
  std::string output = "default.ldc";
  TerrainConfig config;
  std::string size;  // --size X,Y; empty = --size-x / --size-y (or the defaults)
  double cell_size = 0.2;
  int chunk = 32;
  bool validate = false;
  bool overwrite = false;  // .ldcs only: replace an existing store
};

// -o X.ldcs: a store of the landscape, generated chunk by chunk when read
// (instant, and its memory does not depend on the size). A store holds edits,
// so an existing one is replaced only with --overwrite.
int run_terrain_store(const TerrainArgs& a, const CommonOptions& common) {
  if (a.validate) {
    return fail("terrain", "--validate checks a built world; a .ldcs store (" + a.output +
                               ") generates its chunks when they are read");
  }
  ScopedTimer t(nullptr, "");
  Result<Store> store = create_terrain_store(a.output, a.config, a.cell_size, a.chunk, a.overwrite);
  if (!store.ok()) {
    if (!a.overwrite && store.status().code() == ErrorCode::kIoError && std::filesystem::exists(a.output)) {
      return fail("terrain", a.output + " exists: a store holds edits; pass --overwrite to replace it");
    }
    return fail("terrain", store.status());
  }
  const double seconds = t.seconds();
  nlohmann::json info = store_info_json(store.value(), a.output);
  if (common.json) {
    std::printf("%s\n", json_text({{"output", a.output}, {"seconds", seconds}, {"info", info}}).c_str());
  } else {
    std::printf("landscape store (seed %u, %g x %g m, h = %g m) written in %.3f s -> %s\n%s", a.config.seed,
                a.config.size_x, a.config.size_y, a.cell_size, seconds, a.output.c_str(),
                store_info_text(info).c_str());
  }
  return kExitSuccess;
}

int run_terrain(TerrainArgs a, const CommonOptions& common) {
  set_thread_count(common.threads);
  if (!a.size.empty()) {
    std::vector<double> v;
    if (!parse_numbers(a.size, &v) || v.size() != 2) {
      return fail("terrain", "--size '" + a.size + "': expected two finite numbers X,Y (m)");
    }
    a.config.size_x = v[0];
    a.config.size_y = v[1];
  }
  if (has_ldcs_extension(a.output)) return run_terrain_store(a, common);
  ProgressBar bar(!common.quiet);
  BuildReport report;
  Result<World> w = build_terrain(a.config, a.cell_size, a.chunk, bar.context(), &report);
  bar.finish();
  if (!w.ok()) return fail("terrain", w.status());
  nlohmann::json info = world_info_json(w.value(), a.validate, bar.context());
  if (refuse_invalid_world("terrain", info, a.output)) return kExitInvalid;  // never written
  Status s = save_world(w.value(), a.output, {}, bar.context());
  bar.finish();
  if (!s.ok()) return fail("terrain", s);
  if (common.json) {
    std::printf("%s\n", json_text({{"output", a.output}, {"seconds", report.seconds}, {"info", info}}).c_str());
  } else {
    std::printf("landscape (seed %u, %.0f x %.0f m, h = %g m) built in %.3f s -> %s\n%s", a.config.seed,
                a.config.size_x, a.config.size_y, a.cell_size, report.seconds, a.output.c_str(),
                world_info_text(info).c_str());
  }
  return kExitSuccess;
}

}  // namespace

void add_terrain_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<TerrainArgs>();
  CLI::App* cmd = app.add_subcommand("terrain", "Write the default procedural landscape (caves, overhangs, arches)");
  cmd->add_option("-o,--output", args->output,
                  "Output .ldc file; a name ending in .ldcs writes a store instead (chunks generated when read)")
      ->capture_default_str();
  cmd->add_flag("--overwrite", args->overwrite, "Replace an existing .ldcs store (a .ldc output is always replaced)");
  cmd->add_option("--seed", args->config.seed, "Landscape seed")->capture_default_str();
  char size_default[64];
  std::snprintf(size_default, sizeof(size_default), "%g,%g", args->config.size_x, args->config.size_y);
  CLI::Option* size = cmd->add_option("--size", args->size, "Landscape size X,Y (m)")->default_str(size_default);
  // Deprecated spellings of --size, kept working (hidden from the help).
  CLI::Option* size_x = cmd->add_option("--size-x", args->config.size_x, "Extent along x (m); use --size X,Y")->group("");
  CLI::Option* size_y = cmd->add_option("--size-y", args->config.size_y, "Extent along y (m); use --size X,Y")->group("");
  cmd->add_option("--cell-size", args->cell_size, "Cell size h (m)")->capture_default_str();
  cmd->add_option("--chunk-size,--chunk", args->chunk, "Chunk size in cells: 8, 16, 32 or 64")->capture_default_str();
  cmd->add_flag("--validate", args->validate, "Validate the result before writing it (exit 2 and no file if invalid)");
  cmd->callback([args, &common, size, size_x, size_y] {
    if (size->count() > 0 && (size_x->count() > 0 || size_y->count() > 0)) {
      throw CLI::RuntimeError(fail("terrain", "give --size X,Y or the deprecated --size-x / --size-y, not both"));
    }
    int code = run_terrain(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
