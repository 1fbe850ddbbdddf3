// Writing (and reading back) contoured meshes: OBJ, PLY, STL, binary glTF, Draco.
// Re-entrant: calls on different paths may run concurrently. Positions are
// written in the mesh's units (metres): as text (OBJ), doubles (PLY), 32-bit
// floats (STL, GLB) or quantized (Draco, see ExportOptions below).
#pragma once

#include <string>

#include "contour/contour.h"
#include "ldc/mesh.h"
#include "ldc/status.h"

namespace ldc {

enum class MeshFormat { kObj, kPly, kStl, kGlb, kDraco };

// By extension (.obj .ply .stl .glb .drc, case-insensitive); error names it.
Result<MeshFormat> mesh_format_from_path(const std::string& path);

struct ExportOptions {
  // Draco: position quantization bits [Limit: 8 .. 30] and speed [Limit: 0 .. 10].
  int draco_position_bits = 16;
  int draco_speed = 5;
  // Names for material ids (OBJ usemtl, glTF material names); id n without a
  // name is written "material_n".
  std::vector<std::string> material_names;
};

// Writes the mesh in the format the path's extension names:
// - OBJ: positions, normals, faces, `usemtl` groups per material;
// - PLY: binary little-endian, positions, normals, per-face material (uchar/ushort);
// - STL: binary, facet normals, no materials;
// - GLB: glTF 2.0 binary, one primitive per material, POSITION and NORMAL
//   accessors (float), a per-vertex _MATERIAL attribute (unsigned short);
// - DRC: Draco, positions and normals, a generic per-face material attribute.
// Writes to a temporary file and renames it, so a failed export leaves no
// half-written file behind.
Status save_contour_mesh(const ContourMesh& mesh, const std::string& path,
                         const ExportOptions& options = {});

// Reads a file written by save_contour_mesh back (for round-trip tests and
// `ldc` commands that take a mesh in): triangles, positions and per-triangle
// materials; normals where the format has them.
Result<ContourMesh> load_contour_mesh(const std::string& path);

// The same mesh as a TriangleMesh (positions, triangles, materials).
TriangleMesh to_triangle_mesh(const ContourMesh& mesh);

}  // namespace ldc
