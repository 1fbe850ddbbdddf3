#include "json_inputs.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "ldc/internal/vec_text.h"
#include "ldc/io.h"

namespace ldc::tool {
namespace {

Status over_size_limit(const std::string& path, size_t max_bytes) {
  return Status(ErrorCode::kTooLarge, path + ": over the limit of " + std::to_string(max_bytes) + " bytes for this file");
}

// The deepest nesting of [ and { outside strings, counted up to one past
// `limit` (the parse finds any other fault).
int nesting_depth(std::string_view text, int limit) {
  int depth = 0, deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size() && deepest <= limit; ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;  // an escaped character, perhaps a quote
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

template <class Json>
Result<Json> parse_text(std::string_view text, const std::string& name) {
  // Refused before the parse: dump() and copies of a parsed document recurse
  // once per level, and a 600 KB overlay of nested brackets overflowed the
  // stack in the message that dumped it.
  if (nesting_depth(text, kMaxJsonDepth) > kMaxJsonDepth) {
    return Status(ErrorCode::kParseError, name + ": arrays and objects nested deeper than " +
                                              std::to_string(kMaxJsonDepth) + " levels (these files need 4)");
  }
  // nlohmann's parser stops at a zero byte, so a valid document followed by
  // "\0" and anything at all was read as the document (issue 24 sweep).
  if (const size_t nul = text.find('\0'); nul != std::string_view::npos) {
    return Status(ErrorCode::kParseError, name + ": not a JSON text file (a zero byte at offset " +
                                              std::to_string(nul) + ")");
  }
  try {
    return Json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // syntax errors, and numbers too large for a double
    const std::string what = e.what();
    const bool not_finite = what.find("invalid literal") != std::string::npos || what.find("overflow") != std::string::npos;
    return Status(ErrorCode::kParseError, name + ": malformed JSON: " + what +
                                              (not_finite ? " (JSON has no NaN or Infinity: every number must be finite)" : ""));
  }
}

// ---- the overlay (ldc render --overlay) ------------------------------------

Result<std::vector<glm::dvec3>> overlay_points(const nlohmann::json& list, const std::string& where) {
  if (!list.is_array()) return Status(ErrorCode::kParseError, where + " must be an array of [x, y, z]");
  // Bounded before anything is drawn: the cost of drawing grows with the vertices (issue 24).
  if (list.size() > kMaxOverlayVertices) {
    return Status(ErrorCode::kTooLarge, where + ": " + std::to_string(list.size()) + " entries, over the limit of " +
                                            std::to_string(kMaxOverlayVertices));
  }
  std::vector<glm::dvec3> out;
  for (size_t i = 0; i < list.size(); ++i) {
    const nlohmann::json& p = list[i];
    bool ok = p.is_array() && p.size() == 3;
    glm::dvec3 v(0.0);
    for (int k = 0; ok && k < 3; ++k) {
      ok = p[k].is_number() && std::isfinite(p[k].get<double>());
      if (ok) v[k] = p[k].get<double>();
    }
    if (!ok) {
      std::ostringstream s;
      s << where << "[" << i << "] must be [x, y, z] (three finite numbers), not " << p.dump();
      return Status(ErrorCode::kParseError, s.str());
    }
    out.push_back(v);
  }
  return out;
}

// ---- the rays (ldc raycast --rays) -----------------------------------------

// The checks Queries::ray_cast makes, with the ray's index and field named.
Status check_ray_fields(const Ray& r, const std::string& where) {
  if (!detail::is_finite(r.origin)) return {ErrorCode::kInvalidArgument, where + "field 'origin' must hold finite numbers"};
  if (!detail::is_finite(r.direction)) {
    return {ErrorCode::kInvalidArgument, where + "field 'direction' must hold finite numbers"};
  }
  const double len = glm::length(r.direction);
  if (!(len > 1e-300) || !std::isfinite(len)) {
    return {ErrorCode::kInvalidArgument,
            where + "field 'direction' " + detail::vec_text(r.direction) + " has no usable length (zero or overflowing)"};
  }
  if (!(r.max_distance >= 0.0)) {
    return {ErrorCode::kInvalidArgument, where + "field 'max_distance' " + number_text(r.max_distance) +
                                             " must be a number >= 0"};
  }
  return {};
}

Result<glm::dvec3> json_vec3(const nlohmann::json& v, const std::string& where, const char* field) {
  const std::string what = where + "field '" + field + "' ";
  if (!v.is_array() || v.size() != 3) {
    return Status(ErrorCode::kParseError, what + "must be an array of three numbers [x, y, z]");
  }
  glm::dvec3 out;
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number()) {
      return Status(ErrorCode::kParseError, what + "must be an array of three numbers [x, y, z], not holding a " +
                                                std::string(v[i].type_name()));
    }
    out[i] = v[i].get<double>();
  }
  return out;
}

Result<Ray> read_ray(const nlohmann::json& r, const std::string& where) {
  if (!r.is_object()) {
    return Status(ErrorCode::kParseError, where + "expected an object {\"origin\": [x,y,z], \"direction\": [x,y,z]}, "
                                                  "not " + std::string(r.type_name()));
  }
  for (const auto& [key, value] : r.items()) {
    if (key != "origin" && key != "direction" && key != "max_distance") {
      return Status(ErrorCode::kParseError, where + "field '" + key + "' is not known (origin, direction, max_distance)");
    }
  }
  Ray ray;
  for (const char* field : {"origin", "direction"}) {
    auto it = r.find(field);
    if (it == r.end()) return Status(ErrorCode::kParseError, where + "field '" + field + "' is missing");
    Result<glm::dvec3> v = json_vec3(*it, where, field);
    if (!v.ok()) return v.status();
    (field[0] == 'o' ? ray.origin : ray.direction) = v.value();
  }
  auto md = r.find("max_distance");
  if (md != r.end() && !md->is_null()) {
    if (!md->is_number()) {
      return Status(ErrorCode::kParseError,
                    where + "field 'max_distance' must be a number, not " + std::string(md->type_name()));
    }
    ray.max_distance = md->get<double>();
  }
  if (Status s = check_ray_fields(ray, where); !s.ok()) return s;
  return ray;
}

}  // namespace

std::string number_text(double d) {
  std::ostringstream s;
  s.precision(10);
  s << d;
  return s.str();
}

Result<std::string> read_text_file(const std::string& path, size_t max_bytes) {
  // ldc::read_file refuses folders, FIFOs and devices, and checks the size first.
  Result<std::string> text = read_file(path, max_bytes == 0 ? UINT64_MAX : uint64_t(max_bytes));
  if (!text.ok() && text.status().code() == ErrorCode::kTooLarge) return over_size_limit(path, max_bytes);
  return text;
}

Status check_text_size(std::string_view text, const std::string& path, size_t max_bytes) {
  return text.size() <= max_bytes ? Status{} : over_size_limit(path, max_bytes);
}

Result<nlohmann::json> parse_json_text(std::string_view text, const std::string& name) {
  return parse_text<nlohmann::json>(text, name);
}

Result<nlohmann::ordered_json> parse_ordered_json_text(std::string_view text, const std::string& name) {
  return parse_text<nlohmann::ordered_json>(text, name);
}

Result<Overlay> read_overlay(const std::string& path) {
  Result<std::string> text = read_text_file(path, 0);
  if (!text.ok()) return Status(text.status().code(), "--overlay " + text.status().message());
  return read_overlay_text(text.value(), path);
}

Result<Overlay> read_overlay_text(std::string_view text, const std::string& path) {
  Result<nlohmann::json> read = parse_json_text(text, path);
  if (!read.ok()) return Status(read.status().code(), "--overlay " + read.status().message());
  const nlohmann::json& doc = read.value();
  const std::string usage = " (expected {\"path\": [[x,y,z], ...]} and/or {\"points\": [[x,y,z], ...]}; "
                            "\"polyline\" is taken for \"path\")";
  if (!doc.is_object()) return Status(ErrorCode::kParseError, "--overlay " + path + ": not a JSON object" + usage);
  Overlay overlay;
  bool found = false;
  for (const char* key : {"path", "polyline", "points"}) {
    auto it = doc.find(key);
    if (it == doc.end()) continue;
    found = true;
    Result<std::vector<glm::dvec3>> pts = overlay_points(*it, "--overlay " + path + ": " + key);
    if (!pts.ok()) return pts.status();
    if (std::string(key) == "points") overlay.points = std::move(pts).value();
    else overlay.paths.push_back(std::move(pts).value());
  }
  if (!found) return Status(ErrorCode::kParseError, "--overlay " + path + ": nothing to draw" + usage);
  return overlay;
}

Result<std::vector<Ray>> read_rays(const std::string& path) {
  Result<std::string> text = read_text_file(path, 0);
  if (!text.ok()) return text.status();
  return read_rays_text(text.value(), path);
}

Result<std::vector<Ray>> read_rays_text(std::string_view text, const std::string& path) {
  Result<nlohmann::json> doc = parse_json_text(text, path);
  if (!doc.ok()) return doc.status();
  const nlohmann::json* list = &doc.value();
  if (list->is_object() && list->contains("rays")) list = &(*list)["rays"];
  if (!list->is_array()) {
    return Status(ErrorCode::kParseError, path + ": expected a JSON array of rays, or {\"rays\": [...]}");
  }
  std::vector<Ray> rays;
  rays.reserve(list->size());  // one per element of the parsed text: bounded by its size
  for (size_t i = 0; i < list->size(); ++i) {
    Result<Ray> ray = read_ray((*list)[i], path + ": ray " + std::to_string(i) + ": ");
    if (!ray.ok()) return ray.status();
    rays.push_back(ray.value());
  }
  return rays;
}

Result<std::vector<glm::dvec3>> read_points(std::istream& in, const std::string& name) {
  std::vector<glm::dvec3> out;
  std::string line;
  for (size_t n = 1; std::getline(in, line); ++n) {
    size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    for (char& c : line) if (c == ',') c = ' ';
    std::istringstream s(line);
    glm::dvec3 p;
    std::string rest;
    if (!(s >> p.x)) {
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      return Status(ErrorCode::kParseError, name + ":" + std::to_string(n) + ": expected 'x y z'");
    }
    if (!(s >> p.y >> p.z) || (s >> rest)) {
      return Status(ErrorCode::kParseError, name + ":" + std::to_string(n) + ": expected three numbers");
    }
    if (!detail::is_finite(p)) {
      return Status(ErrorCode::kParseError, name + ":" + std::to_string(n) + ": coordinate is not finite");
    }
    out.push_back(p);
  }
  return out;
}

}  // namespace ldc::tool
