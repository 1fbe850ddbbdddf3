// The JSON files `ldc path` reads besides the level: a query filter
// (--filter) and off-mesh links (--links).
//
//   filter: {"materials": {"mud": {"cost": 5}, "water": {"exclude": true},
//                          "3": {"cost": 2, "flags": 4}},
//            "include_flags": 65535, "exclude_flags": 0}
//   links:  {"links": [{"a": [x, y, z], "b": [x, y, z], "bidirectional": true,
//                       "cost": 3.5, "flags": 1, "radius": 1.0}, ...]}
//
// Both are read in full and checked before the level is built (unknown
// fields are refused: they are usually typos); material names are looked up
// in the world's metadata (material.<id> = name) once it is loaded. Every
// message names the file and the field.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ldc/status.h"
#include "ldc/world.h"
#include "nav/nav.h"

namespace ldc::tool {

// The formats, for the command's help text.
extern const char* const kNavFilterHelp;

// Neither file may be larger than this.
inline constexpr size_t kNavInputMaxBytes = size_t(1) << 20;
// At most this many links in a links file.
inline constexpr size_t kMaxLinks = 10000;
// The flag bit "exclude": true gives a material's area (and sets in
// exclude_flags); no other flags may use it while a material is excluded.
inline constexpr uint16_t kExcludedAreaFlag = 0x8000;

// One entry of "materials", as written.
struct MaterialRule {
  std::string key;  // a material name or a decimal id
  double cost = 1.0;
  uint16_t flags = 1;
  bool exclude = false;
};

struct FilterFile {
  std::string path;
  std::vector<MaterialRule> materials;  // in the file's order: areas 1, 2, ...
  uint16_t include_flags = 0xFFFF;
  uint16_t exclude_flags = 0;
  bool excludes() const;  // some material has "exclude": true
};

Result<FilterFile> read_filter_file(const std::string& path);
// The same from the file's text (`path` names it in messages), for tests and the fuzzer.
Result<FilterFile> read_filter_text(std::string_view text, const std::string& path);

// A filter file applied to a world: each material named gets its own area
// (1, 2, ... in the file's order; every other material stays in area 0,
// cost 1, flags 1).
struct ResolvedFilter {
  std::vector<uint8_t> material_areas;  // NavConfig::material_areas
  NavFilter filter;
  std::vector<std::pair<std::string, std::vector<uint16_t>>> areas;  // area k + 1: key and the ids it holds
};

// Looks the names up in the world's metadata (material.<id> = name), or reads
// them as decimal ids; an unknown name is refused with the world's names.
Result<ResolvedFilter> resolve_filter(const FilterFile& file, const World& world);

struct LinksFile {
  std::string path;
  std::vector<NavLink> links;
};

// Reads the links; the library checks the rest (radius, finite ends) when
// they are added (prefix its message with link_context).
Result<LinksFile> read_links_file(const std::string& path);
Result<LinksFile> read_links_text(std::string_view text, const std::string& path);
std::string link_context(const LinksFile& file, size_t index);

}  // namespace ldc::tool
