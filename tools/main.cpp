// The ldc command-line tool: one subcommand per capability.
#include <cstdio>
#include <exception>
#include <new>

#include "common.h"
#include "ldc/io.h"
#include "ldc/version.h"

int main(int argc, char** argv) {
  CLI::App app{"ldc: Layered Depth Cube geometry kernel (format version " +
               std::to_string(ldc::kLdcFormatVersion) + ")"};
  app.require_subcommand(1);
  app.fallthrough();  // global flags may follow the subcommand
  app.set_version_flag("--version", std::string("ldc ") + LDC_VERSION_STRING + " (.ldc format version " +
                                        std::to_string(ldc::kLdcFormatVersion) + ")");
  ldc::tool::CommonOptions common;
  app.add_flag("--json", common.json, "Machine-readable JSON on stdout");
  app.add_flag("-q,--quiet", common.quiet, "No progress bar");
  app.add_option("--threads", common.threads, "Worker threads (0 = all cores)");
  ldc::tool::add_build_command(app, common);
  ldc::tool::add_info_command(app, common);
  ldc::tool::add_inside_command(app, common);
  ldc::tool::add_terrain_command(app, common);
  ldc::tool::add_contour_commands(app, common);
  ldc::tool::add_boolean_command(app, common);
  ldc::tool::add_edit_command(app, common);
  ldc::tool::add_raycast_command(app, common);
  ldc::tool::add_render_command(app, common);
  ldc::tool::add_gi_command(app, common);
  ldc::tool::add_path_command(app, common);
  ldc::tool::add_voxelize_command(app, common);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "ldc: out of memory\n");
    return 1;
  } catch (const std::exception& e) {  // never an abort: name what went wrong
    std::fprintf(stderr, "ldc: internal error: %s\n", e.what());
    return 1;
  }
  return 0;
}
