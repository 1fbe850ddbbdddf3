// ContourMesh -> OpenMesh triangle mesh.
#include "contour/openmesh.h"

#include <OpenMesh/Core/System/omstream.hh>

namespace ldc {
namespace {

// OpenMesh prints "PolyMeshT::add_face: complex edge" to omerr() for every
// face it refuses; those faces are expected here (and handled), so the
// stream is muted while converting and restored to its previous state after.
class QuietOpenMeshErrors {
 public:
  QuietOpenMeshErrors() : was_enabled_(::omerr().is_enabled()) { ::omerr().disable(); }
  ~QuietOpenMeshErrors() {
    if (was_enabled_) ::omerr().enable();
  }
  QuietOpenMeshErrors(const QuietOpenMeshErrors&) = delete;
  QuietOpenMeshErrors& operator=(const QuietOpenMeshErrors&) = delete;

 private:
  bool was_enabled_;
};

OpenTriMesh::Point to_point(const glm::dvec3& p) { return {p.x, p.y, p.z}; }

class OpenMeshBuilder {
 public:
  explicit OpenMeshBuilder(const ContourMesh& mesh) : mesh_(mesh) {
    out_.reserve(mesh.vertex_count(), 3 * mesh.triangle_count() / 2, mesh.triangle_count());
    out_.add_property(material_, kOpenMeshMaterialProperty);
    source_.reserve(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) add_vertex(static_cast<uint32_t>(v));
  }

  void add_triangles() {
    const QuietOpenMeshErrors quiet;
    for (size_t t = 0; t < mesh_.triangle_count(); ++t) {
      const glm::uvec3& tri = mesh_.triangles[t];
      const size_t n = mesh_.vertex_count();
      if (tri.x >= n || tri.y >= n || tri.z >= n) continue;  // nothing to build it from
      OpenTriMesh::FaceHandle face;
      // A repeated index would give OpenMesh a face with a zero-length edge.
      if (tri.x != tri.y && tri.y != tri.z && tri.x != tri.z) {
        face = out_.add_face(OpenTriMesh::VertexHandle(static_cast<int>(tri.x)),
                             OpenTriMesh::VertexHandle(static_cast<int>(tri.y)),
                             OpenTriMesh::VertexHandle(static_cast<int>(tri.z)));
      }
      if (!face.is_valid()) face = add_on_copies(tri);
      out_.property(material_, face) =
          mesh_.triangle_material.empty() ? uint16_t{0} : mesh_.triangle_material[t];
    }
  }

  void set_normals() {
    if (mesh_.normals.size() == mesh_.vertex_count()) {
      for (size_t v = 0; v < source_.size(); ++v) {
        const glm::vec3& n = mesh_.normals[source_[v]];
        out_.set_normal(OpenTriMesh::VertexHandle(static_cast<int>(v)), {n.x, n.y, n.z});
      }
      out_.update_face_normals();
    } else {
      out_.update_normals();  // face normals, then vertex normals from them
    }
  }

  size_t duplicated() const { return source_.size() - mesh_.vertex_count(); }
  OpenTriMesh take() { return std::move(out_); }

 private:
  OpenTriMesh::VertexHandle add_vertex(uint32_t v) {
    source_.push_back(v);
    return out_.add_vertex(to_point(mesh_.positions[v]));
  }

  // A face OpenMesh refuses (it would make an edge or vertex non-manifold)
  // goes on fresh copies of its corners, which it always accepts.
  OpenTriMesh::FaceHandle add_on_copies(const glm::uvec3& tri) {
    const OpenTriMesh::VertexHandle a = add_vertex(tri.x), b = add_vertex(tri.y),
                                    c = add_vertex(tri.z);
    return out_.add_face(a, b, c);
  }

  const ContourMesh& mesh_;
  OpenTriMesh out_;
  OpenMesh::FPropHandleT<unsigned short> material_;
  std::vector<uint32_t> source_;  // the ContourMesh vertex behind each OpenMesh vertex
};

}  // namespace

OpenTriMesh to_openmesh(const ContourMesh& mesh, size_t* duplicated_vertices) {
  OpenMeshBuilder builder(mesh);
  builder.add_triangles();
  builder.set_normals();
  if (duplicated_vertices) *duplicated_vertices = builder.duplicated();
  return builder.take();
}

}  // namespace ldc
