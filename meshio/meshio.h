// Mesh files: every format the project reads or writes, for both mesh types.
//
//   format  read                       write
//   OBJ     yes (usemtl -> materials)  positions, normals, usemtl groups
//   PLY     ascii and binary           binary little-endian, normals, face materials
//   STL     ascii and binary           binary, facet normals, no materials
//   OFF     yes                        yes (positions and faces)
//   GLB     yes (glTF 2.0 binary)      one primitive per material, the palette's colours
//   DRC     yes (Draco)                quantized positions, normals, face materials
//
// TriangleMesh (ldc/mesh.h) is what the builders and brushes take;
// ContourMesh (contour/contour.h) is what contouring gives, with normals and
// per-vertex materials. Both read and write every format; what a format
// lacks is filled on reading (area-weighted normals, material 0).
//
// Readers refuse malformed input with a message naming the file, the line
// (text formats) or byte offset (binary formats) and the offending value.
// They never crash and never allocate more than the file's own size
// justifies; the text and binary parsers are fuzzed (fuzz/). Writers build
// the whole file in memory (text through std::to_chars, in blocks on all
// cores) and hand it to one atomic write: to `path + ".tmp"`, then a rename,
// so a failed or killed save leaves any previous file at `path` intact.
//
// Thread safety: every function is re-entrant; calls on different paths may
// run concurrently.
//
// Link target: ldc::meshio (it links Draco and carries its own tinygltf; no
// other module needs them).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "contour/contour.h"
#include "ldc/mesh.h"
#include "ldc/status.h"

namespace ldc {

enum class MeshFormat { kObj, kPly, kStl, kOff, kGlb, kDraco };
const char* mesh_format_name(MeshFormat format);  // "obj", "ply", ...

// By extension (.obj .ply .stl .off .glb .drc, case-insensitive); the error
// names the extension and lists the accepted ones.
Result<MeshFormat> mesh_format_from_path(const std::string& path);

// --- Reading ---------------------------------------------------------------------

struct LoadOptions {
  // Refuse files with more triangles than this [Limit: >= 1].
  size_t max_triangles = size_t{1} << 28;
};

// Any format, by extension. Polygons are ear-clipped in their best-fit plane
// (a k-gon gives k - 2 triangles; degenerate ones, and any over 256 corners,
// are fanned instead). STL corners at exactly the same position are welded.
Result<TriangleMesh> load_mesh(const std::string& path, const LoadOptions& options = {});

// The same file as a ContourMesh: normals and materials where the format has
// them (an OBJ or PLY written by save_mesh gives back its exact material ids).
Result<ContourMesh> load_contour_mesh(const std::string& path, const LoadOptions& options = {});

// Parsers over bytes already in memory; `name` is used in messages.
Result<TriangleMesh> parse_obj(std::string_view bytes, std::string_view name, const LoadOptions& options = {});
Result<TriangleMesh> parse_ply(std::string_view bytes, std::string_view name, const LoadOptions& options = {});
Result<TriangleMesh> parse_stl(std::string_view bytes, std::string_view name, const LoadOptions& options = {});
Result<TriangleMesh> parse_off(std::string_view bytes, std::string_view name, const LoadOptions& options = {});

// --- Writing ---------------------------------------------------------------------

struct ExportOptions {
  // Draco: position quantization bits [Limit: 8 .. 30] and speed [Limit: 0 .. 10].
  int draco_position_bits = 16;
  int draco_speed = 5;
  // Names for material ids (OBJ usemtl, glTF material names); id n without a
  // name is written "material_n".
  std::vector<std::string> material_names;
};

// Writes the mesh in the format the path's extension names (see the table
// above). A mesh with triangles out of range, non-finite positions or arrays
// of the wrong length is refused, naming the first bad element.
Status save_mesh(const ContourMesh& mesh, const std::string& path, const ExportOptions& options = {});
// A TriangleMesh: positions, triangles and its materials (names from
// material_names when `options` has none); normals are computed for the
// formats that store them.
Status save_mesh(const TriangleMesh& mesh, const std::string& path, const ExportOptions& options = {});

// Conversions between the two mesh types.
TriangleMesh to_triangle_mesh(const ContourMesh& mesh);
ContourMesh to_contour_mesh(const TriangleMesh& mesh);  // area-weighted normals, most common vertex material

// --- Deprecated spellings (removed after 0.3) ----------------------------------

[[deprecated("use save_mesh")]] inline Status save_contour_mesh(const ContourMesh& mesh, const std::string& path,
                                                                const ExportOptions& options = {}) {
  return save_mesh(mesh, path, options);
}
[[deprecated("use save_mesh")]] inline Status save_obj(const TriangleMesh& mesh, const std::string& path) {
  return save_mesh(mesh, path);
}

}  // namespace ldc
