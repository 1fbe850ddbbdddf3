// Booleans and brush edits: exact identities, degenerate contacts, the editor's
// bookkeeping (versions, dirty chunks, undo) and a long random-edit property test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>
#include <random>
#include <set>

#include <glm/gtc/matrix_transform.hpp>

#include "csg/csg.h"
#include "contour/contour.h"
#include "csg/detail/brush_raster.h"
#include "test_util.h"

namespace ldc {
namespace {

using test::is_valid;

constexpr double kPi = 3.14159265358979323846;

// Same box, same chunk kinds, same rays bit for bit.
::testing::AssertionResult identical(const World& a, const World& b) {
  if (a.chunk_origin() != b.chunk_origin() || a.chunk_dims() != b.chunk_dims() ||
      a.chunk_size() != b.chunk_size()) {
    return ::testing::AssertionFailure() << "chunk boxes differ";
  }
  const int c = a.chunk_size();
  std::string diff;
  a.for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk* da) {
    if (!diff.empty()) return;
    if (b.chunk_kind(ch) != kind) {
      diff = "chunk kinds differ";
      return;
    }
    if (!da) return;
    const Chunk* db = b.chunk(ch);
    for (int k = 0; k < 3; ++k) {
      const RayFamily &fa = da->axis[k], &fb = db->axis[k];
      for (int r = 0; r < c * c; ++r) {
        auto pa = fa.points(r), pb = fb.points(r);
        if (fa.starts_inside(r) != fb.starts_inside(r) || pa.size() != pb.size() ||
            (!pa.empty() && std::memcmp(pa.data(), pb.data(), pa.size_bytes()) != 0)) {
          diff = "ray " + std::to_string(r) + " of axis " + std::to_string(k) + " differs";
          return;
        }
      }
    }
  });
  if (diff.empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << diff;
}

// Every lattice node of `result`'s box (and one chunk around) is inside
// exactly when op says so of the inputs' nodes.
::testing::AssertionResult nodes_follow_op(const World& a, const World& b, const World& result, BooleanOp op) {
  glm::ivec3 lo = glm::min(a.node_min(), b.node_min()) - 2, hi = glm::max(a.node_end(), b.node_end()) + 2;
  for (int z = lo.z; z < hi.z; ++z)
    for (int y = lo.y; y < hi.y; ++y)
      for (int x = lo.x; x < hi.x; ++x) {
        glm::ivec3 n(x, y, z);
        bool ia = a.inside_node(n), ib = b.inside_node(n);
        bool want = op == BooleanOp::kUnion ? (ia || ib) : op == BooleanOp::kSubtract ? (ia && !ib) : (ia && ib);
        if (result.inside_node(n) != want) {
          return ::testing::AssertionFailure()
                 << "node (" << x << ", " << y << ", " << z << ") is " << (want ? "outside" : "inside");
        }
      }
  return ::testing::AssertionSuccess();
}

// Two worlds on one lattice: spot, and a sphere through its body.
struct Pair {
  World a, b;
};

Pair spot_and_sphere(int cells = 48) {
  TriangleMesh spot = test::load_test_mesh("spot.obj");
  GridConfig grid{.cells = cells, .chunk_size = 16};
  World a = build_from_mesh(spot, grid).value();
  Primitive s;
  s.radius = 0.45;
  s.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.2, 0.3, 0.1));
  World b = detail::rasterize_primitive(s, a.lattice(), a.chunk_size()).value();
  return {std::move(a), std::move(b)};
}

size_t total_points(const World& w) { return w.stats().points; }

// World position of a stored point.
glm::dvec3 point_position(const World& w, const glm::ivec3& ch, int axis, int ray, const PackedPoint& p) {
  const int c = w.chunk_size();
  glm::dvec3 q;
  q[axis] = decode_point(p, c, ch[axis] * c).depth;
  q[axis_u(axis)] = ch[axis_u(axis)] * c + ray % c;
  q[axis_v(axis)] = ch[axis_v(axis)] * c + ray / c;
  return w.lattice().to_world(q);
}

TEST(Boolean, SelfIdentitiesAreExact) {
  Pair p = spot_and_sphere();
  World diff = boolean(p.a, p.a, BooleanOp::kSubtract).value();
  EXPECT_TRUE(is_valid(diff));
  EXPECT_EQ(total_points(diff), 0u);
  EXPECT_EQ(diff.stats().chunks_solid, 0u);
  EXPECT_TRUE(identical(boolean(p.a, p.a, BooleanOp::kUnion).value(), p.a));
  EXPECT_TRUE(identical(boolean(p.a, p.a, BooleanOp::kIntersect).value(), p.a));
}

TEST(Boolean, EveryNodeFollowsTheOperation) {
  Pair p = spot_and_sphere();
  for (BooleanOp op : {BooleanOp::kUnion, BooleanOp::kSubtract, BooleanOp::kIntersect}) {
    SCOPED_TRACE(boolean_op_name(op));
    World r = boolean(p.a, p.b, op).value();
    EXPECT_TRUE(is_valid(r));
    EXPECT_TRUE(nodes_follow_op(p.a, p.b, r, op));
  }
}

TEST(Boolean, VolumesAddUp) {
  Pair p = spot_and_sphere(64);
  for (int axis = 0; axis < 3; ++axis) {
    double va = p.a.volume(axis), vb = p.b.volume(axis);
    double vu = boolean(p.a, p.b, BooleanOp::kUnion).value().volume(axis);
    double vi = boolean(p.a, p.b, BooleanOp::kIntersect).value().volume(axis);
    double vd = boolean(p.a, p.b, BooleanOp::kSubtract).value().volume(axis);
    ASSERT_GT(vi, 0.01 * va);  // the sphere really overlaps spot
    EXPECT_NEAR(vu + vi, va + vb, 1e-4 * va);
    EXPECT_NEAR(vd + vi, va, 1e-4 * va);
  }
}

TEST(Boolean, TouchingBoxesMergeWithoutAnInnerWall) {
  // Two unit boxes sharing the face x = 1, which lies between lattice nodes.
  GridConfig grid{.cell_size = 0.1, .chunk_size = 16, .use_origin = true, .origin = glm::dvec3(-0.537, -0.461, -0.523)};
  World a = build_from_mesh(test::box_mesh({0, 0, 0}, {1, 1, 1}), grid).value();
  World b = build_from_mesh(test::box_mesh({1, 0, 0}, {2, 1, 1}), grid).value();
  World whole = build_from_mesh(test::box_mesh({0, 0, 0}, {2, 1, 1}), grid).value();
  World u = boolean(a, b, BooleanOp::kUnion).value();
  ASSERT_TRUE(is_valid(u));
  EXPECT_NEAR(u.volume(0), 2.0, 1e-3);
  EXPECT_EQ(total_points(u), total_points(whole));
  for (int y = 0; y < 10; ++y) {
    for (int z = 0; z < 10; ++z) {
      glm::ivec2 uv(int(std::lround((0.05 + 0.1 * y + 0.461) / 0.1)), int(std::lround((0.05 + 0.1 * z + 0.523) / 0.1)));
      EXPECT_LE(u.ray_points(0, uv).size(), 2u);
    }
  }
  EXPECT_TRUE(nodes_follow_op(a, b, u, BooleanOp::kUnion));
}

TEST(Boolean, CoplanarCutLeavesNoSlivers) {
  // A box minus a box whose top face is the same plane: the classic coplanar case.
  GridConfig grid{.cell_size = 0.1, .chunk_size = 16, .use_origin = true, .origin = glm::dvec3(-0.52, -0.47, -0.55)};
  World a = build_from_mesh(test::box_mesh({0, 0, 0}, {2, 2, 1}), grid).value();
  World b = build_from_mesh(test::box_mesh({0.5, 0.5, 0.5}, {1.5, 1.5, 1}), grid).value();
  World d = boolean(a, b, BooleanOp::kSubtract).value();
  ASSERT_TRUE(is_valid(d));
  EXPECT_NEAR(d.volume(2), 4.0 - 0.5, 1e-3);
  // Z rays through the pocket: one span below it, nothing left at the top face.
  for (int i = 8; i < 18; ++i) {
    auto spans = d.ray_spans(2, {i, i});
    ASSERT_EQ(spans.size(), 1u) << i;
  }
  EXPECT_TRUE(nodes_follow_op(a, b, d, BooleanOp::kSubtract));
}

TEST(Boolean, CutSurfacesFaceOutAndTakeTheMaterialCut) {
  TriangleMesh box = test::box_mesh({0, 0, 0}, {2, 2, 2});
  box.triangle_material.assign(box.triangles.size(), 5);
  GridConfig grid{.cell_size = 0.1, .chunk_size = 16, .use_origin = true, .origin = glm::dvec3(-0.53, -0.47, -0.51)};
  World a = build_from_mesh(box, grid).value();
  Primitive s;
  s.radius = 0.5;
  s.material = 9;
  s.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(1.0, 1.0, 2.0));
  World b = detail::rasterize_primitive(s, a.lattice(), a.chunk_size()).value();
  World d = boolean(a, b, BooleanOp::kSubtract).value();
  ASSERT_TRUE(is_valid(d));  // includes: every normal points out of the solid
  std::set<uint16_t> materials;
  d.for_each_chunk([&](const glm::ivec3&, ChunkKind, const Chunk* c) {
    if (c) for (const RayFamily& f : c->axis) for (const PackedPoint& p : f.all_points()) materials.insert(p.material);
  });
  EXPECT_EQ(materials, std::set<uint16_t>{5});
  World tagged = boolean(a, b, BooleanOp::kSubtract, {.cut_material = 7}).value();
  materials.clear();
  tagged.for_each_chunk([&](const glm::ivec3&, ChunkKind, const Chunk* c) {
    if (c) for (const RayFamily& f : c->axis) for (const PackedPoint& p : f.all_points()) materials.insert(p.material);
  });
  EXPECT_EQ(materials, (std::set<uint16_t>{5, 7}));
  // The bowl's volume: a half ball removed.
  EXPECT_NEAR(d.volume(2), 8.0 - 2.0 / 3.0 * kPi * 0.125, 0.01);
}

TEST(Boolean, RefusesMismatchedLatticesAndBadConfig) {
  Pair p = spot_and_sphere();
  World shifted = build_from_mesh(test::load_test_mesh("spot.obj"), {.cells = 47, .chunk_size = 16}).value();
  Result<World> r = boolean(p.a, shifted, BooleanOp::kUnion);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("lattices differ"), std::string::npos) << r.status().message();
  r = boolean(p.a, p.b, BooleanOp::kUnion, {.sliver = 0.7});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("sliver"), std::string::npos);
  r = boolean(p.a, p.b, BooleanOp::kUnion, {.cut_material = 70000});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("cut_material"), std::string::npos);
}

TEST(Boolean, DisjointIntersectionIsEmptyAndUnionHoldsBoth) {
  GridConfig grid{.cell_size = 0.1, .chunk_size = 8, .use_origin = true, .origin = glm::dvec3(0.013)};
  World a = build_from_mesh(test::box_mesh({0, 0, 0}, {1, 1, 1}), grid).value();
  World b = build_from_mesh(test::box_mesh({5, 5, 5}, {6, 6, 6}), grid).value();
  World i = boolean(a, b, BooleanOp::kIntersect).value();
  EXPECT_TRUE(is_valid(i));
  EXPECT_EQ(total_points(i), 0u);
  World u = boolean(a, b, BooleanOp::kUnion).value();
  EXPECT_TRUE(is_valid(u));
  EXPECT_NEAR(u.volume(0), 2.0, 1e-3);
}

// The open bunny (holes in its base) with a sphere through its back: every
// op valid, and the volumes add up: |A - B| + |A n B| is the bunny's own
// volume and |A u B| - |A - B| the sphere's, which an op that dropped or
// doubled a part would break.
TEST(MeshBoolean, OpenBunnyAndSphereAreValidAndTheirVolumesAddUp) {
  TriangleMesh bunny = test::load_test_mesh("stanford-bunny.obj");
  MeshBounds bb = mesh_bounds(bunny);
  glm::dvec3 centre = 0.5 * (bb.min + bb.max);
  const double radius = 0.3 * bb.extent().y;
  TriangleMesh ball = test::sphere_mesh(centre + glm::dvec3(0, 0.3 * bb.extent().y, 0), radius, 3);
  double volume[3] = {0, 0, 0};
  for (BooleanOp op : {BooleanOp::kUnion, BooleanOp::kSubtract, BooleanOp::kIntersect}) {
    Result<World> r = mesh_boolean(bunny, ball, op, {.cells = 48, .chunk_size = 16});
    ASSERT_TRUE(r.ok()) << r.status().message();
    EXPECT_TRUE(is_valid(r.value()));
    volume[int(op)] = r.value().volume(2);
  }
  const double u = volume[int(BooleanOp::kUnion)], d = volume[int(BooleanOp::kSubtract)],
               i = volume[int(BooleanOp::kIntersect)];
  EXPECT_GT(i, 0.0);
  EXPECT_GT(d, i);
  // |A| = |A - B| + |A n B|; |B| = |A u B| - |A - B| (all on one lattice, so nearly exact).
  const double a = d + i, b = u - d;
  const double ball_volume = 4.0 / 3.0 * M_PI * radius * radius * radius;
  EXPECT_NEAR(b, ball_volume, 0.03 * ball_volume);  // the icosphere is a little smaller than the sphere
  // |A| against the bunny built alone (another lattice: a few percent apart).
  const double bunny_alone = build_from_mesh(bunny, {.cells = 48, .chunk_size = 16}).value().volume(2);
  EXPECT_NEAR(a, bunny_alone, 0.03 * bunny_alone);
  TriangleMesh empty;
  Result<World> r = mesh_boolean(bunny, empty, BooleanOp::kUnion, {.cells = 48});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("second mesh"), std::string::npos);
}

// --- Brushes and the editor --------------------------------------------------

// A slab of ground 2 half_width x 2 half_width x 2 m at h = 0.2 (chunks of 16 cells), material 1.
World ground(double half_width = 4.0) {
  Primitive slab;
  slab.shape = Primitive::Shape::kBox;
  slab.half_extents = glm::dvec3(half_width, half_width, 1.0);
  slab.material = 1;
  GridConfig grid{.cell_size = 0.2, .chunk_size = 16, .use_origin = true, .origin = glm::dvec3(-4.9, -4.9, -1.9)};
  return build_from_primitive(slab, grid).value();
}

TEST(Brush, RasterizedBrushesAreValidAndHaveTheirVolume) {
  World w = ground();
  struct Case {
    Brush brush;
    double volume;
    double tolerance;
  };
  NoiseSphere n{.radius = 1.0, .amplitude = 0.3};
  std::vector<Case> cases = {
      {Brush::sphere({0.1, 0.2, 0.3}, 1.0), 4.0 / 3.0 * kPi, 0.03},
      {Brush::box({0.0, 0.0, 0.0}, {0.6, 0.8, 1.0}), 8 * 0.6 * 0.8 * 1.0, 1e-6},  // faces halfway between nodes
      {Brush::capsule({-1, 0, 0}, {1, 0.5, 0.3}, 0.4), kPi * 0.16 * std::sqrt(4 + 0.25 + 0.09) + 4.0 / 3.0 * kPi * 0.064, 0.03},
      {Brush::cylinder({0, 0, -1}, {0, 0, 1}, 0.6), kPi * 0.36 * 2.0, 0.03},
  };
  for (const Case& c : cases) {
    World b = rasterize_brush(c.brush, w.lattice(), w.chunk_size()).value();
    EXPECT_TRUE(is_valid(b));
    EXPECT_NEAR(b.volume(0), c.volume, c.tolerance * c.volume);
    EXPECT_EQ(b.lattice().origin, w.lattice().origin);
  }
  World noisy = rasterize_brush(Brush::noisy_sphere({0, 0, 0}, n, 3), w.lattice(), w.chunk_size()).value();
  EXPECT_TRUE(is_valid(noisy));
  double v = noisy.volume(0), ball = 4.0 / 3.0 * kPi;
  EXPECT_GT(v, ball * std::pow(0.7, 3));
  EXPECT_LT(v, ball * std::pow(1.3, 3));
  EXPECT_GT(std::abs(v - ball), 0.005 * ball);  // the noise really displaces it
  auto mesh = std::make_shared<TriangleMesh>(test::sphere_mesh({0, 0, 0}, 1.0, 3));
  glm::dmat4 t = glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(0.3, 0.1, 0)), 0.4, glm::dvec3(1, 2, 3));
  World m = rasterize_brush(Brush::from_mesh(mesh, glm::scale(t, glm::dvec3(1.0, 0.5, 0.8))), w.lattice(), w.chunk_size()).value();
  EXPECT_TRUE(is_valid(m));
  EXPECT_NEAR(m.volume(1), mesh_signed_volume(*mesh) * 0.4, 0.03 * 0.4 * 4.2);
}

// The noise is tabulated on a cube map: across every seam between two faces
// the brush's surface must not jump (a jump would tear the star-shaped solid).
TEST(Brush, NoiseBrushIsContinuousAcrossCubeMapSeams) {
  for (double frequency : {0.7, 2.0, 9.0}) {
    NoiseSphere n{.radius = 1.0, .amplitude = 0.5, .frequency = frequency, .seed = 5};
    auto solid = detail::make_noise_sphere_solid(std::get<NoiseShape>(Brush::noisy_sphere({0, 0, 0}, n).shape));
    double largest_jump = 0.0, largest_variation = 0.0, previous = NAN;
    for (int axis = 0; axis < 3; ++axis) {
      for (double sa : {-1.0, 1.0}) {
        for (double sb : {-1.0, 1.0}) {
          for (int k = 0; k <= 200; ++k) {  // along the cube edge where |d[axis]| = |d[axis + 1]|
            glm::dvec3 p;
            p[axis] = sa;
            p[(axis + 1) % 3] = sb;
            p[(axis + 2) % 3] = -1.0 + 2.0 * k / 200;
            glm::dvec3 off(0.0);
            off[(axis + 1) % 3] = sb * 1e-9;  // just past the seam into the other face
            double v0 = solid->value(glm::normalize(p - off)), v1 = solid->value(glm::normalize(p + off));
            largest_jump = std::max(largest_jump, std::abs(v0 - v1));
            if (!std::isnan(previous)) largest_variation = std::max(largest_variation, std::abs(v0 - previous));
            previous = v0;
          }
        }
      }
    }
    EXPECT_LT(largest_jump, 1e-6) << "frequency " << frequency;
    EXPECT_GT(largest_variation, 1e-3) << "frequency " << frequency;  // the noise is not flat there
  }
}

TEST(Brush, BadBrushesAreRefusedByName) {
  EXPECT_NE(check_brush(Brush::sphere({0, 0, 0}, -1.0)).message().find("radius"), std::string::npos);
  EXPECT_FALSE(check_brush(Brush::sphere({NAN, 0, 0}, 1.0)).ok());
  EXPECT_NE(check_brush(Brush::noisy_sphere({0, 0, 0}, {.amplitude = 2.0})).message().find("amplitude"), std::string::npos);
  EXPECT_NE(check_brush(Brush::noisy_sphere({0, 0, 0}, {.frequency = 1e300})).message().find("frequency"), std::string::npos);
  EXPECT_FALSE(check_brush(Brush::noisy_sphere({0, 0, 0}, {.frequency = NAN})).ok());
  EXPECT_NE(check_brush(Brush::from_mesh(nullptr, glm::dmat4(1.0))).message().find("without a mesh"), std::string::npos);
  auto mesh = std::make_shared<TriangleMesh>(test::sphere_mesh({0, 0, 0}, 1.0, 1));
  EXPECT_NE(check_brush(Brush::from_mesh(mesh, glm::dmat4(0.0))).message().find("invertible"), std::string::npos);
}

TEST(Editor, DigChangesOnlyTheChunksItTouches) {
  World before = ground();
  WorldEditor ed(before);
  Result<EditReceipt> r = ed.apply(Brush::sphere({0.31, 0.27, 0.9}, 0.8), EditOp::kSubtract);
  ASSERT_TRUE(r.ok()) << r.status().message();
  const World& after = ed.world();
  ASSERT_TRUE(is_valid(after));
  EXPECT_EQ(r.value().version, 1u);
  EXPECT_EQ(ed.version(), 1u);
  ASSERT_FALSE(r.value().changed_chunks.empty());
  // The removed volume: the part of the ball below the slab's top (z = 1).
  double below = kPi * std::pow(0.9, 2) * (3 * 0.8 - 0.9) / 3.0;  // a cap of height 0.8 + 0.1
  EXPECT_NEAR(before.volume(2) - after.volume(2), below, 0.03 * below);
  // Chunks away from the brush are the very same objects.
  size_t shared = 0, changed = 0;
  before.for_each_chunk([&](const glm::ivec3& c, ChunkKind kind, const Chunk* data) {
    bool listed = std::find(r.value().changed_chunks.begin(), r.value().changed_chunks.end(), c) != r.value().changed_chunks.end();
    if (listed) {
      ++changed;
      return;
    }
    EXPECT_EQ(after.chunk_kind(c), kind);
    EXPECT_EQ(after.chunk(c), data);
    ++shared;
  });
  EXPECT_GT(shared, changed);
  // Dirty list: the changed chunks, with node boxes around the brush.
  std::vector<DirtyChunk> dirty = ed.take_dirty();
  ASSERT_EQ(dirty.size(), r.value().changed_chunks.size());
  glm::dvec3 centre = after.lattice().to_lattice({0.31, 0.27, 0.9});
  for (const DirtyChunk& d : dirty) {
    EXPECT_EQ(d.version, 1u);
    for (int a = 0; a < 3; ++a) {
      EXPECT_LT(d.node_lo[a], d.node_hi[a]);
      EXPECT_GE(d.node_lo[a], std::floor(centre[a] - 4.0));  // the brush's radius is 4 cells
      EXPECT_LE(d.node_hi[a], std::ceil(centre[a] + 4.0) + 2);
      EXPECT_GE(d.node_lo[a], d.chunk[a] * 16);
      EXPECT_LE(d.node_hi[a], d.chunk[a] * 16 + 17);
    }
  }
  EXPECT_TRUE(ed.take_dirty().empty());
}

TEST(Editor, BuildGrowsTheWorldAndSubtractOutsideChangesNothing) {
  WorldEditor ed(ground());
  const glm::ivec3 dims = ed.world().chunk_dims();
  Result<EditReceipt> r = ed.apply(Brush::sphere({0, 0, 20.0}, 1.0, 4), EditOp::kSubtract);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.value().changed_chunks.empty());
  r = ed.apply(Brush::box({0, 0, 20.0}, glm::dvec3(1.0), 4), EditOp::kUnion);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_GT(ed.world().chunk_dims().z, dims.z);
  ASSERT_TRUE(is_valid(ed.world()));
  EXPECT_TRUE(ed.world().inside({0.05, 0.05, 20.05}));
  EXPECT_NEAR(ed.world().volume(0), 64.0 * 2 + 8.0, 0.01);
}

TEST(Editor, PaintChangesMaterialsOnly) {
  WorldEditor ed(ground());
  World before = ed.world();
  ASSERT_TRUE(ed.apply(Brush::sphere({0.0, 0.0, 1.0}, 1.0, 7), EditOp::kPaint).ok());
  const World& after = ed.world();
  ASSERT_TRUE(is_valid(after));
  size_t painted = 0, kept = 0;
  const int c = after.chunk_size();
  after.for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk* d) {
    ASSERT_EQ(kind, before.chunk_kind(ch));
    if (!d) return;
    for (int a = 0; a < 3; ++a)
      for (int r = 0; r < c * c; ++r) {
        auto pa = before.chunk(ch)->axis[a].points(r), pb = d->axis[a].points(r);
        ASSERT_EQ(pa.size(), pb.size());
        for (size_t i = 0; i < pa.size(); ++i) {
          ASSERT_EQ(pa[i].depth, pb[i].depth);
          ASSERT_EQ(pa[i].normal, pb[i].normal);
          glm::dvec3 q = point_position(after, ch, a, r, pb[i]);
          bool in_ball = glm::length(q - glm::dvec3(0, 0, 1)) < 1.0 - 0.21;
          bool out_ball = glm::length(q - glm::dvec3(0, 0, 1)) > 1.0 + 0.21;
          if (in_ball) {
            EXPECT_EQ(pb[i].material, 7);
          }
          if (out_ball) {
            EXPECT_EQ(pb[i].material, 1);
          }
          (pb[i].material == 7 ? painted : kept) += 1;
        }
      }
  });
  EXPECT_GT(painted, 50u);
  EXPECT_GT(kept, painted);
  EXPECT_DOUBLE_EQ(after.volume(0), before.volume(0));
}

TEST(Editor, IntersectKeepsOnlyTheBrush) {
  WorldEditor ed(ground());
  ASSERT_TRUE(ed.apply(Brush::sphere({0.0, 0.0, 1.0}, 1.0), EditOp::kIntersect).ok());
  ASSERT_TRUE(is_valid(ed.world()));
  EXPECT_NEAR(ed.world().volume(0), 2.0 / 3.0 * kPi, 0.03 * 2.0);
  EXPECT_FALSE(ed.world().inside({3.0, 3.0, 0.0}));
}

TEST(Editor, UndoRestoresInReverseOrderOnly) {
  World original = ground();
  WorldEditor ed(original);
  EditReceipt first = ed.apply(Brush::sphere({0.0, 0.0, 1.0}, 1.0), EditOp::kSubtract).value();
  World after_first = ed.world();
  EditReceipt second = ed.apply(Brush::box({0.5, 0.0, 1.0}, glm::dvec3(0.6)), EditOp::kUnion).value();
  ed.take_dirty();
  // The first edit's chunks were changed again by the second: refused, nothing changes.
  Status s = ed.undo(first);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("undo that first"), std::string::npos) << s.message();
  EXPECT_TRUE(ed.take_dirty().empty());
  ASSERT_TRUE(ed.undo(second).ok());
  EXPECT_TRUE(identical(ed.world(), after_first));
  EXPECT_FALSE(ed.take_dirty().empty());
  ASSERT_TRUE(ed.undo(first).ok());
  EXPECT_TRUE(identical(ed.world(), original));
  EXPECT_FALSE(ed.undo(first).ok());  // already undone
  EXPECT_TRUE(is_valid(ed.world()));
}

TEST(Editor, BatchEqualsEditsInOrder) {
  std::vector<WorldEditor::Edit> edits = {
      {Brush::sphere({0.0, 0.0, 1.0}, 1.2), EditOp::kSubtract},
      {Brush::capsule({-2, -2, 1}, {2, 1, 0.5}, 0.5, 3), EditOp::kUnion},
      {Brush::box({1.0, 1.0, 1.0}, glm::dvec3(0.7), 6), EditOp::kPaint},
      {Brush::noisy_sphere({-1.0, 1.5, 0.5}, {.radius = 0.9}), EditOp::kSubtract},
  };
  WorldEditor one_by_one(ground()), batched(ground());
  for (const auto& e : edits) ASSERT_TRUE(one_by_one.apply(e.brush, e.op).ok());
  EditReceipt r = batched.apply_batch(edits).value();
  EXPECT_TRUE(identical(batched.world(), one_by_one.world()));
  EXPECT_TRUE(is_valid(batched.world()));
  ASSERT_TRUE(batched.undo(r).ok());
  EXPECT_TRUE(identical(batched.world(), ground()));
}

TEST(Editor, ErrorsLeaveTheWorldAsItWas) {
  World original = ground();
  WorldEditor ed(original);
  std::vector<WorldEditor::Edit> edits = {{Brush::sphere({0, 0, 1}, 1.0), EditOp::kSubtract},
                                          {Brush::sphere({0, 0, NAN}, 1.0), EditOp::kSubtract}};
  Result<EditReceipt> r = ed.apply_batch(edits);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("edit 1"), std::string::npos) << r.status().message();
  r = ed.apply(Brush::box({0, 0, 0}, glm::dvec3(1e6)), EditOp::kUnion);  // far too many cells
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kTooLarge) << r.status().message();
  EXPECT_EQ(ed.version(), 0u);
  EXPECT_TRUE(identical(ed.world(), original));
  EXPECT_TRUE(ed.take_dirty().empty());
}

TEST(Editor, DirtyBoxesRemeshExactlyWhatAFreshBuildWould) {
  WorldEditor ed(ground(8.0));
  ChunkedMesh incremental;
  ASSERT_TRUE(incremental.build(ed.world()).ok());
  std::vector<WorldEditor::Edit> edits = {
      {Brush::sphere({0.0, 0.0, 1.0}, 0.7), EditOp::kSubtract},           // inside a chunk ...
      {Brush::sphere({-1.7, -1.7, 1.0}, 0.5, 2), EditOp::kPaint},         // ... and near chunk corners
      {Brush::box({1.5, 1.55, 1.2}, glm::dvec3(0.4), 3), EditOp::kUnion},
      {Brush::noisy_sphere({-1.6, 1.6, 0.9}, {.radius = 0.6}), EditOp::kSubtract},
  };
  // Then small random edits of every kind centred near chunk faces (x, y = -1.7 or 1.5).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.9, 0.9), unit(0.0, 1.0);
  for (int i = 0; i < 24; ++i) {
    glm::dvec3 c((rng() % 2 ? 1.5 : -1.7) + jitter(rng), (rng() % 2 ? 1.5 : -1.7) + jitter(rng), 1.0 + 0.5 * jitter(rng));
    EditOp op = std::array{EditOp::kUnion, EditOp::kSubtract, EditOp::kPaint}[rng() % 3];
    edits.push_back({Brush::sphere(c, 0.1 + 0.5 * unit(rng), uint16_t(rng() % 3)), op});
  }
  size_t chunks = size_t(ed.world().chunk_dims().x) * ed.world().chunk_dims().y * ed.world().chunk_dims().z;
  for (const auto& e : edits) {
    ASSERT_TRUE(ed.apply(e.brush, e.op).ok());
    Result<MeshUpdate> n = incremental.update(ed.world(), ed.take_dirty());
    ASSERT_TRUE(n.ok()) << n.status().message();
    EXPECT_LE(n->chunks_remeshed, chunks / 4);
    ChunkedMesh fresh;
    ASSERT_TRUE(fresh.build(ed.world()).ok());
    EXPECT_TRUE(test::same_chunk_meshes(incremental, fresh)) << edit_op_name(e.op);
  }
}

// The chunks whose mesh content differs between two sets of chunk meshes
// (present in one only, or with other vertices or triangles).
std::vector<glm::ivec3> differing_chunks(const std::vector<ChunkMesh>& before, const std::vector<ChunkMesh>& after) {
  auto same = [](const ChunkMesh& x, const ChunkMesh& y) {
    return x.own_vertices == y.own_vertices && x.vertex_cell == y.vertex_cell &&
           x.mesh.positions == y.mesh.positions && x.mesh.triangles == y.mesh.triangles &&
           x.mesh.triangle_material == y.mesh.triangle_material && x.mesh.vertex_material == y.mesh.vertex_material;
  };
  std::map<std::tuple<int, int, int>, std::pair<const ChunkMesh*, const ChunkMesh*>> all;
  for (const ChunkMesh& m : before) all[{m.chunk.z, m.chunk.y, m.chunk.x}].first = &m;
  for (const ChunkMesh& m : after) all[{m.chunk.z, m.chunk.y, m.chunk.x}].second = &m;
  std::vector<glm::ivec3> out;
  for (const auto& [key, pair] : all) {
    const auto [b, a] = pair;
    if (!b || !a || !same(*b, *a)) out.push_back(b ? b->chunk : a->chunk);
  }
  return out;
}

TEST(ChunkedMeshUpdate, ReportsExactlyTheChunkMeshesWhoseContentChanged) {
  WorldEditor ed(ground(8.0));
  ChunkedMesh meshes;
  ASSERT_TRUE(meshes.build(ed.world()).ok());
  const uint64_t built = meshes.version();
  EXPECT_GT(built, 0u);
  for (const ChunkMesh& m : meshes.chunks()) EXPECT_EQ(m.version, built);
  const std::vector<WorldEditor::Edit> edits = {
      {Brush::sphere({0.0, 0.0, 1.0}, 0.7), EditOp::kSubtract},
      {Brush::sphere({-1.7, -1.7, 1.0}, 0.5, 2), EditOp::kPaint},
      {Brush::box({1.5, 1.55, 1.2}, glm::dvec3(0.4), 3), EditOp::kUnion},
  };
  for (const auto& e : edits) {
    const std::vector<ChunkMesh> before = meshes.chunks();
    ASSERT_TRUE(ed.apply(e.brush, e.op).ok());
    const std::vector<DirtyChunk> dirty = ed.take_dirty();
    const std::vector<glm::ivec3> may_change = chunks_a_remesh_may_change(dirty, meshes.config(), 16);
    Result<MeshUpdate> u = meshes.update(ed.world(), dirty);
    ASSERT_TRUE(u.ok()) << u.status().message();
    std::vector<glm::ivec3> reported;
    for (const ChunkMeshChange& c : u->changes) {
      reported.push_back(c.chunk);
      EXPECT_FALSE(c.removed());  // these edits leave surface in every chunk they touch
      EXPECT_EQ(c.version, meshes.version());
      EXPECT_TRUE(std::binary_search(may_change.begin(), may_change.end(), c.chunk, chunk_order_less));
    }
    EXPECT_EQ(reported, differing_chunks(before, meshes.chunks())) << edit_op_name(e.op);
    EXPECT_FALSE(reported.empty());
    for (const ChunkMesh& m : meshes.chunks()) {
      const bool was_reported = std::find(reported.begin(), reported.end(), m.chunk) != reported.end();
      if (!was_reported) {
        EXPECT_LT(m.version, meshes.version());
      }
    }
  }
}

TEST(ChunkedMeshUpdate, ChunksLeftWithoutSurfaceAreReportedRemoved) {
  WorldEditor ed(ground(8.0));
  ChunkedMesh meshes;
  ASSERT_TRUE(meshes.build(ed.world()).ok());
  const size_t chunks_before = meshes.chunks().size();
  // Dig the whole slab out: every chunk mesh goes.
  ASSERT_TRUE(ed.apply(Brush::box({0.0, 0.0, 0.0}, {9.0, 9.0, 2.5}), EditOp::kSubtract).ok());
  Result<MeshUpdate> u = meshes.update(ed.world(), ed.take_dirty());
  ASSERT_TRUE(u.ok()) << u.status().message();
  EXPECT_TRUE(meshes.chunks().empty());
  size_t removed = 0;
  for (const ChunkMeshChange& c : u->changes) removed += c.removed();
  EXPECT_EQ(removed, chunks_before);
  EXPECT_EQ(removed, u->changes.size());
}

TEST(ChunkedMeshUpdate, AnEditThatChangesNoSurfaceReportsNothing) {
  WorldEditor ed(ground(8.0));
  ChunkedMesh meshes;
  ASSERT_TRUE(meshes.build(ed.world()).ok());
  const uint64_t version = meshes.version();
  // Adding solid inside the solid slab changes the rays' nothing.
  ASSERT_TRUE(ed.apply(Brush::sphere({0.0, 0.0, 0.0}, 0.3, 1), EditOp::kUnion).ok());
  Result<MeshUpdate> u = meshes.update(ed.world(), ed.take_dirty());
  ASSERT_TRUE(u.ok());
  EXPECT_TRUE(u->changes.empty());
  EXPECT_EQ(meshes.version(), version);
}

// Random brushes of every shape, size and op, many placed on lattice nodes or
// with radii of whole cells (surfaces through nodes), validated after each
// edit, with the editor's promises checked every time: untouched chunks are
// shared, volumes move the right way, paint never moves a point.
TEST(EditorProperty, TenThousandRandomEditsStayValid) {
  Primitive slab;
  slab.shape = Primitive::Shape::kBox;
  slab.half_extents = glm::dvec3(2.0, 2.0, 1.0);
  GridConfig grid{.cell_size = 0.2, .chunk_size = 8, .use_origin = true, .origin = glm::dvec3(-2.6, -2.6, -1.8)};
  WorldEditor ed(build_from_primitive(slab, grid).value());
  std::mt19937 rng(2026);
  std::uniform_real_distribution<double> pos(-3.0, 3.0), unit(0.0, 1.0);
  auto snapped = [&](double v) { return unit(rng) < 0.3 ? std::round(v / 0.2) * 0.2 + -2.6 - std::floor(-2.6 / 0.2) * 0.2 : v; };
  auto centre = [&] { return glm::dvec3(snapped(pos(rng)), snapped(pos(rng)), snapped(pos(rng) * 0.6)); };
  auto radius = [&] {
    double r = unit(rng) < 0.15 ? 0.01 + 0.1 * unit(rng) : 0.1 + 1.2 * unit(rng);  // some smaller than a cell
    return unit(rng) < 0.3 ? std::max(0.2, std::round(r / 0.2) * 0.2) : r;
  };
  const int kEdits = 10000;
  std::vector<EditReceipt> receipts;
  int changing_edits = 0, nonempty_worlds = 0;
  for (int i = 0; i < kEdits; ++i) {
    Brush b;
    switch (rng() % 5) {
      case 0: b = Brush::sphere(centre(), radius(), uint16_t(rng() % 4)); break;
      case 1: b = Brush::box(centre(), glm::dvec3(radius(), radius(), radius()), uint16_t(rng() % 4)); break;
      case 2: b = Brush::capsule(centre(), centre(), radius(), uint16_t(rng() % 4)); break;
      case 3: b = Brush::cylinder(centre(), centre(), radius(), uint16_t(rng() % 4)); break;
      default: b = Brush::noisy_sphere(centre(), {.radius = radius(), .amplitude = 0.4 * unit(rng), .seed = uint32_t(i % 16)}, 2);
    }
    if (std::holds_alternative<Primitive>(b.shape) && rng() % 4 == 0) {  // tilt some
      b.transform() = glm::rotate(b.transform(), 6.28 * unit(rng), glm::dvec3(unit(rng), unit(rng), 0.5));
    }
    EditOp op = std::array{EditOp::kSubtract, EditOp::kSubtract, EditOp::kUnion, EditOp::kUnion, EditOp::kPaint,
                           EditOp::kIntersect}[rng() % 6];
    if (op == EditOp::kIntersect && rng() % 8 != 0) op = EditOp::kUnion;  // intersect empties most of the world
    World before = ed.world();
    Result<EditReceipt> r = ed.apply(b, op);
    ASSERT_TRUE(r.ok()) << i << ": " << r.status().message();
    const World& after = ed.world();
    ValidationReport v = validate(after);
    ASSERT_TRUE(v.ok) << "edit " << i << " (" << edit_op_name(op) << "): " << v.summary();
    const auto& changed = r.value().changed_chunks;
    after.for_each_chunk([&](const glm::ivec3& c, ChunkKind kind, const Chunk* data) {
      if (std::find(changed.begin(), changed.end(), c) != changed.end()) return;
      ASSERT_EQ(kind, before.chunk_kind(c)) << i;
      ASSERT_EQ(data, before.chunk(c)) << i;
    });
    if (i % 16 == 0) {
      double vb = before.volume(0), va = after.volume(0);
      if (op == EditOp::kUnion) {
        ASSERT_GE(va, vb - 1e-9) << i;
      }
      if (op == EditOp::kSubtract || op == EditOp::kIntersect) {
        ASSERT_LE(va, vb + 1e-9) << i;
      }
      if (op == EditOp::kPaint) {
        ASSERT_EQ(va, vb) << i;
      }
    }
    changing_edits += !changed.empty();
    nonempty_worlds += after.stats().points > 0;
    receipts.push_back(std::move(r).value());
    if (ed.world().stats().points == 0 && rng() % 2) {  // refill an emptied world now and then
      ASSERT_TRUE(ed.apply(Brush::box({0, 0, 0}, {2.0, 2.0, 1.0}), EditOp::kUnion).ok());
      receipts.clear();
    }
  }
  // The test exercises what it claims: most edits change something, on a world with surface.
  EXPECT_GT(changing_edits, kEdits / 2);
  EXPECT_GT(nonempty_worlds, kEdits * 9 / 10);
  // The last edits undo in reverse order back to a valid world.
  for (int k = 0; k < 50 && !receipts.empty(); ++k) {
    ASSERT_TRUE(ed.undo(receipts.back()).ok());
    receipts.pop_back();
  }
  EXPECT_TRUE(is_valid(ed.world()));
}

TEST(OpNames, OneNamePerOperationAndThe02SpellingsStillParse) {
  EXPECT_STREQ(boolean_op_name(BooleanOp::kSubtract), "subtract");
  EXPECT_STREQ(boolean_op_name(BooleanOp::kIntersect), "intersect");
  EXPECT_STREQ(edit_op_name(EditOp::kUnion), "union");
  EXPECT_STREQ(edit_op_name(EditOp::kSubtract), "subtract");
  for (BooleanOp op : {BooleanOp::kUnion, BooleanOp::kSubtract, BooleanOp::kIntersect}) {
    EXPECT_EQ(boolean_op_from_name(boolean_op_name(op)), op);
  }
  for (EditOp op : {EditOp::kUnion, EditOp::kSubtract, EditOp::kIntersect, EditOp::kPaint}) {
    EXPECT_EQ(edit_op_from_name(edit_op_name(op)), op);
  }
  EXPECT_EQ(boolean_op_from_name("difference"), BooleanOp::kSubtract);
  EXPECT_EQ(boolean_op_from_name("intersection"), BooleanOp::kIntersect);
  EXPECT_EQ(edit_op_from_name("add"), EditOp::kUnion);
  EXPECT_EQ(boolean_op_from_name("xor"), std::nullopt);
  EXPECT_EQ(edit_op_from_name("dig"), std::nullopt);
}

TEST(WorldEditor, CreateRefusesABadConfigByName) {
  Result<WorldEditor> bad = WorldEditor::create(ground(), {.sliver = 0.9});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("sliver"), std::string::npos) << bad.status().message();
  Result<WorldEditor> good = WorldEditor::create(ground());
  ASSERT_TRUE(good.ok());
  EXPECT_TRUE(good->apply(Brush::sphere({0.0, 0.0, 1.0}, 0.5), EditOp::kSubtract).ok());
}

TEST(ChunkedMesh, CreateEqualsBuildAndRefusesABadConfig) {
  const World w = ground();
  Result<ChunkedMesh> made = ChunkedMesh::create(w);
  ASSERT_TRUE(made.ok());
  ChunkedMesh built;
  ASSERT_TRUE(built.build(w).ok());
  EXPECT_TRUE(test::same_chunk_meshes(*made, built));
  Result<ChunkedMesh> bad = ChunkedMesh::create(w, {.iterations = -1});
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace ldc
