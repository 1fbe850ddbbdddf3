// .ldc files: round trips, and corrupt, truncated or hostile files refused cleanly.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <random>

#include "ldc/build.h"
#include "ldc/detail/crc32.h"
#include "ldc/io.h"
#include "test_util.h"

namespace ldc {
namespace {

World bunny_world() {
  static World w = build_from_mesh(test::load_test_mesh("stanford-bunny.obj"), {.cells = 48, .chunk_size = 16}).value();
  return w;
}

std::string as_string(const std::vector<uint8_t>& v) { return std::string(v.begin(), v.end()); }

bool same_world(const World& a, const World& b) {
  if (a.chunk_dims() != b.chunk_dims() || a.chunk_origin() != b.chunk_origin() ||
      a.lattice().origin != b.lattice().origin || a.lattice().cell_size != b.lattice().cell_size ||
      a.metadata() != b.metadata()) {
    return false;
  }
  bool same = true;
  const int c = a.chunk_size();
  a.for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk* d) {
    if (b.chunk_kind(ch) != kind || !d) return void(same = same && b.chunk_kind(ch) == kind);
    for (int ax = 0; ax < 3; ++ax) {
      for (int r = 0; r < c * c; ++r) {
        auto pa = d->axis[ax].points(r), pb = b.chunk(ch)->axis[ax].points(r);
        same = same && d->axis[ax].starts_inside(r) == b.chunk(ch)->axis[ax].starts_inside(r) &&
               pa.size() == pb.size() && (pa.empty() || std::memcmp(pa.data(), pb.data(), pa.size_bytes()) == 0);
      }
    }
  });
  return same;
}

TEST(LdcFile, RoundTripKeepsEveryBit) {
  World w = bunny_world();
  std::vector<uint8_t> bytes = serialize_world(w).value();
  Result<World> back = deserialize_world(as_string(bytes), "mem");
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_TRUE(same_world(w, back.value()));
  EXPECT_EQ(back.value().metadata_value("source"), "mesh");
  // Same world, same bytes.
  EXPECT_EQ(serialize_world(back.value()).value(), bytes);
}

TEST(LdcFile, SaveAndLoadThroughTheFileSystem) {
  World w = bunny_world();
  std::string path = ::testing::TempDir() + "/bunny.ldc";
  ASSERT_TRUE(save_world(w, path).ok());
  Result<World> back = load_world(path);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_TRUE(same_world(w, back.value()));
  std::remove(path.c_str());
}

TEST(LdcFile, MissingFileNamesThePath) {
  Result<World> w = load_world("/no/such/dir/world.ldc");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().code(), ErrorCode::kIoError);
  EXPECT_NE(w.status().message().find("/no/such/dir/world.ldc"), std::string::npos);
}

TEST(LdcFile, SavingToAnUnwritablePathFailsAndLeavesNothing) {
  Status s = save_world(bunny_world(), "/no/such/dir/world.ldc");
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
}

TEST(LdcFile, EveryTruncationIsRefused) {
  std::string bytes = as_string(serialize_world(bunny_world()).value());
  for (size_t n = 0; n < bytes.size(); n += 1 + n / 16) {
    Result<World> w = deserialize_world(std::string_view(bytes).substr(0, n), "cut");
    ASSERT_FALSE(w.ok()) << "accepted a file cut at " << n;
    EXPECT_FALSE(w.status().message().empty());
  }
}

TEST(LdcFile, FlippedBitsAreCaughtByChecksums) {
  std::string bytes = as_string(serialize_world(bunny_world()).value());
  std::mt19937 rng(11);
  for (int i = 0; i < 300; ++i) {
    std::string bad = bytes;
    size_t at = rng() % bad.size();
    bad[at] = char(bad[at] ^ (1 << (rng() % 8)));
    Result<World> w = deserialize_world(bad, "flip");
    EXPECT_FALSE(w.ok()) << "bit flip at byte " << at << " not detected";
  }
}

TEST(LdcFile, WrongMagicAndVersionAreNamed) {
  std::string bytes = as_string(serialize_world(bunny_world()).value());
  std::string bad = bytes;
  bad[0] = 'X';
  EXPECT_NE(deserialize_world(bad, "m").status().message().find("magic"), std::string::npos);
  bad = bytes;
  bad[4] = 9;  // version 9
  Result<World> w = deserialize_world(bad, "v");
  EXPECT_EQ(w.status().code(), ErrorCode::kUnsupported);
  EXPECT_NE(w.status().message().find("version 9"), std::string::npos);
}

// Rewrites a header field and fixes the header checksum, as a hostile writer would.
std::string with_header_field(std::string bytes, size_t offset, const void* value, size_t n) {
  std::memcpy(bytes.data() + offset, value, n);
  uint32_t crc = detail::crc32(reinterpret_cast<const uint8_t*>(bytes.data()), 124);
  std::memcpy(bytes.data() + 124, &crc, 4);
  return bytes;
}

TEST(LdcFile, HostileHeadersFailWithoutHugeAllocations) {
  std::string bytes = as_string(serialize_world(bunny_world()).value());
  int32_t dims[3] = {1 << 20, 1 << 20, 1 << 20};
  Result<World> w = deserialize_world(with_header_field(bytes, 60, dims, 12), "dims");
  ASSERT_FALSE(w.ok());
  int32_t negative[3] = {-5, 2, 2};
  EXPECT_FALSE(deserialize_world(with_header_field(bytes, 60, negative, 12), "neg").ok());
  uint64_t huge = uint64_t(1) << 60;
  EXPECT_FALSE(deserialize_world(with_header_field(bytes, 72, &huge, 8), "meta").ok());
  EXPECT_FALSE(deserialize_world(with_header_field(bytes, 88, &huge, 8), "payload").ok());
  uint32_t chunk = 24;
  EXPECT_FALSE(deserialize_world(with_header_field(bytes, 12, &chunk, 4), "chunk").ok());
  double nan_h = std::nan("");
  EXPECT_FALSE(deserialize_world(with_header_field(bytes, 40, &nan_h, 8), "h").ok());
}

TEST(LdcFile, MutationFuzzNeverCrashesAndAlwaysExplains) {
  std::string bytes = as_string(serialize_world(bunny_world()).value());
  std::mt19937 rng(5);
  for (int i = 0; i < 2000; ++i) {
    std::string bad = bytes;
    int edits = 1 + int(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      size_t at = rng() % bad.size();
      switch (rng() % 4) {
        case 0: bad[at] = char(rng()); break;
        case 1: bad.erase(at, 1 + rng() % 64); break;
        case 2: bad.insert(at, std::string(1 + rng() % 8, char(rng()))); break;
        case 3: bad.resize(at); break;
      }
      if (bad.empty()) break;
    }
    Result<World> w = deserialize_world(bad, "fuzz");
    if (w.ok()) EXPECT_TRUE(validate(w.value()).ok);
    else EXPECT_FALSE(w.status().message().empty());
  }
}

TEST(LdcFile, UniformChunksCostNoPayload) {
  World w = World::create({.chunk_dims = {4, 4, 4}}).value();
  std::vector<uint8_t> bytes = serialize_world(w).value();
  EXPECT_LT(bytes.size(), 128u + 64u * 24u + 64u);
  Result<World> back = deserialize_world(as_string(bytes), "empty");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back.value().stats().chunks_empty, 64u);
}

}  // namespace
}  // namespace ldc
