// The tool's small input files read from their text: JSON parsing with the
// tool's messages, the render overlay, raycast's rays and inside's points.
// Each reader also takes text (not only a path), so that tests and the
// fuzzer (fuzz/fuzz_json_inputs.cpp) reach it without the command line; the
// `name` or `path` argument only labels the messages.
#pragma once

#include <cstddef>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "ldc/query.h"
#include "ldc/status.h"
#include "render/render.h"

namespace ldc::tool {

// A number in an error message: up to 10 significant digits.
std::string number_text(double d);

// The whole file; errors name it. A file over max_bytes (0: no limit) is
// refused (kTooLarge) without reading it whole.
Result<std::string> read_text_file(const std::string& path, size_t max_bytes = 0);
// kTooLarge, naming `path`, for text over max_bytes (a reader given text checks its limit here).
Status check_text_size(std::string_view text, const std::string& path, size_t max_bytes);

// Arrays and objects nested deeper than this are refused (the tool's files
// nest 4 levels at most).
inline constexpr int kMaxJsonDepth = 64;

// Parses JSON text; errors name `name` (and, for NaN or Infinity, which JSON
// cannot hold, say so).
Result<nlohmann::json> parse_json_text(std::string_view text, const std::string& name);
// The same, keeping objects' keys in the file's order.
Result<nlohmann::ordered_json> parse_ordered_json_text(std::string_view text, const std::string& name);

// `ldc render --overlay`: {"path": [[x,y,z], ...], "points": [[x,y,z], ...]}
// ("polyline" is taken for "path"); at most kMaxOverlayVertices in each list.
Result<Overlay> read_overlay(const std::string& path);
Result<Overlay> read_overlay_text(std::string_view text, const std::string& path);

// `ldc raycast --rays`: [{"origin": [x,y,z], "direction": [x,y,z], "max_distance": d}, ...]
// or {"rays": [...]}; every ray is checked as Queries::ray_cast would.
Result<std::vector<Ray>> read_rays(const std::string& path);
Result<std::vector<Ray>> read_rays_text(std::string_view text, const std::string& path);

// `ldc inside --points`: one point per line, "x y z" or "x,y,z"; blank lines
// and # comments skipped; every coordinate finite.
Result<std::vector<glm::dvec3>> read_points(std::istream& in, const std::string& name);

}  // namespace ldc::tool
