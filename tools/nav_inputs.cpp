#include "nav_inputs.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>

#include <nlohmann/json.hpp>

#include "json_fields.h"
#include "json_inputs.h"

namespace ldc::tool {

const char* const kNavFilterHelp = R"(--filter FILE (JSON): what the ground costs and where the agent may not go, by material:
  {"materials": {"mud": {"cost": 5}, "water": {"exclude": true}, "3": {"cost": 2, "flags": 4}},
   "include_flags": 65535, "exclude_flags": 0}
  A material is named by the world's metadata (material.<id> = name: OBJ usemtl names, the
  landscape's rock, grass, dirt, sand) or by its id as a decimal string. Each named material
  gets its own area (1, 2, ... in the file's order, at most 63); every other material is area 0
  (cost 1, flags 1). Per material, all optional: "cost" (per metre, a finite number >= 0.01,
  default 1), "flags" (0 .. 65535, default 1), "exclude" (true: never walked on; flag 32768 is
  then reserved for it). A floor is usable when its flags share a bit with "include_flags" and
  none with "exclude_flags" (defaults 65535 and 0); the start and goal snap to usable floors.
--links FILE (JSON): off-mesh links (jumps, ladders, teleporters):
  {"links": [{"a": [x,y,z], "b": [x,y,z], "bidirectional": true, "cost": 3.5, "flags": 1,
              "radius": 1.0}, ...]}
  "a" and "b" are required; "bidirectional" (default true: false is a to b only), "cost" (metres
  of cost-1 ground; default -1: the straight distance), "flags" (matched by the filter's
  include/exclude flags, default 1), "radius" (each end snaps to the nearest walkable floor within
  it, in (0, 100] m, default 1). At most 10,000 links. A link with an end on no floor is warned
  about on stderr and unused. The JSON lists "links_taken": [{"id": index in the file, "corner":
  k}]: the link runs from path[k] to path[k + 1].
Unknown fields are refused; either file may be at most 1 MiB.
)";

namespace {

using Json = nlohmann::ordered_json;

using Fields = JsonFields<Json>;

Status invalid(const std::string& message) { return Status(ErrorCode::kInvalidArgument, message); }

// The world's material names: id -> name, from metadata material.<id>.
std::map<uint16_t, std::string> material_names(const World& world) {
  std::map<uint16_t, std::string> names;
  constexpr std::string_view kPrefix = "material.";
  for (const auto& [key, value] : world.metadata()) {
    if (!key.starts_with(kPrefix)) continue;
    unsigned id = 0;
    const char* begin = key.data() + kPrefix.size();
    const char* end = key.data() + key.size();
    auto [next, error] = std::from_chars(begin, end, id);
    if (error == std::errc() && next == end && begin != end && id <= 0xFFFF) names[uint16_t(id)] = value;
  }
  return names;
}

// "123" -> 123 when the key is a decimal id 0 .. 65535.
std::optional<uint16_t> decimal_id(const std::string& key) {
  unsigned id = 0;
  const char* end = key.data() + key.size();
  auto [next, error] = std::from_chars(key.data(), end, id);
  if (key.empty() || error != std::errc() || next != end || id > 0xFFFF) return std::nullopt;
  return uint16_t(id);
}

// Both nav inputs: at most kNavInputMaxBytes of JSON, keys kept in order.
Result<Json> parse_nav_input(std::string_view text, const std::string& path) {
  if (Status s = check_text_size(text, path, kNavInputMaxBytes); !s.ok()) return s;
  return parse_ordered_json_text(text, path);
}

}  // namespace

bool FilterFile::excludes() const {
  return std::any_of(materials.begin(), materials.end(), [](const MaterialRule& m) { return m.exclude; });
}

Result<FilterFile> read_filter_file(const std::string& path) {
  Result<std::string> text = read_text_file(path, kNavInputMaxBytes);
  if (!text.ok()) return text.status();
  return read_filter_text(text.value(), path);
}

Result<FilterFile> read_filter_text(std::string_view text, const std::string& path) {
  Result<Json> doc = parse_nav_input(text, path);
  if (!doc.ok()) return doc.status();
  const Json& top = doc.value();
  if (!top.is_object()) {
    return invalid(path + ": the filter must be an object {\"materials\": {...}, \"include_flags\": n, "
                          "\"exclude_flags\": n}, not " + std::string(top.type_name()));
  }
  FilterFile file;
  file.path = path;
  Fields f(top, path);
  f.refuse_unknown({"materials", "include_flags", "exclude_flags"});
  file.include_flags = uint16_t(f.integer_or("include_flags", file.include_flags, 0xFFFF));
  file.exclude_flags = uint16_t(f.integer_or("exclude_flags", file.exclude_flags, 0xFFFF));
  if (!f.error().ok()) return f.error();
  const auto materials = top.find("materials");
  if (materials == top.end()) return file;
  if (!materials->is_object()) {
    return invalid(path + ": field 'materials' must be an object {\"name or id\": {\"cost\": c, ...}}, not " +
                   std::string(materials->type_name()));
  }
  if (materials->size() > 63) {
    return invalid(path + ": field 'materials' names " + std::to_string(materials->size()) +
                   " materials: at most 63 (each takes one of the areas 1 .. 63)");
  }
  for (const auto& [key, value] : materials->items()) {
    const std::string context = path + ": material '" + key + "'";
    if (!value.is_object()) {
      return invalid(context + ": must be an object {\"cost\": c, \"flags\": n, \"exclude\": b}, not " +
                     std::string(value.type_name()));
    }
    Fields m(value, context);
    m.refuse_unknown({"cost", "flags", "exclude"});
    MaterialRule rule;
    rule.key = key;
    rule.cost = m.number_or("cost", rule.cost);
    if (m.error().ok() && !(rule.cost >= 0.01)) {
      m.fail("cost", "is " + value.at("cost").dump() + ": must be a finite number >= 0.01");
    }
    rule.flags = uint16_t(m.integer_or("flags", rule.flags, 0xFFFF));
    rule.exclude = m.boolean_or("exclude", rule.exclude);
    if (!m.error().ok()) return m.error();
    file.materials.push_back(rule);
  }
  if (file.excludes()) {
    for (const MaterialRule& rule : file.materials) {
      if (rule.flags & kExcludedAreaFlag) {
        return invalid(path + ": material '" + rule.key + "': field 'flags' is " + std::to_string(rule.flags) +
                       ": uses flag 32768, which \"exclude\": true reserves for excluded materials");
      }
    }
  }
  return file;
}

Result<ResolvedFilter> resolve_filter(const FilterFile& file, const World& world) {
  const std::map<uint16_t, std::string> names = material_names(world);
  ResolvedFilter r;
  r.filter.include_flags = file.include_flags;
  r.filter.exclude_flags = file.exclude_flags;
  r.filter.area_cost.assign(file.materials.size() + 1, 1.0);
  r.filter.area_flags.assign(file.materials.size() + 1, uint16_t{1});
  std::map<uint16_t, std::string> taken;  // id -> the key that named it
  for (size_t k = 0; k < file.materials.size(); ++k) {
    const MaterialRule& rule = file.materials[k];
    const std::string context = file.path + ": material '" + rule.key + "'";
    std::vector<uint16_t> ids;
    for (const auto& [id, name] : names) {
      if (name == rule.key) ids.push_back(id);  // names first: a material may be called "3"
    }
    if (ids.empty()) {
      if (std::optional<uint16_t> id = decimal_id(rule.key)) ids.push_back(*id);
    }
    if (ids.empty()) {
      std::string known;
      for (const auto& [id, name] : names) known += (known.empty() ? "" : ", ") + std::to_string(id) + " " + name;
      return invalid(context + " is not a material of the world (" +
                     (known.empty() ? std::string("it names none") : "its materials: " + known) +
                     "): name one, or give a material id 0 .. 65535 as a decimal string");
    }
    for (uint16_t id : ids) {
      auto [at, fresh] = taken.emplace(id, rule.key);
      if (!fresh) {
        return invalid(file.path + ": materials '" + at->second + "' and '" + rule.key + "' are both material " +
                       std::to_string(id));
      }
      if (r.material_areas.size() <= id) r.material_areas.resize(size_t(id) + 1, 0);
      r.material_areas[id] = uint8_t(k + 1);
    }
    r.filter.area_cost[k + 1] = rule.cost;
    r.filter.area_flags[k + 1] = uint16_t(rule.flags | (rule.exclude ? kExcludedAreaFlag : 0));
    if (rule.exclude) r.filter.exclude_flags |= kExcludedAreaFlag;
    r.areas.emplace_back(rule.key, std::move(ids));
  }
  if (Status s = check_nav_filter(r.filter); !s.ok()) return Status(s.code(), file.path + ": " + s.message());
  return r;
}

Result<LinksFile> read_links_file(const std::string& path) {
  Result<std::string> text = read_text_file(path, kNavInputMaxBytes);
  if (!text.ok()) return text.status();
  return read_links_text(text.value(), path);
}

Result<LinksFile> read_links_text(std::string_view text, const std::string& path) {
  Result<Json> doc = parse_nav_input(text, path);
  if (!doc.ok()) return doc.status();
  const Json& top = doc.value();
  if (!top.is_object()) {
    return invalid(path + ": the links file must be an object {\"links\": [...]}, not " +
                   std::string(top.type_name()));
  }
  for (const auto& [name, value] : top.items()) {
    if (name != "links") return invalid(path + ": field '" + name + "' is not known (only \"links\")");
  }
  const auto list = top.find("links");
  if (list == top.end()) return invalid(path + ": field 'links' is missing");
  if (!list->is_array()) {
    return invalid(path + ": field 'links' must be an array, not " + std::string(list->type_name()));
  }
  if (list->size() > kMaxLinks) {
    return invalid(path + ": " + std::to_string(list->size()) + " links: at most " + std::to_string(kMaxLinks));
  }
  LinksFile file;
  file.path = path;
  for (size_t i = 0; i < list->size(); ++i) {
    const Json& value = (*list)[i];
    const std::string context = link_context(file, i);
    if (!value.is_object()) {
      return invalid(context + ": must be an object {\"a\": [x, y, z], \"b\": [x, y, z], ...}, not " +
                     std::string(value.type_name()));
    }
    Fields f(value, context);
    f.refuse_unknown({"a", "b", "bidirectional", "cost", "flags", "radius"});
    NavLink link;
    link.a = f.vec3("a");
    link.b = f.vec3("b");
    link.bidirectional = f.boolean_or("bidirectional", link.bidirectional);
    link.cost = f.number_or("cost", link.cost);
    link.flags = uint16_t(f.integer_or("flags", link.flags, 0xFFFF));
    link.radius = f.number_or("radius", link.radius);
    if (!f.error().ok()) return f.error();
    file.links.push_back(link);
  }
  return file;
}

std::string link_context(const LinksFile& file, size_t index) {
  return file.path + ": link " + std::to_string(index);
}

}  // namespace ldc::tool
