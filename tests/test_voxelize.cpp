// Voxel export: occupancy against exact per-voxel volumes, the solid interior,
// the six-face G-buffer, the packed formats, cascades (scrolling, edits), static
// objects and the errors of bad input.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <signal.h>
#include <sys/resource.h>

#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>

#include <glm/gtc/matrix_transform.hpp>
#include <tbb/global_control.h>

#include "csg/csg.h"
#include "ldc/build.h"
#include "ldc/io.h"
#include "ldc/terrain.h"
#include "test_util.h"
#include "voxelize/voxelize.h"

namespace ldc {
namespace {

GridConfig grid_at(double h, int chunk = 16) {
  GridConfig g;
  g.cell_size = h;
  g.chunk_size = chunk;
  g.use_origin = true;
  g.origin = glm::dvec3(0.0);
  return g;
}

World sphere_world(const glm::dvec3& centre, double radius, double h) {
  Primitive p;
  p.shape = Primitive::Shape::kSphere;
  p.radius = radius;
  p.transform[3] = glm::dvec4(centre, 1.0);
  return build_from_primitive(p, grid_at(h)).value();
}

double overlap(double a0, double a1, double b0, double b1) { return std::max(0.0, std::min(a1, b1) - std::max(a0, b0)); }

// Exact sphere volume inside a voxel (a fraction): 0 or 1 when the voxel is
// wholly outside or inside, else chord lengths integrated over a 48 x 48 midpoint grid.
double sphere_voxel_volume(const glm::dvec3& c, double r, const glm::dvec3& lo, double s) {
  const glm::dvec3 nearest = glm::clamp(c, lo, lo + s);
  if (glm::length(nearest - c) >= r) return 0.0;
  double far = 0.0;
  for (int i = 0; i < 8; ++i) far = std::max(far, glm::length(lo + s * glm::dvec3(i & 1, (i >> 1) & 1, i >> 2) - c));
  if (far <= r) return 1.0;
  const int k = 48;
  double sum = 0.0;
  for (int j = 0; j < k; ++j) {
    for (int i = 0; i < k; ++i) {
      const double x = lo.x + s * (i + 0.5) / k - c.x, y = lo.y + s * (j + 0.5) / k - c.y;
      const double d2 = r * r - x * x - y * y;
      if (d2 <= 0.0) continue;
      const double half = std::sqrt(d2);
      sum += overlap(c.z - half, c.z + half, lo.z, lo.z + s);
    }
  }
  return sum / (k * k) / s;
}

struct ErrorStats {
  double mean = 0.0, max = 0.0;
};

template <class Exact>
ErrorStats occupancy_error(const VoxelGrid& g, Exact exact) {
  ErrorStats e;
  for (int z = 0; z < g.box.dims.z; ++z) {
    for (int y = 0; y < g.box.dims.y; ++y) {
      for (int x = 0; x < g.box.dims.x; ++x) {
        const glm::ivec3 v = g.box.lo + glm::ivec3(x, y, z);
        const double err = std::abs(double(g.at(v)) - exact(g.voxel_min(v), g.voxel_size));
        e.mean += err;
        e.max = std::max(e.max, err);
      }
    }
  }
  e.mean /= double(g.box.count());
  return e;
}

TEST(Occupancy, SphereMatchesItsExactVolumePerVoxel) {
  const glm::dvec3 c(0.613, 0.587, 0.521);
  const double r = 1.07, h = 0.05;
  World w = sphere_world(c, r, h);
  for (int m : {1, 4}) {
    VoxelConfig cfg{.voxel_size = m * h};
    Result<VoxelGrid> g = voxelize(w, cfg);
    ASSERT_TRUE(g.ok()) << g.status().message();
    ErrorStats e = occupancy_error(g.value(), [&](const glm::dvec3& lo, double s) {
      return sphere_voxel_volume(c, r, lo, s);
    });
    // Surface voxels only carry error; the bounds are the header's.
    // Measured: mean 0.0099 / max 0.44 at m = 1, 0.0024 / 0.032 at m = 4.
    EXPECT_LT(e.mean, m == 1 ? 0.02 : 0.005) << "m = " << m;
    EXPECT_LT(e.max, m == 1 ? 0.5 : 0.08) << "m = " << m;
    const double exact = 4.0 / 3.0 * M_PI * r * r * r;
    EXPECT_NEAR(g.value().volume(), exact, 2e-3 * exact) << "m = " << m;
  }
}

TEST(Occupancy, BoxErrorStaysWithinTheTrapezoidBoundAlongEveryRayFamily) {
  // A box of three different extents: a voxel of one family's sums put in
  // another's place (a swapped index) would be off by far more than the bound.
  const glm::dvec3 lo(0.113, 0.071, 0.0437), hi(0.871, 0.6391, 0.7529);
  const double h = 0.05;
  World w = build_from_mesh(test::box_mesh(lo, hi), grid_at(h)).value();
  const int m = 4;
  auto exact = [&](const glm::dvec3& v, double s) {
    return overlap(v.x, v.x + s, lo.x, hi.x) * overlap(v.y, v.y + s, lo.y, hi.y) *
           overlap(v.z, v.z + s, lo.z, hi.z) / (s * s * s);
  };
  for (int axis = 0; axis < 3; ++axis) {
    Result<VoxelGrid> g = voxelize(w, VoxelConfig{.voxel_size = m * h, .axis = axis});
    ASSERT_TRUE(g.ok()) << g.status().message();
    ErrorStats e = occupancy_error(g.value(), exact);
    // A face between two rays is off by at most half a ray interval: 0.5 / n per crossing axis.
    // Measured: mean 0.036 / 0.032 / 0.024 for the x / y / z family (the
    // box's faces sit differently between each family's rays), max 0.071 (z).
    EXPECT_LE(e.max, 2 * 0.5 / m + 1e-6) << "axis " << axis;
    EXPECT_LT(e.mean, 0.04) << "axis " << axis;
  }
}

TEST(Occupancy, VolumeSumsToTheWorldsSpanVolume) {
  World w = sphere_world({0.3, 0.2, 0.1}, 0.9, 0.1);
  for (int axis = 0; axis < 3; ++axis) {
    Result<VoxelGrid> g = voxelize(w, VoxelConfig{.voxel_size = 0.3, .axis = axis});
    ASSERT_TRUE(g.ok());
    EXPECT_NEAR(g.value().volume(), w.volume(axis), 1e-6 * w.volume(axis)) << "axis " << axis;
  }
}

TEST(Occupancy, InteriorVoxelsAreExactlySolidAndChunksAreSkipped) {
  // A sphere big enough to hold solid chunks (chunk size 16, h 0.05).
  const glm::dvec3 c(0.02, 0.01, 0.03);
  const double r = 2.1, h = 0.05, s = 0.2;
  World w = sphere_world(c, r, h);
  ASSERT_GT(w.stats().chunks_solid, 0u);
  VoxelStats stats;
  Result<VoxelGrid> g = voxelize(w, VoxelConfig{.voxel_size = s}, {}, nullptr, &stats);
  ASSERT_TRUE(g.ok());
  EXPECT_GT(stats.chunk_columns_closed, 0u);
  size_t interior = 0;
  for (int z = 0; z < g.value().box.dims.z; ++z) {
    for (int y = 0; y < g.value().box.dims.y; ++y) {
      for (int x = 0; x < g.value().box.dims.x; ++x) {
        const glm::ivec3 v = g.value().box.lo + glm::ivec3(x, y, z);
        const glm::dvec3 lo = g.value().voxel_min(v);
        double far = 0.0;  // the voxel corner farthest from the centre
        for (int k = 0; k < 8; ++k) {
          far = std::max(far, glm::length(lo + s * glm::dvec3(k & 1, (k >> 1) & 1, (k >> 2) & 1) - c));
        }
        if (far >= r - 1e-3) continue;
        ++interior;
        ASSERT_EQ(g.value().at(v), 1.0f) << "voxel " << v.x << "," << v.y << "," << v.z;
      }
    }
  }
  EXPECT_GT(interior, 500u);
}

TEST(Occupancy, SameResultOnOneThreadAndMany) {
  World w = build_terrain(TerrainConfig{.size_x = 8.0, .size_y = 8.0}, 0.25).value();
  VoxelizeOptions opt;
  opt.faces = true;
  Result<VoxelGrid> many = voxelize(w, VoxelConfig{.voxel_size = 0.5}, opt);
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  Result<VoxelGrid> single = voxelize(w, VoxelConfig{.voxel_size = 0.5}, opt);
  ASSERT_TRUE(many.ok() && single.ok());
  EXPECT_EQ(many.value().occupancy, single.value().occupancy);
  EXPECT_EQ(many.value().surface, single.value().surface);
  ASSERT_EQ(many.value().surface.size(), single.value().surface.size());
  for (size_t i = 0; i < many.value().surface.size(); ++i) {
    for (int f = 0; f < kFaces; ++f) {
      ASSERT_EQ(std::memcmp(&many.value().surface_faces[i][size_t(f)], &single.value().surface_faces[i][size_t(f)],
                            sizeof(FaceSample)),
                0);
    }
  }
}

TEST(Occupancy, SurfaceVoxelsAreThePartlyFilledOnes) {
  World w = sphere_world({0.3, 0.2, 0.1}, 0.9, 0.1);
  Result<VoxelGrid> g = voxelize(w, VoxelConfig{.voxel_size = 0.2});
  ASSERT_TRUE(g.ok());
  size_t partial = 0;
  for (float o : g.value().occupancy) partial += o > 0.0f && o < 1.0f;
  EXPECT_GE(g.value().surface.size(), partial);
  EXPECT_LT(g.value().surface.size(), partial + partial / 2);
  for (const glm::ivec3& v : g.value().surface) EXPECT_GT(g.value().at(v), 0.0f);
}

// --- G-buffer --------------------------------------------------------------------

TEST(GBuffer, SixColouredBoxInOneVoxelGivesSixFaceAlbedos) {
  // Each face of the box [0.11, 0.29]^3 gets its own material, in face order +x -x +y -y +z -z.
  TriangleMesh box = test::box_mesh(glm::dvec3(0.11), glm::dvec3(0.29));
  box.triangle_material.resize(box.triangles.size());
  for (size_t t = 0; t < box.triangles.size(); ++t) {
    const glm::dvec3 a = box.positions[box.triangles[t].x], b = box.positions[box.triangles[t].y],
                     c = box.positions[box.triangles[t].z];
    const glm::dvec3 n = glm::cross(b - a, c - a);
    int axis = 0;
    for (int i = 1; i < 3; ++i) axis = std::abs(n[i]) > std::abs(n[axis]) ? i : axis;
    box.triangle_material[t] = uint16_t(2 * axis + (n[axis] > 0 ? 0 : 1));
  }
  World w = build_from_mesh(box, grid_at(0.05)).value();
  MaterialTable colours;
  const glm::vec3 palette[6] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
  for (const glm::vec3& p : palette) colours.materials.push_back({p, glm::vec3(0.0f)});
  Result<GBuffer> gb = voxelize_gbuffer(w, VoxelConfig{.voxel_size = 0.4}, VoxelBox{glm::ivec3(-1), glm::ivec3(3)},
                                        colours);
  ASSERT_TRUE(gb.ok()) << gb.status().message();
  const double side = 0.18 / 0.4;  // the box's share of the voxel's edge
  for (int f = 0; f < kFaces; ++f) {
    const FaceSample& s = gb.value().face(f, glm::ivec3(0));
    EXPECT_EQ(s.flags, kFaceOwn) << kFaceNames[size_t(f)];
    EXPECT_LT(glm::length(glm::vec3(s.albedo) - palette[f]), 1e-5f) << kFaceNames[size_t(f)];
    glm::vec3 n(0.0f);
    n[face_axis(f)] = face_positive(f) ? 1.0f : -1.0f;
    EXPECT_GT(glm::dot(s.normal, n), 0.999f) << kFaceNames[size_t(f)];
    EXPECT_NEAR(s.albedo.a, side * side, 0.08) << kFaceNames[size_t(f)];  // the face's weight: projected area
    EXPECT_NEAR(s.occupancy, side * side, 0.08) << kFaceNames[size_t(f)];
  }
  // Volume: the trapezoid rule sees 3 of the 9 rays per axis inside (0.375 for 0.45).
  EXPECT_NEAR(gb.value().occupancy[gb.value().box.index(glm::ivec3(0))], 0.375 * 0.375 * side, 1e-5);
  // Neighbours hold no solid: nothing is propagated into them.
  EXPECT_EQ(gb.value().face(0, glm::ivec3(1, 0, 0)).flags, 0);
}

TEST(GBuffer, SurfaceAttributesReachTheFirstSubsurfaceLayerOnly) {
  // A slab z in [-1, 0.43]: its top lies in voxel layer z = 1 (voxel 0.4); layers 0 and below are full.
  Primitive slab;
  slab.shape = Primitive::Shape::kBox;
  slab.half_extents = glm::dvec3(3.0, 3.0, 0.715);
  slab.transform[3] = glm::dvec4(0.0, 0.0, -0.285, 1.0);
  slab.material = 1;
  World w = build_from_primitive(slab, grid_at(0.1)).value();
  Result<GBuffer> gb = voxelize_gbuffer(w, VoxelConfig{.voxel_size = 0.4}, VoxelBox{glm::ivec3(-2), glm::ivec3(4)},
                                        default_material_table());
  ASSERT_TRUE(gb.ok());
  const int up = 4;  // +z
  const FaceSample& top = gb.value().face(up, glm::ivec3(0, 0, 1));
  const FaceSample& below = gb.value().face(up, glm::ivec3(0, 0, 0));
  const FaceSample& deeper = gb.value().face(up, glm::ivec3(0, 0, -1));
  EXPECT_EQ(top.flags, kFaceOwn);
  EXPECT_EQ(below.flags, kFacePropagated);
  EXPECT_EQ(below.albedo, top.albedo);
  EXPECT_EQ(below.normal, top.normal);
  EXPECT_EQ(below.occupancy, 1.0f);  // its own opacity
  EXPECT_EQ(deeper.flags, 0);
  EXPECT_EQ(gb.value().face(up, glm::ivec3(0, 0, 2)).flags, 0);  // empty above: nothing to carry
}

TEST(Formats, PackedTexelsRoundTrip) {
  for (float v : {0.0f, 1e-6f, 0.001f, 0.37f, 1.0f, 3.25f, 1000.0f, 60000.0f}) {
    const glm::vec3 back = unpack_r11g11b10f(pack_r11g11b10f(glm::vec3(v, v, v)));
    EXPECT_NEAR(back.x, v, std::max(v / 64.0f, 6.2e-5f / 64.0f)) << v;  // 6 mantissa bits, rounded
    EXPECT_NEAR(back.z, v, std::max(v / 32.0f, 6.2e-5f / 32.0f)) << v;  // 5 mantissa bits
  }
  EXPECT_EQ(pack_r11g11b10f(glm::vec3(-1.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f)), 0u);
  EXPECT_EQ(unpack_r11g11b10f(pack_r11g11b10f(glm::vec3(1e9f))).x, 65024.0f);
  const glm::vec4 c(0.2f, 0.5f, 1.0f, 0.0f);
  EXPECT_LT(glm::length(unpack_unorm8x4(pack_unorm8x4(c)) - c), 0.5f / 255.0f * 2.0f);
  const glm::vec4 n(-1.0f, 0.3f, 0.0f, 1.0f);
  EXPECT_LT(glm::length(unpack_snorm8x4(pack_snorm8x4(n)) - n), 1.0f / 127.0f);
  EXPECT_EQ(pack_unorm8x4(glm::vec4(1.0f, 0.0f, 0.0f, 0.0f)), 255u);  // r in the low byte
}

// --- Cascades --------------------------------------------------------------------

World small_terrain() {
  return build_terrain(TerrainConfig{.size_x = 10.0, .size_y = 10.0, .cave_radius = 0.0, .arches = 1}, 0.25, 16).value();
}

CascadeConfig small_cascade() {
  CascadeConfig c;
  c.levels = 2;
  c.resolution = 8;
  c.voxel_size = 0.25;
  return c;
}

::testing::AssertionResult same_cascades(const Cascades& a, const Cascades& b) {
  PackedGBuffer pa, pb;
  a.pack(&pa);
  b.pack(&pb);
  for (int k = 0; k < a.levels(); ++k) {
    if (a.level_box(k).lo != b.level_box(k).lo) return ::testing::AssertionFailure() << "level " << k << " box";
    if (a.level_grid(k).occupancy != b.level_grid(k).occupancy) {
      return ::testing::AssertionFailure() << "level " << k << " occupancy";
    }
  }
  if (pa.albedo != pb.albedo) return ::testing::AssertionFailure() << "albedo";
  if (pa.normal != pb.normal) return ::testing::AssertionFailure() << "normal";
  if (pa.occupancy != pb.occupancy) return ::testing::AssertionFailure() << "face occupancy";
  if (pa.emission != pb.emission) return ::testing::AssertionFailure() << "emission";
  return ::testing::AssertionSuccess();
}

StaticObject crate() {
  StaticObject o;
  o.mesh = std::make_shared<TriangleMesh>(test::box_mesh(glm::dvec3(4.1, 4.3, 5.0), glm::dvec3(4.9, 4.8, 8.2)));
  o.material = 3;
  return o;
}

TEST(Cascades, ScrollingByAnyShiftEqualsVoxelizingAfresh) {
  World w = small_terrain();
  const double s = 0.25;
  glm::dvec3 cam(5.0, 5.0, 6.0);
  Result<Cascades> moving = Cascades::create(w.lattice(), small_cascade());
  ASSERT_TRUE(moving.ok()) << moving.status().message();
  ASSERT_TRUE(moving.value().add_object(crate()).ok());
  ASSERT_TRUE(moving.value().update_all(w, cam).ok());
  // Shifts in level-0 voxels: 1, 7, N, > N, negative, several axes at once.
  const glm::ivec3 shifts[] = {{1, 0, 0}, {0, 7, 0}, {0, 0, -1}, {8, 0, 0}, {-11, 0, 0}, {-3, 2, 5}, {2, -5, -6}, {0, 0, 0}};
  for (const glm::ivec3& d : shifts) {
    cam += s * glm::dvec3(d);
    for (int k = 0; k < 2; ++k) {
      Result<CascadeUpdate> up = moving.value().update_level(w, k, cam);
      ASSERT_TRUE(up.ok()) << up.status().message();
      if (k == 0) {
        EXPECT_EQ(up.value().shift, d);
        EXPECT_EQ(up.value().full, glm::any(glm::greaterThanEqual(glm::abs(d), glm::ivec3(8))));
      }
    }
    Cascades fresh = Cascades::create(w.lattice(), small_cascade()).value();
    ASSERT_TRUE(fresh.add_object(crate()).ok());
    ASSERT_TRUE(fresh.update_all(w, cam).ok());
    ASSERT_TRUE(same_cascades(moving.value(), fresh)) << "after shift " << d.x << "," << d.y << "," << d.z;
  }
}

// A whole level is cut into smaller blocks when few blocks hold chunks and
// there are more workers to feed: the result may not depend on the cut.
TEST(Cascades, FullUpdateOnOneThreadEqualsOneOnEight) {
  World w = small_terrain();
  CascadeConfig config = small_cascade();
  config.levels = 4;
  config.resolution = 16;
  auto update_on = [&](int threads) {
    Cascades c = Cascades::create(w.lattice(), config).value();
    EXPECT_TRUE(c.add_object(crate()).ok());
    tbb::task_arena arena(threads);
    arena.execute([&] { EXPECT_TRUE(c.update_all(w, {5.0, 5.0, 6.0}).ok()); });
    return c;
  };
  // The cuts differ: levels 0 and 1 take blocks of 16^3 on one thread and
  // 8^3 on eight, level 2 8^3 and 4^3.
  const Cascades one = update_on(1), eight = update_on(8);
  EXPECT_TRUE(same_cascades(one, eight));
}

TEST(Cascades, ScrollVoxelizesOnlyTheExposedSlab) {
  World w = small_terrain();
  Cascades c = Cascades::create(w.lattice(), small_cascade()).value();
  ASSERT_TRUE(c.update_all(w, {5.0, 5.0, 6.0}).ok());
  Result<CascadeUpdate> up = c.update_level(w, 0, {5.0 + 2 * 0.25, 5.0, 6.0 - 0.25});
  ASSERT_TRUE(up.ok());
  EXPECT_EQ(up.value().voxels, size_t(2 * 8 * 8 + 6 * 8 * 1));
  up = c.update_level(w, 0, {5.0 + 2 * 0.25 + 0.1, 5.0, 6.0 - 0.25});  // less than half a voxel: stays
  ASSERT_TRUE(up.ok());
  EXPECT_EQ(up.value().voxels, 0u);
}

TEST(Cascades, EditRefreshesExactlyTheVoxelsUnderDirtyChunks) {
  WorldEditor ed(small_terrain());
  const glm::dvec3 cam(5.0, 5.0, 6.0);
  CascadeConfig cfg = small_cascade();
  Cascades c = Cascades::create(ed.world().lattice(), cfg).value();
  ASSERT_TRUE(c.update_all(ed.world(), cam).ok());
  std::vector<VoxelGrid> before;
  for (int k = 0; k < 2; ++k) before.push_back(c.level_grid(k));
  PackedGBuffer faces_before;
  c.pack(&faces_before);
  ASSERT_TRUE(ed.apply(Brush::sphere({5.2, 4.9, 5.4}, 0.6), EditOp::kSubtract).ok());
  std::vector<DirtyChunk> dirty = ed.take_dirty();
  ASSERT_FALSE(dirty.empty());
  c.invalidate(dirty);
  Result<size_t> refreshed = c.refresh(ed.world());
  ASSERT_TRUE(refreshed.ok());
  EXPECT_GT(refreshed.value(), 0u);
  Cascades fresh = Cascades::create(ed.world().lattice(), cfg).value();
  ASSERT_TRUE(fresh.update_all(ed.world(), cam).ok());
  EXPECT_TRUE(same_cascades(c, fresh));
  PackedGBuffer faces_after;
  c.pack(&faces_after);
  for (int k = 0; k < 2; ++k) {
    const int m = 1 << k;  // cells per voxel
    auto under_dirty = [&](const glm::ivec3& g, int ring) {
      for (const DirtyChunk& d : dirty) {
        bool in = true;
        for (int a = 0; a < 3; ++a) {
          in = in && m * (g[a] + ring) + m >= d.node_lo[a] && m * (g[a] - ring) <= d.node_hi[a] - 1;
        }
        if (in) return true;
      }
      return false;
    };
    const VoxelGrid after = c.level_grid(k);
    size_t changed = 0;
    for (int z = 0; z < 8; ++z) {
      for (int y = 0; y < 8; ++y) {
        for (int x = 0; x < 8; ++x) {
          const glm::ivec3 g = after.box.lo + glm::ivec3(x, y, z);
          if (after.at(g) != before[size_t(k)].at(g)) {
            ++changed;
            EXPECT_TRUE(under_dirty(g, 0)) << "level " << k << " occupancy changed outside the dirty chunks";
          }
          for (int f = 0; f < kFaces; ++f) {
            const size_t t = faces_after.texel(f, k, {x, y, z});
            if (faces_after.albedo[t] != faces_before.albedo[t] || faces_after.normal[t] != faces_before.normal[t] ||
                faces_after.occupancy[t] != faces_before.occupancy[t]) {
              // Propagated faces may change one voxel around the dirty boxes.
              EXPECT_TRUE(under_dirty(g, 1)) << "level " << k << " face " << f << " changed far from the dirty chunks";
            }
          }
        }
      }
    }
    EXPECT_GT(changed, 0u) << "level " << k;
  }
}

TEST(Cascades, ScheduleUpdatesLevelKEvery2PowKPlus1Frames) {
  int count[6] = {0, 0, 0, 0, 0, 0};
  for (uint64_t f = 0; f < 128; ++f) ++count[Cascades::scheduled_level(f, 6)];
  EXPECT_EQ(count[0], 64);
  EXPECT_EQ(count[1], 32);
  EXPECT_EQ(count[2], 16);
  EXPECT_EQ(count[3], 8);
  EXPECT_EQ(count[4], 4);
  EXPECT_EQ(count[5], 4);  // its own 2 plus the frames no level is due
  EXPECT_EQ(Cascades::scheduled_level(0, 6), 0);
  EXPECT_EQ(Cascades::scheduled_level(1, 6), 1);
  EXPECT_EQ(Cascades::scheduled_level(3, 6), 2);
}

TEST(Cascades, PackedLayoutTilesFacesInXAndLevelsInY) {
  World w = small_terrain();
  Cascades c = Cascades::create(w.lattice(), small_cascade()).value();
  ASSERT_TRUE(c.update_all(w, {5.3, 4.1, 6.2}).ok());
  PackedGBuffer p;
  c.pack(&p);
  EXPECT_EQ(p.extent(), glm::ivec3(48, 16, 8));
  EXPECT_EQ(p.albedo.size(), size_t(48 * 16 * 8));
  size_t own = 0;
  for (int k = 0; k < 2; ++k) {
    const VoxelBox b = c.level_box(k);
    for (int z = 0; z < 8; ++z) {
      for (int y = 0; y < 8; ++y) {
        for (int x = 0; x < 8; ++x) {
          for (int f = 0; f < kFaces; ++f) {
            const FaceSample a = p.sample(f, k, {x, y, z});
            const FaceSample b2 = c.sample(k, f, b.lo + glm::ivec3(x, y, z));
            ASSERT_EQ(std::memcmp(&a, &b2, sizeof(FaceSample)), 0);
            own += a.flags == kFaceOwn;
            // texel (f*N + x, k*N + y, z)
            ASSERT_EQ(p.texel(f, k, {x, y, z}), size_t((z * 16 + k * 8 + y) * 48 + f * 8 + x));
          }
        }
      }
    }
  }
  EXPECT_GT(own, 50u);
}

// A lone object voxelized at 0.3 m over an empty landscape.
VoxelGrid voxelize_object(const StaticObject& o) {
  World empty = build_from_primitive(Primitive{.radius = 0.1, .transform = glm::translate(glm::dmat4(1.0), glm::dvec3(-5.0))},
                                     grid_at(0.1)).value();
  VoxelizeOptions opt;
  opt.objects = std::span<const StaticObject>(&o, 1);
  opt.box = VoxelBox{glm::ivec3(-1), glm::ivec3(8)};
  opt.faces = true;
  Result<VoxelGrid> g = voxelize(empty, VoxelConfig{.voxel_size = 0.3}, opt);
  EXPECT_TRUE(g.ok()) << g.status().message();
  return g.ok() ? std::move(g).value() : VoxelGrid{};
}

// Every face an object's surface owns has material `id`'s albedo (and there is one).
void expect_own_faces_of_material(const VoxelGrid& g, uint16_t id) {
  bool saw_material = false;
  for (const VoxelFaces& s : g.surface_faces) {
    if (s[0].flags == kFaceOwn) {
      saw_material = true;
      EXPECT_LT(glm::length(glm::vec3(s[0].albedo) - default_material_table().materials[id].albedo), 1e-5f);
    }
  }
  EXPECT_TRUE(saw_material);
}

TEST(Objects, StaticObjectIsVoxelizedWithItsVolume) {
  StaticObject o;
  const glm::dvec3 lo(0.13, 0.21, 0.05), hi(1.07, 0.93, 1.61);
  o.mesh = std::make_shared<TriangleMesh>(test::box_mesh(lo, hi));
  o.material = 2;
  const VoxelGrid g = voxelize_object(o);
  const glm::dvec3 e = hi - lo;
  EXPECT_NEAR(g.volume(), e.x * e.y * e.z, 0.01 * e.x * e.y * e.z);
  expect_own_faces_of_material(g, 2);
}

// A mesh with its own (named) material ids takes material_base + id.
TEST(Objects, MeshMaterialIdsAreOffsetByMaterialBase) {
  TriangleMesh mesh = test::box_mesh(glm::dvec3(0.13, 0.21, 0.05), glm::dvec3(1.07, 0.93, 1.61));
  mesh.triangle_material.assign(mesh.triangles.size(), 0);
  mesh.material_names = {"stone"};
  StaticObject o;
  o.mesh = std::make_shared<TriangleMesh>(std::move(mesh));
  o.material_base = 3;
  expect_own_faces_of_material(voxelize_object(o), 3);
}

// --- Bad input -------------------------------------------------------------------

TEST(VoxelErrors, BadVoxelSizesAreRefusedWithTheValue) {
  World w = sphere_world({0, 0, 0}, 0.5, 0.2);
  for (double s : {0.3, 0.0, -0.4, std::nan(""), 1e9, 0.1}) {
    Result<VoxelGrid> g = voxelize(w, VoxelConfig{.voxel_size = s});
    ASSERT_FALSE(g.ok()) << s;
    EXPECT_EQ(g.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(g.status().message().find("voxel size"), std::string::npos) << g.status().message();
  }
  Result<VoxelGrid> g = voxelize(w, VoxelConfig{.voxel_size = 0.3});
  EXPECT_NE(g.status().message().find("whole number of cells"), std::string::npos) << g.status().message();
  g = voxelize(w, VoxelConfig{.voxel_size = 0.2, .axis = 3});
  EXPECT_NE(g.status().message().find("axis 3"), std::string::npos);
  VoxelizeOptions opt;
  opt.box = VoxelBox{glm::ivec3(0), glm::ivec3(2000)};
  g = voxelize(w, VoxelConfig{.voxel_size = 0.2}, opt);
  EXPECT_EQ(g.status().code(), ErrorCode::kTooLarge);
  MaterialTable bad;
  bad.materials.push_back({glm::vec3(0.5f, 2.0f, 0.5f), glm::vec3(0.0f)});
  opt = {};
  opt.materials = &bad;
  g = voxelize(w, VoxelConfig{.voxel_size = 0.2}, opt);
  EXPECT_NE(g.status().message().find("material 0: albedo channel 1 = 2"), std::string::npos) << g.status().message();
}

TEST(VoxelErrors, BadCascadeConfigAndCameraAreRefused) {
  World w = sphere_world({0, 0, 0}, 0.5, 0.2);
  CascadeConfig c;
  c.resolution = 31;
  EXPECT_NE(Cascades::create(w.lattice(), c).status().message().find("resolution 31"), std::string::npos);
  c = {};
  c.levels = 0;
  EXPECT_FALSE(Cascades::create(w.lattice(), c).ok());
  c = {};
  c.levels = 12;  // 2^11 cells per voxel at the last level
  EXPECT_NE(Cascades::create(w.lattice(), c).status().message().find("level 11"), std::string::npos);
  c = {};
  c.voxel_size = 0.25;
  EXPECT_NE(Cascades::create(w.lattice(), c).status().message().find("whole number"), std::string::npos);
  Cascades ok = Cascades::create(w.lattice(), CascadeConfig{.levels = 1, .resolution = 4}).value();
  Result<CascadeUpdate> up = ok.update_level(w, 0, glm::dvec3(std::nan(""), 0.0, 0.0));
  ASSERT_FALSE(up.ok());
  EXPECT_NE(up.status().message().find("camera"), std::string::npos);
  EXPECT_FALSE(ok.update_level(w, 3, glm::dvec3(0.0)).ok());
  World other = sphere_world({0, 0, 0}, 0.5, 0.1);
  EXPECT_NE(ok.update_level(other, 0, glm::dvec3(0.0)).status().message().find("lattice"), std::string::npos);
}

// save_raw writes "<stem>.raw" and "<stem>.json" through AtomicFile: a
// write that fails part way (RLIMIT_FSIZE, as a full disk) leaves the
// previous pair whole and no temp file beside it (before, a truncated .raw).
TEST(RawExport, AFailedSaveLeavesThePreviousPairWhole) {
  namespace fs = std::filesystem;
  const std::string folder = ::testing::TempDir() + "/raw_failed_save";
  fs::remove_all(folder);
  fs::create_directories(folder);
  World w = build_terrain(TerrainConfig{.size_x = 8.0, .size_y = 8.0, .cave_radius = 0.0, .arches = 1}, 0.25, 16).value();
  VoxelGrid small = voxelize(w, VoxelConfig{.voxel_size = 1.0}).value();
  VoxelizeOptions faces;
  faces.faces = true;
  VoxelGrid big = voxelize(w, VoxelConfig{.voxel_size = 0.25}, faces).value();
  ASSERT_TRUE(save_raw(small, folder + "/v.raw").ok());
  const std::string old_raw = read_file(folder + "/v.raw").value(), old_json = read_file(folder + "/v.json").value();
  struct rlimit old_limit;
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  struct rlimit limit = old_limit;
  limit.rlim_cur = old_raw.size() + 4096;
  auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &limit), 0);
  Status s = save_raw(big, folder + "/v.raw");
  ::setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find(folder + "/v.raw: cannot write: "), std::string::npos) << s.message();
  EXPECT_EQ(read_file(folder + "/v.raw").value(), old_raw);
  EXPECT_EQ(read_file(folder + "/v.json").value(), old_json);
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(folder)) ++entries;
  EXPECT_EQ(entries, 2u);
  fs::remove_all(folder);
}

}  // namespace
}  // namespace ldc
