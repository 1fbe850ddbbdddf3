// Queries: ray casts, sphere casts, overlaps and closest points against
// analytic shapes and against the contoured mesh.
#include <algorithm>
#include <cmath>
#include <random>
#include <thread>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/build.h"
#include "ldc/detail/cell_index.h"
#include "ldc/query.h"
#include "ldc/terrain.h"
#include "test_util.h"

namespace ldc {
namespace {

World build_primitive(const Primitive& p, double h) {
  GridConfig grid;
  grid.cell_size = h;
  grid.chunk_size = 16;
  auto world = build_from_primitive(p, grid);
  EXPECT_TRUE(world.ok()) << world.status().to_string();
  return std::move(world).value();
}

Primitive sphere(double radius, const glm::dvec3& centre) {
  Primitive p;
  p.shape = Primitive::Shape::kSphere;
  p.radius = radius;
  p.transform[3] = glm::dvec4(centre, 1.0);
  return p;
}

glm::dvec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> n;
  glm::dvec3 v(n(rng), n(rng), n(rng));
  return glm::normalize(v);
}

// Exact first hit of a ray with a sphere, or -1.
double sphere_hit(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& c, double r) {
  const glm::dvec3 oc = o - c;
  const double b = glm::dot(oc, d), q = glm::dot(oc, oc) - r * r, disc = b * b - q;
  if (disc < 0.0) return -1.0;
  const double t = -b - std::sqrt(disc);
  return t >= 0.0 ? t : -1.0;
}

double point_triangle_distance2(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  // Ericson, Real-Time Collision Detection 5.1.5.
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  auto d2of = [&](const glm::dvec3& q) { return glm::dot(p - q, p - q); };
  if (d1 <= 0 && d2 <= 0) return d2of(a);
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return d2of(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return d2of(a + ab * (d1 / (d1 - d3)));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return d2of(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return d2of(a + ac * (d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return d2of(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const double denom = 1.0 / (va + vb + vc);
  return d2of(a + ab * (vb * denom) + ac * (vc * denom));
}

// Distance from p to the nearest triangle of the mesh within `reach`, or reach.
double distance_to_mesh(const ContourMesh& mesh, const glm::dvec3& p, double reach) {
  double best = reach * reach;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 &a = mesh.positions[t.x], &b = mesh.positions[t.y], &c = mesh.positions[t.z];
    const glm::dvec3 lo = glm::min(a, glm::min(b, c)) - reach, hi = glm::max(a, glm::max(b, c)) + reach;
    if (glm::any(glm::lessThan(p, lo)) || glm::any(glm::greaterThan(p, hi))) continue;
    best = std::min(best, point_triangle_distance2(p, a, b, c));
  }
  return std::sqrt(best);
}

TEST(RayCast, SphereHitsLieOnTheAnalyticSurface) {
  const double h = 0.1;
  const glm::dvec3 centre(0.031, 0.017, -0.023);
  World world = build_primitive(sphere(1.0, centre), h);
  Queries queries(world);
  std::mt19937 rng(7);
  double worst = 0.0;
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::dvec3 o = centre + 2.5 * random_unit(rng);
    const glm::dvec3 target = centre + 0.95 * random_unit(rng);
    const glm::dvec3 d = glm::normalize(target - o);
    Result<RayHit> hit = queries.ray_cast({o, d});
    ASSERT_TRUE(hit.ok()) << hit.status().to_string();
    ASSERT_TRUE(hit->hit) << "ray " << i << " aimed inside the sphere missed";
    const double exact = sphere_hit(o, d, centre, 1.0);
    worst = std::max(worst, std::abs(hit->distance - exact));
    EXPECT_NEAR(glm::length(glm::dvec3(hit->normal)), 1.0, 1e-3);
    ++hits;
  }
  std::printf("sphere r=1 h=%.2f: %d hits, worst distance error %.4f h\n", h, hits, worst / h);
  EXPECT_LT(worst, 0.1 * h);
}

TEST(RayCast, HitsLieOnTheContouredSurface) {
  const double h = 0.1;
  struct Case {
    const char* name;
    Primitive shape;
  };
  Primitive box;
  box.shape = Primitive::Shape::kBox;
  box.half_extents = glm::dvec3(0.8, 0.6, 0.5);
  box.transform = glm::rotate(glm::dmat4(1.0), 0.4, glm::dvec3(0.3, 0.5, 0.8));
  Primitive cylinder;
  cylinder.shape = Primitive::Shape::kCylinder;
  cylinder.radius = 0.7;
  cylinder.half_height = 0.8;
  cylinder.transform = glm::rotate(glm::dmat4(1.0), 0.7, glm::dvec3(1.0, 0.2, 0.0));
  for (const Case& c : {Case{"sphere", sphere(1.0, glm::dvec3(0.03, 0.01, -0.02))}, Case{"box", box},
                        Case{"cylinder", cylinder}}) {
    World world = build_primitive(c.shape, h);
    // Placement alone (the planes' meeting points); untangling moves ~1% of
    // the vertices, next to folds at the box's and cylinder's edges, to their
    // mass points (checked below, looser).
    Result<ContourMesh> mesh = contour_world(world, {.untangle = false});
    Result<ContourMesh> untangled = contour_world(world);
    ASSERT_TRUE(untangled.ok());
    ASSERT_TRUE(mesh.ok());
    Queries queries(world);
    std::mt19937 rng(11);
    std::vector<double> errors, untangled_errors;
    int agree = 0, total = 0;
    for (int i = 0; i < 1000; ++i) {
      // Aimed at a point inside every shape (0.45 < the smallest half-extent): every ray hits.
      const glm::dvec3 o = 2.5 * random_unit(rng), target = 0.45 * random_unit(rng);
      Result<RayHit> hit = queries.ray_cast({o, target - o});
      ASSERT_TRUE(hit.ok());
      ++total;
      ASSERT_TRUE(hit->hit) << c.name << " ray " << i << " aimed inside missed";
      ++agree;
      errors.push_back(distance_to_mesh(mesh.value(), hit->point, 2 * h) / h);
      untangled_errors.push_back(distance_to_mesh(untangled.value(), hit->point, 2 * h) / h);
    }
    std::sort(untangled_errors.begin(), untangled_errors.end());
    const double untangled_p99 = untangled_errors[untangled_errors.size() * 99 / 100];
    std::printf("%s: untangled p99 %.3f h\n", c.name, untangled_p99);
    EXPECT_LT(untangled_p99, 0.35) << c.name << " (untangled)";
    std::sort(errors.begin(), errors.end());
    const double median = errors[errors.size() / 2], p99 = errors[errors.size() * 99 / 100], worst = errors.back();
    std::printf("%s: %d/%d hit, distance to contoured mesh median %.3f h, p99 %.3f h, worst %.3f h\n", c.name, agree,
                total, median, p99, worst);
    // Measured p99: sphere 0.005 h, box 0.010 h, cylinder 0.031 h (the
    // documented query tolerance, kQuerySurfaceTolerance, is 0.25 h).
    EXPECT_LT(p99, 0.05) << c.name;
    EXPECT_LT(p99, kQuerySurfaceTolerance) << c.name;
  }
}


Primitive box_primitive(const glm::dvec3& half_extents) {
  Primitive p;
  p.shape = Primitive::Shape::kBox;
  p.half_extents = half_extents;
  return p;
}

TEST(RayCast, AlongALatticeLineReturnsTheStoredCrossing) {
  const glm::dvec3 centre(0.013, 0.021, -0.017);
  World world = build_primitive(sphere(1.0, centre), 0.1);
  Queries queries(world);
  const glm::dvec3 c = glm::round(world.lattice().to_lattice(centre));
  for (glm::ivec2 uv : {glm::ivec2(0, 0), glm::ivec2(3, -4), glm::ivec2(-6, 2)}) {
    uv += glm::ivec2(int(c.y), int(c.z));
    const std::vector<SurfacePoint> points = world.ray_points(0, uv);
    ASSERT_EQ(points.size(), 2u);
    const glm::dvec3 start = world.lattice().to_world(glm::dvec3(c.x - 20.0, uv.x, uv.y));
    RayHit hit = queries.ray_cast({start, glm::dvec3(1, 0, 0)}).value();
    ASSERT_TRUE(hit.hit);
    EXPECT_DOUBLE_EQ(hit.distance, (points[0].depth - (c.x - 20.0)) * world.lattice().cell_size);
    EXPECT_EQ(hit.normal, points[0].normal);
    // Backwards from the far side: the exit point.
    const glm::dvec3 far = world.lattice().to_world(glm::dvec3(c.x + 20.0, uv.x, uv.y));
    hit = queries.ray_cast({far, glm::dvec3(-1, 0, 0)}).value();
    ASSERT_TRUE(hit.hit);
    EXPECT_DOUBLE_EQ(hit.distance, (c.x + 20.0 - points[1].depth) * world.lattice().cell_size);
    EXPECT_EQ(hit.normal, points[1].normal);
  }
}

TEST(RayCast, StartingInsideHitsAtDistanceZero) {
  World world = build_primitive(sphere(1.0, glm::dvec3(0.0)), 0.1);
  Queries queries(world);
  for (const glm::dvec3 o : {glm::dvec3(0.01, 0.02, 0.03), glm::dvec3(0.0), glm::dvec3(0.5, -0.3, 0.6)}) {
    RayHit hit = queries.ray_cast({o, glm::dvec3(0.3, 0.4, 0.5)}).value();
    EXPECT_TRUE(hit.hit && hit.started_inside);
    EXPECT_EQ(hit.distance, 0.0);
    EXPECT_NEAR(glm::dot(glm::dvec3(hit.normal), glm::normalize(glm::dvec3(0.3, 0.4, 0.5))), -1.0, 1e-6);
    RayHit sphere_hit = queries.sphere_cast({o, glm::dvec3(0.3, 0.4, 0.5)}, 0.05).value();
    EXPECT_TRUE(sphere_hit.hit && sphere_hit.started_inside);
    EXPECT_EQ(sphere_hit.distance, 0.0);
  }
}

TEST(RayCast, RejectsBadRaysByName) {
  World world = build_primitive(sphere(1.0, glm::dvec3(0.0)), 0.2);
  Queries queries(world);
  const double nan = std::nan("");
  struct Bad {
    Ray ray;
    const char* says;
  };
  for (const Bad& bad : {Bad{{glm::dvec3(nan, 0, 0), glm::dvec3(1, 0, 0)}, "origin"},
                         Bad{{glm::dvec3(0.0), glm::dvec3(0, nan, 0)}, "direction"},
                         Bad{{glm::dvec3(0.0), glm::dvec3(0.0)}, "no length"},
                         Bad{{glm::dvec3(0.0), glm::dvec3(1, 0, 0), -1.0}, "max_distance"},
                         Bad{{glm::dvec3(0.0), glm::dvec3(1, 0, 0), nan}, "max_distance"}}) {
    Result<RayHit> hit = queries.ray_cast(bad.ray);
    ASSERT_FALSE(hit.ok());
    EXPECT_NE(hit.status().message().find(bad.says), std::string::npos) << hit.status().message();
    EXPECT_FALSE(queries.sphere_cast(bad.ray, 0.1).ok());
  }
  std::vector<Ray> rays(3, Ray{glm::dvec3(0, 0, 5), glm::dvec3(0, 0, -1)});
  rays[2].direction = glm::dvec3(0.0);
  std::vector<RayHit> hits(3);
  hits[0].material = 77;
  Status s = queries.ray_cast(rays, hits);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("ray 2"), std::string::npos) << s.message();
  EXPECT_EQ(hits[0].material, 77) << "a refused batch must leave the hits untouched";
  EXPECT_FALSE(queries.closest_point(glm::dvec3(0.0), 100.0).ok());
  EXPECT_FALSE(queries.overlap(glm::dvec3(0.0), -1.0).ok());
  EXPECT_FALSE(queries.overlap(Capsule{glm::dvec3(0.0), glm::dvec3(nan), 0.5}).ok());
  OrientedBox skew;
  skew.rotation[0] = glm::dvec3(2, 0, 0);
  EXPECT_FALSE(queries.overlap(skew).ok());
}

TEST(RayCast, HitNormalsNeverFaceAwayFromTheRay) {
  // The default landscape has steps and lips thinner than a cell, where a ray
  // can enter a cell already inside its planes; found by ldc render.
  TerrainConfig config;
  config.size_x = config.size_y = 16.0;
  World world = build_terrain(config, 0.2).value();
  Queries queries(world);
  const WorldBox b = world.solid_bounds().value();
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int hits = 0, away = 0;
  for (int i = 0; i < 100000; ++i) {
    const glm::dvec3 o = b.min + (b.max - b.min) * glm::dvec3(u(rng), u(rng), u(rng) + 1.0);
    const glm::dvec3 d = random_unit(rng);
    RayHit hit = queries.ray_cast({o, d}).value();
    if (!hit.hit || hit.started_inside) continue;
    ++hits;
    away += glm::dot(glm::dvec3(hit.normal), d) > 0.0 ? 1 : 0;
  }
  EXPECT_GT(hits, 5000) << hits;
  EXPECT_EQ(away, 0);
}

TEST(RayCast, MaxDistanceStopsShortOfTheSurface) {
  World world = build_primitive(sphere(1.0, glm::dvec3(0.0)), 0.1);
  Queries queries(world);
  const Ray ray{glm::dvec3(0.02, 0.03, 3.0), glm::dvec3(0, 0, -1), 1.9};
  EXPECT_FALSE(queries.ray_cast(ray).value().hit);
  Ray longer = ray;
  longer.max_distance = 2.1;
  EXPECT_TRUE(queries.ray_cast(longer).value().hit);
}

TEST(RayCast, GrazingRaysAlongFacesAndThroughLatticeEdges) {
  // Box faces at +-0.55 sit halfway between lattice planes (h = 0.1).
  World world = build_primitive(box_primitive(glm::dvec3(0.55)), 0.1);
  Queries queries(world);
  for (double z : {0.54, 0.549, 0.551, 0.56}) {
    RayHit hit = queries.ray_cast({glm::dvec3(-3.0, 0.013, z), glm::dvec3(1, 0, 0)}).value();
    EXPECT_EQ(hit.hit, z < 0.55) << "z " << z;
    if (hit.hit) {
      EXPECT_NEAR(hit.distance, 3.0 - 0.55, 0.01) << "z " << z;
    }
  }
  // Diagonal rays through lattice nodes and edges: every cell corner is a tie in the walk.
  for (const glm::dvec3 d : {glm::dvec3(1, 1, 0), glm::dvec3(1, 1, 1), glm::dvec3(1, 0, 1)}) {
    const glm::dvec3 o = -3.0 * d;
    RayHit hit = queries.ray_cast({o, d}).value();
    ASSERT_TRUE(hit.hit);
    const double exact = (3.0 - 0.55) * glm::length(d);
    EXPECT_NEAR(hit.distance, exact, 0.05 * 0.1 * glm::length(d)) << glm::length(d);
  }
}

TEST(RayCast, NeverPassesThroughAThinWall) {
  // A wall a third of a cell thick, tilted: most cell edges it crosses hold two points.
  TriangleMesh slab = test::box_mesh(glm::dvec3(-1.0, -1.0, -0.017), glm::dvec3(1.0, 1.0, 0.017));
  const glm::dmat3 tilt = glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.5, glm::dvec3(1, 0.4, 0)));
  for (glm::dvec3& p : slab.positions) p = tilt * p;
  GridConfig grid;
  grid.cell_size = 0.1;
  World world = build_from_mesh(slab, grid).value();
  ASSERT_TRUE(test::is_valid(world));
  Queries queries(world);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.7, 0.7);
  int missed = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::dvec3 target = tilt * glm::dvec3(u(rng), u(rng), 0.0);
    const glm::dvec3 o = target + 2.0 * random_unit(rng);
    RayHit hit = queries.ray_cast({o, target - o}).value();
    missed += hit.hit ? 0 : 1;
  }
  EXPECT_EQ(missed, 0);
}

TEST(RayCast, BatchEqualsSingleRaysWithAColdCacheOnManyThreads) {
  World world = build_primitive(sphere(1.0, glm::dvec3(0.02, -0.03, 0.01)), 0.05);
  std::mt19937 rng(5);
  std::vector<Ray> rays;
  for (int i = 0; i < 20000; ++i) rays.push_back({2.0 * random_unit(rng), random_unit(rng)});
  Queries cold(world);  // every chunk's bits are derived concurrently by the batch
  std::vector<RayHit> hits(rays.size());
  ASSERT_TRUE(cold.ray_cast(rays, hits).ok());
  Queries serial(world);
  for (size_t i = 0; i < rays.size(); ++i) {
    RayHit one = serial.ray_cast(rays[i]).value();
    ASSERT_EQ(one.hit, hits[i].hit) << i;
    ASSERT_EQ(one.distance, hits[i].distance) << i;
  }
  QueryCacheStats stats = cold.cache_stats();
  EXPECT_GT(stats.chunks_indexed, 0u);
  EXPECT_EQ(stats.retired, 0u);
}

TEST(RayCast, SeesEditsWithoutARebuild) {
  WorldEditor editor(build_primitive(sphere(1.0, glm::dvec3(0.0)), 0.05));
  Queries queries(editor.world());
  const Ray ray{glm::dvec3(0.013, 0.021, 3.0), glm::dvec3(0, 0, -1)};
  const double before = queries.ray_cast(ray).value().distance;
  EXPECT_NEAR(before, 2.0, 0.01);
  // Dig a 0.5 m sphere where the ray meets the top: the ray now goes 0.5 m deeper.
  Result<EditReceipt> dig = editor.apply(Brush::sphere(glm::dvec3(0.0, 0.0, 1.0), 0.5), EditOp::kSubtract);
  ASSERT_TRUE(dig.ok());
  const double after = queries.ray_cast(ray).value().distance;
  EXPECT_NEAR(after, 2.5, 0.01);
  EXPECT_GT(queries.cache_stats().retired, 0u);
  queries.refresh();
  EXPECT_EQ(queries.cache_stats().retired, 0u);
  EXPECT_NEAR(queries.ray_cast(ray).value().distance, 2.5, 0.01);
  ASSERT_TRUE(editor.undo(dig.value()).ok());
  EXPECT_EQ(queries.ray_cast(ray).value().distance, before);
  // A build that grows the world's box is followed too.
  ASSERT_TRUE(editor.apply(Brush::sphere(glm::dvec3(0.0, 0.0, 2.4), 0.3), EditOp::kUnion).ok());
  EXPECT_NEAR(queries.ray_cast(ray).value().distance, 0.3, 0.01);
  queries.refresh();
  EXPECT_NEAR(queries.ray_cast(ray).value().distance, 0.3, 0.01);
}

TEST(RayCast, AfterRandomEditsEqualsAFreshCache) {
  // Bits derived before each edit (digs, builds that grow the box, with and
  // without refresh()) must answer exactly as bits derived from scratch.
  TerrainConfig config;
  config.size_x = config.size_y = 12.0;
  WorldEditor editor(build_terrain(config, 0.25).value());
  Queries warm(editor.world());
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto random_rays = [&](int n) {
    const WorldBox b = editor.world().solid_bounds().value();
    std::vector<Ray> rays;
    for (int i = 0; i < n; ++i) rays.push_back({b.min + (b.max - b.min) * glm::dvec3(u(rng), u(rng), u(rng)), random_unit(rng)});
    return rays;
  };
  for (int edit = 0; edit < 12; ++edit) {
    for (const Ray& ray : random_rays(500)) (void)warm.ray_cast(ray);  // derive bits before the edit
    const WorldBox b = editor.world().solid_bounds().value();
    const glm::dvec3 at = b.min + (b.max - b.min) * glm::dvec3(u(rng), u(rng), u(rng));
    const EditOp op = edit % 3 == 2 ? EditOp::kUnion : EditOp::kSubtract;
    ASSERT_TRUE(editor.apply(Brush::sphere(at, 0.5 + 2.0 * u(rng), uint16_t(edit)), op).ok());
    if (edit % 4 == 3) warm.refresh();
    Queries fresh(editor.world());
    for (const Ray& ray : random_rays(3000)) {
      const RayHit a = warm.ray_cast(ray).value(), c = fresh.ray_cast(ray).value();
      ASSERT_EQ(a.hit, c.hit) << "edit " << edit;
      ASSERT_EQ(a.distance, c.distance) << "edit " << edit;
      ASSERT_EQ(a.material, c.material) << "edit " << edit;
    }
  }
}

TEST(RayCast, SeesABuildInsideACubeOfClearChunksItSkippedBefore) {
  // A ray through empty chunks leaves a cube of them at once
  // (CellIndex::clear_radius). A build in such a cube, in a chunk that is
  // none of the skipping chunk's own sources (its -x neighbour), must still
  // be seen.
  WorldEditor editor(build_primitive(sphere(1.0, glm::dvec3(0.0)), 0.05));
  ASSERT_TRUE(editor.apply(Brush::sphere(glm::dvec3(10.0, 0.0, 0.0), 0.5), EditOp::kUnion).ok());
  Queries queries(editor.world());
  const Ray ray{glm::dvec3(9.0, 0.013, 0.021), glm::dvec3(-1.0, 0.0, 0.0)};
  EXPECT_NEAR(queries.ray_cast(ray).value().distance, 8.0, 0.01);
  const World& w = editor.world();
  const glm::dvec3 centre(5.6, 0.0, 0.0);
  const double radius = 0.25;
  const glm::ivec3 target = w.chunk_of_node(glm::ivec3(glm::floor(w.lattice().to_lattice(centre))));
  for (double x : {centre.x - radius, centre.x + radius}) {
    const glm::ivec3 node(glm::floor(w.lattice().to_lattice(glm::dvec3(x, 0.0, 0.0))));
    ASSERT_EQ(w.chunk_of_node(node), target) << "the build should fill one chunk";
  }
  ASSERT_GE(queries.cell_index(target + glm::ivec3(1, 0, 0))->clear_radius, 2)
      << "the ray should skip the build's chunk from its +x neighbour";
  ASSERT_TRUE(editor.apply(Brush::sphere(centre, radius), EditOp::kUnion).ok());
  const RayHit after = queries.ray_cast(ray).value();
  EXPECT_NEAR(after.distance, 9.0 - (centre.x + radius), 0.01);
  Queries fresh(editor.world());
  const RayHit expected = fresh.ray_cast(ray).value();
  EXPECT_EQ(after.distance, expected.distance);
  EXPECT_EQ(after.material, expected.material);
  // refresh() drops such cubes rather than checking them chunk by chunk.
  queries.refresh();
  EXPECT_EQ(queries.ray_cast(ray).value().distance, expected.distance);
}

TEST(RayCast, CellSurfacesKeptByAThreadFollowEdits) {
  // Neighbouring rays cross the same cells, whose surfaces this thread keeps
  // between casts. A bundle aimed at each edit is cast just before it; after
  // it, this thread's answers must equal a new thread's (which starts with
  // nothing kept), and most must have changed (earlier edits may cover a spot).
  WorldEditor editor(build_primitive(sphere(1.0, glm::dvec3(0.01, -0.02, 0.03)), 0.05));
  Queries queries(editor.world());
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  for (int edit = 0; edit < 8; ++edit) {
    const glm::dvec3 at(u(rng), u(rng), 0.0);
    std::vector<Ray> rays;
    for (int y = -3; y <= 3; ++y)
      for (int x = -3; x <= 3; ++x) rays.push_back({at + glm::dvec3(0.011 * x, 0.013 * y, 3.0), glm::dvec3(0.0, 0.0, -1.0)});
    auto cast_all = [&] {
      std::vector<RayHit> hits;
      for (const Ray& r : rays) hits.push_back(queries.ray_cast(r).value());
      return hits;
    };
    const std::vector<RayHit> before = cast_all();  // keeps this thread's cells
    const glm::dvec3 top(at.x, at.y, std::sqrt(1.0 - at.x * at.x - at.y * at.y));
    const EditOp op = edit % 2 ? EditOp::kUnion : EditOp::kSubtract;
    ASSERT_TRUE(editor.apply(Brush::sphere(top, 0.2, uint16_t(edit + 1)), op).ok());
    const std::vector<RayHit> here = cast_all();
    std::vector<RayHit> fresh;
    std::thread([&] { fresh = cast_all(); }).join();
    size_t changed = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      ASSERT_EQ(here[i].hit, fresh[i].hit) << "edit " << edit << " ray " << i;
      ASSERT_EQ(here[i].distance, fresh[i].distance) << "edit " << edit << " ray " << i;
      ASSERT_EQ(here[i].material, fresh[i].material) << "edit " << edit << " ray " << i;
      changed += here[i].distance != before[i].distance ? 1 : 0;
    }
    EXPECT_GT(changed, rays.size() / 2) << "edit " << edit << ": the rays should meet the edit";
  }
}

TEST(SphereCast, ContactDistanceMatchesTheAnalyticAnswer) {
  const double h = 0.05, radius = 1.0;
  World world = build_primitive(sphere(radius, glm::dvec3(0.0)), h);
  Queries queries(world);
  std::mt19937 rng(9);
  double worst = 0.0;
  for (int i = 0; i < 300; ++i) {
    const double r = 0.05 + 0.3 * (i % 7) / 6.0;
    const glm::dvec3 o = 2.5 * random_unit(rng), target = 0.8 * random_unit(rng);
    const glm::dvec3 d = glm::normalize(target - o);
    RayHit hit = queries.sphere_cast({o, d}, r).value();
    const double exact = sphere_hit(o, d, glm::dvec3(0.0), radius + r);
    ASSERT_TRUE(hit.hit);
    ASSERT_FALSE(hit.started_inside);
    worst = std::max(worst, std::abs(hit.distance - exact));
    // The contact lies on the sphere, and the normal points from it to the cast sphere's centre.
    EXPECT_NEAR(glm::length(hit.point), radius, 0.1 * h);
    const glm::dvec3 centre = o + hit.distance * d;
    EXPECT_GT(glm::dot(glm::dvec3(hit.normal), glm::normalize(centre - hit.point)), 0.99);
  }
  std::printf("sphere cast: worst contact distance error %.3f h\n", worst / h);
  EXPECT_LT(worst, 0.2 * h);
  // A sphere passing beside the solid misses.
  EXPECT_FALSE(queries.sphere_cast({glm::dvec3(-3, 1.3, 0), glm::dvec3(1, 0, 0)}, 0.25).value().hit);
  EXPECT_TRUE(queries.sphere_cast({glm::dvec3(-3, 1.2, 0), glm::dvec3(1, 0, 0)}, 0.25).value().hit);
}

TEST(SphereCast, FarFromTheWorldsBoxAndPastIt) {
  // Everything outside the world's box is empty: a cast that leaves the box
  // (grown by the radius) stops there, and one that never meets it misses.
  const double h = 0.05, radius = 1.0;
  World world = build_primitive(sphere(radius, glm::dvec3(0.0)), h);
  Queries queries(world);
  const glm::dvec3 d = glm::normalize(glm::dvec3(-1.0, -0.2, 0.1));
  const glm::dvec3 far = -1000.0 * d;
  for (double r : {0.1, 2.0, 5.0}) {
    const RayHit hit = queries.sphere_cast({far, d}, r).value();
    ASSERT_TRUE(hit.hit) << r;
    EXPECT_NEAR(hit.distance, sphere_hit(far, d, glm::dvec3(0.0), radius + r), 0.2 * h) << r;
  }
  // Big spheres whose centres pass beside the box still touch the solid.
  EXPECT_TRUE(queries.sphere_cast({glm::dvec3(-50, 2.9, 0), glm::dvec3(1, 0, 0)}, 2.0).value().hit);
  EXPECT_FALSE(queries.sphere_cast({glm::dvec3(-50, 3.1, 0), glm::dvec3(1, 0, 0)}, 2.0).value().hit);
  // Away from the box, past it, and along a face plane far outside.
  EXPECT_FALSE(queries.sphere_cast({glm::dvec3(0, 0, 3), glm::dvec3(0, 0, 1)}, 0.5).value().hit);
  EXPECT_FALSE(queries.sphere_cast({glm::dvec3(-9, 9, 9), glm::dvec3(1, 0, 0)}, 0.5).value().hit);
  EXPECT_FALSE(queries.sphere_cast({glm::dvec3(0, 0, -5), glm::dvec3(0, 0, -1), 1e300}, 0.5).value().hit);
}

TEST(Overlap, SphereBoxAndCapsuleAgainstABox) {
  const double h = 0.05;
  World world = build_primitive(box_primitive(glm::dvec3(1.0)), h);  // top face at z = 1
  Queries queries(world);
  // Sphere above the top face, touching by 0.3.
  Overlap o = queries.overlap(glm::dvec3(0.1, 0.2, 1.2), 0.5).value();
  EXPECT_TRUE(o.overlaps);
  EXPECT_NEAR(o.depth, 0.3, 0.1 * h);
  EXPECT_GT(o.normal.z, 0.99f);
  // Centre inside: out by the radius plus the centre's depth.
  o = queries.overlap(glm::dvec3(0.1, 0.2, 0.8), 0.5).value();
  EXPECT_TRUE(o.overlaps);
  EXPECT_NEAR(o.depth, 0.7, 0.1 * h);
  EXPECT_GT(o.normal.z, 0.99f);
  EXPECT_FALSE(queries.overlap(glm::dvec3(0.1, 0.2, 1.6), 0.5).value().overlaps);
  // A box rotated about z, sunk 0.2 into the top face.
  OrientedBox box;
  box.centre = glm::dvec3(0.1, -0.2, 1.3);
  box.half_extents = glm::dvec3(0.3, 0.2, 0.5);
  box.rotation = glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.6, glm::dvec3(0, 0, 1)));
  o = queries.overlap(box).value();
  EXPECT_TRUE(o.overlaps);
  EXPECT_NEAR(o.depth, 0.2, 0.1 * h);
  EXPECT_GT(o.normal.z, 0.99f);
  box.centre.z = 1.55;
  EXPECT_FALSE(queries.overlap(box).value().overlaps);
  // A lying capsule 0.1 into the top face, and one above it.
  Capsule capsule{glm::dvec3(-0.4, 0.0, 1.15), glm::dvec3(0.5, 0.1, 1.15), 0.25};
  o = queries.overlap(capsule).value();
  EXPECT_TRUE(o.overlaps);
  EXPECT_NEAR(o.depth, 0.1, 0.1 * h);
  EXPECT_GT(o.normal.z, 0.99f);
  capsule.a.z = capsule.b.z = 1.3;
  EXPECT_FALSE(queries.overlap(capsule).value().overlaps);
  // A small box wholly inside the solid overlaps.
  box.centre = glm::dvec3(0.0);
  box.half_extents = glm::dvec3(0.1);
  EXPECT_TRUE(queries.overlap(box).value().overlaps);
}

TEST(ClosestPoint, OnASphereLiesOnTheRadialLine) {
  const double h = 0.05;
  World world = build_primitive(sphere(1.0, glm::dvec3(0.0)), h);
  Queries queries(world);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> radial(0.7, 1.3);
  double worst = 0.0;
  for (int i = 0; i < 500; ++i) {
    const glm::dvec3 dir = random_unit(rng), p = radial(rng) * dir;
    ClosestPoint cp = queries.closest_point(p, 0.5).value();
    ASSERT_TRUE(cp.found) << i;
    EXPECT_EQ(cp.query_inside, glm::length(p) < 1.0) << i;
    worst = std::max(worst, std::abs(cp.distance - std::abs(glm::length(p) - 1.0)));
    EXPECT_NEAR(glm::length(cp.point), 1.0, 0.05 * h);
    EXPECT_GT(glm::dot(glm::dvec3(cp.normal), dir), 0.99);
  }
  std::printf("closest point: worst distance error %.3f h\n", worst / h);
  EXPECT_LT(worst, 0.1 * h);
  EXPECT_FALSE(queries.closest_point(glm::dvec3(0, 0, 2.0), 0.5).value().found);
}

}  // namespace
}  // namespace ldc
