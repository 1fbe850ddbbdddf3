// Internals of meshio: meshio.cpp (dispatch, checks, OBJ, PLY, STL, OFF)
// shares these with gltf.cpp and draco.cpp, kept
// apart so that tinygltf's and Draco's heavy headers are compiled once, in
// the file that needs them.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "meshio/draco_codec.h"
#include "meshio/meshio.h"

namespace ldc::meshio_detail {

// What the first block of a `format` file (`head`: up to 64 KiB, or all of
// it) must look like, checked before the rest is read (ldc::read_file's
// HeadCheck): no zero byte in a text format, PLY's first line, binary STL's
// size from its header, glTF's and Draco's magic. Errors name `path`.
Status check_mesh_file_head(MeshFormat format, std::string_view head, uint64_t size, std::string_view path);

// triangle_material[t], or 0 when the mesh has no materials.
inline uint16_t material_of(const ContourMesh& mesh, size_t triangle) {
  return mesh.triangle_material.empty() ? uint16_t{0} : mesh.triangle_material[triangle];
}

// Triangle indices grouped by material (ascending ids), each group in the
// original triangle order; group_start has one entry per group plus the end.
struct MaterialGroups {
  std::vector<uint32_t> order;
  std::vector<uint16_t> material;   // id of each group
  std::vector<size_t> group_start;  // order[group_start[g] .. group_start[g + 1])
};
MaterialGroups group_by_material(const ContourMesh& mesh);

// ExportOptions::material_names[id] when given and non-empty, else "material_<id>".
std::string material_name(const ExportOptions& options, uint16_t id);

// mesh.vertex_material when set, else the most common material of each
// vertex's triangles (ties: the smaller id; no triangles: 0).
std::vector<uint16_t> vertex_materials(const ContourMesh& mesh);

// Fills what a loaded file lacked: triangle materials (0), vertex normals
// (area-weighted from the triangles) and vertex materials (most common).
void complete_loaded_mesh(ContourMesh& mesh);

// error_at, encode_draco, decode_draco: meshio/draco_codec.h.

// glTF 2.0 binary (gltf.cpp).
Result<std::string> encode_glb(const ContourMesh& mesh, const ExportOptions& options,
                               const std::string& path);
Result<ContourMesh> decode_glb(std::string_view bytes, const std::string& path);

}  // namespace ldc::meshio_detail
