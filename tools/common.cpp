#include "common.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include <tbb/global_control.h>

#include "ldc/internal/validate_work.h"
#include "ldc/internal/vec_text.h"

namespace ldc::tool {

namespace {
// The bar of the running command (one per process), ended before a message.
std::atomic<ProgressBar*> active_bar{nullptr};
}  // namespace

ProgressBar::ProgressBar(bool enabled)
    : enabled_(enabled), tty_(isatty(STDERR_FILENO)), start_(std::chrono::steady_clock::now()) {
  if (!enabled_) return;
  ctx_.set_progress([this](std::string_view stage, double fraction) { report(stage, fraction); });
  ProgressBar* none = nullptr;
  active_bar.compare_exchange_strong(none, this);
  ticker_ = std::thread([this] { tick(); });
}

ProgressBar::~ProgressBar() {
  if (ticker_.joinable()) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    ticker_.join();
  }
  ProgressBar* self = this;
  active_bar.compare_exchange_strong(self, nullptr);
  finish();
}

void ProgressBar::report(std::string_view stage, double fraction) {
  std::lock_guard<std::mutex> lock(mutex_);
  active_ = true;
  stage_.assign(stage);
  fraction_ = fraction;
  draw_locked();
}

void ProgressBar::tick() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    wake_.wait_for(lock, std::chrono::milliseconds(500));
    if (!stop_ && active_) draw_locked();
  }
}

void ProgressBar::draw_locked() {
  const auto now = std::chrono::steady_clock::now();
  double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < 1.0) return;  // short work gets no bar
  int decile = int(fraction_ * 10.0), percent = int(fraction_ * 100.0);
  if (!tty_ && stage_ == last_stage_ && decile == last_decile_) return;
  // On a terminal: a new stage or percentage at once, the time at most 5 times a second.
  if (tty_ && stage_ == last_stage_ && percent == last_percent_ && now - last_draw_ < std::chrono::milliseconds(200)) return;
  last_stage_ = stage_;
  last_decile_ = decile;
  last_percent_ = percent;
  last_draw_ = now;
  const int width = 30;
  int filled = int(std::lround(fraction_ * width));
  std::string bar(size_t(filled), '#');
  bar.resize(width, '.');
  std::fprintf(stderr, "%s%-10.*s [%s] %3d%%  %.1fs%s", tty_ ? "\r" : "", int(stage_.size()),
               stage_.data(), bar.c_str(), int(fraction_ * 100.0), elapsed, tty_ ? "" : "\n");
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (drawn_ && tty_) std::fprintf(stderr, "\n");
  drawn_ = false;
  active_ = false;
}

namespace {
void end_progress_line() {
  if (ProgressBar* bar = active_bar.load()) bar->finish();
}
}  // namespace

int fail(const std::string& command, const Status& status) {
  return fail(command, status.to_string());
}

int fail(const std::string& command, const std::string& message) {
  end_progress_line();
  std::fprintf(stderr, "ldc %s: %s\n", command.c_str(), message.c_str());
  return 1;
}

namespace {
std::vector<const CLI::Option*>& output_options() {
  static std::vector<const CLI::Option*> options;
  return options;
}

// One file an option names: an existing regular file (what a command reads
// or would overwrite; a name that does not exist yet clashes with nothing).
struct NamedFile {
  dev_t device;
  ino_t inode;
  const CLI::Option* option;
  std::string path;
};

std::string option_label(const CLI::Option* option) {
  const std::string name = option->get_name();
  return name.rfind("--", 0) == 0 ? name : "the " + name + " argument";
}
}  // namespace

CLI::Option* output_file(CLI::Option* option) {
  output_options().push_back(option);
  return option;
}

std::string output_clash(const CLI::App& command) {
  const auto& outputs = output_options();
  std::vector<NamedFile> files;
  for (const CLI::Option* option : command.get_options()) {
    if (option->get_expected_min() == 0) continue;  // a flag
    for (const std::string& text : option->results()) {
      struct stat st;
      if (!text.empty() && ::stat(text.c_str(), &st) == 0 && S_ISREG(st.st_mode))
        files.push_back({st.st_dev, st.st_ino, option, text});
    }
  }
  for (size_t i = 0; i < files.size(); ++i) {
    if (std::find(outputs.begin(), outputs.end(), files[i].option) == outputs.end()) continue;
    for (size_t j = 0; j < files.size(); ++j) {
      if (j == i || files[j].device != files[i].device || files[j].inode != files[i].inode) continue;
      return option_label(files[i].option) + " " + files[i].path + " is the file that " +
             option_label(files[j].option) + " names (" + files[j].path +
             "): the command would overwrite it; write the output to another file";
    }
  }
  return {};
}

const char* const kExitStatusHelp =
    "Exit status: 0 success; 1 error (nothing usable written); 2 invalid result (validation found "
    "errors); 3 a warning under --strict (the output is still written, the warning is on stderr and "
    "under \"warnings\" in --json).\n";

namespace {
std::vector<std::string> printed_warnings;  // the tool is one command per process
}  // namespace

void warn(const std::string& command, const std::string& message) {
  end_progress_line();
  std::fprintf(stderr, "ldc %s: warning: %s\n", command.c_str(), message.c_str());
  printed_warnings.push_back(message);
}

const std::vector<std::string>& warnings() { return printed_warnings; }

nlohmann::json with_warnings(nlohmann::json report) {
  if (!printed_warnings.empty()) report["warnings"] = printed_warnings;
  return report;
}

bool warn_if_rasterized_empty(const std::string& command, const World& world, const std::string& input,
                              std::optional<BuildMode> mesh_mode) {
  if (world.solid_bounds()) return false;
  char cell[32];
  std::snprintf(cell, sizeof(cell), "%g", world.lattice().cell_size);
  std::string why = input + " rasterizes to nothing at cell size " + cell + " m: no lattice node lies inside it";
  if (mesh_mode == BuildMode::kSolid) {
    why += "; it is thinner than a cell (use a smaller --cell-size or more --cells) or made only of sheets, "
           "which build mode solid reads as enclosing nothing (build mode auto or surface, ldc build --mode, "
           "keeps sheets as thin shells)";
  } else {
    why += " (use a smaller --cell-size or more --cells)";
  }
  warn(command, why + "; the output holds no solid");
  return true;
}

bool parse_numbers(const std::string& text, std::vector<double>* out) {
  std::istringstream in(text);
  std::vector<double> v;
  for (char sep = ','; sep == ',';) {
    double x = 0.0;
    if (!(in >> x) || !std::isfinite(x)) return false;
    v.push_back(x);
    sep = 0;
    in >> sep;  // ',' or the end
    if (sep != ',' && sep != 0) return false;
  }
  *out = std::move(v);
  return true;
}

bool parse_vec3(const std::string& text, glm::dvec3* out) {
  std::vector<double> v;
  if (!parse_numbers(text, &v) || v.size() != 3) return false;
  *out = glm::dvec3(v[0], v[1], v[2]);
  return true;
}

nlohmann::json world_info_json(const World& world, bool run_validate, Context* ctx) {
  nlohmann::json j;
  const WorldStats s = world.stats();
  const Lattice& lat = world.lattice();
  j["lattice"] = {{"origin", {lat.origin.x, lat.origin.y, lat.origin.z}}, {"cell_size", lat.cell_size}};
  j["chunk_size"] = world.chunk_size();
  glm::ivec3 d = world.chunk_dims(), o = world.chunk_origin();
  j["chunk_box"] = {{"origin", {o.x, o.y, o.z}}, {"dims", {d.x, d.y, d.z}}};
  j["chunks"] = {{"total", s.chunks_total}, {"empty", s.chunks_empty}, {"solid", s.chunks_solid},
                 {"mixed", s.chunks_mixed}};
  j["rays_stored"] = s.rays_stored;
  j["points"] = s.points;
  j["bytes_per_point_record"] = sizeof(PackedPoint);
  j["memory_bytes"] = s.memory_bytes;
  j["bytes_per_point"] = s.bytes_per_point();
  j["volume_m3"] = {world.volume(0), world.volume(1), world.volume(2)};
  if (auto b = world.solid_bounds()) {
    j["solid_bounds"] = {{"min", {b->min.x, b->min.y, b->min.z}}, {"max", {b->max.x, b->max.y, b->max.z}}};
  }
  nlohmann::json meta = nlohmann::json::object();
  for (const auto& [k, v] : world.metadata()) meta[k] = v;
  j["metadata"] = meta;
  if (run_validate) j["validation"] = validation_json(world, ctx);
  return j;
}

nlohmann::json validation_json(const World& world, Context* ctx) {
  // Reported as the stage 'validate' (issue 24: 36 s of it went unshown).
  ValidationReport r = detail::validate_with_progress(world, {}, ctx);
  return {{"ok", r.ok}, {"errors", r.errors}, {"nodes_checked", r.nodes_checked}, {"messages", r.messages}};
}

std::string validation_text(const nlohmann::json& v) {
  std::ostringstream s;
  s << "validation  " << (v["ok"].get<bool>() ? "valid" : "INVALID") << " (" << v["errors"] << " errors, "
    << v["nodes_checked"] << " nodes checked across axes)\n";
  for (const auto& m : v["messages"]) s << "  " << m.get<std::string>() << "\n";
  return s.str();
}

std::string world_info_text(const nlohmann::json& j) {
  std::ostringstream s;
  s.precision(6);
  auto v3 = [](const nlohmann::json& a) {
    std::ostringstream o;
    o << a[0].get<double>() << ", " << a[1].get<double>() << ", " << a[2].get<double>();
    return o.str();
  };
  s << "lattice     origin (" << v3(j["lattice"]["origin"]) << "), cell size "
    << j["lattice"]["cell_size"].get<double>() << " m\n";
  s << "chunks      " << j["chunks"]["total"] << " of " << j["chunk_size"] << "^3 cells: "
    << j["chunks"]["empty"] << " empty, " << j["chunks"]["solid"] << " solid, "
    << j["chunks"]["mixed"] << " mixed\n";
  s << "rays        " << j["rays_stored"] << " stored\n";
  s << "points      " << j["points"] << " (" << j["bytes_per_point_record"] << " bytes each)\n";
  s << "memory      " << j["memory_bytes"].get<size_t>() / 1024 << " KiB, "
    << j["bytes_per_point"].get<double>() << " bytes per point all-in\n";
  s << "volume      " << v3(j["volume_m3"]) << " m^3 (from x, y, z spans)\n";
  if (j.contains("solid_bounds")) {
    s << "solid       (" << v3(j["solid_bounds"]["min"]) << ") .. (" << v3(j["solid_bounds"]["max"]) << ")\n";
  }
  for (const auto& [k, v] : j["metadata"].items()) s << "  " << k << ": " << v.get<std::string>() << "\n";
  if (j.contains("validation")) s << validation_text(j["validation"]);
  return s.str();
}

bool refuse_invalid_world(const std::string& command, const nlohmann::json& info, const std::string& output) {
  if (!info.contains("validation") || info["validation"]["ok"].get<bool>()) return false;
  end_progress_line();
  std::fprintf(stderr, "ldc %s: the world is invalid; %s not written\n%s", command.c_str(), output.c_str(),
               validation_text(info["validation"]).c_str());
  return true;
}

void print_seconds(const nlohmann::json& seconds) {
  for (const auto& [stage, s] : seconds.items()) {
    if (s.is_number()) std::printf("  %s: %.3f s\n", stage.c_str(), s.get<double>());
  }
}

nlohmann::json stage_seconds(const Context& ctx) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [stage, s] : ctx.timers()) out[stage] = s;
  return out;
}

void set_thread_count(int threads) {
  static std::unique_ptr<tbb::global_control> control;
  if (threads > 0) {
    control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    size_t(threads));
  }
}

int thread_count() {
  return int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

bool has_ldc_extension(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".ldc";
}

bool is_store_file(const std::string& path) {
  // Regular files only, opened without blocking: a FIFO with no writer hung
  // `info` and `render` here (load_world then refuses it, naming it).
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return false;
  struct stat st;
  char magic[4] = {};
  const bool is_store = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && ::read(fd, magic, 4) == 4 &&
                        std::string_view(magic, 4) == "LDCS";
  ::close(fd);
  return is_store;
}

Result<World> load_world_file(const std::string& path, const LoadLimits& limits, Context* ctx) {
  if (is_store_file(path)) {
    return Status(ErrorCode::kInvalidArgument,
                  path + " is a .ldcs store (a large world's chunk log), not a .ldc world: use ldc contour " + path +
                      " --region X0,Y0,Z0,X1,Y1,Z1, ldc edit " + path + " --script, or ldc info " + path);
  }
  return load_world(path, limits, ctx);
}

void add_up_option(CLI::App* cmd, std::string& up, const std::string& auto_means) {
  cmd->add_option("--up", up, "Up axis: x, y or z; auto: " + auto_means)->capture_default_str();
}

Result<int> parse_up_axis(const std::string& text, int auto_axis) {
  if (text == "auto") return auto_axis;
  if (text == "x" || text == "y" || text == "z") return text[0] - 'x';
  return Status(ErrorCode::kInvalidArgument, "--up '" + text + "': use x, y, z or auto");
}

void add_mesh_reading_options(CLI::App* cmd, MeshReadingArgs& args, const std::string& default_mode) {
  args.mode = default_mode;
  cmd->add_option("--mode", args.mode,
                  "How a mesh becomes a solid: solid (winding number, open parts repaired by votes), "
                  "surface (every triangle a thin shell below it: one-sided floors, single-quad walls), "
                  "auto (per connected component: closed outward-facing parts solid, the rest shells)")
      ->capture_default_str();
  cmd->add_option("--shell-thickness", args.shell_thickness,
                  "How far a shell reaches below its triangle (m); 0: a little over one cell");
}

Result<BuildConfig> mesh_build_config(const MeshReadingArgs& args, int up_axis) {
  BuildConfig config;
  if (args.mode == "solid") config.mode = BuildMode::kSolid;
  else if (args.mode == "surface") config.mode = BuildMode::kSurface;
  else if (args.mode == "auto") config.mode = BuildMode::kAuto;
  else return Status(ErrorCode::kInvalidArgument, "--mode '" + args.mode + "': use solid, surface or auto");
  config.shell_thickness = args.shell_thickness;
  config.up_axis = up_axis;
  return config;
}

std::string axis_name(int axis) { return std::string(1, char('x' + axis)); }

nlohmann::json vec_json(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

std::string json_text(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace ldc::tool
