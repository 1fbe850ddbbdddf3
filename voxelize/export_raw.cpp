// Raw arrays with a JSON header.
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "ldc/io.h"
#include "voxelize/voxelize.h"

namespace ldc {
namespace {

struct RawArray {
  std::string name;
  std::string type;  // float32, int32, uint32, uint8
  std::vector<size_t> shape;
  std::string format;  // GPU format, or ""
  size_t bytes = 0;
};

// Where the two files go: "<stem>.raw" and "<stem>.json".
std::string stem_of(const std::string& path) {
  for (const char* ext : {".json", ".raw"}) {
    const std::string e(ext);
    if (path.size() > e.size() && path.compare(path.size() - e.size(), e.size(), e) == 0) {
      return path.substr(0, path.size() - e.size());
    }
  }
  return path;
}

std::string base_name(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// A JSON string literal: quotes, backslashes and control characters escaped.
std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char code[8];
      std::snprintf(code, sizeof code, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
      out += code;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

template <class T>
std::string json_vec(const T& v) {
  std::ostringstream s;
  s.precision(17);
  s << "[" << v.x << ", " << v.y << ", " << v.z << "]";
  return s.str();
}

// Both files go through AtomicFile (ldc/io.h): a failure or a kill leaves
// any previous pair whole, not a truncated .raw beside an old header.
class RawWriter {
 public:
  explicit RawWriter(const std::string& path) : stem_(stem_of(path)) {
    Result<AtomicFile> raw = AtomicFile::create(stem_ + ".raw");
    if (raw.ok()) raw_.emplace(std::move(raw).value());
    else open_error_ = raw.status();
  }
  bool ok() const { return raw_.has_value(); }
  const Status& open_error() const { return open_error_; }

  template <class T>
  void add(const std::string& name, const std::string& type, std::vector<size_t> shape, const T* data, size_t count,
           const std::string& format = "") {
    // A short write sets the stream's error flag, which commit() reports.
    (void)std::fwrite(data, sizeof(T), count, raw_->stream());
    arrays_.push_back({name, type, std::move(shape), format, count * sizeof(T)});
  }

  // The header: `fields` (JSON members, already formatted) and the arrays.
  Status finish(const std::string& fields) {
    if (Status s = raw_->commit(); !s.ok()) return s;
    std::ostringstream h;
    h << "{\n  \"format\": \"ldc-voxels\",\n  \"version\": 1,\n  \"data\": " << json_string(base_name(stem_ + ".raw"))
      << ",\n  \"byte_order\": \"little\",\n" << fields << "  \"arrays\": [";
    size_t offset = 0;
    for (size_t i = 0; i < arrays_.size(); ++i) {
      const RawArray& a = arrays_[i];
      h << (i ? ",\n" : "\n") << "    {\"name\": " << json_string(a.name) << ", \"type\": " << json_string(a.type)
        << ", \"shape\": [";
      for (size_t d = 0; d < a.shape.size(); ++d) h << (d ? ", " : "") << a.shape[d];
      h << "], \"offset\": " << offset << ", \"bytes\": " << a.bytes;
      if (!a.format.empty()) h << ", \"format\": " << json_string(a.format);
      h << "}";
      offset += a.bytes;
    }
    h << "\n  ]\n}\n";
    return write_file_atomically(stem_ + ".json", h.str());
  }

 private:
  std::string stem_;
  std::optional<AtomicFile> raw_;
  Status open_error_;
  std::vector<RawArray> arrays_;
};

}  // namespace

Status save_raw(const VoxelGrid& grid, const std::string& path) {
  RawWriter w(path);
  if (!w.ok()) return w.open_error();
  const glm::ivec3 d = grid.box.dims;
  w.add("occupancy", "float32", {size_t(d.z), size_t(d.y), size_t(d.x)}, grid.occupancy.data(), grid.occupancy.size());
  std::vector<int32_t> coords;
  coords.reserve(grid.surface.size() * 3);
  for (const glm::ivec3& v : grid.surface) coords.insert(coords.end(), {v.x, v.y, v.z});
  w.add("surface_voxels", "int32", {grid.surface.size(), 3}, coords.data(), coords.size());
  if (grid.has_faces) {
    std::vector<float> faces;
    faces.reserve(grid.surface.size() * kFaces * 12);
    for (const VoxelFaces& s : grid.surface_faces) {
      for (const FaceSample& f : s) {
        faces.insert(faces.end(), {f.albedo.r, f.albedo.g, f.albedo.b, f.albedo.a, f.normal.x, f.normal.y, f.normal.z,
                                   f.occupancy, f.emission.r, f.emission.g, f.emission.b, float(f.flags)});
      }
    }
    w.add("surface_faces", "float32", {grid.surface.size(), size_t(kFaces), 12}, faces.data(), faces.size());
  }
  std::ostringstream f;
  f.precision(17);
  f << "  \"voxel_size\": " << grid.voxel_size << ",\n  \"origin\": " << json_vec(grid.origin)
    << ",\n  \"box_lo\": " << json_vec(grid.box.lo) << ",\n  \"dims\": " << json_vec(grid.box.dims)
    << ",\n  \"faces\": [\"+x\", \"-x\", \"+y\", \"-y\", \"+z\", \"-z\"],\n"
    << "  \"face_fields\": [\"albedo_r\", \"albedo_g\", \"albedo_b\", \"weight\", \"normal_x\", \"normal_y\", "
       "\"normal_z\", \"occupancy\", \"emission_r\", \"emission_g\", \"emission_b\", \"flags\"],\n";
  return w.finish(f.str());
}

Status save_raw(const Cascades& cascades, const std::string& path) {
  RawWriter w(path);
  if (!w.ok()) return w.open_error();
  PackedGBuffer packed;
  cascades.pack(&packed);
  const glm::ivec3 e = packed.extent();
  const std::vector<size_t> shape = {size_t(e.z), size_t(e.y), size_t(e.x)};
  w.add("albedo", "uint32", shape, packed.albedo.data(), packed.albedo.size(), "R8G8B8A8_UNORM");
  w.add("normal", "uint32", shape, packed.normal.data(), packed.normal.size(), "R8G8B8A8_SNORM");
  w.add("occupancy", "uint8", shape, packed.occupancy.data(), packed.occupancy.size(), "R8_UNORM");
  w.add("emission", "uint32", shape, packed.emission.data(), packed.emission.size(), "B10G11R11_UFLOAT_PACK32");
  const size_t n = size_t(cascades.resolution());
  std::vector<float> occ;
  occ.reserve(size_t(cascades.levels()) * n * n * n);
  for (int k = 0; k < cascades.levels(); ++k) {
    const VoxelGrid g = cascades.level_grid(k);
    occ.insert(occ.end(), g.occupancy.begin(), g.occupancy.end());
  }
  w.add("level_occupancy", "float32", {size_t(cascades.levels()), n, n, n}, occ.data(), occ.size());
  std::ostringstream f;
  f.precision(17);
  f << "  \"resolution\": " << n << ",\n  \"origin\": " << json_vec(cascades.origin()) << ",\n  \"levels\": [";
  for (int k = 0; k < cascades.levels(); ++k) {
    const VoxelBox b = cascades.level_box(k);
    f << (k ? ",\n" : "\n") << "    {\"voxel_size\": " << cascades.voxel_size(k) << ", \"box_lo\": " << json_vec(b.lo)
      << ", \"valid\": " << (cascades.level_valid(k) ? "true" : "false") << "}";
  }
  f << "\n  ],\n  \"layout\": \"texel (f*N + x, k*N + y, z) = face f of voxel box_lo + (x, y, z) of level k\",\n"
    << "  \"faces\": [\"+x\", \"-x\", \"+y\", \"-y\", \"+z\", \"-z\"],\n";
  return w.finish(f.str());
}

}  // namespace ldc
