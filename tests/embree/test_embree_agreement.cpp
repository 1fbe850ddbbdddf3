// Ray casts (Queries::ray_cast) against Embree 3 on the contoured mesh of the
// same world (contour_world): hit/miss agreement and the hit point's distance
// from Embree's hit plane, on random rays through four test meshes.
//
// Rays that pass within the tolerance of an edge are left out: shifting the
// origin sideways by kQuerySurfaceTolerance * h (four shifts, perpendicular to
// the direction) changes Embree's answer (hit against miss, or a hit distance
// that jumps by more than h). Such rays graze a silhouette, where either answer
// is right within the tolerance.
//
// A ray that starts inside: ldc reports started_inside (distance 0), Embree
// hits a back face of the mesh. Both count as hits. Rays both start inside
// agree and have no hit point to compare (they are counted, and left out of
// the plane distances); ldc started_inside against an Embree front hit is
// measured from the origin (ldc's hit point) to Embree's hit plane; an Embree
// back face against an ldc hit from outside counts as a miss of the plane.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include <embree3/rtcore.h>
#include <gtest/gtest.h>

#include "contour/contour.h"
#include "embree/embree_ray.h"
#include "ldc/build.h"
#include "ldc/query.h"
#include "test_util.h"

namespace ldc {
namespace {

struct EmbreeScene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<glm::dvec3> face_normal;  // unit, outward (counter-clockwise)

  explicit EmbreeScene(const ContourMesh& mesh) {
    device = rtcNewDevice(nullptr);
    scene = rtcNewScene(device);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), mesh.positions.size()));
    for (size_t i = 0; i < mesh.positions.size(); ++i)
      for (int k = 0; k < 3; ++k) v[3 * i + k] = float(mesh.positions[i][k]);
    auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                3 * sizeof(unsigned), mesh.triangles.size()));
    for (size_t i = 0; i < mesh.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k) idx[3 * i + k] = mesh.triangles[i][k];
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    face_normal.reserve(mesh.triangles.size());
    for (const glm::uvec3& t : mesh.triangles) {
      const glm::dvec3 n =
          glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]);
      const double l = glm::length(n);
      face_normal.push_back(l > 0.0 ? n / l : glm::dvec3(0.0));
    }
  }
  ~EmbreeScene() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  struct Answer {
    bool hit = false;
    bool back = false;  // the first hit is a back face: the ray starts inside
    double t = 0.0;
    glm::dvec3 point{0.0};
    glm::dvec3 normal{0.0};
  };

  Answer cast(const glm::dvec3& o, const glm::dvec3& d) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = ldc::test::embree_ray(o, d);
    rtcIntersect1(scene, &ctx, &rh);
    Answer a;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return a;
    a.hit = true;
    a.t = rh.ray.tfar;
    a.point = o + a.t * d;
    a.normal = face_normal[rh.hit.primID];
    a.back = glm::dot(a.normal, d) > 0.0;
    return a;
  }
};

glm::dvec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  for (;;) {
    const glm::dvec3 v(n(rng), n(rng), n(rng));
    const double l = glm::length(v);
    if (l > 1e-12) return v / l;
  }
}

struct Case {
  const char* file;
  int cells;
};

class EmbreeAgreement : public ::testing::TestWithParam<Case> {};

TEST_P(EmbreeAgreement, RayCastsAgreeWithEmbreeOnTheContouredMesh) {
  const Case c = GetParam();
  TriangleMesh mesh = test::load_test_mesh(c.file);
  ASSERT_FALSE(mesh.positions.empty());
  GridConfig grid;
  grid.cells = c.cells;
  Result<World> built = build_from_mesh(mesh, grid);
  ASSERT_TRUE(built.ok()) << built.status().to_string();
  const World& world = built.value();
  Result<ContourMesh> contour = contour_world(world);
  ASSERT_TRUE(contour.ok()) << contour.status().to_string();
  const EmbreeScene embree(contour.value());
  const Queries queries(world);
  const double h = world.lattice().cell_size;
  const double shift = kQuerySurfaceTolerance * h;

  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const glm::dvec3& p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);

  std::mt19937_64 rng(0xe3b7ee + uint64_t(c.cells));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 10000;
  int left_out = 0, compared = 0, agree = 0, both_hit = 0, both_inside = 0, inside_mismatch = 0, within = 0;
  std::vector<double> errors;  // in h, over rays both hit that do not both start inside
  struct Failure {
    glm::dvec3 o, d;
    EmbreeScene::Answer e;
    RayHit l;
    const char* why;
    double error;
  };
  std::vector<Failure> failures;
  for (int i = 0; i < n; ++i) {
    const glm::dvec3 o = lo + glm::dvec3(u(rng), u(rng), u(rng)) * (hi - lo);
    const glm::dvec3 d = random_unit(rng);
    const EmbreeScene::Answer e = embree.cast(o, d);
    // Sideways shifts: an orthonormal pair perpendicular to d.
    const glm::dvec3 a = std::abs(d.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 s1 = glm::normalize(glm::cross(d, a)), s2 = glm::cross(d, s1);
    bool near_edge = false;
    for (const glm::dvec3& s : {s1, -s1, s2, -s2}) {
      const EmbreeScene::Answer es = embree.cast(o + shift * s, d);
      if (es.hit != e.hit || (e.hit && std::abs(es.t - e.t) > h)) near_edge = true;
    }
    if (near_edge) {
      ++left_out;
      continue;
    }
    Result<RayHit> l = queries.ray_cast({o, d});
    ASSERT_TRUE(l.ok()) << l.status().to_string();
    ++compared;
    if (l->hit != e.hit) {
      failures.push_back({o, d, e, l.value(), "hit/miss", 0.0});
      continue;
    }
    ++agree;
    if (!e.hit) continue;
    if (e.back && l->started_inside) {
      ++both_inside;  // both say the ray starts inside: no hit point to compare
      continue;
    }
    ++both_hit;
    double err = 0.0;
    if (e.back) {
      ++inside_mismatch;  // Embree: the ray starts inside; ldc: outside
      failures.push_back({o, d, e, l.value(), "inside/outside", std::nan("")});
      continue;
    }
    err = std::abs(glm::dot(e.normal, l->point - e.point)) / h;
    errors.push_back(err);
    if (err <= kQuerySurfaceTolerance) {
      ++within;
    } else {
      failures.push_back({o, d, e, l.value(), "plane distance", err});
    }
  }
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  auto pick = [&](double p) {
    return sorted.empty() ? 0.0 : sorted[std::min(sorted.size() - 1, size_t(p * double(sorted.size() - 1) + 0.5))];
  };
  const double agree_pct = compared ? 100.0 * agree / compared : 0.0;
  const double within_pct = both_hit ? 100.0 * within / both_hit : 0.0;
  std::printf(
      "%s at %d cells (h = %.6g): %d rays, %d left out near edges, %d compared: hit/miss agreement %.3f%% "
      "(%d disagree); %d both start inside; %d both hit otherwise, of which %d start inside for Embree only; "
      "error to Embree's hit plane (the others) median %.4f h, p99 %.4f h, max %.4g h; %.3f%% of the %d within "
      "%.2f h\n",
      c.file, c.cells, h, n, left_out, compared, agree_pct, compared - agree, both_inside, both_hit,
      inside_mismatch, pick(0.5), pick(0.99), sorted.empty() ? 0.0 : sorted.back(), within_pct, both_hit,
      kQuerySurfaceTolerance);
  for (size_t k = 0; k < std::min<size_t>(failures.size(), 5); ++k) {
    const Failure& f = failures[k];
    std::printf(
        "  %s: origin (%.9g, %.9g, %.9g) dir (%.9g, %.9g, %.9g); Embree %s t=%.6g (%.3f h)%s; ldc %s t=%.6g "
        "(%.3f h)%s; error %.3f h\n",
        f.why, f.o.x, f.o.y, f.o.z, f.d.x, f.d.y, f.d.z, f.e.hit ? "hit" : "miss", f.e.t, f.e.t / h,
        f.e.back ? " back face" : "", f.l.hit ? "hit" : "miss", f.l.distance, f.l.distance / h,
        f.l.started_inside ? " started inside" : "", f.error);
  }
  EXPECT_GE(agree_pct, 99.5) << c.file;
  EXPECT_GE(within_pct, 99.0) << c.file;
  EXPECT_LT(left_out, n / 10) << c.file << ": too many rays left out for the test to mean much";
}

INSTANTIATE_TEST_SUITE_P(Meshes, EmbreeAgreement,
                         ::testing::Values(Case{"stanford-bunny.obj", 128}, Case{"spot.obj", 112},
                                           Case{"fandisk.obj", 96}, Case{"rocker-arm.obj", 128}),
                         [](const ::testing::TestParamInfo<Case>& p) {
                           std::string name = p.param.file;
                           name = name.substr(0, name.find('.'));
                           name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
                           return name + "_" + std::to_string(p.param.cells);
                         });

}  // namespace
}  // namespace ldc
