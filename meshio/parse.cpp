// Mesh file loaders: OBJ, PLY, STL and OFF into TriangleMesh.
//
// Every parser works on bytes already in memory and follows the same rules:
// numbers go through std::from_chars (locale-independent and fast), counts
// read from a header are checked against the bytes actually present before
// anything is reserved, polygons are triangulated by one shared ear clipper,
// and every refusal names the file plus a line (text) or byte offset (binary).
#include "meshio/meshio.h"
#include "meshio/detail/codecs.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <concepts>
#include <cstdio>
#include <cstring>
#include <limits>
#include <new>
#include <span>
#include <stdexcept>
#include <unordered_map>

namespace ldc {
namespace {

// Triangles index positions with uint32, so no file may hold more vertices.
constexpr uint64_t kMaxVertices = std::numeric_limits<uint32_t>::max();
// Ear clipping costs O(k^3) in the worst case; larger polygons (rare outside
// hostile input) are fanned so that a crafted file cannot stall the loader.
constexpr size_t kMaxEarClipVertices = 256;
// Faces met before the first OBJ `usemtl` take this material name.
constexpr std::string_view kDefaultMaterial = "default";

// ------------------------------------------------------------------ messages

void append_part(std::string& out, std::string_view text) { out += text; }
template <std::integral T>
void append_part(std::string& out, T value) {
  out += std::to_string(value);
}
void append_part(std::string& out, double value) {
  char buffer[32];
  auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}

template <class... Parts>
std::string concat(const Parts&... parts) {
  std::string out;
  (append_part(out, parts), ...);
  return out;
}

// A token as it appears in messages: quoted, shortened, control bytes hidden,
// so that a binary file fed to a text parser still gives a readable message.
std::string quoted(std::string_view token) {
  constexpr size_t kMaxShown = 32;
  std::string out = "'";
  for (size_t i = 0; i < std::min(token.size(), kMaxShown); ++i) {
    const auto byte = static_cast<unsigned char>(token[i]);
    out += (byte >= 0x20 && byte < 0x7f) ? static_cast<char>(byte) : '?';
  }
  if (token.size() > kMaxShown) out += "...";
  out += "'";
  return out;
}

Status parse_error(std::string message) { return {ErrorCode::kParseError, std::move(message)}; }

// The PLY parser's first-line refusal, also given from a file's first block.
constexpr const char* kNotPly = "not a PLY file (the first line is not 'ply')";

Status no_triangles(std::string_view name) { return parse_error(concat(name, ": no triangles")); }

// ------------------------------------------------------------- text scanning

constexpr bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

std::string_view trim(std::string_view text) {
  while (!text.empty() && is_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  return text;
}

std::string_view strip_comment(std::string_view line) { return line.substr(0, line.find('#')); }

// Walks text line by line without copying. The '\r' of "\r\n" stays on the
// line; Tokens treats it as white space.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const char* begin = text_.data() + pos_;
    const void* newline = std::memchr(begin, '\n', text_.size() - pos_);
    const size_t length = newline ? static_cast<size_t>(static_cast<const char*>(newline) - begin)
                                  : text_.size() - pos_;
    line = std::string_view(begin, length);
    pos_ += length + 1;
    ++line_number_;
    return true;
  }
  size_t line_number() const { return line_number_; }
  // Byte offset of the first line not yet returned.
  size_t offset() const { return std::min(pos_, text_.size()); }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  size_t line_number_ = 0;
};

// White-space separated tokens of one line.
class Tokens {
 public:
  explicit Tokens(std::string_view text) : text_(text) {}

  bool next(std::string_view& token) {
    while (pos_ < text_.size() && is_space(text_[pos_])) ++pos_;
    if (pos_ == text_.size()) return false;
    const size_t start = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
    token = text_.substr(start, pos_ - start);
    return true;
  }
  std::string_view rest() const { return trim(text_.substr(pos_)); }

 private:
  std::string_view text_;
  size_t pos_ = 0;
};

// ------------------------------------------------------------------- numbers

// std::from_chars reports overflow and underflow alike, but the useful
// answers differ (inf versus 0), so look at the decimal exponent of the
// first significant digit.
bool underflows(std::string_view number) {
  int64_t magnitude = 0;
  bool significant = false;
  bool fraction = false;
  size_t i = (!number.empty() && number[0] == '-') ? 1 : 0;
  for (; i < number.size() && number[i] != 'e' && number[i] != 'E'; ++i) {
    if (number[i] == '.') {
      fraction = true;
      continue;
    }
    if (fraction && !significant) --magnitude;
    if (!fraction && significant) ++magnitude;
    if (number[i] != '0') significant = true;
  }
  if (i + 1 >= number.size()) return magnitude < 0;
  std::string_view exponent_text = number.substr(i + 1);
  if (exponent_text[0] == '+') exponent_text.remove_prefix(1);
  int64_t exponent = 0;
  auto [ptr, ec] =
      std::from_chars(exponent_text.data(), exponent_text.data() + exponent_text.size(), exponent);
  if (ec == std::errc::result_out_of_range) return exponent_text[0] == '-';
  return magnitude + exponent < 0;
}

// Parses a whole token as a double. "nan" and "inf" parse (the caller decides
// whether they are allowed); overflow gives +-inf and underflow +-0, as strtod.
bool parse_double(std::string_view token, double& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ptr != end) return false;
  if (ec == std::errc::result_out_of_range) {
    const double sign = token[0] == '-' ? -1.0 : 1.0;
    value = underflows(token) ? sign * 0.0 : sign * HUGE_VAL;
    return true;
  }
  return ec == std::errc{};
}

template <class Integer>
bool parse_integer(std::string_view token, Integer& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return !token.empty() && ptr == end && ec == std::errc{};
}

// Reads "x y z" from `tokens`; returns what was wrong, or "" on success.
// `number` is how the file's own indices would name this vertex.
std::string read_xyz(Tokens& tokens, uint64_t number, glm::dvec3& position) {
  for (int axis = 0; axis < 3; ++axis) {
    std::string_view token;
    if (!tokens.next(token))
      return concat("vertex ", number, " has ", axis, " coordinates (needs 3)");
    if (!parse_double(token, position[axis])) {
      return concat("vertex ", number, " coordinate ", quoted(token), " is not a number");
    }
    if (!std::isfinite(position[axis])) {
      return concat("vertex ", number, " coordinate ", quoted(token), " is not a finite number");
    }
  }
  return {};
}

// ------------------------------------------------------------ triangulation

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Splits polygons into triangles. Ear clipping runs in the polygon's best-fit
// plane so that non-convex faces (L-shaped floors in game levels) come out
// right; what ear clipping cannot handle (collinear or self-overlapping
// corners) is finished as a fan, so a k-gon always gives k - 2 triangles in
// the polygon's own winding.
class PolygonTriangulator {
 public:
  void triangulate(std::span<const glm::dvec3> positions, std::span<const uint32_t> polygon,
                   std::vector<glm::uvec3>& out) {
    if (polygon.size() == 3) {
      out.emplace_back(polygon[0], polygon[1], polygon[2]);
      return;
    }
    link(polygon.size());
    if (polygon.size() <= kMaxEarClipVertices && project(positions, polygon)) {
      clip_ears(polygon, out);
    } else {
      fan(polygon, 0, polygon.size(), out);
    }
  }

 private:
  // A circular doubly linked list over the corners still to be cut.
  void link(size_t count) {
    next_.resize(count);
    prev_.resize(count);
    for (size_t i = 0; i < count; ++i) {
      next_[i] = static_cast<uint32_t>((i + 1) % count);
      prev_[i] = static_cast<uint32_t>((i + count - 1) % count);
    }
  }

  // 2D coordinates in the plane of the Newell normal, oriented so that the
  // polygon's own winding is counter-clockwise. False for a polygon without
  // area (all corners on a line), which has no plane to project into.
  bool project(std::span<const glm::dvec3> positions, std::span<const uint32_t> polygon) {
    const size_t count = polygon.size();
    const glm::dvec3 origin = positions[polygon[0]];  // relative coordinates keep precision
    glm::dvec3 normal(0.0);
    for (size_t i = 0; i < count; ++i) {
      const glm::dvec3 a = positions[polygon[i]] - origin;
      const glm::dvec3 b = positions[polygon[(i + 1) % count]] - origin;
      normal += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x),
                           (a.x - b.x) * (a.y + b.y));
    }
    const double length = glm::length(normal);
    if (!(length > 0.0) || !std::isfinite(length)) return false;
    normal /= length;
    const glm::dvec3 helper = std::abs(normal.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, normal));
    const glm::dvec3 v = glm::cross(normal, u);  // u x v = normal: right-handed
    points_.resize(count);
    for (size_t i = 0; i < count; ++i) {
      const glm::dvec3 d = positions[polygon[i]] - origin;
      points_[i] = glm::dvec2(glm::dot(d, u), glm::dot(d, v));
    }
    return true;
  }

  static bool inside_or_on(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b,
                           const glm::dvec2& c) {
    return cross2(b - a, p - a) >= 0.0 && cross2(c - b, p - b) >= 0.0 &&
           cross2(a - c, p - c) >= 0.0;
  }

  // A strictly convex corner whose triangle holds no other remaining corner.
  // Corners at the same spot as the ear's own (repeated vertices) do not block it.
  bool is_ear(uint32_t corner) const {
    const uint32_t before = prev_[corner];
    const uint32_t after = next_[corner];
    const glm::dvec2& a = points_[before];
    const glm::dvec2& b = points_[corner];
    const glm::dvec2& c = points_[after];
    if (!(cross2(b - a, c - b) > 0.0)) return false;
    for (uint32_t j = next_[after]; j != before; j = next_[j]) {
      const glm::dvec2& p = points_[j];
      if (p == a || p == b || p == c) continue;
      if (inside_or_on(p, a, b, c)) return false;
    }
    return true;
  }

  void clip_ears(std::span<const uint32_t> polygon, std::vector<glm::uvec3>& out) {
    size_t remaining = polygon.size();
    uint32_t corner = 0;
    size_t misses = 0;
    while (remaining > 3) {
      if (is_ear(corner)) {
        out.emplace_back(polygon[prev_[corner]], polygon[corner], polygon[next_[corner]]);
        const uint32_t after = next_[corner];
        next_[prev_[corner]] = after;
        prev_[after] = prev_[corner];
        corner = after;
        --remaining;
        misses = 0;
      } else if (++misses >= remaining) {
        break;  // a full turn without an ear: degenerate; the fan finishes it
      } else {
        corner = next_[corner];
      }
    }
    fan(polygon, corner, remaining, out);
  }

  // Triangles (start, b, next(b)) around the corners still linked.
  void fan(std::span<const uint32_t> polygon, uint32_t start, size_t remaining,
           std::vector<glm::uvec3>& out) const {
    uint32_t b = next_[start];
    for (size_t k = 0; k + 2 < remaining; ++k) {
      const uint32_t c = next_[b];
      out.emplace_back(polygon[start], polygon[b], polygon[c]);
      b = c;
    }
  }

  std::vector<glm::dvec2> points_;
  std::vector<uint32_t> next_;
  std::vector<uint32_t> prev_;
};

// The mesh being built from one file, with LoadOptions::max_triangles enforced.
class MeshAssembler {
 public:
  explicit MeshAssembler(const LoadOptions& options) : limit_(options.max_triangles) {}

  TriangleMesh mesh;

  // Adds a polygon of >= 3 valid indices; false when it would pass the limit.
  bool add_polygon(std::span<const uint32_t> polygon) {
    if (polygon.size() - 2 > limit_ - mesh.triangles.size()) return false;
    triangulator_.triangulate(mesh.positions, polygon, mesh.triangles);
    return true;
  }
  bool add_triangle(const glm::uvec3& triangle) {
    if (mesh.triangles.size() >= limit_) return false;
    mesh.triangles.push_back(triangle);
    return true;
  }

  Status too_many_triangles(std::string_view where) const {
    return {ErrorCode::kTooLarge,
            concat(where, ": more than ", limit_, " triangles (LoadOptions::max_triangles)")};
  }

  Result<TriangleMesh> finish(std::string_view name) {
    if (mesh.triangles.empty()) return no_triangles(name);
    return std::move(mesh);
  }

 private:
  size_t limit_;
  PolygonTriangulator triangulator_;
};

// ----------------------------------------------------------------------- OBJ

class ObjParser {
 public:
  ObjParser(std::string_view name, const LoadOptions& options) : name_(name), out_(options) {}

  Result<TriangleMesh> parse(std::string_view bytes) {
    LineReader lines(bytes);
    std::string_view line;
    while (lines.next(line)) {
      line_ = lines.line_number();
      Status status = parse_line(strip_comment(line));
      if (!status.ok()) return status;
    }
    if (!saw_usemtl_) {
      out_.mesh.triangle_material.clear();
      out_.mesh.material_names.clear();
    }
    return out_.finish(name_);
  }

 private:
  Status parse_line(std::string_view line) {
    Tokens tokens(line);
    std::string_view keyword;
    if (!tokens.next(keyword)) return {};
    if (keyword == "v") return parse_vertex(tokens);
    if (keyword == "f") return parse_face(tokens);
    if (keyword == "usemtl") return parse_usemtl(tokens.rest());
    return {};  // vn vt vp o g s mtllib l and unknown keywords hold nothing a TriangleMesh keeps
  }

  Status parse_vertex(Tokens& tokens) {
    std::vector<glm::dvec3>& positions = out_.mesh.positions;
    if (positions.size() >= kMaxVertices) {
      return {ErrorCode::kTooLarge, where(concat("more than ", kMaxVertices, " vertices"))};
    }
    glm::dvec3 position;
    std::string problem = read_xyz(tokens, positions.size() + 1, position);
    if (!problem.empty()) return parse_error(where(problem));
    positions.push_back(position);  // w and vertex colours after x y z are ignored
    return {};
  }

  Status parse_face(Tokens& tokens) {
    polygon_.clear();
    std::string_view token;
    while (tokens.next(token)) {
      uint32_t index = 0;
      Status status = resolve_index(token, index);
      if (!status.ok()) return status;
      polygon_.push_back(index);
    }
    if (polygon_.size() < 3) {
      return parse_error(
          where(concat("face has ", polygon_.size(), " vertices (needs at least 3)")));
    }
    if (!out_.add_polygon(polygon_)) return out_.too_many_triangles(where_prefix());
    out_.mesh.triangle_material.resize(out_.mesh.triangles.size(), face_material());
    return {};
  }

  // Turns "v", "v/vt", "v//vn" or "v/vt/vn" (1-based, or negative = relative
  // to the end) into a 0-based position index.
  Status resolve_index(std::string_view token, uint32_t& index) const {
    const std::string_view vertex_part = token.substr(0, token.find('/'));
    int64_t value = 0;
    if (!parse_integer(vertex_part, value)) {
      return parse_error(where(concat("face index ", quoted(token), " is not an integer")));
    }
    const auto count = static_cast<int64_t>(out_.mesh.positions.size());
    if (value == 0) return parse_error(where("face index 0 is invalid (OBJ indices start at 1)"));
    if (value > count || value < -count) {
      return parse_error(
          where(concat("face index ", value, " out of range (", count, " vertices so far)")));
    }
    index = static_cast<uint32_t>(value > 0 ? value - 1 : count + value);
    return {};
  }

  Status parse_usemtl(std::string_view material) {
    saw_usemtl_ = true;
    if (material.empty()) material = kDefaultMaterial;
    auto found = material_ids_.find(std::string(material));
    if (found != material_ids_.end()) {
      current_material_ = found->second;
      return {};
    }
    if (out_.mesh.material_names.size() > std::numeric_limits<uint16_t>::max()) {
      return {ErrorCode::kTooLarge, where("more than 65536 material names")};
    }
    current_material_ = static_cast<uint16_t>(out_.mesh.material_names.size());
    out_.mesh.material_names.emplace_back(material);
    material_ids_.emplace(material, current_material_);
    return {};
  }

  // Faces before any usemtl get "default", registered when first needed.
  uint16_t face_material() {
    if (!saw_usemtl_ && out_.mesh.material_names.empty()) {
      // Cannot fail: it is the first name. saw_usemtl_ goes back to false so
      // that a file without any usemtl still ends with no materials.
      (void)parse_usemtl(kDefaultMaterial);
      saw_usemtl_ = false;
    }
    return current_material_;
  }

  std::string where_prefix() const { return concat(name_, ":", line_); }
  std::string where(std::string_view what) const { return concat(name_, ":", line_, ": ", what); }

  std::string_view name_;
  size_t line_ = 0;
  MeshAssembler out_;
  std::vector<uint32_t> polygon_;
  std::unordered_map<std::string, uint16_t> material_ids_;
  uint16_t current_material_ = 0;
  bool saw_usemtl_ = false;
};

// ----------------------------------------------------------------------- PLY

enum class PlyType : uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};
enum class PlyFormat : uint8_t { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

bool parse_ply_type(std::string_view text, PlyType& type) {
  static constexpr std::pair<std::string_view, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [name, value] : kNames) {
    if (text == name) {
      type = value;
      return true;
    }
  }
  return false;
}

size_t ply_type_size(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8: return 1;
    case PlyType::kInt16:
    case PlyType::kUint16: return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32: return 4;
    case PlyType::kFloat64: return 8;
  }
  return 1;
}

bool is_integer_type(PlyType type) { return type < PlyType::kFloat32; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // for a list: the type of its entries
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  size_t line = 0;  // header line, for messages
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  size_t data_offset = 0;  // first byte after the end_header line
  size_t data_line = 0;    // line number of that byte (ascii)
};

class PlyHeaderParser {
 public:
  PlyHeaderParser(std::string_view bytes, std::string_view name) : bytes_(bytes), name_(name) {}

  Result<PlyHeader> parse() {
    LineReader lines(bytes_);
    std::string_view line;
    bool saw_format = false;
    while (lines.next(line)) {
      line_ = lines.line_number();
      Tokens tokens(line);
      std::string_view keyword;
      tokens.next(keyword);
      if (line_ == 1) {
        if (keyword != "ply") return error(kNotPly);
        continue;
      }
      if (keyword == "end_header") {
        if (!saw_format) return error("header has no 'format' line");
        header_.data_offset = lines.offset();
        header_.data_line = line_ + 1;
        return std::move(header_);
      }
      saw_format = saw_format || keyword == "format";
      Status status = parse_line(keyword, tokens);
      if (!status.ok()) return status;
    }
    return parse_error(concat(name_, ": header has no end_header line"));
  }

 private:
  Status parse_line(std::string_view keyword, Tokens& tokens) {
    if (keyword.empty() || keyword == "comment" || keyword == "obj_info") return {};
    if (keyword == "format") return parse_format(tokens);
    if (keyword == "element") return parse_element(tokens);
    if (keyword == "property") return parse_property(tokens);
    return error(concat("unknown header keyword ", quoted(keyword)));
  }

  Status parse_format(Tokens& tokens) {
    std::string_view format;
    tokens.next(format);
    if (format == "ascii") {
      header_.format = PlyFormat::kAscii;
    } else if (format == "binary_little_endian") {
      header_.format = PlyFormat::kBinaryLittleEndian;
    } else if (format == "binary_big_endian") {
      header_.format = PlyFormat::kBinaryBigEndian;
    } else {
      return error(concat("unknown format ", quoted(format)));
    }
    return {};
  }

  Status parse_element(Tokens& tokens) {
    PlyElement element;
    std::string_view name, count;
    if (!tokens.next(name) || !tokens.next(count)) return error("element needs a name and a count");
    if (!parse_integer(count, element.count)) {
      return error(concat("element count ", quoted(count), " is not a non-negative integer"));
    }
    element.name = name;
    element.line = line_;
    header_.elements.push_back(std::move(element));
    return {};
  }

  Status parse_property(Tokens& tokens) {
    if (header_.elements.empty()) return error("property before any element");
    PlyProperty property;
    std::string_view type, name;
    tokens.next(type);
    if (type == "list") {
      property.is_list = true;
      std::string_view count_type;
      tokens.next(count_type);
      if (!parse_ply_type(count_type, property.count_type)) {
        return error(concat("unknown property type ", quoted(count_type)));
      }
      tokens.next(type);
    }
    if (!parse_ply_type(type, property.type))
      return error(concat("unknown property type ", quoted(type)));
    if (!tokens.next(name)) return error("property has no name");
    property.name = name;
    header_.elements.back().properties.push_back(std::move(property));
    return {};
  }

  Status error(std::string_view what) const {
    return parse_error(concat(name_, ":", line_, ": ", what));
  }

  std::string_view bytes_;
  std::string_view name_;
  size_t line_ = 0;
  PlyHeader header_;
};

template <class T>
T load_scalar(const char* bytes, bool swap) {
  std::array<char, sizeof(T)> raw;
  std::memcpy(raw.data(), bytes, sizeof(T));
  if (swap) std::reverse(raw.begin(), raw.end());
  return std::bit_cast<T>(raw);
}

double decode_ply_value(PlyType type, const char* bytes, bool swap) {
  switch (type) {
    case PlyType::kInt8: return load_scalar<int8_t>(bytes, swap);
    case PlyType::kUint8: return load_scalar<uint8_t>(bytes, swap);
    case PlyType::kInt16: return load_scalar<int16_t>(bytes, swap);
    case PlyType::kUint16: return load_scalar<uint16_t>(bytes, swap);
    case PlyType::kInt32: return load_scalar<int32_t>(bytes, swap);
    case PlyType::kUint32: return load_scalar<uint32_t>(bytes, swap);
    case PlyType::kFloat32: return load_scalar<float>(bytes, swap);
    case PlyType::kFloat64: return load_scalar<double>(bytes, swap);
  }
  return 0.0;
}

// The values after a PLY header, read one at a time as doubles (every PLY
// type fits a double exactly), from ascii tokens or binary of either order.
class PlyValues {
 public:
  PlyValues(std::string_view data, const PlyHeader& header)
      : data_(data),
        ascii_(header.format == PlyFormat::kAscii),
        swap_((header.format == PlyFormat::kBinaryBigEndian) !=
              (std::endian::native == std::endian::big)),
        base_offset_(header.data_offset),
        line_(header.data_line) {}

  // False at the end of the data or, for ascii, on a token that is not a number.
  bool read(PlyType type, double& value) {
    if (ascii_) return next_token() && parse_double(token_, value);
    const size_t size = ply_type_size(type);
    if (data_.size() - pos_ < size) return false;
    value = decode_ply_value(type, data_.data() + pos_, swap_);
    pos_ += size;
    return true;
  }
  // After a failed read: whether the data had simply run out.
  bool exhausted() const { return !ascii_ || token_.empty(); }
  // At most how many more values of `type` the data can hold.
  uint64_t capacity(PlyType type) const {
    const size_t left = data_.size() - pos_;
    return ascii_ ? (left + 1) / 2 : left / ply_type_size(type);
  }
  void begin_item() { item_offset_ = pos_; }
  // "file:line" (ascii) or "file: byte N" (binary, start of the current item).
  std::string location(std::string_view name) const {
    return ascii_ ? concat(name, ":", line_) : concat(name, ": byte ", base_offset_ + item_offset_);
  }
  // A value as messages show it: the token as written (ascii) or its value.
  std::string show(double value) const { return ascii_ ? quoted(token_) : concat(value); }

 private:
  bool next_token() {
    for (; pos_ < data_.size() && (is_space(data_[pos_]) || data_[pos_] == '\n'); ++pos_) {
      if (data_[pos_] == '\n') ++line_;
    }
    const size_t start = pos_;
    while (pos_ < data_.size() && !is_space(data_[pos_]) && data_[pos_] != '\n') ++pos_;
    token_ = data_.substr(start, pos_ - start);
    return !token_.empty();
  }

  std::string_view data_;
  bool ascii_;
  bool swap_;
  size_t base_offset_;
  size_t line_;
  size_t pos_ = 0;
  size_t item_offset_ = 0;
  std::string_view token_;
};

class PlyParser {
 public:
  PlyParser(std::string_view bytes, std::string_view name, const LoadOptions& options)
      : bytes_(bytes), name_(name), out_(options), max_triangles_(options.max_triangles) {}

  Result<TriangleMesh> parse() {
    Result<PlyHeader> header = PlyHeaderParser(bytes_, name_).parse();
    if (!header.ok()) return header.status();
    header_ = std::move(header.value());
    Status status = find_roles();
    if (status.ok()) status = check_sizes();
    if (!status.ok()) return status;
    PlyValues values(bytes_.substr(header_.data_offset), header_);
    for (const PlyElement& element : header_.elements) {
      status = read_element(element, values);
      if (!status.ok()) return status;
    }
    return assemble();
  }

 private:
  // Finds the vertex element with x y z and the face element's index list.
  Status find_roles() {
    for (const PlyElement& element : header_.elements) {
      const bool is_vertex = element.name == "vertex";
      const bool is_face = element.name == "face";
      if ((is_vertex && vertex_) || (is_face && face_)) {
        return header_error(element, concat("second element ", quoted(element.name)));
      }
      if (is_vertex) vertex_ = &element;
      if (is_face) face_ = &element;
    }
    if (!vertex_) return parse_error(concat(name_, ": header has no 'vertex' element"));
    Status status = find_xyz();
    if (status.ok() && face_) status = find_index_list();
    return status;
  }

  Status find_xyz() {
    vertex_axis_.assign(vertex_->properties.size(), -1);
    static constexpr std::string_view kAxes[] = {"x", "y", "z"};
    for (int axis = 0; axis < 3; ++axis) {
      bool found = false;
      for (size_t k = 0; k < vertex_->properties.size() && !found; ++k) {
        const PlyProperty& property = vertex_->properties[k];
        if (property.name != kAxes[axis] || property.is_list) continue;
        vertex_axis_[k] = static_cast<int8_t>(axis);
        found = true;
      }
      if (!found) {
        return header_error(*vertex_,
                            concat("element 'vertex' has no scalar property '", kAxes[axis], "'"));
      }
    }
    return {};
  }

  Status find_index_list() {
    for (size_t k = 0; k < face_->properties.size(); ++k) {
      const PlyProperty& property = face_->properties[k];
      if (!property.is_list ||
          (property.name != "vertex_indices" && property.name != "vertex_index")) {
        continue;
      }
      if (!is_integer_type(property.type) || !is_integer_type(property.count_type)) {
        return header_error(*face_,
                            concat("list ", quoted(property.name), " must have integer types"));
      }
      index_property_ = k;
      return {};
    }
    return header_error(*face_, "element 'face' has no list property 'vertex_indices'");
  }

  // Refuses headers whose counts the data cannot hold before anything is
  // reserved: every value takes at least its size in binary, or one digit and
  // one separator in ascii. So a tiny file claiming 2^40 vertices fails here.
  Status check_sizes() const {
    const bool ascii = header_.format == PlyFormat::kAscii;
    uint64_t available = bytes_.size() - header_.data_offset + (ascii ? 1 : 0);
    for (const PlyElement& element : header_.elements) {
      uint64_t item_bytes = 0;
      for (const PlyProperty& property : element.properties) {
        item_bytes +=
            ascii ? 2 : ply_type_size(property.is_list ? property.count_type : property.type);
      }
      if (item_bytes == 0) continue;
      if (element.count > available / item_bytes) {
        return {ErrorCode::kCorruptData,
                concat(name_, ":", element.line, ": element ", quoted(element.name), " declares ",
                       element.count, " items but the ", bytes_.size() - header_.data_offset,
                       " bytes of data hold at most ", available / item_bytes)};
      }
      available -= element.count * item_bytes;
    }
    if (vertex_->count > kMaxVertices) {
      return {ErrorCode::kTooLarge,
              concat(name_, ":", vertex_->line, ": more than ", kMaxVertices, " vertices")};
    }
    if (face_ && face_->count > max_triangles_) {
      return out_.too_many_triangles(concat(name_, ":", face_->line));
    }
    return {};
  }

  Status read_element(const PlyElement& element, PlyValues& in) {
    if (element.properties.empty()) return {};  // no bytes per item, however many items
    if (&element == vertex_) return read_vertices(in);
    if (&element == face_) return read_faces(in);
    for (uint64_t item = 0; item < element.count; ++item) {
      in.begin_item();
      for (const PlyProperty& property : element.properties) {
        Status status = skip_property(property, element, item, in);
        if (!status.ok()) return status;
      }
    }
    return {};
  }

  Status read_vertices(PlyValues& in) {
    std::vector<glm::dvec3>& positions = out_.mesh.positions;
    positions.reserve(vertex_->count);  // bounded by check_sizes
    for (uint64_t item = 0; item < vertex_->count; ++item) {
      in.begin_item();
      glm::dvec3 position(0.0);
      for (size_t k = 0; k < vertex_->properties.size(); ++k) {
        const int axis = vertex_axis_[k];
        if (axis < 0) {
          Status status = skip_property(vertex_->properties[k], *vertex_, item, in);
          if (!status.ok()) return status;
          continue;
        }
        Status status = read_value(vertex_->properties[k].type, *vertex_, item, in, position[axis]);
        if (!status.ok()) return status;
        if (!std::isfinite(position[axis])) {
          return parse_error(concat(in.location(name_), ": vertex ", item, " coordinate ",
                                    in.show(position[axis]), " is not a finite number"));
        }
      }
      positions.push_back(position);
    }
    return {};
  }

  Status read_faces(PlyValues& in) {
    face_sizes_.reserve(face_->count);  // bounded by check_sizes
    for (uint64_t item = 0; item < face_->count; ++item) {
      in.begin_item();
      for (size_t k = 0; k < face_->properties.size(); ++k) {
        Status status = k == index_property_
                            ? read_face_indices(face_->properties[k], item, in)
                            : skip_property(face_->properties[k], *face_, item, in);
        if (!status.ok()) return status;
      }
    }
    return {};
  }

  Status read_face_indices(const PlyProperty& property, uint64_t item, PlyValues& in) {
    uint64_t count = 0;
    Status status = read_list_count(property, *face_, item, in, count);
    if (!status.ok()) return status;
    if (count < 3) {
      return parse_error(concat(in.location(name_), ": face ", item, " has ", count,
                                " vertices (needs at least 3)"));
    }
    for (uint64_t j = 0; j < count; ++j) {
      double index = 0.0;
      status = read_value(property.type, *face_, item, in, index);
      if (!status.ok()) return status;
      if (!(index >= 0.0 && index < static_cast<double>(vertex_->count))) {
        return parse_error(concat(in.location(name_), ": face ", item, " vertex index ",
                                  in.show(index), " out of range (", vertex_->count, " vertices)"));
      }
      face_indices_.push_back(static_cast<uint32_t>(index));
    }
    face_sizes_.push_back(count);
    return {};
  }

  Status skip_property(const PlyProperty& property, const PlyElement& element, uint64_t item,
                       PlyValues& in) const {
    double value = 0.0;
    if (!property.is_list) return read_value(property.type, element, item, in, value);
    uint64_t count = 0;
    Status status = read_list_count(property, element, item, in, count);
    for (uint64_t j = 0; j < count && status.ok(); ++j) {
      status = read_value(property.type, element, item, in, value);
    }
    return status;
  }

  // A list's length; one the remaining data cannot hold is refused up front,
  // so no buffer ever grows towards a hostile count.
  Status read_list_count(const PlyProperty& property, const PlyElement& element, uint64_t item,
                         PlyValues& in, uint64_t& count) const {
    double value = 0.0;
    Status status = read_value(property.count_type, element, item, in, value);
    if (!status.ok()) return status;
    if (!(value >= 0.0 && value == std::floor(value))) {
      return parse_error(concat(in.location(name_), ": ", element.name, " ", item, ": list length ",
                                in.show(value), " is not a non-negative integer"));
    }
    if (value > static_cast<double>(in.capacity(property.type))) {
      return parse_error(concat(in.location(name_), ": ", element.name, " ", item, ": list of ",
                                in.show(value), " entries runs past the end of the data"));
    }
    count = static_cast<uint64_t>(value);
    return {};
  }

  Status read_value(PlyType type, const PlyElement& element, uint64_t item, PlyValues& in,
                    double& value) const {
    if (in.read(type, value)) return {};
    if (in.exhausted()) {
      return parse_error(concat(in.location(name_), ": data ends inside ", element.name, " ", item,
                                " (the header declares ", element.count, ")"));
    }
    return parse_error(concat(in.location(name_), ": ", element.name, " ", item, ": ",
                              in.show(value), " is not a number"));
  }

  Result<TriangleMesh> assemble() {
    size_t first = 0;
    for (size_t face = 0; face < face_sizes_.size(); ++face) {
      const std::span<const uint32_t> polygon(face_indices_.data() + first, face_sizes_[face]);
      if (!out_.add_polygon(polygon))
        return out_.too_many_triangles(concat(name_, ": face ", face));
      first += face_sizes_[face];
    }
    return out_.finish(name_);
  }

  Status header_error(const PlyElement& element, std::string_view what) const {
    return parse_error(concat(name_, ":", element.line, ": ", what));
  }

  std::string_view bytes_;
  std::string_view name_;
  MeshAssembler out_;
  size_t max_triangles_;
  PlyHeader header_;
  const PlyElement* vertex_ = nullptr;
  const PlyElement* face_ = nullptr;
  std::vector<int8_t> vertex_axis_;  // per vertex property: 0 1 2 for x y z, -1 to skip
  size_t index_property_ = 0;
  // Faces are kept until every element is read: the face element may come first.
  std::vector<uint32_t> face_indices_;
  std::vector<size_t> face_sizes_;
};

// ----------------------------------------------------------------------- STL

// STL is a triangle soup: vertices with exactly the same position become one.
class VertexWelder {
 public:
  explicit VertexWelder(std::vector<glm::dvec3>& positions) : positions_(positions) {}

  uint32_t index_of(glm::dvec3 position) {
    position += glm::dvec3(0.0);  // -0.0 + 0.0 == +0.0: both zeros weld together
    const Key key{std::bit_cast<uint64_t>(position.x), std::bit_cast<uint64_t>(position.y),
                  std::bit_cast<uint64_t>(position.z)};
    auto [it, inserted] = ids_.try_emplace(key, static_cast<uint32_t>(positions_.size()));
    if (inserted) positions_.push_back(position);
    return it->second;
  }
  void reserve(size_t count) { ids_.reserve(count); }

 private:
  using Key = std::array<uint64_t, 3>;
  struct KeyHash {
    size_t operator()(const Key& key) const {
      uint64_t h = key[0] * 0x9E3779B97F4A7C15ull;
      h = (h ^ (h >> 29) ^ key[1]) * 0xBF58476D1CE4E5B9ull;
      h = (h ^ (h >> 31) ^ key[2]) * 0x94D049BB133111EBull;
      return static_cast<size_t>(h ^ (h >> 32));
    }
  };
  std::vector<glm::dvec3>& positions_;
  std::unordered_map<Key, uint32_t, KeyHash> ids_;
};

constexpr size_t kStlHeaderBytes = 84;
constexpr size_t kStlTriangleBytes = 50;

uint64_t stl_declared_triangles(std::string_view bytes) {
  return load_scalar<uint32_t>(bytes.data() + 80, std::endian::native == std::endian::big);
}

// Text STL starts with "solid", but so do many binary headers; those are told
// apart by their exact size, and a truncated binary file by the zero bytes
// that text never has.
// `head` is the file's start (at least its first 1024 bytes, or all of it),
// `size` the whole file's.
bool looks_like_text_stl(std::string_view head, uint64_t size) {
  if (head.size() >= kStlHeaderBytes && size >= kStlHeaderBytes &&
      kStlHeaderBytes + kStlTriangleBytes * stl_declared_triangles(head) == size) {
    return false;
  }
  const std::string_view start = trim(head.substr(0, 1024));
  return start.starts_with("solid") && start.find('\0') == std::string_view::npos;
}

Status binary_stl_size_error(std::string_view head, uint64_t size, std::string_view name) {
  if (size < kStlHeaderBytes) {
    return parse_error(concat(name, ": ", size, " bytes is too short for a binary STL and it does not start with 'solid'"));
  }
  const uint64_t count = stl_declared_triangles(head);
  if (kStlHeaderBytes + kStlTriangleBytes * count != size) {
    return parse_error(concat(name, ": binary STL header declares ", count, " triangles, which take ",
                              kStlHeaderBytes + kStlTriangleBytes * count, " bytes, but the file has ", size));
  }
  return Status();
}

Result<TriangleMesh> parse_binary_stl(std::string_view bytes, std::string_view name,
                                      const LoadOptions& options) {
  if (Status size = binary_stl_size_error(bytes, bytes.size(), name); !size.ok()) return size;
  const uint64_t count = stl_declared_triangles(bytes);
  MeshAssembler out(options);
  if (count > options.max_triangles) return out.too_many_triangles(name);
  out.mesh.triangles.reserve(count);
  VertexWelder welder(out.mesh.positions);
  welder.reserve(count);
  const bool swap = std::endian::native == std::endian::big;
  for (uint64_t t = 0; t < count; ++t) {
    const size_t record = kStlHeaderBytes + kStlTriangleBytes * t;
    glm::uvec3 triangle;
    for (int corner = 0; corner < 3; ++corner) {
      glm::dvec3 position;
      for (int axis = 0; axis < 3; ++axis) {
        const size_t offset = record + 12 + 12 * corner + 4 * axis;  // after the facet normal
        position[axis] = load_scalar<float>(bytes.data() + offset, swap);
        if (!std::isfinite(position[axis])) {
          return parse_error(concat(name, ": byte ", offset, ": triangle ", t, " corner ", corner,
                                    " coordinate ", position[axis], " is not a finite number"));
        }
      }
      triangle[corner] = welder.index_of(position);
    }
    out.mesh.triangles.push_back(triangle);
  }
  return out.finish(name);
}

class TextStlParser {
 public:
  TextStlParser(std::string_view name, const LoadOptions& options)
      : name_(name), out_(options), welder_(out_.mesh.positions) {}

  Result<TriangleMesh> parse(std::string_view bytes) {
    LineReader lines(bytes);
    std::string_view line;
    while (lines.next(line)) {
      line_ = lines.line_number();
      Status status = parse_line(line);
      if (!status.ok()) return status;
    }
    if (corners_ != 0) return parse_error(concat(name_, ": file ends inside a facet"));
    return out_.finish(name_);
  }

 private:
  // Only vertex lines carry data; facet and endloop frame each triangle.
  // Normals are ignored: the corner order defines the orientation.
  Status parse_line(std::string_view line) {
    Tokens tokens(line);
    std::string_view keyword;
    if (!tokens.next(keyword)) return {};
    if (keyword == "facet" && corners_ != 0)
      return error("facet starts before the previous one ended");
    if (keyword == "vertex") return parse_vertex(tokens);
    if (keyword == "endloop") return end_facet();
    return {};  // solid, facet, outer loop, endfacet, endsolid
  }

  Status parse_vertex(Tokens& tokens) {
    if (corners_ == 3) return error("facet has more than 3 vertices");
    glm::dvec3 position;
    std::string problem = read_xyz(tokens, vertices_seen_++, position);
    if (!problem.empty()) return error(problem);
    pending_[corners_++] = welder_.index_of(position);
    return {};
  }

  Status end_facet() {
    if (corners_ != 3) return error(concat("facet has ", corners_, " vertices (needs 3)"));
    corners_ = 0;
    if (!out_.add_triangle(pending_)) return out_.too_many_triangles(concat(name_, ":", line_));
    return {};
  }

  Status error(std::string_view what) const {
    return parse_error(concat(name_, ":", line_, ": ", what));
  }

  std::string_view name_;
  size_t line_ = 0;
  MeshAssembler out_;
  VertexWelder welder_;
  glm::uvec3 pending_{0};
  int corners_ = 0;
  uint64_t vertices_seen_ = 0;
};

// ----------------------------------------------------------------------- OFF

// "OFF" with optional prefixes for extra per-vertex data: ST (texture), C
// (colour), N (normal). The extra values are ignored.
bool is_off_keyword(std::string_view keyword) {
  if (!keyword.ends_with("OFF")) return false;
  const std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  return prefix.size() <= 4 && prefix.find_first_not_of("STCN") == std::string_view::npos;
}

class OffParser {
 public:
  OffParser(std::string_view bytes, std::string_view name, const LoadOptions& options)
      : bytes_(bytes),
        name_(name),
        lines_(bytes),
        out_(options),
        max_triangles_(options.max_triangles) {}

  Result<TriangleMesh> parse() {
    Status status = parse_header();
    if (status.ok()) status = check_counts();
    for (uint64_t i = 0; i < vertex_count_ && status.ok(); ++i) status = read_vertex(i);
    for (uint64_t i = 0; i < face_count_ && status.ok(); ++i) status = read_face(i);
    if (!status.ok()) return status;
    return out_.finish(name_);
  }

 private:
  // The next line with something on it after '#' comments are cut.
  bool next_line(std::string_view& line) {
    while (lines_.next(line)) {
      line_ = lines_.line_number();
      line = trim(strip_comment(line));
      if (!line.empty()) return true;
    }
    return false;
  }

  Status parse_header() {
    std::string_view line, keyword;
    if (!next_line(line)) return no_triangles(name_);
    Tokens tokens(line);
    tokens.next(keyword);
    if (!is_off_keyword(keyword)) {
      if (keyword.ends_with("OFF")) return unsupported(concat("OFF variant ", quoted(keyword)));
      return error(concat("expected an 'OFF' header, found ", quoted(keyword)));
    }
    Tokens rest = tokens;
    std::string_view first;
    if (rest.next(first)) {  // counts on the header line
      if (first == "BINARY") return unsupported("binary OFF");
      return parse_counts(tokens);
    }
    if (!next_line(line)) return error("file ends before the counts line");
    Tokens counts(line);
    return parse_counts(counts);
  }

  Status parse_counts(Tokens& tokens) {
    std::string_view vertices, faces;
    if (!tokens.next(vertices) || !tokens.next(faces) || !parse_integer(vertices, vertex_count_) ||
        !parse_integer(faces, face_count_)) {
      return error("counts line needs vertex and face counts");
    }
    return {};  // the edge count, if any, means nothing to a loader
  }

  // A vertex line takes at least 6 bytes ("0 0 0\n") and a face line 8
  // ("3 0 1 2\n"); counts the rest of the file cannot hold fail before any
  // reservation.
  Status check_counts() {
    const uint64_t left = bytes_.size() - lines_.offset() + 1;
    if (vertex_count_ > left / 6 || face_count_ > left / 8 ||
        vertex_count_ * 6 + face_count_ * 8 > left) {
      return {ErrorCode::kCorruptData,
              concat(name_, ":", line_, ": header declares ", vertex_count_, " vertices and ",
                     face_count_, " faces, more than the remaining ", left - 1, " bytes can hold")};
    }
    if (vertex_count_ > kMaxVertices)
      return {ErrorCode::kTooLarge, concat(name_, ": too many vertices")};
    if (face_count_ > max_triangles_) return out_.too_many_triangles(concat(name_, ":", line_));
    out_.mesh.positions.reserve(vertex_count_);
    return {};
  }

  Status read_vertex(uint64_t index) {
    std::string_view line;
    if (!next_line(line)) {
      return parse_error(
          concat(name_, ": file ends after ", index, " of ", vertex_count_, " vertices"));
    }
    Tokens tokens(line);
    glm::dvec3 position;
    std::string problem = read_xyz(tokens, index, position);
    if (!problem.empty()) return error(problem);
    out_.mesh.positions.push_back(position);  // colours and normals after x y z are ignored
    return {};
  }

  Status read_face(uint64_t index) {
    std::string_view line, token;
    if (!next_line(line)) {
      return parse_error(concat(name_, ": file ends after ", index, " of ", face_count_, " faces"));
    }
    Tokens tokens(line);
    uint64_t corners = 0;
    if (!tokens.next(token) || !parse_integer(token, corners)) {
      return error(
          concat("face ", index, " size ", quoted(token), " is not a non-negative integer"));
    }
    if (corners < 3)
      return error(concat("face ", index, " has ", corners, " vertices (needs at least 3)"));
    polygon_.clear();
    for (uint64_t j = 0; j < corners; ++j) {
      uint64_t vertex = 0;
      if (!tokens.next(token))
        return error(concat("face ", index, " lists ", j, " of ", corners, " vertices"));
      if (!parse_integer(token, vertex) || vertex >= vertex_count_) {
        return error(concat("face ", index, " vertex index ", quoted(token), " out of range (",
                            vertex_count_, " vertices)"));
      }
      polygon_.push_back(static_cast<uint32_t>(vertex));
    }
    if (!out_.add_polygon(polygon_)) return out_.too_many_triangles(concat(name_, ":", line_));
    return {};  // colour values after the indices are ignored
  }

  Status error(std::string_view what) const {
    return parse_error(concat(name_, ":", line_, ": ", what));
  }
  Status unsupported(std::string_view what) const {
    return {ErrorCode::kUnsupported, concat(name_, ":", line_, ": ", what, " is not supported")};
  }

  std::string_view bytes_;
  std::string_view name_;
  LineReader lines_;
  size_t line_ = 0;
  MeshAssembler out_;
  size_t max_triangles_;
  uint64_t vertex_count_ = 0;
  uint64_t face_count_ = 0;
  std::vector<uint32_t> polygon_;
};

// ------------------------------------------------------------------- entries

// Runs one parser with the checks every entry point shares; out-of-memory
// becomes an error instead of crossing the API as an exception.
template <class Parse>
Result<TriangleMesh> guarded(std::string_view bytes, std::string_view name,
                             const LoadOptions& options, Parse&& parse) {
  if (options.max_triangles < 1) {
    return Status(ErrorCode::kInvalidArgument, "LoadOptions::max_triangles must be >= 1");
  }
  if (bytes.find_first_not_of(" \t\r\n\v\f") == std::string_view::npos) {
    return parse_error(concat(name, ": no triangles (the file is empty)"));
  }
  try {
    return parse();
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, concat(name, ": out of memory while parsing"));
  } catch (const std::length_error&) {
    return Status(ErrorCode::kTooLarge, concat(name, ": out of memory while parsing"));
  }
}

}  // namespace

Result<TriangleMesh> parse_obj(std::string_view bytes, std::string_view name,
                               const LoadOptions& options) {
  return guarded(bytes, name, options, [&] { return ObjParser(name, options).parse(bytes); });
}

Result<TriangleMesh> parse_ply(std::string_view bytes, std::string_view name,
                               const LoadOptions& options) {
  return guarded(bytes, name, options, [&] { return PlyParser(bytes, name, options).parse(); });
}

Result<TriangleMesh> parse_stl(std::string_view bytes, std::string_view name,
                               const LoadOptions& options) {
  return guarded(bytes, name, options, [&]() -> Result<TriangleMesh> {
    if (looks_like_text_stl(bytes, bytes.size())) return TextStlParser(name, options).parse(bytes);
    return parse_binary_stl(bytes, name, options);
  });
}

Result<TriangleMesh> parse_off(std::string_view bytes, std::string_view name,
                               const LoadOptions& options) {
  return guarded(bytes, name, options, [&] { return OffParser(bytes, name, options).parse(); });
}

namespace meshio_detail {

Status check_mesh_file_head(MeshFormat format, std::string_view head, uint64_t size, std::string_view path) {
  auto text_only = [&](const char* kind) -> Status {
    const size_t nul = head.find('\0');
    if (nul == std::string_view::npos) return Status();
    return parse_error(concat(path, ": not a text ", kind, " file (a zero byte at offset ", nul, ")"));
  };
  switch (format) {
    case MeshFormat::kObj:
      return text_only("OBJ");
    case MeshFormat::kOff:
      return text_only("OFF");
    case MeshFormat::kPly: {
      Tokens tokens(head.substr(0, head.find_first_of("\r\n")));
      std::string_view keyword;
      tokens.next(keyword);
      if (keyword == "ply") return Status();
      return parse_error(concat(path, ":1: ", kNotPly));
    }
    case MeshFormat::kStl:
      return looks_like_text_stl(head, size) ? Status() : binary_stl_size_error(head, size, path);
    case MeshFormat::kGlb:
      if (head.starts_with("glTF")) return Status();
      return parse_error(concat(path, ": not a binary glTF file (it does not start with 'glTF')"));
    case MeshFormat::kDraco:
      if (head.starts_with("DRACO")) return Status();
      return parse_error(concat(path, ": not a Draco file (it does not start with 'DRACO')"));
  }
  return Status();
}

}  // namespace meshio_detail

}  // namespace ldc
