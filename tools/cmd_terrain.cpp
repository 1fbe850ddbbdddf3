// ldc terrain: write the built-in default landscape.
#include <cstdio>
#include <memory>

#include "common.h"
#include "ldc/io.h"
#include "ldc/terrain.h"

namespace ldc::tool {
namespace {

struct TerrainArgs {
  std::string output = "default.ldc";
  TerrainConfig config;
  double cell_size = 0.2;
  int chunk = 32;
  bool validate = false;
};

int run_terrain(const TerrainArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  ProgressBar bar(!common.quiet);
  BuildReport report;
  Result<World> w = build_terrain(a.config, a.cell_size, a.chunk, bar.context(), &report);
  bar.finish();
  if (!w.ok()) return fail("terrain", w.status());
  Status s = save_world(w.value(), a.output);
  if (!s.ok()) return fail("terrain", s);
  nlohmann::json info = world_info_json(w.value(), a.validate);
  if (common.json) {
    std::printf("%s\n", nlohmann::json({{"output", a.output}, {"seconds", report.seconds}, {"info", info}}).dump(2).c_str());
  } else {
    std::printf("landscape (seed %u, %.0f x %.0f m, h = %g m) built in %.3f s -> %s\n%s", a.config.seed,
                a.config.size_x, a.config.size_y, a.cell_size, report.seconds, a.output.c_str(),
                world_info_text(info).c_str());
  }
  if (a.validate && !info["validation"]["ok"].get<bool>()) return 2;
  return 0;
}

}  // namespace

void add_terrain_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<TerrainArgs>();
  CLI::App* cmd = app.add_subcommand("terrain", "Write the default procedural landscape (caves, overhangs, arches)");
  cmd->add_option("-o,--output", args->output, "Output .ldc file")->capture_default_str();
  cmd->add_option("--seed", args->config.seed, "Landscape seed")->capture_default_str();
  cmd->add_option("--size-x", args->config.size_x, "Extent along x (m)")->capture_default_str();
  cmd->add_option("--size-y", args->config.size_y, "Extent along y (m)")->capture_default_str();
  cmd->add_option("--cell-size", args->cell_size, "Cell size h (m)")->capture_default_str();
  cmd->add_option("--chunk", args->chunk, "Chunk size in cells")->capture_default_str();
  cmd->add_flag("--validate", args->validate, "Validate the result (exit 2 if invalid)");
  cmd->callback([args, &common] {
    int code = run_terrain(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
