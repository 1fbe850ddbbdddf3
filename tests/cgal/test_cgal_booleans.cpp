// ldc's mesh booleans against CGAL's corefinement (an outside, exact-predicate
// answer), on two of the boolean cases of shared/PEERS.md (bench/boolean_cases.cpp
// makes them the same way): spot with a copy of itself moved by
// (0.15, 0.08, 0.05) of its diagonal, and fandisk with a 128-sided cylinder
// through it. Each op of each case: ldc's mesh_boolean at 128 cells, contoured
// as `ldc boolean --max-error 0` writes it (contour_world without its local
// untangling, then untangle_mesh), against PMP::corefine_and_compute_*
// (Epick), by the mean symmetric surface distance (bench/meshdist.cpp, as the
// benchmark measures it, here with 50,000 samples a side), the volume, and
// CGAL's verdict on ldc's output (valid, closed, no self-intersection).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Surface_mesh.h>

#include "cgal/cgal_mesh.h"
#include "cgal/cgal_validity.h"
#include "contour/contour.h"
#include "csg/csg.h"
#include "meshdist.h"
#include "meshio/meshio.h"
#include "test_util.h"

namespace ldc {
namespace {

using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
using Mesh = test::CgalMesh;
namespace PMP = CGAL::Polygon_mesh_processing;
using test::to_cgal;

TriangleMesh from_cgal(const Mesh& m) {
  TriangleMesh out;
  std::vector<uint32_t> index(m.number_of_vertices() + m.number_of_removed_vertices());
  for (Mesh::Vertex_index v : m.vertices()) {
    index[v] = uint32_t(out.positions.size());
    const Point& p = m.point(v);
    out.positions.push_back({p.x(), p.y(), p.z()});
  }
  for (Mesh::Face_index f : m.faces()) {
    glm::uvec3 t;
    int k = 0;
    for (Mesh::Vertex_index v : CGAL::vertices_around_face(m.halfedge(f), m)) t[k++] = index[v];
    out.triangles.push_back(t);
  }
  return out;
}

// CGAL's answer; the inputs are copied, as corefinement refines them in place.
Mesh corefined(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op) {
  Mesh ca = to_cgal(a), cb = to_cgal(b), out;
  bool ok = false;
  switch (op) {
    case BooleanOp::kUnion: ok = PMP::corefine_and_compute_union(ca, cb, out); break;
    case BooleanOp::kSubtract: ok = PMP::corefine_and_compute_difference(ca, cb, out); break;
    case BooleanOp::kIntersect: ok = PMP::corefine_and_compute_intersection(ca, cb, out); break;
  }
  EXPECT_TRUE(ok) << "CGAL corefinement failed: " << boolean_op_name(op);
  return out;
}

// A capped cylinder along z, `segments` around (bench/boolean_cases.cpp's cylinder_z).
TriangleMesh cylinder_z(glm::dvec2 axis, double z0, double z1, double radius, uint32_t segments) {
  TriangleMesh m;
  for (double z : {z0, z1})
    for (uint32_t i = 0; i < segments; ++i) {
      const double a = 2.0 * std::numbers::pi * double(i) / double(segments);
      m.positions.push_back({axis.x + radius * std::cos(a), axis.y + radius * std::sin(a), z});
    }
  m.positions.push_back({axis.x, axis.y, z0});
  m.positions.push_back({axis.x, axis.y, z1});
  const uint32_t n = segments, bottom = 2 * n, top = 2 * n + 1;
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t j = (i + 1) % n;
    m.triangles.push_back({i, j, n + j});
    m.triangles.push_back({i, n + j, n + i});
    m.triangles.push_back({bottom, j, i});
    m.triangles.push_back({top, n + i, n + j});
  }
  return m;
}

struct Bounds {
  double mean_distance;  // mean symmetric distance / diagonal of CGAL's result
  double volume;         // |V_ldc / V_cgal - 1|
};

void expect_booleans_agree_with_cgal(const char* name, const TriangleMesh& a, const TriangleMesh& b,
                                     const Bounds& bounds) {
  for (BooleanOp op : {BooleanOp::kUnion, BooleanOp::kSubtract, BooleanOp::kIntersect}) {
    const auto start = std::chrono::steady_clock::now();
    const Mesh reference = corefined(a, b, op);
    Result<World> w = mesh_boolean(a, b, op, {.cells = 128});
    ASSERT_TRUE(w.ok()) << w.status().to_string();
    Result<ContourMesh> m = contour_world(w.value(), {.untangle = false});
    ASSERT_TRUE(m.ok()) << m.status().to_string();
    Result<UntangleMeshStats> untangled = untangle_mesh(m.value());
    ASSERT_TRUE(untangled.ok()) << untangled.status().to_string();
    const TriangleMesh ours = to_triangle_mesh(m.value());
    bench::MeshDistOptions o;
    o.samples = 50000;
    const bench::MeshDistResult d = bench::mesh_distance(ours, from_cgal(reference), o);
    ASSERT_TRUE(d.status.ok()) << d.status.to_string();
    const double v_ref = PMP::volume(reference), v_ours = mesh_signed_volume(ours);
    const cgal_validity::Verdict verdict = cgal_validity::check(m.value().positions, m.value().triangles);
    std::printf("%s %s: mean distance %.3g, Hausdorff >= %.3g of the diagonal, volume %.6g vs CGAL %.6g (%+.4f%%), "
                "%zu triangles, %s (%.2f s)\n",
                name, boolean_op_name(op), d.mean_rel, d.hausdorff_rel, v_ours, v_ref, 100.0 * (v_ours / v_ref - 1.0),
                m.value().triangle_count(), verdict.ok() ? "valid" : verdict.text().c_str(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    EXPECT_LT(d.mean_rel, bounds.mean_distance) << name << " " << boolean_op_name(op);
    EXPECT_NEAR(v_ours / v_ref, 1.0, bounds.volume) << name << " " << boolean_op_name(op);
    EXPECT_TRUE(verdict.ok()) << name << " " << boolean_op_name(op) << ": " << verdict.text();
  }
}

// Measured (128 cells): mean distance 2.0e-5, 2.7e-5, 3.3e-5 of the diagonal
// (union, subtract, intersect), volume within 0.013%. Bounds: about twice.
TEST(CgalBoolean, SpotWithAMovedSpotAgreesWithCorefinement) {
  const TriangleMesh spot = test::load_test_mesh("spot.obj");
  TriangleMesh moved = spot;
  const double diag = mesh_bounds(spot).diagonal();
  for (glm::dvec3& p : moved.positions) p += glm::dvec3(0.15, 0.08, 0.05) * diag;
  expect_booleans_agree_with_cgal("spot_spot", spot, moved, {7e-5, 3e-4});
}

// Measured (128 cells): mean distance 1.2e-5, 1.2e-5, 3.4e-5 of the diagonal,
// volume within 0.019%. Bounds: about twice.
TEST(CgalBoolean, FandiskWithACylinderAgreesWithCorefinement) {
  const TriangleMesh fandisk = test::load_test_mesh("fandisk.obj");
  const MeshBounds bb = mesh_bounds(fandisk);
  const double diag = bb.diagonal();
  const glm::dvec3 c = 0.5 * (bb.min + bb.max);
  const TriangleMesh cylinder = cylinder_z({c.x, c.y}, bb.min.z - 0.1 * diag, bb.max.z + 0.1 * diag, 0.1 * diag, 128);
  expect_booleans_agree_with_cgal("fandisk_cylinder", fandisk, cylinder, {7e-5, 4e-4});
}

}  // namespace
}  // namespace ldc
