// meshio: dispatch by format, the checks every writer shares, OBJ, PLY, STL
// and OFF writing, and reading every format back (the text and binary
// parsers are in parse.cpp, glTF in gltf.cpp, Draco in draco.cpp).
//
// Every encoder builds the whole file in memory and hands it to one atomic
// write (ldc/io.h). OBJ text is formatted with std::to_chars straight into
// buffers, in blocks on all cores, which keeps a million-triangle OBJ well
// under a second.
#include "meshio/meshio.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <optional>
#include <unordered_map>
#include <utility>

#include "ldc/internal/vec_text.h"
#include "ldc/io.h"
#include "meshio/detail/codecs.h"

namespace ldc {
namespace meshio_detail {

Status error_at(ErrorCode code, std::string_view path, std::string_view message) {
  std::string text(path);
  text += ": ";
  text += message;
  return {code, std::move(text)};
}

std::string material_name(const ExportOptions& options, uint16_t id) {
  if (id < options.material_names.size() && !options.material_names[id].empty()) {
    return options.material_names[id];
  }
  return "material_" + std::to_string(id);
}

// A counting sort: linear, and stable so each group keeps the input order.
MaterialGroups group_by_material(const ContourMesh& mesh) {
  constexpr size_t kIds = size_t{std::numeric_limits<uint16_t>::max()} + 1;
  std::vector<size_t> next(kIds, 0);  // first a count per id, then the next free slot
  for (size_t t = 0; t < mesh.triangle_count(); ++t) ++next[material_of(mesh, t)];
  MaterialGroups groups;
  size_t start = 0;
  for (size_t id = 0; id < kIds; ++id) {
    if (next[id] == 0) continue;
    groups.material.push_back(static_cast<uint16_t>(id));
    groups.group_start.push_back(start);
    start += std::exchange(next[id], start);
  }
  groups.group_start.push_back(start);
  groups.order.resize(mesh.triangle_count());
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    groups.order[next[material_of(mesh, t)]++] = static_cast<uint32_t>(t);
  }
  return groups;
}

// Most vertices touch one material only; just the others (material borders)
// have their (vertex, material) corners sorted and counted.
std::vector<uint16_t> vertex_materials(const ContourMesh& mesh) {
  if (!mesh.vertex_material.empty()) return mesh.vertex_material;
  const size_t n = mesh.vertex_count();
  std::vector<uint16_t> first(n, 0);
  std::vector<uint8_t> state(n, 0);  // 0 unseen, 1 one material, 2 several
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint16_t m = material_of(mesh, t);
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.triangles[t][k];
      if (state[v] == 0) {
        first[v] = m;
        state[v] = 1;
      } else if (first[v] != m) {
        state[v] = 2;
      }
    }
  }
  std::vector<uint64_t> corners;  // vertex << 16 | material, border vertices only
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.triangles[t][k];
      if (state[v] == 2) corners.push_back((uint64_t{v} << 16) | material_of(mesh, t));
    }
  }
  std::sort(corners.begin(), corners.end());
  size_t best_run = 0;
  for (size_t i = 0; i < corners.size();) {
    size_t j = i;
    while (j < corners.size() && corners[j] == corners[i]) ++j;
    const auto v = static_cast<uint32_t>(corners[i] >> 16);
    if (i == 0 || (corners[i - 1] >> 16) != v) best_run = 0;  // first run of this vertex
    if (j - i > best_run) {  // strictly more: ties keep the smaller id, seen first
      best_run = j - i;
      first[v] = static_cast<uint16_t>(corners[i] & 0xffff);
    }
    i = j;
  }
  return first;
}

namespace {

// Sum of the triangles' (area-weighted) normals at each vertex; a vertex with
// no area around it gets +z so that every normal written is unit length.
std::vector<glm::vec3> area_weighted_normals(const ContourMesh& mesh) {
  std::vector<glm::dvec3> sum(mesh.vertex_count(), glm::dvec3(0.0));
  for (const glm::uvec3& tri : mesh.triangles) {
    const glm::dvec3& a = mesh.positions[tri.x];
    const glm::dvec3 n = glm::cross(mesh.positions[tri.y] - a, mesh.positions[tri.z] - a);
    for (int k = 0; k < 3; ++k) sum[tri[k]] += n;
  }
  std::vector<glm::vec3> normals(sum.size());
  for (size_t v = 0; v < sum.size(); ++v) {
    const double length = glm::length(sum[v]);
    normals[v] = length > 0.0 && std::isfinite(length) ? glm::vec3(sum[v] / length)
                                                       : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  return normals;
}

}  // namespace

void complete_loaded_mesh(ContourMesh& mesh) {
  if (mesh.triangle_material.size() != mesh.triangle_count()) {
    mesh.triangle_material.assign(mesh.triangle_count(), 0);
  }
  if (mesh.normals.size() != mesh.vertex_count()) mesh.normals = area_weighted_normals(mesh);
  if (mesh.vertex_material.size() != mesh.vertex_count()) {
    mesh.vertex_material.clear();
    mesh.vertex_material = vertex_materials(mesh);
  }
}

}  // namespace meshio_detail

using namespace meshio_detail;

namespace {

// ----------------------------------------------------------------- checks

using detail::vec_text;
using detail::is_finite;

Status invalid(const std::string& path, const std::string& message) {
  return error_at(ErrorCode::kInvalidArgument, path, message);
}

Status check_array_sizes(const ContourMesh& mesh, const std::string& path) {
  auto check = [&](size_t size, size_t expected, const char* name, const char* per) -> Status {
    if (size == 0 || size == expected) return {};
    return invalid(path, std::string(name) + " has " + std::to_string(size) +
                             " entries; expected " + std::to_string(expected) + " (one per " + per +
                             ") or none");
  };
  Status status = check(mesh.normals.size(), mesh.vertex_count(), "normals", "vertex");
  if (status.ok())
    status = check(mesh.vertex_material.size(), mesh.vertex_count(), "vertex_material", "vertex");
  if (status.ok()) {
    status = check(mesh.triangle_material.size(), mesh.triangle_count(), "triangle_material",
                   "triangle");
  }
  return status;
}

// Names the first bad element: array sizes, then positions, normals, indices.
Status check_contour_mesh(const ContourMesh& mesh, const std::string& path) {
  Status status = check_array_sizes(mesh, path);
  if (!status.ok()) return status;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    if (!is_finite(mesh.positions[v])) {
      return invalid(path, "vertex " + std::to_string(v) + " position " + vec_text(mesh.positions[v]) +
                               " is not finite");
    }
  }
  for (size_t v = 0; v < mesh.normals.size(); ++v) {
    if (!is_finite(glm::dvec3(mesh.normals[v]))) {
      return invalid(path, "vertex " + std::to_string(v) + " normal " +
                               vec_text(glm::dvec3(mesh.normals[v])) + " is not finite");
    }
  }
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (mesh.triangles[t][k] >= mesh.vertex_count()) {
        return invalid(path, "triangle " + std::to_string(t) + " corner " + std::to_string(k) +
                                 ": vertex index " + std::to_string(mesh.triangles[t][k]) +
                                 " out of range (" + std::to_string(mesh.vertex_count()) +
                                 " vertices)");
      }
    }
  }
  return {};
}

// OBJ names go on `usemtl` lines that parse_obj trims and cuts at '#', and our
// reader maps names back to ids, so names must survive that and be distinct.
Status check_obj_names(const ExportOptions& options, const MaterialGroups& groups,
                       const std::string& path) {
  std::unordered_map<std::string, uint16_t> seen;
  for (uint16_t id : groups.material) {
    const std::string name = material_name(options, id);
    const bool bad_char =
        name.find_first_of("#\r\n", 0) != std::string::npos || name.find('\0') != std::string::npos;
    const bool padded = std::isspace(static_cast<unsigned char>(name.front())) ||
                        std::isspace(static_cast<unsigned char>(name.back()));
    if (bad_char || padded) {
      return invalid(path, "material name '" + name + "' (id " + std::to_string(id) +
                               ") cannot be written to OBJ (no '#', line breaks or outer spaces)");
    }
    auto [it, inserted] = seen.emplace(name, id);
    if (!inserted) {
      return invalid(path, "material ids " + std::to_string(it->second) + " and " +
                               std::to_string(id) + " share the name '" + name + "'");
    }
  }
  return {};
}

Status check_options(const ExportOptions& options, MeshFormat format, const std::string& path) {
  if (format != MeshFormat::kDraco) return {};
  if (options.draco_position_bits < 8 || options.draco_position_bits > 30) {
    return invalid(path, "ExportOptions::draco_position_bits " +
                             std::to_string(options.draco_position_bits) + " is outside [8, 30]");
  }
  if (options.draco_speed < 0 || options.draco_speed > 10) {
    return invalid(path, "ExportOptions::draco_speed " + std::to_string(options.draco_speed) +
                             " is outside [0, 10]");
  }
  return {};
}

// -------------------------------------------------------------- byte output

// Text output: numbers are formatted straight into the string's spare room.
class TextBuffer {
 public:
  explicit TextBuffer(size_t reserve) { text_.resize(reserve); }
  template <class T>
  void number(T value) {
    room(32);
    size_ += static_cast<size_t>(std::to_chars(at(), at() + 32, value).ptr - at());
  }
  void put(std::string_view s) {
    room(s.size());
    std::memcpy(at(), s.data(), s.size());
    size_ += s.size();
  }
  void put(char c) {
    room(1);
    text_[size_++] = c;
  }
  std::string take() && {
    text_.resize(size_);
    return std::move(text_);
  }

 private:
  char* at() { return text_.data() + size_; }
  void room(size_t n) {
    if (size_ + n > text_.size()) text_.resize(std::max(2 * text_.size(), size_ + n + 4096));
  }
  std::string text_;
  size_t size_ = 0;
};

// Binary output, little-endian whatever the host.
class ByteWriter {
 public:
  explicit ByteWriter(std::string& out, size_t offset) : out_(out), pos_(offset) {}
  template <class T>
  void put(T value) {
    using U = std::conditional_t<
        sizeof(T) == 8, uint64_t,
        std::conditional_t<sizeof(T) == 4, uint32_t,
                           std::conditional_t<sizeof(T) == 2, uint16_t, uint8_t>>>;
    const U bits = std::bit_cast<U>(value);
    for (size_t i = 0; i < sizeof(T); ++i)
      out_[pos_++] = static_cast<char>((bits >> (8 * i)) & 0xff);
  }

 private:
  std::string& out_;
  size_t pos_;
};

// -------------------------------------------------------------------- OBJ

constexpr std::string_view kObjMaterialComment = "# ldc-material ";

void append_obj_header(TextBuffer& out, const MaterialGroups& groups,
                       const ExportOptions& options) {
  out.put("# written by ldc (contour mesh)\n");
  for (uint16_t id : groups.material) {  // lets load_contour_mesh give back the exact ids
    out.put(kObjMaterialComment);
    out.number(id);
    out.put(' ');
    out.put(material_name(options, id));
    out.put('\n');
  }
}

// A text file as pieces formatted in parallel and joined once at the end:
// one allocation of the exact size, no zero-filling and no regrowth.
class TextPieces {
 public:
  void add(std::string piece) { pieces_.push_back(std::move(piece)); }
  // Formats items [0, count) in blocks on all cores; the blocks keep their
  // order, so the bytes are the same whatever the thread count.
  template <class Format>
  void add_in_blocks(size_t count, size_t bytes_per_item, Format format) {
    constexpr size_t kBlock = 16384;
    const size_t first = pieces_.size();
    pieces_.resize(first + (count + kBlock - 1) / kBlock);
    tbb::parallel_for(first, pieces_.size(), [&](size_t b) {
      const size_t begin = (b - first) * kBlock, end = std::min(count, begin + kBlock);
      TextBuffer part((end - begin) * bytes_per_item);
      for (size_t i = begin; i < end; ++i) format(part, i);
      pieces_[b] = std::move(part).take();
    });
  }
  std::string join() && {
    size_t total = 0;
    for (const std::string& p : pieces_) total += p.size();
    std::string out;
    out.reserve(total);
    for (std::string& p : pieces_) {
      out += p;
      std::string().swap(p);  // free as we go: peak memory about the file's size
    }
    return out;
  }

 private:
  std::vector<std::string> pieces_;
};

template <class Vector>
void put_obj_vector(TextBuffer& out, std::string_view keyword, const Vector& vector) {
  out.put(keyword);
  for (int axis = 0; axis < 3; ++axis) {
    out.put(' ');
    out.number(vector[axis]);  // shortest form that reads back to the same value
  }
  out.put('\n');
}

void put_obj_face(TextBuffer& out, const glm::uvec3& tri, bool normals) {
  out.put('f');
  for (int k = 0; k < 3; ++k) {
    out.put(' ');
    out.number(uint64_t{tri[k]} + 1);
    if (!normals) continue;
    out.put("//");  // the normal of vertex i is vn i
    out.number(uint64_t{tri[k]} + 1);
  }
  out.put('\n');
}

std::string encode_obj(const ContourMesh& mesh, const MaterialGroups& groups,
                       const ExportOptions& options) {
  TextPieces out;
  TextBuffer header(4096);
  append_obj_header(header, groups, options);
  out.add(std::move(header).take());
  out.add_in_blocks(mesh.vertex_count(), 64, [&](TextBuffer& part, size_t v) {
    put_obj_vector(part, "v", mesh.positions[v]);
  });
  out.add_in_blocks(mesh.normals.size(), 40, [&](TextBuffer& part, size_t v) {
    put_obj_vector(part, "vn", mesh.normals[v]);
  });
  // Faces in the mesh's own order (a round trip keeps it), a usemtl line
  // wherever the material changes.
  const bool normals = !mesh.normals.empty();
  out.add_in_blocks(mesh.triangle_count(), 48, [&](TextBuffer& part, size_t t) {
    const uint16_t material = material_of(mesh, t);
    if (t == 0 || material != material_of(mesh, t - 1)) {
      part.put("usemtl ");
      part.put(material_name(options, material));
      part.put('\n');
    }
    put_obj_face(part, mesh.triangles[t], normals);
  });
  return std::move(out).join();
}

// -------------------------------------------------------------------- PLY

constexpr size_t kPlyFaceBytes = 1 + 3 * 4 + 2;  // uchar count, 3 int, ushort material

std::string ply_header(size_t vertices, size_t triangles, bool normals) {
  std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment written by ldc (contour mesh)\n"
      "element vertex " +
      std::to_string(vertices) + "\nproperty double x\nproperty double y\nproperty double z\n";
  if (normals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  header += "element face " + std::to_string(triangles) +
            "\nproperty list uchar int vertex_indices\nproperty ushort material\nend_header\n";
  return header;
}

size_t ply_vertex_bytes(bool normals) { return 3 * 8 + (normals ? 3 * 4 : 0); }

Result<std::string> encode_ply(const ContourMesh& mesh, const std::string& path) {
  if (mesh.vertex_count() > size_t{std::numeric_limits<int32_t>::max()}) {
    return error_at(ErrorCode::kTooLarge, path, "PLY indices are 'int': too many vertices");
  }
  const bool normals = !mesh.normals.empty();
  std::string out = ply_header(mesh.vertex_count(), mesh.triangle_count(), normals);
  const size_t header = out.size();
  out.resize(header + mesh.vertex_count() * ply_vertex_bytes(normals) +
             mesh.triangle_count() * kPlyFaceBytes);
  ByteWriter bytes(out, header);
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    for (int axis = 0; axis < 3; ++axis) bytes.put(mesh.positions[v][axis]);
    if (normals) {
      for (int axis = 0; axis < 3; ++axis) bytes.put(mesh.normals[v][axis]);
    }
  }
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    bytes.put(uint8_t{3});
    for (int k = 0; k < 3; ++k) bytes.put(static_cast<int32_t>(mesh.triangles[t][k]));
    bytes.put(material_of(mesh, t));
  }
  return out;
}

// -------------------------------------------------------------------- STL

constexpr size_t kStlHeaderBytes = 84;
constexpr size_t kStlTriangleBytes = 50;

Result<std::string> encode_stl(const ContourMesh& mesh, const std::string& path) {
  if (mesh.triangle_count() > std::numeric_limits<uint32_t>::max()) {
    return error_at(ErrorCode::kTooLarge, path, "binary STL holds at most 2^32 - 1 triangles");
  }
  std::string out(kStlHeaderBytes + kStlTriangleBytes * mesh.triangle_count(), '\0');
  // The header must not start with "solid": readers would take it for text STL.
  constexpr std::string_view kTitle = "binary STL written by ldc (contour mesh)";
  std::memcpy(out.data(), kTitle.data(), kTitle.size());
  ByteWriter bytes(out, 80);
  bytes.put(static_cast<uint32_t>(mesh.triangle_count()));
  for (const glm::uvec3& tri : mesh.triangles) {
    const glm::dvec3& a = mesh.positions[tri.x];
    const glm::dvec3 cross = glm::cross(mesh.positions[tri.y] - a, mesh.positions[tri.z] - a);
    const double length = glm::length(cross);
    const glm::vec3 normal = length > 0.0 ? glm::vec3(cross / length) : glm::vec3(0.0f);
    for (int axis = 0; axis < 3; ++axis) bytes.put(normal[axis]);
    for (int k = 0; k < 3; ++k) {
      for (int axis = 0; axis < 3; ++axis)
        bytes.put(static_cast<float>(mesh.positions[tri[k]][axis]));
    }
    bytes.put(uint16_t{0});  // attribute byte count
  }
  return out;
}

// ------------------------------------------------------------------- files


std::string encode_off(const ContourMesh& mesh);  // below, beside the OFF reader

Result<std::string> encode(const ContourMesh& mesh, MeshFormat format, const ExportOptions& options,
                           const std::string& path) {
  switch (format) {
    case MeshFormat::kObj: {
      const MaterialGroups groups = group_by_material(mesh);
      Status names = check_obj_names(options, groups, path);
      if (!names.ok()) return names;
      return encode_obj(mesh, groups, options);
    }
    case MeshFormat::kPly:
      return encode_ply(mesh, path);
    case MeshFormat::kStl:
      return encode_stl(mesh, path);
    case MeshFormat::kOff:
      return encode_off(mesh);
    case MeshFormat::kGlb:
      return encode_glb(mesh, options, path);
    case MeshFormat::kDraco:
      return encode_draco(mesh, options, path);
  }
  return error_at(ErrorCode::kInternal, path, "unknown MeshFormat");
}

// ------------------------------------------------------------ OBJ reading

std::optional<glm::dvec3> parse_vector(std::string_view text) {
  glm::dvec3 value;
  const char* p = text.data();
  const char* end = text.data() + text.size();
  for (int axis = 0; axis < 3; ++axis) {
    while (p < end && (*p == ' ' || *p == '\t')) ++p;
    auto [next, error] = std::from_chars(p, end, value[axis]);
    if (error != std::errc()) return std::nullopt;
    p = next;
  }
  return value;
}

// What parse_obj does not keep: normals, our material-id comments, and (for
// a file without faces, which parse_obj refuses) the positions.
struct ObjExtras {
  std::vector<glm::dvec3> positions;
  std::vector<glm::vec3> normals;
  std::unordered_map<std::string, uint16_t> material_ids;
  bool has_faces = false;
};

ObjExtras scan_obj(std::string_view bytes) {
  ObjExtras extras;
  for (size_t pos = 0; pos < bytes.size();) {
    size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) end = bytes.size();
    std::string_view line = bytes.substr(pos, end - pos);
    pos = end + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.starts_with("f ")) extras.has_faces = true;
    if (line.starts_with("v ") || line.starts_with("vn ")) {
      const bool normal = line[1] == 'n';
      const std::optional<glm::dvec3> value = parse_vector(line.substr(normal ? 3 : 2));
      if (!value) continue;
      if (normal)
        extras.normals.emplace_back(*value);
      else
        extras.positions.push_back(*value);
    }
    if (line.starts_with(kObjMaterialComment)) {
      std::string_view rest = line.substr(kObjMaterialComment.size());
      unsigned id = 0;
      auto [next, error] = std::from_chars(rest.data(), rest.data() + rest.size(), id);
      if (error != std::errc() || id > 0xffff || next == rest.data() + rest.size()) continue;
      extras.material_ids[std::string(rest.substr(next - rest.data() + 1))] =
          static_cast<uint16_t>(id);
    }
  }
  return extras;
}

// parse_obj numbers names in order of appearance; give back the ids we wrote.
uint16_t obj_material_id(const std::string& name, uint16_t parsed_id, const ObjExtras& extras) {
  auto found = extras.material_ids.find(name);
  if (found != extras.material_ids.end()) return found->second;
  unsigned id = 0;
  constexpr std::string_view kPrefix = "material_";
  if (name.starts_with(kPrefix)) {
    const char* end = name.data() + name.size();
    auto [next, error] = std::from_chars(name.data() + kPrefix.size(), end, id);
    if (error == std::errc() && next == end && id <= 0xffff) return static_cast<uint16_t>(id);
  }
  return parsed_id;
}

Result<ContourMesh> decode_obj(std::string_view bytes, const std::string& path, const LoadOptions& options) {
  ObjExtras extras = scan_obj(bytes);
  ContourMesh mesh;
  if (!extras.has_faces) {
    mesh.positions = std::move(extras.positions);
  } else {
    Result<TriangleMesh> parsed = parse_obj(bytes, path, options);
    if (!parsed.ok()) return parsed.status();
    TriangleMesh& tm = parsed.value();
    std::vector<uint16_t> ids(tm.material_names.size());
    for (size_t i = 0; i < ids.size(); ++i) {
      ids[i] = obj_material_id(tm.material_names[i], static_cast<uint16_t>(i), extras);
    }
    mesh.positions = std::move(tm.positions);
    mesh.triangles = std::move(tm.triangles);
    mesh.triangle_material.reserve(tm.triangle_material.size());
    for (uint16_t parsed_id : tm.triangle_material)
      mesh.triangle_material.push_back(ids[parsed_id]);
  }
  if (extras.normals.size() == mesh.vertex_count()) mesh.normals = std::move(extras.normals);
  complete_loaded_mesh(mesh);
  return mesh;
}

// ------------------------------------------------------------ PLY reading

template <class T>
T load_le(const char* p) {
  using U = std::conditional_t<sizeof(T) == 8, uint64_t,
                               std::conditional_t<sizeof(T) == 4, uint32_t, uint16_t>>;
  U bits = 0;
  for (size_t i = 0; i < sizeof(T); ++i) bits |= U{static_cast<unsigned char>(p[i])} << (8 * i);
  return std::bit_cast<T>(bits);
}

// The element counts of a header, if it is exactly the one encode_ply writes.
std::optional<std::array<size_t, 3>> own_ply_layout(std::string_view bytes) {
  const size_t end = bytes.find("end_header\n");
  if (end == std::string_view::npos) return std::nullopt;
  const std::string_view header = bytes.substr(0, end + 11);
  auto count_after = [&](std::string_view key) -> std::optional<size_t> {
    const size_t at = header.find(key);
    if (at == std::string_view::npos) return std::nullopt;
    size_t value = 0;
    const char* begin = header.data() + at + key.size();
    auto [next, error] = std::from_chars(begin, header.data() + header.size(), value);
    return error == std::errc() ? std::optional<size_t>(value) : std::nullopt;
  };
  const auto vertices = count_after("element vertex ");
  const auto faces = count_after("element face ");
  if (!vertices || !faces) return std::nullopt;
  for (size_t normals = 0; normals < 2; ++normals) {
    if (ply_header(*vertices, *faces, normals != 0) == header) {
      return std::array<size_t, 3>{*vertices, *faces, normals};
    }
  }
  return std::nullopt;
}

Status read_own_ply_faces(std::string_view data, ContourMesh& mesh, const std::string& path,
                          size_t data_offset) {
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const char* p = data.data() + t * kPlyFaceBytes;
    const size_t at = data_offset + t * kPlyFaceBytes;
    if (static_cast<unsigned char>(p[0]) != 3) {
      return error_at(
          ErrorCode::kCorruptData, path,
          "byte " + std::to_string(at) + ": face " + std::to_string(t) + " is not a triangle");
    }
    for (int k = 0; k < 3; ++k) {
      const auto index = load_le<int32_t>(p + 1 + 4 * k);
      if (index < 0 || static_cast<size_t>(index) >= mesh.vertex_count()) {
        return error_at(ErrorCode::kCorruptData, path,
                        "byte " + std::to_string(at) + ": face " + std::to_string(t) +
                            " vertex index " + std::to_string(index) + " out of range");
      }
      mesh.triangles[t][k] = static_cast<uint32_t>(index);
    }
    mesh.triangle_material[t] = load_le<uint16_t>(p + 13);
  }
  return {};
}

// Our own layout, read directly: parse_ply would drop normals and materials.
Result<ContourMesh> read_own_ply(std::string_view bytes, const std::array<size_t, 3>& layout,
                                 const std::string& path) {
  const auto [vertices, faces, normals] = layout;
  const size_t offset = bytes.find("end_header\n") + 11;
  const size_t vertex_bytes = ply_vertex_bytes(normals != 0);
  const std::string_view data = bytes.substr(offset);
  if (vertices > data.size() / vertex_bytes || faces > data.size() / kPlyFaceBytes ||
      vertices * vertex_bytes + faces * kPlyFaceBytes != data.size()) {
    return error_at(ErrorCode::kCorruptData, path,
                    "the header declares " + std::to_string(vertices) + " vertices and " +
                        std::to_string(faces) + " faces but the data has " +
                        std::to_string(data.size()) + " bytes");
  }
  ContourMesh mesh;
  mesh.positions.resize(vertices);
  if (normals) mesh.normals.resize(vertices);
  for (size_t v = 0; v < vertices; ++v) {
    const char* p = data.data() + v * vertex_bytes;
    for (int axis = 0; axis < 3; ++axis) mesh.positions[v][axis] = load_le<double>(p + 8 * axis);
    if (!normals) continue;
    for (int axis = 0; axis < 3; ++axis) mesh.normals[v][axis] = load_le<float>(p + 24 + 4 * axis);
  }
  mesh.triangles.resize(faces);
  mesh.triangle_material.resize(faces);
  Status status = read_own_ply_faces(data.substr(vertices * vertex_bytes), mesh, path,
                                     offset + vertices * vertex_bytes);
  if (!status.ok()) return status;
  return mesh;
}

Result<ContourMesh> decode_ply(std::string_view bytes, const std::string& path, const LoadOptions& options) {
  ContourMesh mesh;
  if (const auto layout = own_ply_layout(bytes)) {
    Result<ContourMesh> own = read_own_ply(bytes, *layout, path);
    if (!own.ok()) return own.status();
    mesh = std::move(own.value());
  } else {  // someone else's PLY: positions and triangles only
    Result<TriangleMesh> parsed = parse_ply(bytes, path, options);
    if (!parsed.ok()) return parsed.status();
    mesh.positions = std::move(parsed->positions);
    mesh.triangles = std::move(parsed->triangles);
  }
  complete_loaded_mesh(mesh);
  return mesh;
}

// ------------------------------------------------------------ STL reading

Result<ContourMesh> decode_stl(std::string_view bytes, const std::string& path, const LoadOptions& options) {
  ContourMesh mesh;
  // parse_stl refuses a file without triangles; ours writes one for an empty mesh.
  const bool empty = bytes.size() == kStlHeaderBytes && load_le<uint32_t>(bytes.data() + 80) == 0;
  if (!empty) {
    Result<TriangleMesh> parsed = parse_stl(bytes, path, options);
    if (!parsed.ok()) return parsed.status();
    mesh.positions = std::move(parsed->positions);
    mesh.triangles = std::move(parsed->triangles);
  }
  complete_loaded_mesh(mesh);
  return mesh;
}

// ------------------------------------------------------------ OFF

std::string encode_off(const ContourMesh& mesh) {
  TextPieces out;
  out.add("OFF\n" + std::to_string(mesh.vertex_count()) + ' ' + std::to_string(mesh.triangle_count()) + " 0\n");
  out.add_in_blocks(mesh.vertex_count(), 64, [&](TextBuffer& part, size_t v) {
    for (int axis = 0; axis < 3; ++axis) {
      if (axis) part.put(' ');
      part.number(mesh.positions[v][axis]);
    }
    part.put('\n');
  });
  out.add_in_blocks(mesh.triangle_count(), 40, [&](TextBuffer& part, size_t t) {
    part.put('3');
    for (int k = 0; k < 3; ++k) {
      part.put(' ');
      part.number(uint64_t{mesh.triangles[t][k]});
    }
    part.put('\n');
  });
  return std::move(out).join();
}

Result<ContourMesh> decode_off(std::string_view bytes, const std::string& path, const LoadOptions& options) {
  Result<TriangleMesh> parsed = parse_off(bytes, path, options);
  if (!parsed.ok()) return parsed.status();
  ContourMesh mesh;
  mesh.positions = std::move(parsed->positions);
  mesh.triangles = std::move(parsed->triangles);
  complete_loaded_mesh(mesh);
  return mesh;
}

Result<ContourMesh> decode(std::string_view bytes, MeshFormat format, const std::string& path,
                           const LoadOptions& options) {
  Result<ContourMesh> mesh = [&]() -> Result<ContourMesh> {
    switch (format) {
      case MeshFormat::kObj: return decode_obj(bytes, path, options);
      case MeshFormat::kPly: return decode_ply(bytes, path, options);
      case MeshFormat::kStl: return decode_stl(bytes, path, options);
      case MeshFormat::kOff: return decode_off(bytes, path, options);
      case MeshFormat::kGlb: return decode_glb(bytes, path);
      case MeshFormat::kDraco: return decode_draco(bytes, path);
    }
    return error_at(ErrorCode::kInternal, path, "unknown MeshFormat");
  }();
  if (mesh.ok() && mesh->triangle_count() > options.max_triangles) {
    return error_at(ErrorCode::kTooLarge, path,
                    std::to_string(mesh->triangle_count()) + " triangles exceed the limit of " +
                        std::to_string(options.max_triangles));
  }
  return mesh;
}

// Materials of a TriangleMesh written under its own names unless the caller named them.
ExportOptions with_material_names(const TriangleMesh& mesh, const ExportOptions& options) {
  ExportOptions named = options;
  if (named.material_names.empty()) named.material_names = mesh.material_names;
  return named;
}

}  // namespace

const char* mesh_format_name(MeshFormat format) {
  switch (format) {
    case MeshFormat::kObj: return "obj";
    case MeshFormat::kPly: return "ply";
    case MeshFormat::kStl: return "stl";
    case MeshFormat::kOff: return "off";
    case MeshFormat::kGlb: return "glb";
    case MeshFormat::kDraco: return "drc";
  }
  return "unknown";
}

Result<MeshFormat> mesh_format_from_path(const std::string& path) {
  const size_t slash = path.find_last_of("/\\");
  const size_t dot = path.rfind('.');
  std::string extension;
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) {
    extension = path.substr(dot + 1);
    for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  for (MeshFormat f : {MeshFormat::kObj, MeshFormat::kPly, MeshFormat::kStl, MeshFormat::kOff, MeshFormat::kGlb,
                       MeshFormat::kDraco}) {
    if (extension == mesh_format_name(f)) return f;
  }
  const std::string shown = extension.empty() ? "no extension" : "'." + path.substr(dot + 1) + "'";
  return error_at(ErrorCode::kUnsupported, path,
                  "unsupported mesh file type (" + shown + "; expected .obj, .ply, .stl, .off, .glb or .drc)");
}

Status save_mesh(const ContourMesh& mesh, const std::string& path, const ExportOptions& options) {
  Result<MeshFormat> format = mesh_format_from_path(path);
  if (!format.ok()) return format.status();
  Status status = check_options(options, format.value(), path);
  if (status.ok()) status = check_contour_mesh(mesh, path);
  if (!status.ok()) return status;
  try {  // no exception crosses the API, whatever the encoders' libraries throw
    Result<std::string> bytes = encode(mesh, format.value(), options, path);
    if (!bytes.ok()) return bytes.status();
    return write_file_atomically(path, bytes.value());
  } catch (const std::bad_alloc&) {
    return error_at(ErrorCode::kTooLarge, path, "out of memory while encoding");
  } catch (const std::exception& e) {
    return error_at(ErrorCode::kInternal, path, std::string("encoder failed: ") + e.what());
  }
}

Status save_mesh(const TriangleMesh& mesh, const std::string& path, const ExportOptions& options) {
  if (Status s = check_mesh(mesh, path); !s.ok()) return s;
  return save_mesh(to_contour_mesh(mesh), path, with_material_names(mesh, options));
}

namespace {
// The whole file, once its first block looks like `format` (a 300 MB file of
// zeros named .obj was read whole before the parser found no triangles).
Result<std::string> read_mesh_file(const std::string& path, MeshFormat format) {
  return read_file(path, UINT64_MAX, [&](std::string_view head, uint64_t size) {
    return meshio_detail::check_mesh_file_head(format, head, size, path);
  });
}
}  // namespace

Result<ContourMesh> load_contour_mesh(const std::string& path, const LoadOptions& options) {
  Result<MeshFormat> format = mesh_format_from_path(path);
  if (!format.ok()) return format.status();
  try {
    Result<std::string> bytes = read_mesh_file(path, format.value());
    if (!bytes.ok()) return bytes.status();
    return decode(bytes.value(), format.value(), path, options);
  } catch (const std::bad_alloc&) {
    return error_at(ErrorCode::kTooLarge, path, "out of memory while reading");
  } catch (const std::exception& e) {
    return error_at(ErrorCode::kParseError, path, std::string("decoder failed: ") + e.what());
  }
}

Result<TriangleMesh> load_mesh(const std::string& path, const LoadOptions& options) {
  using Parser = Result<TriangleMesh> (*)(std::string_view, std::string_view, const LoadOptions&);
  Result<MeshFormat> format = mesh_format_from_path(path);
  if (!format.ok()) return format.status();
  const MeshFormat f = format.value();
  Parser parser = f == MeshFormat::kObj   ? parse_obj
                  : f == MeshFormat::kPly ? parse_ply
                  : f == MeshFormat::kStl ? parse_stl
                  : f == MeshFormat::kOff ? parse_off
                                          : nullptr;
  if (!parser) {  // GLB, Draco: through the ContourMesh decoders
    Result<ContourMesh> mesh = load_contour_mesh(path, options);
    if (!mesh.ok()) return mesh.status();
    if (mesh->triangles.empty()) return error_at(ErrorCode::kParseError, path, "no triangles");
    return to_triangle_mesh(mesh.value());
  }
  Result<std::string> bytes = read_mesh_file(path, f);
  if (!bytes.ok()) return bytes.status();
  return parser(bytes.value(), path, options);
}

TriangleMesh to_triangle_mesh(const ContourMesh& mesh) {
  TriangleMesh out;
  out.positions = mesh.positions;
  out.triangles = mesh.triangles;
  out.triangle_material = mesh.triangle_material;
  return out;
}

ContourMesh to_contour_mesh(const TriangleMesh& mesh) {
  ContourMesh out;
  out.positions = mesh.positions;
  out.triangles = mesh.triangles;
  out.triangle_material = mesh.triangle_material;
  complete_loaded_mesh(out);
  return out;
}

}  // namespace ldc
