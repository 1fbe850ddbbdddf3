// Shared pieces of the ldc command-line tool: progress bar, errors, warnings,
// JSON output.
//
// Exit status of every command (issue 24; `ldc --help` prints the same):
//   0  success (warnings, if any, were printed on stderr)
//   1  error: nothing usable was written (bad arguments, unreadable input,
//      refused lattice, write failure, out of memory, internal error)
//   2  invalid result: --validate found errors (build, terrain and edit then
//      write nothing; info reports a file that is already there)
//   3  a warning under --strict: the command finished and wrote its output
//      as it would without --strict, but printed a warning (for example a
//      non-empty input that rasterizes to nothing, an empty boolean result)
// An error outranks a warning: a command that warns and then fails exits 1.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "ldc/build.h"
#include "ldc/context.h"
#include "ldc/io.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc::tool {

// Options every command shares.
struct CommonOptions {
  bool json = false;       // machine-readable output on stdout
  bool quiet = false;      // no progress bar
  int threads = 0;         // 0 = all cores
  bool strict = false;     // a warning exits kExitWarning
};

inline constexpr int kExitSuccess = 0;
inline constexpr int kExitError = 1;
inline constexpr int kExitInvalid = 2;
inline constexpr int kExitWarning = 3;
// The exit codes above, for --help.
extern const char* const kExitStatusHelp;

// A Context whose progress callback draws a bar on stderr once the work has
// taken more than a second (redrawn in place on a terminal, one line per 10%
// otherwise). A ticker thread redraws the current stage every half second, so
// a stage that reports nothing for a while still shows its time running
// (issue 24: 'load 90%' sat still through 36 s of validation). fail() and
// warn() end the bar's line before printing (an error was glued onto it).
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  Context* context() { return &ctx_; }
  // Ends the bar's line; a later report starts a new one.
  void finish();

 private:
  void report(std::string_view stage, double fraction);
  void draw_locked();
  void tick();
  Context ctx_;
  bool enabled_;
  bool tty_;
  std::mutex mutex_;  // guards everything below
  std::condition_variable wake_;
  bool stop_ = false;
  bool active_ = false;  // a stage reported since the last finish()
  std::string stage_;
  double fraction_ = 0.0;
  bool drawn_ = false;
  int last_decile_ = -1;
  std::string last_stage_;
  int last_percent_ = -1;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_{};
  std::thread ticker_;
};

// Prints "ldc <command>: <message>" on stderr; returns the exit status for it.
int fail(const std::string& command, const Status& status);
int fail(const std::string& command, const std::string& message);

// Prints "ldc <command>: warning: <message>" on stderr (after the progress
// bar's line) and records it: warnings() lists it, with_warnings adds it to
// --json output, and under --strict main() exits kExitWarning.
void warn(const std::string& command, const std::string& message);
const std::vector<std::string>& warnings();
// `report` with "warnings": [...] added when any were printed.
nlohmann::json with_warnings(nlohmann::json report);

// Issue 24: a non-empty input whose world holds no solid. Warns, naming the
// cell size and what would keep it (for a mesh read in `mesh_mode` solid:
// --mode auto or surface, which keep sheets as shells); returns whether it warned.
bool warn_if_rasterized_empty(const std::string& command, const World& world, const std::string& input,
                              std::optional<BuildMode> mesh_mode);

// Marks `option` as naming a file the command writes; returns it. Before the
// command runs, main() refuses a command line where a marked option names
// the same file (same device and inode, so through links too) as another
// option of that command: `ldc build model.obj -o model.obj` overwrote the
// model (issue 24). .ldcs stores are edited in place without -o.
CLI::Option* output_file(CLI::Option* option);
// That check for a parsed command: the message naming both options and the
// file, or empty when no output is also an input or another output.
std::string output_clash(const CLI::App& command);

// Reading JSON input files: json_inputs.h.

// Whether a path ends in .ldc (any case).
bool has_ldc_extension(const std::string& path);
// Whether the file starts with a chunk log's magic "LDCS" (a .ldcs store,
// ldc/chunk_log.h), whatever its name; false when it cannot be read.
bool is_store_file(const std::string& path);
// load_world, but a .ldcs store is refused (kInvalidArgument) with a message
// that names the file and the commands that read stores, before any of it is read.
Result<World> load_world_file(const std::string& path, const LoadLimits& limits = {}, Context* ctx = nullptr);

// --up, the world's up axis, shared by render, gi, voxelize and path: x, y or
// z; "auto" (the default) is the input's convention, `auto_means` in the help.
// An .ldc world records no up axis (no command writes one in its metadata):
// for it, auto is z (kLdcUpAxis).
inline constexpr int kLdcUpAxis = 2;
void add_up_option(CLI::App* cmd, std::string& up, const std::string& auto_means);
// "x" 0, "y" 1, "z" 2, "auto" `auto_axis`; anything else is refused, naming it.
Result<int> parse_up_axis(const std::string& text, int auto_axis);
// --mode and --shell-thickness of build and path: how a mesh's triangles
// become a solid (BuildConfig in ldc/build.h). `mode` is the option's text.
struct MeshReadingArgs {
  std::string mode;
  double shell_thickness = 0.0;
};
void add_mesh_reading_options(CLI::App* cmd, MeshReadingArgs& args, const std::string& default_mode);
// The BuildConfig those options give, with the up axis; refuses an unknown mode, naming it.
Result<BuildConfig> mesh_build_config(const MeshReadingArgs& args, int up_axis);

// "x", "y" or "z" for an axis 0, 1 or 2 (JSON output).
std::string axis_name(int axis);

// [x, y, z] for JSON output.
nlohmann::json vec_json(const glm::dvec3& v);

// The JSON text of a report (indent as nlohmann's dump; -1 = one line).
// Strings that are not valid UTF-8 (file names, metadata read from a file)
// have their bad bytes replaced by U+FFFD instead of aborting the tool.
std::string json_text(const nlohmann::json& j, int indent = 2);

// "1,2.5,3" -> finite numbers; false when malformed.
bool parse_numbers(const std::string& text, std::vector<double>* out);
// "1,2,3" -> vector; false when malformed.
bool parse_vec3(const std::string& text, glm::dvec3* out);

// The world's statistics and validation as JSON (what `ldc info --json` prints).
nlohmann::json world_info_json(const World& world, bool run_validate, Context* ctx = nullptr);
// The same, as human-readable lines.
std::string world_info_text(const nlohmann::json& info);

// validate() as JSON {"ok", "errors", "nodes_checked", "messages"}, and as text.
nlohmann::json validation_json(const World& world, Context* ctx = nullptr);
std::string validation_text(const nlohmann::json& validation);

// --validate before a save: when `info` (world_info_json with validation)
// says invalid, prints "ldc <command>: the world is invalid; <output> not
// written" and the validation, and returns true (the caller exits kExitInvalid).
bool refuse_invalid_world(const std::string& command, const nlohmann::json& info, const std::string& output);

// "  <stage>: <seconds> s", one line per entry of a {"stage": seconds} object.
void print_seconds(const nlohmann::json& seconds);
// The library's stage timers a Context gathered (Context::timers), for --json.
nlohmann::json stage_seconds(const Context& ctx);

// Limits the TBB worker threads for the rest of the process (0 = all).
void set_thread_count(int threads);
// The worker threads TBB may use now.
int thread_count();

// Registers the subcommands.
void add_build_command(CLI::App& app, CommonOptions& common);
void add_info_command(CLI::App& app, CommonOptions& common);
void add_inside_command(CLI::App& app, CommonOptions& common);
void add_terrain_command(CLI::App& app, CommonOptions& common);
void add_contour_commands(CLI::App& app, CommonOptions& common);
void add_boolean_command(CLI::App& app, CommonOptions& common);
void add_edit_command(CLI::App& app, CommonOptions& common);
void add_raycast_command(CLI::App& app, CommonOptions& common);
void add_render_command(CLI::App& app, CommonOptions& common);
void add_gi_command(CLI::App& app, CommonOptions& common);
void add_path_command(CLI::App& app, CommonOptions& common);
void add_voxelize_command(CLI::App& app, CommonOptions& common);

}  // namespace ldc::tool
