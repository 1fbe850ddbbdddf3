// Binary glTF 2.0 through tinygltf (ldc's private copy: see
// detail/tiny_gltf.h, whose implementation this file compiles).
//
// Layout: one buffer holding positions (float32 vec3), normals (float32 vec3,
// when the mesh has them), per-vertex materials (uint16 at a 4-byte stride:
// glTF requires vertex attribute elements on 4-byte boundaries) and the
// triangle indices (uint32) grouped by material. One primitive per material
// shares the vertex accessors and has its own slice of the indices.
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <string>

#include "ldc/materials.h"
#include "meshio/detail/codecs.h"
#define TINYGLTF_IMPLEMENTATION
#include "meshio/detail/tiny_gltf.h"

namespace ldc::meshio_detail {
namespace {

namespace gltf = ::ldc_tinygltf;

constexpr const char* kMaterialAttribute = "_MATERIAL";
constexpr const char* kMaterialIdExtra = "ldc_material";

// The palette's linear albedo (ldc/materials.h), opaque: what baseColorFactor holds.
std::vector<double> material_colour(uint16_t id) {
  const glm::vec3 albedo = material_albedo(id);
  return {albedo.x, albedo.y, albedo.z, 1.0};
}

int add_view(gltf::Model& model, size_t offset, size_t length, int target, size_t stride = 0) {
  gltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = offset;
  view.byteLength = length;
  view.byteStride = stride;
  view.target = target;
  model.bufferViews.push_back(view);
  return static_cast<int>(model.bufferViews.size() - 1);
}

int add_accessor(gltf::Model& model, int view, size_t offset, int component, int type,
                 size_t count) {
  gltf::Accessor accessor;
  accessor.bufferView = view;
  accessor.byteOffset = offset;
  accessor.componentType = component;
  accessor.type = type;
  accessor.count = count;
  model.accessors.push_back(accessor);
  return static_cast<int>(model.accessors.size() - 1);
}

// Copies floats into the buffer and returns the accessor (with the min/max
// that the spec requires on POSITION, computed on the stored float values).
int add_vec3_attribute(gltf::Model& model, size_t offset, const std::vector<glm::vec3>& values,
                       bool bounds) {
  std::memcpy(model.buffers[0].data.data() + offset, values.data(), values.size() * 12);
  const int view = add_view(model, offset, values.size() * 12, TINYGLTF_TARGET_ARRAY_BUFFER);
  const int accessor = add_accessor(model, view, 0, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                    TINYGLTF_TYPE_VEC3, values.size());
  if (bounds) {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const glm::vec3& v : values) {
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
    model.accessors[accessor].minValues = {lo.x, lo.y, lo.z};
    model.accessors[accessor].maxValues = {hi.x, hi.y, hi.z};
  }
  return accessor;
}

int add_material_attribute(gltf::Model& model, size_t offset, const ContourMesh& mesh) {
  const std::vector<uint16_t> materials = vertex_materials(mesh);
  unsigned char* out = model.buffers[0].data.data() + offset;
  for (size_t v = 0; v < materials.size(); ++v) std::memcpy(out + 4 * v, &materials[v], 2);
  const int view = add_view(model, offset, materials.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER, 4);
  return add_accessor(model, view, 0, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR,
                      materials.size());
}

void add_material(gltf::Model& model, uint16_t id, const ExportOptions& options) {
  gltf::Material material;
  material.name = material_name(options, id);
  material.pbrMetallicRoughness.baseColorFactor = material_colour(id);
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 0.8;
  gltf::Value::Object extras;
  extras[kMaterialIdExtra] = gltf::Value(static_cast<int>(id));  // the exact id, for loading
  material.extras = gltf::Value(extras);
  model.materials.push_back(material);
}

// The index slices, one primitive per material group.
void add_primitives(gltf::Model& model, size_t offset, const ContourMesh& mesh,
                    const ExportOptions& options, const std::map<std::string, int>& attributes) {
  const MaterialGroups groups = group_by_material(mesh);
  auto* out = reinterpret_cast<uint32_t*>(model.buffers[0].data.data() + offset);
  for (size_t i = 0; i < groups.order.size(); ++i) {
    const glm::uvec3& tri = mesh.triangles[groups.order[i]];
    std::memcpy(out + 3 * i, &tri, 12);
  }
  const int view =
      add_view(model, offset, mesh.triangle_count() * 12, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  gltf::Mesh gltf_mesh;
  gltf_mesh.name = "contour";
  for (size_t g = 0; g < groups.material.size(); ++g) {
    add_material(model, groups.material[g], options);
    const size_t first = groups.group_start[g];
    gltf::Primitive primitive;
    primitive.attributes = attributes;
    primitive.indices = add_accessor(model, view, first * 12, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                     TINYGLTF_TYPE_SCALAR, 3 * (groups.group_start[g + 1] - first));
    primitive.material = static_cast<int>(g);
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    gltf_mesh.primitives.push_back(std::move(primitive));
  }
  model.meshes.push_back(std::move(gltf_mesh));
}

void add_mesh(gltf::Model& model, const ContourMesh& mesh, const ExportOptions& options) {
  const size_t n = mesh.vertex_count();
  const bool normals = !mesh.normals.empty();
  const size_t normal_offset = 12 * n;
  const size_t material_offset = normal_offset + (normals ? 12 * n : 0);
  const size_t index_offset = material_offset + 4 * n;
  model.buffers.emplace_back();
  model.buffers[0].data.assign(index_offset + 12 * mesh.triangle_count(), 0);

  std::vector<glm::vec3> positions(n);  // glTF positions are float
  for (size_t v = 0; v < n; ++v) positions[v] = glm::vec3(mesh.positions[v]);
  std::map<std::string, int> attributes;
  attributes["POSITION"] = add_vec3_attribute(model, 0, positions, true);
  if (normals) attributes["NORMAL"] = add_vec3_attribute(model, normal_offset, mesh.normals, false);
  attributes[kMaterialAttribute] = add_material_attribute(model, material_offset, mesh);
  add_primitives(model, index_offset, mesh, options, attributes);

  gltf::Node node;
  node.mesh = 0;
  model.nodes.push_back(node);
  model.scenes[0].nodes.push_back(0);
}

}  // namespace

Result<std::string> encode_glb(const ContourMesh& mesh, const ExportOptions& options,
                               const std::string& path) {
  gltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "ldc";
  // Named: tinygltf writes a scene with no property as null, which is invalid.
  model.scenes.emplace_back();
  model.scenes[0].name = "contour";
  model.defaultScene = 0;
  // A glTF mesh needs at least one primitive and an accessor at least one
  // element, so an empty mesh is written as a scene without nodes.
  if (mesh.triangle_count() > 0) add_mesh(model, mesh, options);
  gltf::TinyGLTF writer;
  std::ostringstream stream;
  if (!writer.WriteGltfSceneToStream(&model, stream, false, true)) {
    return error_at(ErrorCode::kInternal, path, "tinygltf could not serialise the model");
  }
  return std::move(stream).str();
}

// ------------------------------------------------------------------ reading

namespace {

// An accessor's elements, checked to lie inside their buffer view and buffer.
struct AccessorView {
  const unsigned char* data = nullptr;
  size_t stride = 0;
  size_t count = 0;
  int component = 0;
};

class GltfReader {
 public:
  GltfReader(const gltf::Model& model, const std::string& path) : model_(model), path_(path) {}

  Result<ContourMesh> read() {
    for (const gltf::Mesh& mesh : model_.meshes) {
      for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        Status status = read_primitive(mesh.primitives[p]);
        if (!status.ok()) return status;
      }
    }
    if (!all_have_normals_) mesh_.normals.clear();
    if (!all_have_materials_) mesh_.vertex_material.clear();
    complete_loaded_mesh(mesh_);
    return std::move(mesh_);
  }

 private:
  Status error(const std::string& what) const {
    return error_at(ErrorCode::kParseError, path_, what);
  }

  Result<AccessorView> view(int index, int type, const char* what) const {
    if (index < 0 || static_cast<size_t>(index) >= model_.accessors.size()) {
      return error(std::string(what) + " accessor " + std::to_string(index) + " does not exist");
    }
    const gltf::Accessor& accessor = model_.accessors[index];
    if (accessor.type != type || accessor.sparse.isSparse || accessor.bufferView < 0 ||
        static_cast<size_t>(accessor.bufferView) >= model_.bufferViews.size()) {
      return error(std::string(what) + " accessor " + std::to_string(index) +
                   " has an unsupported type or no buffer view");
    }
    const gltf::BufferView& bv = model_.bufferViews[accessor.bufferView];
    const int element_size = gltf::GetComponentSizeInBytes(accessor.componentType) *
                             gltf::GetNumComponentsInType(accessor.type);
    if (element_size <= 0 || bv.buffer < 0 ||
        static_cast<size_t>(bv.buffer) >= model_.buffers.size()) {
      return error(std::string(what) + " accessor " + std::to_string(index) + " is malformed");
    }
    const auto size = static_cast<size_t>(element_size);
    AccessorView out{nullptr, bv.byteStride ? bv.byteStride : size, accessor.count,
                     accessor.componentType};
    const size_t start = bv.byteOffset + accessor.byteOffset;
    const size_t end =
        std::min(bv.byteOffset + bv.byteLength, model_.buffers[bv.buffer].data.size());
    if (out.count > 0 && (start > end || (end - start) < size ||
                          (end - start - size) / out.stride < out.count - 1)) {
      return error(std::string(what) + " accessor " + std::to_string(index) +
                   " runs past the end of its buffer");
    }
    out.data = model_.buffers[bv.buffer].data.data() + start;
    return out;
  }

  struct VertexRange {
    uint32_t first = 0;
    size_t count = 0;
  };
  Result<VertexRange> vertices_of(const gltf::Primitive& primitive);
  Status read_vertices(const gltf::Primitive& primitive, const AccessorView& positions);
  Status read_normals(const gltf::Primitive& primitive, size_t first, size_t count);
  void read_materials(const gltf::Primitive& primitive, size_t first, size_t count);
  Status read_primitive(const gltf::Primitive& primitive);
  uint16_t material_id(int material) const;

  const gltf::Model& model_;
  const std::string& path_;
  ContourMesh mesh_;
  std::map<int, VertexRange> base_;  // POSITION accessor -> its vertices in mesh_
  bool all_have_normals_ = true;
  bool all_have_materials_ = true;
};

template <class T>
T element(const AccessorView& view, size_t i, int k = 0) {
  T value;
  std::memcpy(&value, view.data + i * view.stride + k * sizeof(T), sizeof(T));
  return value;
}

uint32_t index_element(const AccessorView& view, size_t i) {
  switch (view.component) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return element<uint8_t>(view, i);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return element<uint16_t>(view, i);
    default:
      return element<uint32_t>(view, i);
  }
}

Status GltfReader::read_vertices(const gltf::Primitive& primitive, const AccessorView& positions) {
  const size_t first = mesh_.positions.size();
  for (size_t i = 0; i < positions.count; ++i) {
    mesh_.positions.emplace_back(element<float>(positions, i, 0), element<float>(positions, i, 1),
                                 element<float>(positions, i, 2));
  }
  mesh_.normals.resize(mesh_.positions.size(), glm::vec3(0.0f));
  mesh_.vertex_material.resize(mesh_.positions.size(), 0);
  Status status = read_normals(primitive, first, positions.count);
  if (status.ok()) read_materials(primitive, first, positions.count);
  return status;
}

Status GltfReader::read_normals(const gltf::Primitive& primitive, size_t first, size_t count) {
  auto normal = primitive.attributes.find("NORMAL");
  if (normal == primitive.attributes.end()) {
    all_have_normals_ = false;
    return {};
  }
  Result<AccessorView> normals = view(normal->second, TINYGLTF_TYPE_VEC3, "NORMAL");
  if (!normals.ok()) return normals.status();
  if (normals->count != count || normals->component != TINYGLTF_COMPONENT_TYPE_FLOAT) {
    return error("NORMAL accessor does not match POSITION (count or float type)");
  }
  for (size_t i = 0; i < count; ++i) {
    for (int k = 0; k < 3; ++k) mesh_.normals[first + i][k] = element<float>(normals.value(), i, k);
  }
  return {};
}

// Our _MATERIAL attribute gives back the exact vertex materials; a file
// without it (or with another layout) gets them derived from the triangles.
void GltfReader::read_materials(const gltf::Primitive& primitive, size_t first, size_t count) {
  auto material = primitive.attributes.find(kMaterialAttribute);
  Result<AccessorView> materials =
      material == primitive.attributes.end()
          ? Result<AccessorView>(error("no _MATERIAL"))
          : view(material->second, TINYGLTF_TYPE_SCALAR, kMaterialAttribute);
  if (!materials.ok() || materials->count != count ||
      materials->component != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
    all_have_materials_ = false;
    return;
  }
  for (size_t i = 0; i < count; ++i)
    mesh_.vertex_material[first + i] = element<uint16_t>(materials.value(), i);
}

// Primitives sharing a POSITION accessor (ours do) share their vertices.
Result<GltfReader::VertexRange> GltfReader::vertices_of(const gltf::Primitive& primitive) {
  auto position = primitive.attributes.find("POSITION");
  if (position == primitive.attributes.end()) return error("a primitive has no POSITION");
  auto known = base_.find(position->second);
  if (known != base_.end()) return known->second;
  Result<AccessorView> positions = view(position->second, TINYGLTF_TYPE_VEC3, "POSITION");
  if (!positions.ok()) return positions.status();
  if (positions->component != TINYGLTF_COMPONENT_TYPE_FLOAT) return error("POSITION is not float");
  if (mesh_.positions.size() + positions->count > std::numeric_limits<uint32_t>::max()) {
    return error("too many vertices");
  }
  const VertexRange range{static_cast<uint32_t>(mesh_.positions.size()), positions->count};
  Status status = read_vertices(primitive, positions.value());
  if (!status.ok()) return status;
  base_[position->second] = range;
  return range;
}

uint16_t GltfReader::material_id(int material) const {
  if (material < 0 || static_cast<size_t>(material) >= model_.materials.size()) return 0;
  const gltf::Value& extras = model_.materials[material].extras;
  if (extras.IsObject() && extras.Has(kMaterialIdExtra) && extras.Get(kMaterialIdExtra).IsInt()) {
    const int id = extras.Get(kMaterialIdExtra).Get<int>();
    if (id >= 0 && id <= 0xffff) return static_cast<uint16_t>(id);
  }
  return static_cast<uint16_t>(std::min(material, 0xffff));
}

Status GltfReader::read_primitive(const gltf::Primitive& primitive) {
  if (primitive.mode != TINYGLTF_MODE_TRIANGLES && primitive.mode != -1) {
    return error("primitive mode " + std::to_string(primitive.mode) + " is not TRIANGLES");
  }
  Result<VertexRange> vertices = vertices_of(primitive);
  if (!vertices.ok()) return vertices.status();
  const size_t count = vertices->count;
  AccessorView indices;
  if (primitive.indices >= 0) {
    Result<AccessorView> found = view(primitive.indices, TINYGLTF_TYPE_SCALAR, "index");
    if (!found.ok()) return found.status();
    indices = found.value();
  }
  const size_t corners = primitive.indices >= 0 ? indices.count : count;
  const uint16_t material = material_id(primitive.material);
  for (size_t c = 0; c + 2 < corners; c += 3) {
    glm::uvec3 tri;
    for (int k = 0; k < 3; ++k) {
      const uint32_t i =
          primitive.indices >= 0 ? index_element(indices, c + k) : static_cast<uint32_t>(c + k);
      if (i >= count) return error("index " + std::to_string(i) + " out of range");
      tri[k] = vertices->first + i;
    }
    mesh_.triangles.push_back(tri);
    mesh_.triangle_material.push_back(material);
  }
  return {};
}

}  // namespace

Result<ContourMesh> decode_glb(std::string_view bytes, const std::string& path) {
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
    return error_at(ErrorCode::kTooLarge, path, "a GLB file is at most 4 GiB");
  }
  gltf::Model model;
  gltf::TinyGLTF loader;
  // Images are not part of a ContourMesh: accept them without decoding.
  loader.SetImageLoader([](gltf::Image*, const int, std::string*, std::string*, int, int,
                           const unsigned char*, int, void*) { return true; },
                        nullptr);
  std::string err, warn;
  const bool loaded = loader.LoadBinaryFromMemory(
      &model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
      static_cast<unsigned int>(bytes.size()), "");
  if (!loaded || !err.empty()) {
    return error_at(ErrorCode::kParseError, path, "not a valid GLB file: " + err);
  }
  return GltfReader(model, path).read();
}

}  // namespace ldc::meshio_detail
