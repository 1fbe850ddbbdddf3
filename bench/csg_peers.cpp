// Peers of bench_csg (see csg_peers.h). Compiled with NDEBUG and CGAL_NDEBUG
// (bench/CMakeLists.txt), as the peer harness of shared/PEERS.md built them.
#include "csg_peers.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <vector>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Composite.h>

#include "vdb_mesh.h"

namespace ldc::bench {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;

// Only the vertices that triangles use (the raw bunny has unreferenced ones).
// Faces the half-edge structure refuses (non-manifold) are counted.
template <class Mesh>
Mesh to_cgal(const TriangleMesh& m, size_t* refused_faces = nullptr) {
  using Point = typename Mesh::Point;
  Mesh cm;
  std::vector<typename Mesh::Vertex_index> v(m.positions.size(), Mesh::null_vertex());
  size_t refused = 0;
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (v[t[k]] == Mesh::null_vertex()) {
        const glm::dvec3& p = m.positions[t[k]];
        v[t[k]] = cm.add_vertex(Point(p.x, p.y, p.z));
      }
    }
    if (cm.add_face(v[t[0]], v[t[1]], v[t[2]]) == Mesh::null_face()) ++refused;
  }
  if (refused_faces) *refused_faces = refused;
  return cm;
}

template <class Mesh>
TriangleMesh from_cgal(const Mesh& cm) {
  TriangleMesh out;
  std::vector<uint32_t> index(cm.number_of_vertices() + cm.number_of_removed_vertices(), 0);
  for (auto vi : cm.vertices()) {
    index[vi] = uint32_t(out.positions.size());
    const auto& p = cm.point(vi);
    out.positions.push_back({CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())});
  }
  for (auto f : cm.faces()) {
    glm::uvec3 t(0);
    int i = 0;
    for (auto vi : CGAL::vertices_around_face(cm.halfedge(f), cm)) {
      if (i < 3) t[i] = index[vi];
      ++i;
    }
    if (i == 3) out.triangles.push_back(t);
  }
  return out;
}

template <class Mesh>
bool corefine(Mesh& a, Mesh& b, Mesh& out, BooleanOp op) {
  switch (op) {
    case BooleanOp::kUnion: return PMP::corefine_and_compute_union(a, b, out);
    case BooleanOp::kSubtract: return PMP::corefine_and_compute_difference(a, b, out);
    case BooleanOp::kIntersect: return PMP::corefine_and_compute_intersection(a, b, out);
  }
  return false;
}

// What is wrong with the inputs by corefinement's preconditions; empty if nothing.
std::string precondition_failures(const TriangleMesh& a, const TriangleMesh& b) {
  using Mesh = CGAL::Surface_mesh<CGAL::Exact_predicates_inexact_constructions_kernel::Point_3>;
  std::string what;
  auto add = [&](const std::string& s) { what += (what.empty() ? "" : ", ") + s; };
  const TriangleMesh* in[2] = {&a, &b};
  for (int i = 0; i < 2; ++i) {
    const std::string name = i == 0 ? "A" : "B";
    size_t refused = 0;
    Mesh m = to_cgal<Mesh>(*in[i], &refused);
    if (refused) add(name + " non-manifold (" + std::to_string(refused) + " faces refused)");
    bool closed = CGAL::is_closed(m);
    if (!closed) add(name + " not closed");
    bool self = PMP::does_self_intersect(m);
    if (self) add(name + " self-intersects");
    if (closed && !self && !PMP::does_bound_a_volume(m)) add(name + " does not bound a volume");
  }
  return what;
}

template <class Kernel>
CgalBooleanResult run_cgal(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op, int reps,
                           const std::string& failed_preconditions) {
  using Mesh = CGAL::Surface_mesh<typename Kernel::Point_3>;
  CgalBooleanResult r;
  std::vector<double> times;
  Mesh result;
  for (int rep = 0; rep < reps; ++rep) {
    Mesh ca = to_cgal<Mesh>(a), cb = to_cgal<Mesh>(b), out;
    bool ok = false;
    std::string error;
    auto t0 = std::chrono::steady_clock::now();
    try {
      ok = corefine(ca, cb, out, op);
    } catch (const std::exception& e) {
      error = e.what();
    }
    auto t1 = std::chrono::steady_clock::now();
    if (!ok) {
      std::string call = error.empty() ? "returned false" : "threw: " + error.substr(0, 120);
      r.status = failed_preconditions.empty() ? "failed: call " + call
                                              : "failed (precondition: " + failed_preconditions + "; forced call " +
                                                    call + ")";
      return r;
    }
    times.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    if (rep + 1 == reps) result = std::move(out);
  }
  std::sort(times.begin(), times.end());
  r.ok = true;
  r.status = failed_preconditions.empty() ? "ok" : "ok despite precondition: " + failed_preconditions;
  r.ms = times[times.size() / 2];
  r.mesh = from_cgal(result);
  return r;
}


}  // namespace

const char* cgal_kernel_name(CgalKernel kernel) { return kernel == CgalKernel::kEpick ? "Epick" : "Epeck"; }

CgalBooleanResult cgal_boolean(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op, CgalKernel kernel,
                               int reps) {
  std::string pre = precondition_failures(a, b);
  if (kernel == CgalKernel::kEpick)
    return run_cgal<CGAL::Exact_predicates_inexact_constructions_kernel>(a, b, op, reps, pre);
  return run_cgal<CGAL::Exact_predicates_exact_constructions_kernel>(a, b, op, reps, pre);
}

void vdb_initialize() { openvdb::initialize(); }

TriangleMesh vdb_boolean(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op, double h) {
  auto xform = openvdb::math::Transform::createLinearTransform(h);
  openvdb::FloatGrid::Ptr ga = vdb_level_set(a, *xform), gb = vdb_level_set(b, *xform);
  // Each leaves the result in its first argument and empties the second.
  switch (op) {
    case BooleanOp::kUnion: openvdb::tools::csgUnion(*ga, *gb); break;
    case BooleanOp::kSubtract: openvdb::tools::csgDifference(*ga, *gb); break;
    case BooleanOp::kIntersect: openvdb::tools::csgIntersection(*ga, *gb); break;
  }
  return vdb_to_mesh(*ga);
}

}  // namespace ldc::bench
