// Issue 24, finding 3: empty and solid chunk slots cost O(1) to load and validate
// (a 6 MB all-empty file of 512 x 512 chunks of 64^3 took 40 s in `ldc info`),
// and LoadLimits::validate_world = false (`ldc info --no-validate`) skips the
// world-wide pass. ctest runs the first test again under a TIMEOUT (tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "csg/csg.h"
#include "ldc/internal/validate_work.h"
#include "ldc/io.h"
#include "ldc/world.h"

namespace ldc {
namespace {

std::string as_string(const std::vector<uint8_t>& v) { return std::string(v.begin(), v.end()); }

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

TEST(HostileLoad, EmptyChunkSlotsLoadAndValidateFast) {
  // 65,536 empty slots of 64^3 cells: ray by ray that is 8e8 continuity checks.
  World w = World::create({.chunk_size = 64, .chunk_dims = {256, 256, 1}}).value();
  const std::vector<uint8_t> bytes = serialize_world(w).value();
  const auto t0 = std::chrono::steady_clock::now();
  Result<World> back = deserialize_world(as_string(bytes), "all-empty");
  ASSERT_TRUE(back.ok()) << back.status().message();
  const double load = seconds_since(t0);
  const auto t1 = std::chrono::steady_clock::now();
  const ValidationReport v = validate(back.value());
  const double check = seconds_since(t1);
  EXPECT_TRUE(v.ok) << v.summary();
  EXPECT_EQ(back.value().stats().chunks_empty, 65536u);
  EXPECT_EQ(serialize_world(back.value()).value(), bytes);  // the format is unchanged
  std::printf("load %.3f s, validate %.3f s\n", load, check);
}

// A solid chunk at the box face: one comparison per uniform face, but every
// ray still counts as an error, as when the rays were checked one by one.
World solid_at_the_face() {
  World w = World::create({.chunk_size = 8, .chunk_dims = {2, 1, 1}}).value();
  w.set_uniform_chunk({0, 0, 0}, true);
  return w;
}

TEST(HostileLoad, UniformFaceErrorsCountEveryRay) {
  const ValidationReport v = validate(solid_at_the_face());
  EXPECT_FALSE(v.ok);
  // Chunk (0,0,0): starts inside at three box faces, breaks toward three empty neighbours.
  EXPECT_EQ(v.errors, 6u * 64u);
  ASSERT_FALSE(v.messages.empty());
  EXPECT_NE(v.messages.front().find("chunk (0,0,0)"), std::string::npos) << v.messages.front();
}

TEST(HostileLoad, NoValidateSkipsTheWorldPass) {
  const std::string bytes = as_string(serialize_world(solid_at_the_face()).value());
  Result<World> checked = deserialize_world(bytes, "solid-face");
  ASSERT_FALSE(checked.ok());
  EXPECT_EQ(checked.status().code(), ErrorCode::kCorruptData);
  EXPECT_NE(checked.status().message().find("solid-face: chunk (0,0,0)"), std::string::npos)
      << checked.status().message();
  LoadLimits limits;
  limits.validate_world = false;
  Result<World> unchecked = deserialize_world(bytes, "solid-face", limits);
  ASSERT_TRUE(unchecked.ok()) << unchecked.status().message();
  EXPECT_EQ(unchecked.value().stats().chunks_solid, 1u);
}


// --- Issue 24 item 3: the work a load does, counted rather than timed ---------

TEST(HostileLoad, UniformSlotsAreValidatedWithoutVisitingTheirRays) {
  // 65,536 empty slots of 64^3: ray by ray that was 8e8 continuity checks.
  World w = World::create({.chunk_size = 64, .chunk_dims = {256, 256, 1}}).value();
  detail::ValidateWork work;
  const ValidationReport v = detail::validate_with_progress(w, {}, nullptr, &work);
  EXPECT_TRUE(v.ok) << v.summary();
  EXPECT_EQ(work.slots, 65536u);
  EXPECT_EQ(work.rays_visited, 0u);
  EXPECT_EQ(work.uniform_faces, 3u * 65536u);  // each slot's three faces, once each
}

// A chunk of 8^3 whose only points are an enter and an exit on one X ray,
// inside one cell: no node is inside, so the three axes agree.
std::shared_ptr<Chunk> one_sliver_chunk() {
  const int c = 8;
  const uint32_t q = depth_steps_per_cell(c);
  RayFamilyWriter x(c);
  for (int r = 0; r < c * c; ++r) {
    x.begin_ray(false);
    if (r != 0) continue;
    PackedPoint enter, exit;
    enter.depth = uint16_t(3 * q + q / 4);
    enter.normal = encode_normal({-1.0, 0.0, 0.0});
    exit.depth = uint16_t(3 * q + q / 2);
    exit.normal = encode_normal({1.0, 0.0, 0.0}) | kPointExitBit;
    x.add_point(enter);
    x.add_point(exit);
  }
  auto chunk = std::make_shared<Chunk>();
  chunk->axis[0] = x.finish();
  return chunk;
}

TEST(HostileLoad, AMixedChunkAmongEmptyOnesVisitsOnlyItsOwnRays) {
  World w = World::create({.chunk_size = 8, .chunk_dims = {3, 3, 3}}).value();
  w.set_chunk({1, 1, 1}, one_sliver_chunk());
  ASSERT_EQ(w.stats().chunks_mixed, 1u);
  detail::ValidateWork work;
  const ValidationReport v = detail::validate_with_progress(w, {}, nullptr, &work);
  EXPECT_TRUE(v.ok) << v.summary();
  // Its one stored family (64 rays), its three faces toward the next chunks and
  // the three faces of the chunks before it: 7 x 64 rays. Every other face is
  // between two uniform slots and compared once.
  EXPECT_EQ(work.rays_visited, 7u * 64u);
  EXPECT_EQ(work.uniform_faces, 27u * 3u - 6u);
  // The load gives the same world back.
  Result<World> back = deserialize_world(as_string(serialize_world(w).value()), "sliver");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back.value().stats().points, 2u);
}

// --- Issue 24 finding 10: honest progress ------------------------------------

using Reports = std::vector<std::pair<std::string, double>>;

void record_progress(Context& ctx, Reports& out) {
  ctx.set_progress([&out](std::string_view stage, double f) { out.emplace_back(std::string(stage), f); });
}

TEST(HostileLoad, LoadReportsItsValidationAsAStageOfItsOwn) {
  World w = World::create({.chunk_size = 8, .chunk_dims = {40, 40, 2}}).value();
  w.set_chunk({1, 1, 1}, one_sliver_chunk());
  const std::string bytes = as_string(serialize_world(w).value());
  Context ctx;
  Reports reports;
  record_progress(ctx, reports);
  ASSERT_TRUE(deserialize_world(bytes, "progress", {}, &ctx).ok());
  // 'load' runs to 100%, then 'validate' from 0% to 100%, and nothing after
  // (it sat at 'load 90%' through the validation).
  size_t load_done = reports.size(), validate_start = reports.size();
  for (size_t i = 0; i < reports.size(); ++i) {
    if (reports[i] == Reports::value_type{"load", 1.0} && load_done == reports.size()) load_done = i;
    if (reports[i] == Reports::value_type{"validate", 0.0} && validate_start == reports.size()) validate_start = i;
  }
  ASSERT_LT(load_done, reports.size()) << "'load' never reached 100%";
  ASSERT_LT(validate_start, reports.size()) << "no 'validate' stage";
  EXPECT_LT(load_done, validate_start);
  EXPECT_EQ(reports.back(), (Reports::value_type{"validate", 1.0}));
  for (size_t i = validate_start; i < reports.size(); ++i) EXPECT_EQ(reports[i].first, "validate");
}

TEST(HostileLoad, NoValidateReportsNoValidationStage) {
  const std::string bytes =
      as_string(serialize_world(World::create({.chunk_size = 8, .chunk_dims = {4, 4, 4}}).value()).value());
  Context ctx;
  Reports reports;
  record_progress(ctx, reports);
  LoadLimits limits;
  limits.validate_world = false;
  ASSERT_TRUE(deserialize_world(bytes, "progress", limits, &ctx).ok());
  for (const auto& [stage, f] : reports) EXPECT_NE(stage, "validate");
  ASSERT_FALSE(reports.empty());
  EXPECT_EQ(reports.back(), (Reports::value_type{"load", 1.0}));
}

TEST(HostileLoad, SaveReportsCompleteOnlyOnceTheFileIsWritten) {
  World w = World::create({.chunk_size = 8, .chunk_dims = {4, 4, 4}}).value();
  w.set_chunk({1, 1, 1}, one_sliver_chunk());
  Context ctx;
  Reports reports;
  record_progress(ctx, reports);
  ASSERT_FALSE(save_world(w, "/nonexistent-folder-of-ldc-tests/w.ldc", {}, &ctx).ok());
  ASSERT_FALSE(reports.empty());
  for (const auto& [stage, f] : reports) EXPECT_LT(f, 1.0) << stage << " reported 100% before a failed write";
  reports.clear();
  const std::string path = ::testing::TempDir() + "hostile_save_progress.ldc";
  ASSERT_TRUE(save_world(w, path, {}, &ctx).ok());
  ASSERT_FALSE(reports.empty());
  EXPECT_EQ(reports.back(), (Reports::value_type{"save", 1.0}));
  std::remove(path.c_str());
}

TEST(HostileLoad, AnEditReportsRasterizingBeforeAnythingElse) {
  World w = World::create({.chunk_size = 8, .chunk_dims = {2, 2, 2}}).value();
  WorldEditor editor = WorldEditor::create(std::move(w)).value();
  Context ctx;
  Reports reports;
  record_progress(ctx, reports);
  // A sphere far past the world's box: the world grows to hold it.
  ASSERT_TRUE(editor.apply(Brush::sphere({6.0, 6.0, 6.0}, 1.5), EditOp::kUnion, &ctx).ok());
  ASSERT_FALSE(reports.empty());
  // The first report comes before the brush is rasterized (nothing was shown
  // during a 185 s rasterization).
  EXPECT_EQ(reports.front(), (Reports::value_type{"rasterize", 0.0}));
  EXPECT_NE(std::find(reports.begin(), reports.end(), Reports::value_type{"rasterize", 1.0}), reports.end());
  EXPECT_EQ(reports.back(), (Reports::value_type{"edit", 1.0}));
}

// Issue 24 finding 10: one large brush reported nothing while it was
// rasterized (a 300 m sphere: minutes at 0%). Its build's progress is now the
// edit's "rasterize" stage, many reports between 0 and 1, before "edit".
World small_ground() {
  Primitive slab{.shape = Primitive::Shape::kBox, .half_extents = {4.0, 4.0, 1.0}};
  return build_from_primitive(slab, {.cell_size = 0.25, .chunk_size = 8}).value();
}

TEST(HostileLoad, OneLargeBrushReportsItsRasterizationAsItGoes) {
  WorldEditor editor(small_ground());
  Context ctx;
  Reports reports;
  record_progress(ctx, reports);
  ASSERT_TRUE(editor.apply(Brush::sphere({0, 0, 0}, 12.0), EditOp::kUnion, &ctx).ok());
  size_t within = 0, first_edit = reports.size(), last_rasterize = 0;
  for (size_t i = 0; i < reports.size(); ++i) {
    if (reports[i].first == "rasterize") {
      last_rasterize = i;
      within += reports[i].second > 0.0 && reports[i].second < 1.0;
    }
    if (reports[i].first == "edit" && first_edit == reports.size()) first_edit = i;
  }
  EXPECT_GE(within, 10u) << "the brush's rasterization reported no fraction between 0 and 1";
  EXPECT_LT(last_rasterize, first_edit);
  EXPECT_TRUE(validate(editor.world()).ok);
}

TEST(HostileLoad, CancellingDuringOneBrushLeavesTheWorldAsItWas) {
  WorldEditor editor(small_ground());
  const size_t points = editor.world().stats().points;
  Context ctx;
  ctx.set_progress([&ctx](std::string_view stage, double f) {
    if (stage == "rasterize" && f > 0.1 && f < 1.0) ctx.cancel();  // within the one brush
  });
  Result<EditReceipt> r = editor.apply(Brush::sphere({0, 0, 0}, 12.0), EditOp::kUnion, &ctx);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kCancelled) << r.status().message();
  EXPECT_EQ(editor.world().stats().points, points);
  EXPECT_TRUE(editor.take_dirty().empty());
}

}  // namespace
}  // namespace ldc
