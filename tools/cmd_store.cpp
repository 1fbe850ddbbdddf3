// .ldcs stores in the tool: regions of chunks, `ldc info` of a store, `ldc compact`.
#include "cmd_store.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <vector>

#include "ldc/chunk_log.h"

namespace ldc::tool {

namespace {

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

std::string box_text(const glm::dvec3& min, const glm::dvec3& max) {
  return "(" + number_text(min.x) + ", " + number_text(min.y) + ", " + number_text(min.z) + ") .. (" +
         number_text(max.x) + ", " + number_text(max.y) + ", " + number_text(max.z) + ") m";
}

double chunk_metres(const SourceLayout& layout) { return layout.lattice.cell_size * layout.chunk_size; }

glm::dvec3 chunk_corner(const SourceLayout& layout, const glm::ivec3& chunk) {
  return layout.lattice.origin + glm::dvec3(chunk) * chunk_metres(layout);
}

}  // namespace

bool has_ldcs_extension(const std::string& path) {
  if (path.size() < 5) return false;
  std::string ext = path.substr(path.size() - 5);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".ldcs";
}

namespace {

// `r` (already within a chunk of the box) clipped to the box and bounded.
Result<ChunkRange> clip_and_bound(const SourceLayout& layout, ChunkRange r, const glm::dvec3& min,
                                  const glm::dvec3& max, const std::string& what) {
  const SourceBox& box = layout.box;
  const glm::ivec3 box_hi = box.chunk_origin + box.chunk_dims;
  r.lo = glm::max(r.lo, box.chunk_origin);
  r.hi = glm::min(r.hi, box_hi);
  if (r.hi.x <= r.lo.x || r.hi.y <= r.lo.y || r.hi.z <= r.lo.z) {
    return Status(ErrorCode::kInvalidArgument,
                  what + ": " + box_text(min, max) + " lies outside the store's box " +
                      box_text(chunk_corner(layout, box.chunk_origin), chunk_corner(layout, box_hi)));
  }
  if (r.slots() > kMaxStoreWindowSlots) {
    const glm::ivec3 d = r.hi - r.lo;
    return Status(ErrorCode::kTooLarge, what + ": " + std::to_string(d.x) + " x " + std::to_string(d.y) + " x " +
                                            std::to_string(d.z) + " chunks of " + number_text(chunk_metres(layout)) +
                                            " m (" + std::to_string(r.slots()) +
                                            " chunk slots) is over the limit of " +
                                            std::to_string(kMaxStoreWindowSlots) + " chunk slots");
  }
  return r;
}

// A chunk coordinate in doubles, clamped to a chunk beyond the box before it becomes an int.
int clamped_chunk(double c, int box_lo, int box_hi) {
  return int(std::clamp(c, double(box_lo) - 1.0, double(box_hi) + 1.0));
}

}  // namespace

Result<ChunkRange> chunks_of_box(const SourceLayout& layout, const glm::dvec3& min, const glm::dvec3& max,
                                 int margin, const std::string& what) {
  const SourceBox& box = layout.box;
  const double cs = chunk_metres(layout);
  ChunkRange r;
  for (int a = 0; a < 3; ++a) {
    const int box_lo = box.chunk_origin[a], box_hi = box.chunk_origin[a] + box.chunk_dims[a];
    r.lo[a] = clamped_chunk(std::floor((min[a] - layout.lattice.origin[a]) / cs) - margin, box_lo, box_hi);
    r.hi[a] = clamped_chunk(std::ceil((max[a] - layout.lattice.origin[a]) / cs) + margin, box_lo, box_hi);
  }
  return clip_and_bound(layout, r, min, max, what);
}

Result<ChunkRange> clip_chunks(const SourceLayout& layout, const ChunkRange& wanted, int margin,
                               const std::string& what) {
  const SourceBox& box = layout.box;
  ChunkRange r;
  for (int a = 0; a < 3; ++a) {
    const int box_lo = box.chunk_origin[a], box_hi = box.chunk_origin[a] + box.chunk_dims[a];
    r.lo[a] = clamped_chunk(double(wanted.lo[a]) - margin, box_lo, box_hi);
    r.hi[a] = clamped_chunk(double(wanted.hi[a]) + margin, box_lo, box_hi);
  }
  return clip_and_bound(layout, r, chunk_corner(layout, wanted.lo), chunk_corner(layout, wanted.hi), what);
}

Result<ChunkRange> parse_region(const SourceLayout& layout, const std::string& text) {
  const std::string what = "--region '" + text + "'";
  std::vector<double> v;
  if (!parse_numbers(text, &v) || v.size() != 6) {
    return Status(ErrorCode::kInvalidArgument, what + ": expected six finite numbers X0,Y0,Z0,X1,Y1,Z1 (m)");
  }
  const glm::dvec3 min(v[0], v[1], v[2]), max(v[3], v[4], v[5]);
  for (int a = 0; a < 3; ++a) {
    if (!(min[a] < max[a])) {
      return Status(ErrorCode::kInvalidArgument, what + ": empty along " + axis_name(a) + " (" +
                                                     number_text(min[a]) + " >= " + number_text(max[a]) +
                                                     "); give the lower corner first");
    }
  }
  return chunks_of_box(layout, min, max, 0, what);
}

nlohmann::json range_json(const SourceLayout& layout, const ChunkRange& range) {
  const glm::ivec3 d = range.hi - range.lo;
  return {{"chunk_origin", {range.lo.x, range.lo.y, range.lo.z}},
          {"chunk_dims", {d.x, d.y, d.z}},
          {"slots", range.slots()},
          {"min_m", vec_json(chunk_corner(layout, range.lo))},
          {"max_m", vec_json(chunk_corner(layout, range.hi))}};
}

std::string range_text(const nlohmann::json& r) {
  std::ostringstream s;
  s.precision(6);
  s << r["chunk_dims"][0] << " x " << r["chunk_dims"][1] << " x " << r["chunk_dims"][2] << " chunks ("
    << r["slots"] << " slots) from (" << r["min_m"][0].get<double>() << ", " << r["min_m"][1].get<double>() << ", "
    << r["min_m"][2].get<double>() << ") to (" << r["max_m"][0].get<double>() << ", "
    << r["max_m"][1].get<double>() << ", " << r["max_m"][2].get<double>() << ") m";
  return s.str();
}

nlohmann::json store_info_json(const Store& store, const std::string& path) {
  const SourceLayout& layout = store.log->layout();
  const ChunkLogStats st = store.log->stats();
  const glm::dvec3 extent = glm::dvec3(layout.box.chunk_dims) * chunk_metres(layout);
  nlohmann::json j;
  j["file"] = path;
  j["format"] = "ldcs";
  j["format_version"] = kChunkLogFormatVersion;
  j["base"] = store.log->base_description();
  if (Result<TerrainSourceParams> p = parse_terrain_source_description(store.log->base_description()); p.ok()) {
    j["landscape"] = {{"seed", p->config.seed}, {"size_m", {p->config.size_x, p->config.size_y}}};
  }
  j["lattice"] = {{"origin", vec_json(layout.lattice.origin)}, {"cell_size", layout.lattice.cell_size}};
  j["chunk_size"] = layout.chunk_size;
  j["chunk_box"] = range_json(layout, {layout.box.chunk_origin, layout.box.chunk_origin + layout.box.chunk_dims});
  j["extent_m"] = vec_json(extent);
  j["log"] = {{"file_bytes", st.file_bytes}, {"header_bytes", st.header_bytes}, {"commits", st.commits},
              {"sequence", st.sequence},     {"live_chunks", st.live_chunks},   {"live_bytes", st.live_bytes},
              {"dead_bytes", st.dead_bytes}, {"dead_fraction", st.dead_fraction()}};
  return j;
}

std::string store_info_text(const nlohmann::json& j) {
  std::ostringstream s;
  s.precision(6);
  s << "file        " << j["file"].get<std::string>() << " (.ldcs chunk log, format version "
    << j["format_version"] << ")\n";
  s << "base        " << j["base"].get<std::string>() << "\n";
  if (j.contains("landscape")) {
    s << "landscape   seed " << j["landscape"]["seed"] << ", " << j["landscape"]["size_m"][0].get<double>() << " x "
      << j["landscape"]["size_m"][1].get<double>() << " m\n";
  }
  s << "lattice     origin (" << j["lattice"]["origin"][0].get<double>() << ", "
    << j["lattice"]["origin"][1].get<double>() << ", " << j["lattice"]["origin"][2].get<double>()
    << "), cell size " << j["lattice"]["cell_size"].get<double>() << " m\n";
  s << "chunk box   " << range_text(j["chunk_box"]) << ", chunks of " << j["chunk_size"] << "^3 cells\n";
  s << "extent      " << j["extent_m"][0].get<double>() << " x " << j["extent_m"][1].get<double>() << " x "
    << j["extent_m"][2].get<double>() << " m\n";
  const nlohmann::json& l = j["log"];
  char dead[32];
  std::snprintf(dead, sizeof(dead), "%.1f%%", 100.0 * l["dead_fraction"].get<double>());
  s << "log         " << l["commits"] << " commits (sequence " << l["sequence"] << "), " << l["live_chunks"]
    << " live chunks, " << l["file_bytes"] << " bytes (header " << l["header_bytes"] << ", live chunks "
    << l["live_bytes"] << ", dead " << l["dead_bytes"] << ": " << dead << ")\n";
  return s.str();
}

namespace {

struct CompactArgs {
  std::string input;
};

int run_compact(const CompactArgs& a, const CommonOptions& common) {
  if (!is_store_file(a.input)) {
    return fail("compact", a.input + ": not a .ldcs store (no LDCS magic); only chunk logs are compacted");
  }
  Result<ChunkLog> log = ChunkLog::open(a.input);
  if (!log.ok()) return fail("compact", log.status());
  const ChunkLogStats before = log->stats();
  ScopedTimer t(nullptr, "");
  if (Status s = log->compact(); !s.ok()) return fail("compact", s);
  const double seconds = t.seconds();
  const ChunkLogStats after = log->stats();
  if (common.json) {
    nlohmann::json j = {{"file", a.input},
                        {"bytes_before", before.file_bytes},
                        {"bytes_after", after.file_bytes},
                        {"commits_before", before.commits},
                        {"commits_after", after.commits},
                        {"live_chunks", after.live_chunks},
                        {"sequence", after.sequence},
                        {"seconds", seconds}};
    std::printf("%s\n", json_text(j).c_str());
  } else {
    std::printf("compacted %s: %llu -> %llu bytes, %llu dropped (%llu live chunks; %llu commits -> %llu, sequence "
                "%llu) in %.3f s\n",
                a.input.c_str(), static_cast<unsigned long long>(before.file_bytes),
                static_cast<unsigned long long>(after.file_bytes),
                static_cast<unsigned long long>(before.file_bytes - std::min(before.file_bytes, after.file_bytes)),
                static_cast<unsigned long long>(after.live_chunks),
                static_cast<unsigned long long>(before.commits), static_cast<unsigned long long>(after.commits),
                static_cast<unsigned long long>(after.sequence), seconds);
  }
  return kExitSuccess;
}

}  // namespace

void add_compact_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<CompactArgs>();
  CLI::App* cmd = app.add_subcommand("compact", "Rewrite a .ldcs store with only its live chunks (crash-safe: "
                                                "temp file and rename)");
  cmd->add_option("input", args->input, ".ldcs store")->required();
  cmd->callback([args, &common] {
    int code = run_compact(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
