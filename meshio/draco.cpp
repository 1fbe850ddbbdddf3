// Draco compression (libdraco 1.5).
//
// Draco attributes belong to points (corners), not to faces. A per-triangle
// material is therefore stored as a GENERIC uint16 attribute on points that
// are the distinct (vertex, material) pairs of the corners: a vertex on a
// material border becomes one point per material around it, each with the
// same position and normal, and every corner of a triangle carries the
// triangle's material. Decoding reads the material of a face from its first
// corner and welds points with equal position and normal back into one vertex.
//
// Encoding may reorder faces and vertices (edgebreaker, speeds 0..9); speed
// 10 selects sequential encoding, which keeps the order. Meshes with a
// triangle that repeats an index are always encoded sequentially, because
// edgebreaker drops such triangles.
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <draco/metadata/geometry_metadata.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <unordered_map>

#include "meshio/detail/codecs.h"

namespace ldc::meshio_detail {
namespace {

constexpr const char* kMaterialName = "_MATERIAL";
// Normals are octahedrally quantized; 10 bits is what draco_encoder uses by
// default and keeps them within ~0.1 degree.
constexpr int kNormalBits = 10;

// The points of the Draco mesh: distinct (vertex, material) corner pairs.
struct DracoPoints {
  std::vector<uint32_t> vertex;
  std::vector<uint16_t> material;
  std::vector<uint32_t> corner_point;  // 3 per triangle
};

DracoPoints make_points(const ContourMesh& mesh) {
  DracoPoints points;
  std::vector<uint32_t> first(mesh.vertex_count(), UINT32_MAX);  // the vertex's first point
  std::unordered_map<uint64_t, uint32_t> extra;                  // (vertex, other material)
  points.corner_point.resize(3 * mesh.triangle_count());
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint16_t m = material_of(mesh, t);
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.triangles[t][k];
      uint32_t* point = &first[v];
      if (*point != UINT32_MAX && points.material[*point] != m) {
        point = &extra.try_emplace((uint64_t{v} << 16) | m, UINT32_MAX).first->second;
      }
      if (*point == UINT32_MAX) {
        *point = static_cast<uint32_t>(points.vertex.size());
        points.vertex.push_back(v);
        points.material.push_back(m);
      }
      points.corner_point[3 * t + k] = *point;
    }
  }
  return points;
}

// `values` holds `components` entries per point, in point order.
template <class T>
int add_attribute(draco::Mesh& out, draco::GeometryAttribute::Type type, draco::DataType data_type,
                  int components, const std::vector<T>& values) {
  const uint32_t count = out.num_points();
  draco::GeometryAttribute attribute;
  attribute.Init(type, nullptr, static_cast<uint8_t>(components), data_type, false,
                 static_cast<int64_t>(sizeof(T)) * components, 0);
  const int id = out.AddAttribute(attribute, true, count);
  draco::PointAttribute* stored = out.attribute(id);
  for (uint32_t p = 0; p < count; ++p) {
    stored->SetAttributeValue(draco::AttributeValueIndex(p),
                              values.data() + size_t{p} * components);
  }
  return id;
}

// Per point: the vertex's position (as float, which Draco quantizes) or normal.
std::vector<float> point_vectors(const DracoPoints& points, auto&& vector_of) {
  std::vector<float> values(3 * points.vertex.size());
  for (size_t p = 0; p < points.vertex.size(); ++p) {
    const auto v = vector_of(points.vertex[p]);
    for (int axis = 0; axis < 3; ++axis) values[3 * p + axis] = static_cast<float>(v[axis]);
  }
  return values;
}

std::unique_ptr<draco::Mesh> build_draco_mesh(const ContourMesh& mesh, const DracoPoints& points) {
  auto out = std::make_unique<draco::Mesh>();
  out->set_num_points(static_cast<uint32_t>(points.vertex.size()));
  out->SetNumFaces(mesh.triangle_count());
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    draco::Mesh::Face face;
    for (int k = 0; k < 3; ++k) face[k] = draco::PointIndex(points.corner_point[3 * t + k]);
    out->SetFace(draco::FaceIndex(static_cast<uint32_t>(t)), face);
  }
  using Attribute = draco::GeometryAttribute;
  add_attribute(*out, Attribute::POSITION, draco::DT_FLOAT32, 3,
                point_vectors(points, [&](uint32_t v) { return mesh.positions[v]; }));
  if (!mesh.normals.empty()) {
    add_attribute(*out, Attribute::NORMAL, draco::DT_FLOAT32, 3,
                  point_vectors(points, [&](uint32_t v) { return mesh.normals[v]; }));
  }
  const int material =
      add_attribute(*out, Attribute::GENERIC, draco::DT_UINT16, 1, points.material);
  auto metadata = std::make_unique<draco::AttributeMetadata>();
  metadata->AddEntryString("name", kMaterialName);
  out->AddAttributeMetadata(material, std::move(metadata));
  return out;
}

bool has_repeated_index(const ContourMesh& mesh) {
  return std::any_of(mesh.triangles.begin(), mesh.triangles.end(),
                     [](const glm::uvec3& t) { return t.x == t.y || t.y == t.z || t.x == t.z; });
}

}  // namespace

Result<std::string> encode_draco(const ContourMesh& mesh, const ExportOptions& options,
                                 const std::string& path) {
  if (mesh.triangle_count() == 0) {
    // Edgebreaker refuses a mesh without faces ("All triangles are
    // degenerate") and libdraco 1.5.5's sequential encoder crashes on one.
    return error_at(ErrorCode::kUnsupported, path, "draco: cannot encode an empty mesh");
  }
  const DracoPoints points = make_points(mesh);
  const std::unique_ptr<draco::Mesh> draco_mesh = build_draco_mesh(mesh, points);
  draco::Encoder encoder;
  encoder.SetSpeedOptions(options.draco_speed, options.draco_speed);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, options.draco_position_bits);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, kNormalBits);
  if (has_repeated_index(mesh)) {
    // Edgebreaker silently drops triangles with a repeated index (and refuses
    // a mesh made only of them); the sequential encoder keeps every one.
    encoder.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
  }
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodeMeshToBuffer(*draco_mesh, &buffer);
  if (!status.ok()) {
    return error_at(ErrorCode::kInternal, path, std::string("draco: ") + status.error_msg());
  }
  return std::string(buffer.data(), buffer.size());
}

// ------------------------------------------------------------------ reading

namespace {

// Points with the same position and normal bits are one vertex (split only
// because of their materials).
struct WeldKey {
  std::array<uint32_t, 6> bits;
  bool operator==(const WeldKey&) const = default;
};
struct WeldHash {
  size_t operator()(const WeldKey& key) const {
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (uint32_t b : key.bits) {
      h = (h ^ b) * 0xBF58476D1CE4E5B9ull;
      h ^= h >> 31;
    }
    return static_cast<size_t>(h);
  }
};

class DracoReader {
 public:
  DracoReader(const draco::Mesh& mesh, const std::string& path) : in_(mesh), path_(path) {}

  Result<ContourMesh> read() {
    const draco::PointAttribute* positions =
        in_.GetNamedAttribute(draco::GeometryAttribute::POSITION);
    if (!positions || positions->num_components() != 3) {
      return error_at(ErrorCode::kParseError, path_, "draco: no 3-component POSITION attribute");
    }
    const draco::PointAttribute* normals = in_.GetNamedAttribute(draco::GeometryAttribute::NORMAL);
    if (normals && normals->num_components() != 3) normals = nullptr;
    weld(*positions, normals);
    read_faces();
    if (!normals) out_.normals.clear();
    complete_loaded_mesh(out_);
    return std::move(out_);
  }

 private:
  const draco::PointAttribute* material_attribute() const {
    int id = in_.GetAttributeIdByMetadataEntry("name", kMaterialName);
    if (id < 0) id = in_.GetNamedAttributeId(draco::GeometryAttribute::GENERIC);
    const draco::PointAttribute* attribute = id >= 0 ? in_.attribute(id) : nullptr;
    return attribute && attribute->num_components() == 1 ? attribute : nullptr;
  }

  void weld(const draco::PointAttribute& positions, const draco::PointAttribute* normals) {
    std::unordered_map<WeldKey, uint32_t, WeldHash> vertex_of;
    point_vertex_.resize(in_.num_points());
    for (uint32_t p = 0; p < in_.num_points(); ++p) {
      std::array<float, 6> value{};
      const draco::PointIndex point(p);
      positions.ConvertValue<float>(positions.mapped_index(point), 3, value.data());
      if (normals) normals->ConvertValue<float>(normals->mapped_index(point), 3, value.data() + 3);
      WeldKey key;
      std::memcpy(key.bits.data(), value.data(), sizeof(value));
      auto [it, inserted] =
          vertex_of.try_emplace(key, static_cast<uint32_t>(out_.positions.size()));
      if (inserted) {
        out_.positions.emplace_back(value[0], value[1], value[2]);
        out_.normals.emplace_back(value[3], value[4], value[5]);
      }
      point_vertex_[p] = it->second;
    }
  }

  void read_faces() {
    const draco::PointAttribute* materials = material_attribute();
    out_.triangles.resize(in_.num_faces());
    out_.triangle_material.assign(in_.num_faces(), 0);
    for (uint32_t f = 0; f < in_.num_faces(); ++f) {
      const draco::Mesh::Face& face = in_.face(draco::FaceIndex(f));
      for (int k = 0; k < 3; ++k) out_.triangles[f][k] = point_vertex_[face[k].value()];
      if (!materials) continue;
      uint16_t material = 0;
      materials->ConvertValue<uint16_t>(materials->mapped_index(face[0]), 1, &material);
      out_.triangle_material[f] = material;
    }
  }

  const draco::Mesh& in_;
  const std::string& path_;
  ContourMesh out_;
  std::vector<uint32_t> point_vertex_;
};

}  // namespace

Result<ContourMesh> decode_draco(std::string_view bytes, const std::string& path) {
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) {
    return error_at(ErrorCode::kParseError, path,
                    std::string("draco: ") + decoded.status().error_msg());
  }
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (!mesh) return error_at(ErrorCode::kParseError, path, "draco: the file holds no mesh");
  return DracoReader(*mesh, path).read();
}

}  // namespace ldc::meshio_detail
