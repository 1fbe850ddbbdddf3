#include "edit_script.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "json_fields.h"
#include "json_inputs.h"
#include "meshio/meshio.h"

namespace ldc::tool {

const char* const kEditScriptHelp = R"(Script (JSON): {"edits": [ edit, ... ]}, applied in order. Every edit has
  "op": union | subtract | intersect | paint ("add" = union), "brush": one of the below,
  "material": id 0..65535 (optional, default 0), and the brush's fields:
  sphere    "centre": [x,y,z], "radius": r
  box       "centre": [x,y,z], "half_extents": [x,y,z]
  capsule   "a": [x,y,z], "b": [x,y,z], "radius": r
  cylinder  "a": [x,y,z], "b": [x,y,z], "radius": r
  noise     "centre": [x,y,z], "radius": r, optional "amplitude" (0.25), "frequency" (2), "seed" (1)
  mesh      "mesh": file (relative to the script's folder), optional "translate": [x,y,z],
            "scale": s (uniform, 1)
  sphere, box, noise and mesh also take optional "rotate_deg" (0) about "axis" ([0,0,1]),
  turning the brush about its centre (a mesh about its own origin, before "translate").
Unknown fields are refused. Example:
  {"edits": [{"op": "subtract", "brush": "sphere", "centre": [0,0,1], "radius": 1.5},
             {"op": "paint", "brush": "box", "centre": [2,0,1], "half_extents": [1,1,1],
              "rotate_deg": 30, "axis": [0,0,1], "material": 3}]}
)";

namespace {

using EditFields = JsonFields<nlohmann::json>;

// Mesh brushes' files, each loaded once however many edits use it.
class MeshFiles {
 public:
  MeshFiles(std::filesystem::path folder, const MeshLoader& load) : folder_(std::move(folder)), load_(load) {}
  std::shared_ptr<const TriangleMesh> load(const std::string& file, EditFields& f) {
    std::filesystem::path path(file);
    if (path.is_relative()) path = folder_ / path;  // relative to the script, not the working folder
    auto found = meshes_.find(path.string());
    if (found != meshes_.end()) return found->second;
    Result<TriangleMesh> mesh = load_(path.string());
    if (!mesh.ok()) {
      f.fail("mesh", "('" + file + "'): " + mesh.status().to_string());
      return nullptr;
    }
    auto shared = std::make_shared<const TriangleMesh>(std::move(mesh).value());
    meshes_.emplace(path.string(), shared);
    return shared;
  }

 private:
  std::filesystem::path folder_;
  const MeshLoader& load_;
  std::map<std::string, std::shared_ptr<const TriangleMesh>> meshes_;
};

// Optional "rotate_deg" about "axis". Composed on the local side of a brush's
// transform, so the brush turns about its own centre (a mesh about its origin).
glm::dmat4 rotation(EditFields& f) {
  double degrees = f.number_or("rotate_deg", 0.0);
  glm::dvec3 axis = f.vec3_or("axis", glm::dvec3(0.0, 0.0, 1.0));
  if (glm::length(axis) == 0.0) {
    f.fail("axis", "must not be zero");
    return glm::dmat4(1.0);
  }
  return glm::rotate(glm::dmat4(1.0), glm::radians(degrees), glm::normalize(axis));
}

Brush sphere_brush(EditFields& f, uint16_t material, MeshFiles&) {
  glm::dvec3 centre = f.vec3("centre");
  double radius = f.number("radius");
  Brush b = Brush::sphere(centre, radius, material);
  b.transform() = b.transform() * rotation(f);
  return b;
}

Brush box_brush(EditFields& f, uint16_t material, MeshFiles&) {
  glm::dvec3 centre = f.vec3("centre");
  glm::dvec3 half_extents = f.vec3("half_extents");
  Brush b = Brush::box(centre, half_extents, material);
  b.transform() = b.transform() * rotation(f);
  return b;
}

Brush capsule_brush(EditFields& f, uint16_t material, MeshFiles&) {
  glm::dvec3 a = f.vec3("a"), b = f.vec3("b");
  return Brush::capsule(a, b, f.number("radius"), material);
}

Brush cylinder_brush(EditFields& f, uint16_t material, MeshFiles&) {
  glm::dvec3 a = f.vec3("a"), b = f.vec3("b");
  return Brush::cylinder(a, b, f.number("radius"), material);
}

Brush noise_brush(EditFields& f, uint16_t material, MeshFiles&) {
  glm::dvec3 centre = f.vec3("centre");
  NoiseSphere noise;
  noise.radius = f.number("radius");
  noise.amplitude = f.number_or("amplitude", noise.amplitude);
  noise.frequency = f.number_or("frequency", noise.frequency);
  noise.seed = f.integer_or("seed", noise.seed, UINT32_MAX);
  Brush b = Brush::noisy_sphere(centre, noise, material);
  b.transform() = b.transform() * rotation(f);
  return b;
}

Brush mesh_brush(EditFields& f, uint16_t material, MeshFiles& files) {
  std::string file = f.text("mesh");
  glm::dvec3 translate = f.vec3_or("translate", glm::dvec3(0.0));
  double scale = f.number_or("scale", 1.0);
  if (!(scale > 0.0)) f.fail("scale", "must be > 0");
  glm::dmat4 transform = glm::translate(glm::dmat4(1.0), translate) * rotation(f);
  transform = glm::scale(transform, glm::dvec3(scale));
  std::shared_ptr<const TriangleMesh> mesh = f.error().ok() ? files.load(file, f) : nullptr;
  return Brush::from_mesh(std::move(mesh), transform, material);
}

struct BrushKind {
  const char* name;
  std::vector<std::string> fields;  // besides op, brush and material
  Brush (*read)(EditFields&, uint16_t material, MeshFiles&);
};

const BrushKind* find_brush_kind(const std::string& name) {
  static const BrushKind kinds[] = {
      {"sphere", {"centre", "radius", "rotate_deg", "axis"}, sphere_brush},
      {"box", {"centre", "half_extents", "rotate_deg", "axis"}, box_brush},
      {"capsule", {"a", "b", "radius"}, capsule_brush},
      {"cylinder", {"a", "b", "radius"}, cylinder_brush},
      {"noise", {"centre", "radius", "amplitude", "frequency", "seed", "rotate_deg", "axis"}, noise_brush},
      {"mesh", {"mesh", "translate", "scale", "rotate_deg", "axis"}, mesh_brush},
  };
  for (const BrushKind& k : kinds) {
    if (name == k.name) return &k;
  }
  return nullptr;
}

// Refuses fields the brush does not take: a misspelt optional field would
// otherwise be dropped without a word.
void refuse_unknown_fields(const BrushKind& kind, EditFields& f) {
  std::vector<std::string> known = {"op", "brush", "material"};
  known.insert(known.end(), kind.fields.begin(), kind.fields.end());
  f.refuse_unknown(known, " for brush '" + std::string(kind.name) + "'");
}

Result<ScriptEdit> read_edit(const nlohmann::json& edit, size_t index, MeshFiles& files) {
  if (!edit.is_object()) {
    return Status(ErrorCode::kInvalidArgument,
                  "edit " + std::to_string(index) + ": must be an object, not " + edit.type_name());
  }
  EditFields f(edit, "edit " + std::to_string(index));
  std::string op_name = f.text("op"), brush_name = f.text("brush");
  std::optional<EditOp> op = edit_op_from_name(op_name);
  const BrushKind* kind = find_brush_kind(brush_name);
  if (!op) f.fail("op", "is '" + op_name + "', not an op (union, subtract, intersect, paint)");
  if (!kind) f.fail("brush", "is '" + brush_name + "', not a brush (sphere, box, capsule, cylinder, noise, mesh)");
  if (!f.error().ok()) return f.error();
  refuse_unknown_fields(*kind, f);
  auto material = uint16_t(f.integer_or("material", 0, 65535));
  Brush brush = kind->read(f, material, files);
  if (!f.error().ok()) return f.error();
  Status s = check_brush(brush);  // the library's own limits (radius > 0, ...), before any edit runs
  if (!s.ok()) return Status(s.code(), "edit " + std::to_string(index) + ": " + s.message());
  return ScriptEdit{brush_name, WorldEditor::Edit{std::move(brush), *op}};
}

Status check_top_level(const nlohmann::json& doc) {
  if (!doc.is_object()) return {ErrorCode::kInvalidArgument, "the script must be an object {\"edits\": [...]}"};
  for (const auto& [name, value] : doc.items()) {
    if (name != "edits") return {ErrorCode::kInvalidArgument, "unknown top-level field '" + name + "' (only \"edits\")"};
  }
  if (!doc.contains("edits")) return {ErrorCode::kInvalidArgument, "field 'edits' is missing"};
  if (!doc.at("edits").is_array()) return {ErrorCode::kInvalidArgument, "field 'edits' must be an array"};
  return {};
}

}  // namespace

Result<std::vector<ScriptEdit>> read_edit_script(const std::string& path) {
  Result<std::string> text = read_text_file(path);
  if (!text.ok()) return text.status();
  return read_edit_script_text(text.value(), path, [](const std::string& mesh) { return load_mesh(mesh); });
}

Result<std::vector<ScriptEdit>> read_edit_script_text(std::string_view text, const std::string& path,
                                                      const MeshLoader& load) {
  Result<nlohmann::json> doc = parse_json_text(text, path);
  if (!doc.ok()) return doc.status();
  Status s = check_top_level(doc.value());
  if (!s.ok()) return Status(s.code(), path + ": " + s.message());
  MeshFiles files(std::filesystem::path(path).parent_path(), load);
  const nlohmann::json& list = doc.value().at("edits");
  std::vector<ScriptEdit> edits;
  for (size_t i = 0; i < list.size(); ++i) {
    Result<ScriptEdit> e = read_edit(list[i], i, files);
    if (!e.ok()) return Status(e.status().code(), path + ": " + e.status().message());
    edits.push_back(std::move(e).value());
  }
  return edits;
}

}  // namespace ldc::tool
