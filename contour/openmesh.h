// The contoured mesh as an OpenMesh triangle mesh, with vertex normals and a
// per-face material property. Kept out of contour.h so that OpenMesh's headers
// reach only the code that asks for them.
#pragma once

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "contour/contour.h"

namespace ldc {

struct OpenMeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3f;
  VertexAttributes(OpenMesh::Attributes::Normal);
  FaceAttributes(OpenMesh::Attributes::Normal);
};
using OpenTriMesh = OpenMesh::TriMesh_ArrayKernelT<OpenMeshTraits>;

// Name of the per-face material property (unsigned short) on the result.
inline constexpr const char* kOpenMeshMaterialProperty = "ldc:material";

// Converts; faces OpenMesh refuses as non-manifold are added through
// duplicated vertices so no triangle is lost (their count is returned in
// *duplicated_vertices when given).
OpenTriMesh to_openmesh(const ContourMesh& mesh, size_t* duplicated_vertices = nullptr);

}  // namespace ldc
