// ldc info: what a .ldc file holds, and whether it is valid; what a .ldcs store holds.
#include <cstdio>
#include <memory>

#include "cmd_store.h"
#include "common.h"
#include "ldc/io.h"

namespace ldc::tool {
namespace {

struct InfoArgs {
  std::string input;
  bool no_validate = false;
};

// A store: its base, layout and log, without generating any chunk.
int run_store_info(const InfoArgs& a, const CommonOptions& common) {
  Result<Store> store = open_store(a.input);
  if (!store.ok()) return fail("info", store.status());
  nlohmann::json info = store_info_json(store.value(), a.input);
  if (common.json) std::printf("%s\n", json_text(info).c_str());
  else std::printf("%s", store_info_text(info).c_str());
  return kExitSuccess;
}

int run_info(const InfoArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  if (is_store_file(a.input)) return run_store_info(a, common);  // by its magic, whatever its name
  ProgressBar bar(!common.quiet);
  LoadLimits limits;
  limits.validate_world = !a.no_validate;  // --no-validate skips every optional check, the loader's too
  Result<World> w = load_world(a.input, limits, bar.context());
  if (!w.ok()) return fail("info", w.status());
  nlohmann::json info = world_info_json(w.value(), !a.no_validate, bar.context());
  bar.finish();
  info["file"] = a.input;
  if (common.json) std::printf("%s\n", json_text(info).c_str());
  else std::printf("file        %s\n%s", a.input.c_str(), world_info_text(info).c_str());
  if (!a.no_validate && !info["validation"]["ok"].get<bool>()) return kExitInvalid;
  return kExitSuccess;
}

}  // namespace

void add_info_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand("info", "Chunks, rays, points, memory, repairs and validation of a .ldc file; base, chunk box and log of a .ldcs store");
  cmd->add_option("input", args->input, ".ldc file or .ldcs store")->required();
  cmd->add_flag("--no-validate", args->no_validate, "Skip the full invariant check and the loader's world-wide one (each chunk is still checked)");
  cmd->callback([args, &common] {
    int code = run_info(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
