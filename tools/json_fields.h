// Reading the fields of one JSON object with their checks, for the tool's
// input files (edit scripts, nav filters and links). The first error is kept
// and later reads return defaults, so a reader is straight-line code checked
// once at the end; every message names the context and the field.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "ldc/status.h"

namespace ldc::tool {

// Json: nlohmann::json or nlohmann::ordered_json.
template <class Json>
class JsonFields {
 public:
  // context: what the object is, e.g. "edit 3" or "links.json: link 0".
  JsonFields(const Json& object, std::string context) : object_(object), context_(std::move(context)) {}

  const Status& error() const { return error_; }
  void fail(const std::string& field, const std::string& problem) {
    if (!error_.ok()) return;
    error_ = Status(ErrorCode::kInvalidArgument, context_ + ": field '" + field + "' " + problem);
  }

  // Refuses fields not in `known`: a misspelt optional field would otherwise
  // be dropped without a word. `where` qualifies the message (" for brush 'box'").
  void refuse_unknown(const std::vector<std::string>& known, const std::string& where = "") {
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
    for (const auto& [name, value] : object_.items()) {
      if (std::find(known.begin(), known.end(), name) == known.end()) {
        fail(name, "is not known" + where + " (fields: " + list + ")");
      }
    }
  }

  std::string text(const char* name) {
    const Json* v = find(name, true);
    if (v && !v->is_string()) fail(name, std::string("must be a string, not ") + v->type_name());
    return v && v->is_string() ? v->template get<std::string>() : std::string();
  }
  double number(const char* name) {
    const Json* v = find(name, true);
    return v ? to_number(name, *v) : 0.0;
  }
  double number_or(const char* name, double fallback) {
    const Json* v = find(name, false);
    return v ? to_number(name, *v) : fallback;
  }
  uint32_t integer_or(const char* name, uint32_t fallback, uint32_t max) {
    const Json* v = find(name, false);
    if (!v) return fallback;
    const double d = to_number(name, *v);
    if (d >= 0.0 && d <= double(max) && std::floor(d) == d) return uint32_t(d);
    fail(name, "is " + v->dump() + ": must be a whole number in 0 .. " + std::to_string(max));
    return fallback;
  }
  bool boolean_or(const char* name, bool fallback) {
    const Json* v = find(name, false);
    if (!v) return fallback;
    if (!v->is_boolean()) {
      fail(name, std::string("must be true or false, not ") + v->type_name());
      return fallback;
    }
    return v->template get<bool>();
  }
  glm::dvec3 vec3(const char* name) {
    const Json* v = find(name, true);
    return v ? to_vec3(name, *v) : glm::dvec3(0.0);
  }
  glm::dvec3 vec3_or(const char* name, const glm::dvec3& fallback) {
    const Json* v = find(name, false);
    return v ? to_vec3(name, *v) : fallback;
  }

 private:
  const Json* find(const char* name, bool required) {
    auto it = object_.find(name);
    if (it != object_.end()) return &*it;
    if (required) fail(name, "is missing");
    return nullptr;
  }
  double to_number(const char* name, const Json& v) {
    if (!v.is_number()) fail(name, std::string("must be a number, not ") + v.type_name());
    const double d = v.is_number() ? v.template get<double>() : 0.0;
    if (!std::isfinite(d)) fail(name, "must be a finite number");
    return std::isfinite(d) ? d : 0.0;
  }
  glm::dvec3 to_vec3(const char* name, const Json& v) {
    if (!v.is_array() || v.size() != 3) {
      fail(name, "must be an array of three numbers [x, y, z]");
      return glm::dvec3(0.0);
    }
    return {to_number(name, v[0]), to_number(name, v[1]), to_number(name, v[2])};
  }

  const Json& object_;
  std::string context_;
  Status error_;
};

}  // namespace ldc::tool
