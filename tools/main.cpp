// The ldc command-line tool: one subcommand per capability. A command-line
// error exits 1 with its message after "ldc: " (issue 24), as other errors do.
// Exit codes (0 success, 1 error, 2 invalid result, 3 a warning under
// --strict): tools/common.h, and the footer of --help.
#include <cstdio>
#include <exception>
#include <iostream>
#include <new>
#include <sstream>
#include <string>
#include <string_view>

#include "cmd_store.h"  // add_compact_command (.ldcs stores, issue 21)
#include "common.h"
#include "ldc/io.h"
#include "ldc/version.h"

namespace ldc::tool {
void add_bake_command(CLI::App& app, CommonOptions& common);  // tools/cmd_bake.cpp (issue 23)
}  // namespace ldc::tool

namespace {

// A command-line error exits 1 (the documented "error" status, not CLI11's
// 104-109), its message prefixed "ldc: " like every other error. --help and
// --version (exit 0) and a subcommand's own exit status pass through.
int parse_error_exit(const CLI::App& app, const CLI::ParseError& e) {
  if (e.get_exit_code() == 0 || e.get_name() == "RuntimeError") return app.exit(e);
  std::ostringstream message;
  app.exit(e, std::cout, message);
  std::fprintf(stderr, "ldc: %s", message.str().c_str());
  return 1;
}

std::string version_text() {
  return std::string("ldc ") + LDC_VERSION_STRING + " (.ldc format version " +
         std::to_string(ldc::kLdcFormatVersion) + ")";
}

}  // namespace

int main(int argc, char** argv) {
  // `ldc --version` alone answers before the command line is built: the
  // options of every command (needed for --help and parsing) cost about as
  // much as the rest of the tool's start-up (issue 22). The same output.
  if (argc == 2 && std::string_view(argv[1]) == "--version") {
    const bool written = std::printf("%s\n", version_text().c_str()) >= 0 && std::fflush(stdout) == 0;
    return written ? ldc::tool::kExitSuccess : 1;
  }
  CLI::App app{"ldc: Layered Depth Cube geometry kernel (format version " +
               std::to_string(ldc::kLdcFormatVersion) + ")"};
  app.require_subcommand(1);
  app.fallthrough();  // global flags may follow the subcommand
  app.set_version_flag("--version", version_text());
  ldc::tool::CommonOptions common;
  app.add_flag("--json", common.json, "Machine-readable JSON on stdout");
  app.add_flag("-q,--quiet", common.quiet, "No progress bar");
  app.add_option("--threads", common.threads, "Worker threads (0 = all cores)")->check(CLI::Range(0, 4096));
  app.add_flag("--strict", common.strict,
               "Exit 3 when the command printed a warning (its output is still written)");
  app.footer(ldc::tool::kExitStatusHelp);
  ldc::tool::add_build_command(app, common);
  ldc::tool::add_info_command(app, common);
  ldc::tool::add_inside_command(app, common);
  ldc::tool::add_terrain_command(app, common);
  ldc::tool::add_contour_commands(app, common);
  ldc::tool::add_boolean_command(app, common);
  ldc::tool::add_edit_command(app, common);
  ldc::tool::add_compact_command(app, common);
  ldc::tool::add_raycast_command(app, common);
  ldc::tool::add_render_command(app, common);
  ldc::tool::add_gi_command(app, common);
  ldc::tool::add_path_command(app, common);
  ldc::tool::add_voxelize_command(app, common);
  ldc::tool::add_bake_command(app, common);
  for (CLI::App* command : app.get_subcommands({})) {  // after a command's own footer, if any
    // (a command without one has inherited the app's, which is this already)
    const std::string own = command->get_footer();
    const bool inherited = own.empty() || own == ldc::tool::kExitStatusHelp;
    command->footer(inherited ? ldc::tool::kExitStatusHelp : own + "\n" + ldc::tool::kExitStatusHelp);
    // Runs once the command line is parsed, before the command: no output over an input.
    command->parse_complete_callback([command] {
      const std::string clash = ldc::tool::output_clash(*command);
      if (!clash.empty()) throw CLI::RuntimeError(ldc::tool::fail(command->get_name(), clash));
    });
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return parse_error_exit(app, e);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "ldc: out of memory\n");
    return 1;
  } catch (const std::exception& e) {  // never an abort: name what went wrong
    std::fprintf(stderr, "ldc: internal error: %s\n", e.what());
    return 1;
  }
  // Only a command that succeeded gets here: its warnings decide under --strict.
  if (common.strict && !ldc::tool::warnings().empty()) return ldc::tool::kExitWarning;
  return ldc::tool::kExitSuccess;
}
