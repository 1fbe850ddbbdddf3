// Issue 24, finding 3: empty and solid chunk slots cost O(1) to load and validate
// (a 6 MB all-empty file of 512 x 512 chunks of 64^3 took 40 s in `ldc info`),
// and LoadLimits::validate_world = false (`ldc info --no-validate`) skips the
// world-wide pass. ctest runs the first test again under a TIMEOUT (tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

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

}  // namespace
}  // namespace ldc
