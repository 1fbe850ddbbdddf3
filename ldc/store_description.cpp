// Base descriptions and stores: the procedural landscape named by one line
// of text that a chunk log carries, and a log opened over its base (see store.h).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include "ldc/internal/vec_text.h"
#include "ldc/store.h"

namespace ldc {
namespace {

constexpr const char* kTerrainTag = "ldc-terrain 1";

std::string exact(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  return buffer;
}

Status bad_description(const std::string& what) {
  return {ErrorCode::kCorruptData, "base description: " + what};
}

// key=value words after the tag; each key once.
Result<std::map<std::string, std::string>> description_fields(const std::string& text) {
  if (text.rfind(kTerrainTag, 0) != 0) {
    // Appends, not "'" + ...: GCC 12 warns falsely (-Wrestrict) on that form.
    std::string what = text.substr(0, 40);
    what.insert(0, 1, '\'');
    what += "' is not a landscape description (expected '";
    what += kTerrainTag;
    what += " ...')";
    return bad_description(what);
  }
  std::map<std::string, std::string> fields;
  std::istringstream words(text.substr(std::string(kTerrainTag).size()));
  std::string word;
  while (words >> word) {
    const size_t eq = word.find('=');
    if (eq == std::string::npos || eq == 0) return bad_description("'" + word + "' is not key=value");
    if (!fields.emplace(word.substr(0, eq), word.substr(eq + 1)).second) {
      return bad_description("key '" + word.substr(0, eq) + "' given twice");
    }
  }
  return fields;
}

// Takes `key` out of the fields as a finite number.
Status take_number(std::map<std::string, std::string>& fields, const char* key, double* out) {
  auto it = fields.find(key);
  if (it == fields.end()) return bad_description(std::string("missing ") + key);
  char* end = nullptr;
  const double v = std::strtod(it->second.c_str(), &end);
  if (it->second.empty() || *end != '\0' || !std::isfinite(v)) {
    return bad_description(std::string(key) + " = '" + it->second + "' is not a finite number");
  }
  *out = v;
  fields.erase(it);
  return {};
}

// Takes `key` as an integer in [lo, hi].
Status take_int(std::map<std::string, std::string>& fields, const char* key, double lo, double hi, double* out) {
  if (Status s = take_number(fields, key, out); !s.ok()) return s;
  if (*out != std::floor(*out) || *out < lo || *out > hi) {
    return bad_description(std::string(key) + " = " + detail::number_g(*out) + " is not an integer in " +
                           detail::number_g(lo) + " .. " + detail::number_g(hi));
  }
  return {};
}

}  // namespace

std::string terrain_source_description(const TerrainConfig& c, double cell_size, int chunk_size) {
  return std::string(kTerrainTag) + " seed=" + std::to_string(c.seed) + " size_x=" + exact(c.size_x) +
         " size_y=" + exact(c.size_y) + " floor_z=" + exact(c.floor_z) + " base_height=" + exact(c.base_height) +
         " relief=" + exact(c.relief) + " overhang=" + exact(c.overhang) + " cave_radius=" + exact(c.cave_radius) +
         " arches=" + std::to_string(c.arches) + " cell_size=" + exact(cell_size) +
         " chunk_size=" + std::to_string(chunk_size);
}

Result<TerrainSourceParams> parse_terrain_source_description(const std::string& text) {
  Result<std::map<std::string, std::string>> parsed = description_fields(text);
  if (!parsed.ok()) return parsed.status();
  std::map<std::string, std::string> f = std::move(parsed).value();
  TerrainSourceParams p;
  double seed = 0, arches = 0, chunk = 0;
  Status s = take_int(f, "seed", 0, 4294967295.0, &seed);
  if (s.ok()) s = take_number(f, "size_x", &p.config.size_x);
  if (s.ok()) s = take_number(f, "size_y", &p.config.size_y);
  if (s.ok()) s = take_number(f, "floor_z", &p.config.floor_z);
  if (s.ok()) s = take_number(f, "base_height", &p.config.base_height);
  if (s.ok()) s = take_number(f, "relief", &p.config.relief);
  if (s.ok()) s = take_number(f, "overhang", &p.config.overhang);
  if (s.ok()) s = take_number(f, "cave_radius", &p.config.cave_radius);
  if (s.ok()) s = take_int(f, "arches", 0, 64, &arches);
  if (s.ok()) s = take_number(f, "cell_size", &p.cell_size);
  if (s.ok()) s = take_int(f, "chunk_size", 8, 64, &chunk);
  if (!s.ok()) return s;
  if (!f.empty()) return bad_description("unknown key '" + f.begin()->first + "'");
  p.config.seed = uint32_t(seed);
  p.config.arches = int(arches);
  p.chunk_size = int(chunk);
  if (Status t = check_terrain(p.config); !t.ok()) return bad_description(t.message());
  return p;
}

Result<std::shared_ptr<const ChunkSource>> source_from_description(const std::string& description) {
  Result<TerrainSourceParams> p = parse_terrain_source_description(description);
  if (!p.ok()) return p.status();
  Result<std::shared_ptr<const ImplicitSource>> source =
      make_terrain_source(p.value().config, p.value().cell_size, p.value().chunk_size);
  if (!source.ok()) return source.status();
  return std::shared_ptr<const ChunkSource>(std::move(source).value());
}

namespace {

bool same_layout(const SourceLayout& a, const SourceLayout& b) {
  return a.chunk_size == b.chunk_size && a.lattice.cell_size == b.lattice.cell_size &&
         a.lattice.origin == b.lattice.origin && a.box.chunk_origin == b.box.chunk_origin &&
         a.box.chunk_dims == b.box.chunk_dims;
}

}  // namespace

Result<Store> create_terrain_store(const std::string& path, const TerrainConfig& config, double cell_size,
                                   int chunk_size, bool overwrite) {
  const std::string description = terrain_source_description(config, cell_size, chunk_size);
  Result<std::shared_ptr<const ChunkSource>> base = source_from_description(description);
  if (!base.ok()) return base.status();
  ChunkLogCreateOptions options;
  options.overwrite = overwrite;
  Result<ChunkLog> log = ChunkLog::create(path, base.value()->layout(), description, options);
  if (!log.ok()) return log.status();
  Store store;
  store.log = std::make_shared<ChunkLog>(std::move(log).value());
  store.base = std::move(base).value();
  store.source = std::make_shared<OverlaySource>(store.base, store.log_finder());
  return store;
}

Result<Store> open_store(const std::string& path, const ChunkLogLimits& limits) {
  Result<ChunkLog> log = ChunkLog::open(path, limits);
  if (!log.ok()) return log.status();
  Result<std::shared_ptr<const ChunkSource>> base = source_from_description(log.value().base_description());
  if (!base.ok()) return Status(base.status().code(), path + ": " + base.status().message());
  if (!same_layout(base.value()->layout(), log.value().layout())) {
    return Status(ErrorCode::kCorruptData, path + ": the log's lattice and chunk box differ from those of "
                                                  "its base description (made by another version?)");
  }
  Store store;
  store.log = std::make_shared<ChunkLog>(std::move(log).value());
  store.base = std::move(base).value();
  store.source = std::make_shared<OverlaySource>(store.base, store.log_finder());
  return store;
}

ChunkFinder Store::log_finder() const {
  std::shared_ptr<const ChunkLog> held = log;
  return [held](const glm::ivec3& chunk) { return held->find(chunk); };
}

Status Store::save(PagedWorld& paged) {
  std::vector<DirtyStoredChunk> dirty = paged.take_dirty();
  if (dirty.empty()) return {};
  std::vector<std::pair<glm::ivec3, StoredChunk>> chunks;
  chunks.reserve(dirty.size());
  for (DirtyStoredChunk& d : dirty) chunks.emplace_back(d.chunk, std::move(d.data));
  return log->commit(chunks);
}

}  // namespace ldc
