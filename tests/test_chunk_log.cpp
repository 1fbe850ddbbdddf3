// Chunk logs (.ldcs): round trips, crash safety under SIGKILL, hostile files,
// write failures and compaction.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "ldc/build.h"
#include "ldc/chunk_log.h"
#include "ldc/detail/crc32.h"
#include "ldc/io.h"

namespace ldc {
namespace {

namespace fs = std::filesystem;

constexpr int kChunkSize = 16;

// Real mixed chunks (a sphere's and a box's) plus the two uniform kinds.
const std::vector<StoredChunk>& chunk_pool() {
  static const std::vector<StoredChunk> pool = [] {
    std::vector<StoredChunk> out{{ChunkKind::kEmpty, nullptr}, {ChunkKind::kSolid, nullptr}};
    Primitive sphere;
    sphere.radius = 1.0;
    Primitive box;
    box.shape = Primitive::Shape::kBox;
    box.half_extents = {0.7, 0.9, 0.5};
    for (const Primitive& p : {sphere, box}) {
      const World w = build_from_primitive(p, {.cells = 40, .chunk_size = kChunkSize}).value();
      w.for_each_chunk([&](const glm::ivec3& c, ChunkKind kind, const Chunk*) {
        if (kind == ChunkKind::kMixed && out.size() < 8) out.push_back({kind, w.chunk_shared(c)});
      });
    }
    return out;
  }();
  return pool;
}

SourceLayout test_layout() {
  SourceLayout l;
  l.lattice.cell_size = 0.05;
  l.chunk_size = kChunkSize;
  l.box.chunk_origin = {-4, -4, -2};
  l.box.chunk_dims = {8, 8, 4};
  return l;
}

// The chunks edits touch.
const std::vector<glm::ivec3>& coords() {
  static const std::vector<glm::ivec3> c = {{0, 0, 0}, {1, 0, 0}, {-4, -4, -2}, {3, 3, 1},
                                            {0, 1, 0}, {2, -1, 1}, {-1, 2, -1}, {1, 1, 1}};
  return c;
}

// Expected log content: coordinate index -> pool index.
using Expected = std::map<int, int>;

// A fresh folder per test and process (ctest runs tests in parallel).
std::string temp_folder() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path p = fs::path(::testing::TempDir()) /
                     ("chunk_log_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

bool same_family(const RayFamily& a, const RayFamily& b, int c) {
  if (a.is_uniform() != b.is_uniform() || a.uniform_inside() != b.uniform_inside()) return false;
  if (a.start_bits() != b.start_bits()) {
    return false;
  }
  for (int r = 0; r < c * c; ++r) {
    if (a.point_count(r) != b.point_count(r)) return false;
  }
  auto pa = a.all_points(), pb = b.all_points();
  if (pa.size() != pb.size()) return false;
  for (size_t i = 0; i < pa.size(); ++i) {
    if (pa[i].depth != pb[i].depth || pa[i].material != pb[i].material || pa[i].normal != pb[i].normal) return false;
  }
  return true;
}

::testing::AssertionResult same_stored(const StoredChunk& got, const StoredChunk& want) {
  if (got.kind != want.kind) return ::testing::AssertionFailure() << "kind " << chunk_kind_name(got.kind);
  if (!want.data) {
    if (got.data) return ::testing::AssertionFailure() << "uniform chunk with data";
    return ::testing::AssertionSuccess();
  }
  if (!got.data) return ::testing::AssertionFailure() << "mixed chunk without data";
  for (int a = 0; a < 3; ++a) {
    if (!same_family(got.data->axis[a], want.data->axis[a], kChunkSize)) {
      return ::testing::AssertionFailure() << "axis " << a << " differs";
    }
  }
  if (Status s = validate_chunk(*got.data, kChunkSize, true); !s.ok()) {
    return ::testing::AssertionFailure() << s.to_string();
  }
  return ::testing::AssertionSuccess();
}

// The log holds exactly `expected` (and nothing for the other coordinates).
::testing::AssertionResult holds(const ChunkLog& log, const Expected& expected) {
  for (int i = 0; i < int(coords().size()); ++i) {
    Result<std::optional<StoredChunk>> got = log.find(coords()[size_t(i)]);
    if (!got.ok()) return ::testing::AssertionFailure() << got.status().to_string();
    auto it = expected.find(i);
    if (it == expected.end()) {
      if (got->has_value()) return ::testing::AssertionFailure() << "coordinate " << i << " should be absent";
      continue;
    }
    if (!got->has_value()) return ::testing::AssertionFailure() << "coordinate " << i << " is missing";
    if (auto r = same_stored(**got, chunk_pool()[size_t(it->second)]); !r) {
      return ::testing::AssertionFailure() << "coordinate " << i << ": " << r.message();
    }
  }
  return ::testing::AssertionSuccess();
}

using Edit = std::vector<std::pair<int, int>>;  // (coordinate index, pool index)

Status commit_edit(ChunkLog& log, const Edit& edit) {
  std::vector<std::pair<glm::ivec3, StoredChunk>> chunks;
  for (auto [c, p] : edit) chunks.emplace_back(coords()[size_t(c)], chunk_pool()[size_t(p)]);
  return log.commit(chunks);
}

void apply_edit(Expected& e, const Edit& edit) {
  for (auto [c, p] : edit) e[c] = p;
}

// A small random dig: 1 to 3 chunks. The kill test's child and parent draw
// the same edits from the same seed.
Edit random_edit(std::mt19937& rng) {
  Edit edit;
  const int n = 1 + int(rng() % 3);
  for (int i = 0; i < n; ++i) {
    edit.emplace_back(int(rng() % coords().size()), int(rng() % chunk_pool().size()));
  }
  return edit;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}
uint32_t get_u32(const std::string& b, size_t at) {
  uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}
void set_u32(std::string& b, size_t at, uint32_t v) { std::memcpy(b.data() + at, &v, 4); }
void set_u64(std::string& b, size_t at, uint64_t v) { std::memcpy(b.data() + at, &v, 8); }
// Recomputes the CRC of the record at `at` after an edit of its payload.
void reseal_record(std::string& b, size_t at) {
  const uint32_t payload = get_u32(b, at + 4);
  set_u32(b, at + 8 + payload, detail::crc32(reinterpret_cast<const uint8_t*>(b.data() + at), 8 + payload));
}

ChunkLog create_log(const std::string& path) {
  return ChunkLog::create(path, test_layout(), "terrain seed=42 v3", {.overwrite = true}).value();
}

// Mixed chunks first, so that the first record of each commit has a frame.
const Edit kFirst = {{0, 2}, {1, 3}, {2, 0}, {3, 1}};
const Edit kSecond = {{0, 4}, {4, 5}};
const Edit kThird = {{5, 6}, {1, 2}};

Expected after_first() {
  Expected e;
  apply_edit(e, kFirst);
  return e;
}
Expected after_second() {
  Expected e = after_first();
  apply_edit(e, kSecond);
  return e;
}

// --- round trips --------------------------------------------------------------------

TEST(ChunkLog, ReopenedLogHoldsTheLastCommit) {
  const std::string path = temp_folder() + "/world.ldcs";
  Expected e;
  {
    ChunkLog log = create_log(path);
    EXPECT_TRUE(holds(log, e));
    ASSERT_TRUE(commit_edit(log, kFirst).ok());
    apply_edit(e, kFirst);
    EXPECT_TRUE(holds(log, e));
    ASSERT_TRUE(commit_edit(log, kSecond).ok());
    apply_edit(e, kSecond);
    EXPECT_TRUE(holds(log, e));
  }
  Result<ChunkLog> log = ChunkLog::open(path);
  ASSERT_TRUE(log.ok()) << log.status().to_string();
  EXPECT_TRUE(holds(*log, e));
  EXPECT_EQ(log->base_description(), "terrain seed=42 v3");
  EXPECT_EQ(log->layout().chunk_size, kChunkSize);
  EXPECT_EQ(log->layout().box.chunk_origin, test_layout().box.chunk_origin);
  EXPECT_EQ(log->layout().box.chunk_dims, test_layout().box.chunk_dims);
  EXPECT_EQ(log->layout().lattice.cell_size, 0.05);
  EXPECT_EQ(log->stats().commits, 2u);
  EXPECT_EQ(log->stats().live_chunks, 5u);
}

TEST(ChunkLog, LaterCommitsOverrideEarlierOnesAndAbsentChunksAreNullopt) {
  const std::string path = temp_folder() + "/world.ldcs";
  ChunkLog log = create_log(path);
  ASSERT_TRUE(commit_edit(log, {{0, 2}, {0, 1}}).ok());  // listed twice: the later entry wins
  ASSERT_TRUE(commit_edit(log, {{1, 3}}).ok());
  ASSERT_TRUE(commit_edit(log, {{1, 0}}).ok());
  EXPECT_TRUE(holds(log, {{0, 1}, {1, 0}}));
  EXPECT_FALSE(log.find({7, 7, 1}).value().has_value());
  EXPECT_TRUE(commit_edit(log, {}).ok());  // writes nothing
  EXPECT_EQ(log.stats().commits, 3u);
}

TEST(ChunkLog, CreateRefusesAnExistingFileAndBadArguments) {
  const std::string path = temp_folder() + "/world.ldcs";
  { ChunkLog log = create_log(path); }
  EXPECT_EQ(ChunkLog::create(path, test_layout(), "x").status().code(), ErrorCode::kIoError);
  SourceLayout bad = test_layout();
  bad.chunk_size = 12;
  EXPECT_EQ(ChunkLog::create(path + "2", bad, "x").status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(ChunkLog::create(path + "3", test_layout(), std::string(kMaxBaseDescriptionBytes + 1, 'a')).status().code(),
            ErrorCode::kInvalidArgument);
  ChunkLog log = ChunkLog::open(path).value();
  EXPECT_EQ(ChunkLog::open(path).status().code(), ErrorCode::kIoError);  // locked by `log`
  const std::vector<std::pair<glm::ivec3, StoredChunk>> outside = {{{9, 0, 0}, chunk_pool()[2]}};
  EXPECT_EQ(log.commit(outside).code(), ErrorCode::kInvalidArgument);
  const std::vector<std::pair<glm::ivec3, StoredChunk>> mismatch = {{{0, 0, 0}, {ChunkKind::kMixed, nullptr}}};
  EXPECT_EQ(log.commit(mismatch).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(log.stats().commits, 0u);
}

TEST(ChunkLog, ConcurrentFindsReadTheSameChunks) {
  const std::string path = temp_folder() + "/world.ldcs";
  ChunkLog log = create_log(path);
  ASSERT_TRUE(commit_edit(log, kFirst).ok());
  ASSERT_TRUE(commit_edit(log, kSecond).ok());
  std::vector<std::thread> threads;
  std::vector<int> failures(4, 0);
  for (size_t t = 0; t < failures.size(); ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 20; ++i) failures[t] += holds(log, after_second()) ? 0 : 1;
    });
  }
  for (std::thread& t : threads) t.join();
  for (int f : failures) EXPECT_EQ(f, 0);
}

// --- crash safety -----------------------------------------------------------------

// Reads what the child reported: the last commit it finished, and whether it
// had started the next one.
void read_reports(int fd, int& committed, bool& started_next) {
  std::string text;
  char buffer[4096];
  ssize_t n;
  while ((n = ::read(fd, buffer, sizeof buffer)) > 0) text.append(buffer, size_t(n));
  committed = 0;
  int started = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    const size_t end = text.find('\n', pos);
    if (end == std::string::npos) break;  // a line cut by the kill
    const int number = std::atoi(text.c_str() + pos + 2);
    (text[pos] == 'C' ? committed : started) = number;
    pos = end + 1;
  }
  started_next = started == committed + 1;
}

[[noreturn]] void commit_until_killed(const std::string& path, uint32_t seed, int pipe_fd) {
  std::mt19937 rng(seed);
  Result<ChunkLog> log = ChunkLog::open(path);
  if (!log.ok()) ::_exit(3);
  if (::write(pipe_fd, "R\n", 2) != 2) ::_exit(4);
  for (int n = 1;; ++n) {
    const Edit edit = random_edit(rng);
    char line[32];
    int len = std::snprintf(line, sizeof line, "A %d\n", n);
    if (::write(pipe_fd, line, size_t(len)) != len) ::_exit(4);
    if (!commit_edit(*log, edit).ok()) ::_exit(5);
    len = std::snprintf(line, sizeof line, "C %d\n", n);
    if (::write(pipe_fd, line, size_t(len)) != len) ::_exit(4);
  }
}

// Waits for the child's "R" (log open), so that the kill lands among commits.
bool wait_until_ready(int fd) {
  char c[2];
  return ::read(fd, c, 2) == 2 && c[0] == 'R';
}

// A SIGKILL loses no page cache, so what a kill test checks does not depend
// on the file system: where there is one, a tmpfs (whose fsync costs nothing)
// lets each child commit many times before its kill, at every point of a commit.
std::string kill_test_folder() {
  if (!fs::is_directory("/dev/shm") || ::access("/dev/shm", W_OK) != 0) return temp_folder();
  const fs::path p = fs::path("/dev/shm") / ("ldc_chunk_log_kill_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

TEST(ChunkLog, KilledWritersLoseNothingCommittedAndShowNothingHalfWritten) {
  const std::string folder = kill_test_folder();
  const std::string path = folder + "/world.ldcs";
  { ChunkLog log = create_log(path); }
  std::mt19937 rng(20261126);
  Expected state;
  int total_commits = 0;
  for (int round = 0; round < 200; ++round) {
    const uint32_t seed = rng();
    const int sleep_us = int(rng() % 15001);
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(fds[0]);
      commit_until_killed(path, seed, fds[1]);
    }
    ::close(fds[1]);
    ASSERT_TRUE(wait_until_ready(fds[0])) << "round " << round;
    std::this_thread::sleep_for(std::chrono::microseconds(sleep_us));
    ::kill(child, SIGKILL);
    int wstatus = 0;
    ASSERT_EQ(::waitpid(child, &wstatus, 0), child);
    ASSERT_TRUE(WIFSIGNALED(wstatus)) << "the child exited with " << WEXITSTATUS(wstatus);
    int committed = 0;
    bool started_next = false;
    read_reports(fds[0], committed, started_next);
    ::close(fds[0]);

    // The states after `committed` and, if it had started, `committed + 1` edits.
    std::mt19937 replay(seed);
    Expected done = state;
    for (int n = 0; n < committed; ++n) apply_edit(done, random_edit(replay));
    Expected next = done;
    apply_edit(next, random_edit(replay));

    Result<ChunkLog> log = ChunkLog::open(path);
    ASSERT_TRUE(log.ok()) << "round " << round << ": " << log.status().to_string();
    if (holds(*log, done)) {
      state = done;
    } else {
      ASSERT_TRUE(started_next) << "round " << round << ": " << holds(*log, done).message();
      ASSERT_TRUE(holds(*log, next)) << "round " << round;
      state = next;
      ++committed;
    }
    total_commits += committed;
    // A commit on the reopened file truncates any torn tail and reopens.
    if (round % 10 == 0) {
      const Edit edit = random_edit(rng);
      ASSERT_TRUE(commit_edit(*log, edit).ok());
      apply_edit(state, edit);
      { ChunkLog closed = std::move(*log); }  // releases the lock
      log = ChunkLog::open(path);
      ASSERT_TRUE(log.ok()) << log.status().to_string();
      ASSERT_TRUE(holds(*log, state)) << "round " << round;
    }
    // Keeps the file, which each open scans, small: children commit often.
    if (log->needs_compaction()) {
      ASSERT_TRUE(log->compact().ok());
    }
  }
  EXPECT_GT(total_commits, 200);  // the children did commit
  std::printf("[ figures  ] %d commits by 200 killed writers\n", total_commits);
  fs::remove_all(folder);
}

TEST(ChunkLog, CommitAfterATornTailTruncatesItAndReopens) {
  const std::string dir = temp_folder();
  const std::string path = dir + "/world.ldcs";
  std::string one, two;
  {
    ChunkLog log = create_log(path);
    ASSERT_TRUE(commit_edit(log, kFirst).ok());
    one = read_bytes(path);
    ASSERT_TRUE(commit_edit(log, kSecond).ok());
    two = read_bytes(path);
  }
  write_bytes(path, two.substr(0, two.size() - 3));  // commit 2 cut short
  Expected e;
  apply_edit(e, kFirst);
  {
    ChunkLog log = ChunkLog::open(path).value();
    EXPECT_TRUE(holds(log, e));
    EXPECT_EQ(log.stats().file_bytes, two.size() - 3);
    ASSERT_TRUE(commit_edit(log, kThird).ok());
    apply_edit(e, kThird);
    EXPECT_EQ(log.stats().file_bytes, fs::file_size(path));
    EXPECT_EQ(log.stats().dead_bytes + log.stats().live_bytes + log.stats().header_bytes + 12 + 16 + 8 * kThird.size(),
              log.stats().file_bytes);
  }
  ChunkLog log = ChunkLog::open(path).value();
  EXPECT_TRUE(holds(log, e));
  EXPECT_EQ(log.stats().commits, 2u);
  EXPECT_EQ(read_bytes(path).substr(0, one.size()), one);  // the torn bytes are gone
}

// --- hostile files --------------------------------------------------------------

// A log with commits kFirst and kSecond, and where its records lie.
struct TwoCommits {
  std::string bytes;
  size_t header = 0;         // end of the header: commit 1's first chunk record
  size_t first_end = 0;      // end of commit 1
  size_t second_start = 0;   // commit 2's first chunk record
};

TwoCommits two_commits(const std::string& path) {
  TwoCommits t;
  ChunkLog log = create_log(path);
  t.header = log.stats().header_bytes;
  EXPECT_TRUE(commit_edit(log, kFirst).ok());
  t.first_end = t.second_start = log.stats().file_bytes;
  EXPECT_TRUE(commit_edit(log, kSecond).ok());
  t.bytes = read_bytes(path);
  return t;
}


// Opens `bytes` written to `path`: the error's code, or kOk with the log
// checked against `expected`.
ErrorCode open_bytes(const std::string& path, const std::string& bytes, const Expected& expected,
                     std::string* message = nullptr, const ChunkLogLimits& limits = {}) {
  write_bytes(path, bytes);
  Result<ChunkLog> log = ChunkLog::open(path, limits);
  if (!log.ok()) {
    if (message) *message = log.status().message();
    return log.status().code();
  }
  EXPECT_TRUE(holds(*log, expected));
  return ErrorCode::kOk;
}

TEST(ChunkLog, BadHeadersAreRefusedNamingWhat) {
  const std::string dir = temp_folder();
  const TwoCommits t = two_commits(dir + "/a.ldcs");
  const std::string path = dir + "/b.ldcs";
  std::string message;
  EXPECT_EQ(open_bytes(path, t.bytes.substr(0, 50), {}, &message), ErrorCode::kCorruptData);
  EXPECT_NE(message.find("shorter than a chunk log header"), std::string::npos) << message;
  EXPECT_EQ(open_bytes(path, t.bytes.substr(0, t.header - 1), {}, &message), ErrorCode::kCorruptData);
  EXPECT_NE(message.find("truncated header"), std::string::npos) << message;
  EXPECT_EQ(open_bytes(path, "", {}, &message), ErrorCode::kCorruptData);

  std::string other = t.bytes;
  other[3] = 'W';  // an .ldc world's magic
  EXPECT_EQ(open_bytes(path, other, {}, &message), ErrorCode::kCorruptData);
  EXPECT_NE(message.find("bad magic"), std::string::npos) << message;

  std::string version = t.bytes;
  set_u32(version, 4, 2);
  EXPECT_EQ(open_bytes(path, version, {}, &message), ErrorCode::kUnsupported);
  EXPECT_NE(message.find("version 2"), std::string::npos) << message;

  std::string flipped = t.bytes;
  flipped[t.header - 10] ^= 0x01;  // in the description
  EXPECT_EQ(open_bytes(path, flipped, {}, &message), ErrorCode::kCorruptData);
  EXPECT_NE(message.find("header checksum"), std::string::npos) << message;

  std::string huge_description = t.bytes;
  set_u32(huge_description, 72, 0xFFFFFFF0u);
  EXPECT_EQ(open_bytes(path, huge_description, {}, &message), ErrorCode::kCorruptData);
}

TEST(ChunkLog, ATruncatedLogOpensInItsLastCompleteCommit) {
  const std::string dir = temp_folder();
  const TwoCommits t = two_commits(dir + "/a.ldcs");
  const std::string path = dir + "/b.ldcs";
  // About 100 cuts, and every byte around the end of commit 1.
  std::vector<size_t> cuts;
  for (size_t cut = t.header; cut <= t.bytes.size(); cut += t.bytes.size() / 100) cuts.push_back(cut);
  for (size_t cut = t.first_end - 50; cut <= t.first_end + 20; ++cut) cuts.push_back(cut);
  for (size_t cut : cuts) {
    const Expected e = cut == t.bytes.size() ? after_second() : cut >= t.first_end ? after_first() : Expected{};
    ASSERT_EQ(open_bytes(path, t.bytes.substr(0, cut), e), ErrorCode::kOk) << "cut at " << cut;
  }
  EXPECT_EQ(open_bytes(path, t.bytes.substr(0, t.first_end), after_first()), ErrorCode::kOk);
  EXPECT_EQ(open_bytes(path, t.bytes.substr(0, t.bytes.size() - 1), after_first()), ErrorCode::kOk);
  EXPECT_EQ(open_bytes(path, t.bytes, after_second()), ErrorCode::kOk);
}

TEST(ChunkLog, AFlippedPayloadByteIsATornTailOnlyAfterTheLastGoodCommit) {
  const std::string dir = temp_folder();
  const TwoCommits t = two_commits(dir + "/a.ldcs");
  const std::string path = dir + "/b.ldcs";
  std::string message;
  // A chunk record after the last commit (written, never committed).
  std::string tail = t.bytes + t.bytes.substr(t.second_start, t.bytes.size() - t.second_start - (12 + 16 + 16));
  tail[t.bytes.size() + 40] ^= 0x20;
  EXPECT_EQ(open_bytes(path, tail, after_second()), ErrorCode::kOk);
  // A chunk record the last commit names: that commit is not complete, the
  // one before it is the state.
  std::string last = t.bytes;
  last[t.second_start + 40] ^= 0x20;
  EXPECT_EQ(open_bytes(path, last, after_first()), ErrorCode::kOk);
  // A record of commit 1, with commit 2 after it: committed data is damaged.
  std::string middle = t.bytes;
  middle[t.header + 40] ^= 0x20;
  EXPECT_EQ(open_bytes(path, middle, {}, &message), ErrorCode::kCorruptData);
  EXPECT_NE(message.find("byte " + std::to_string(t.header)), std::string::npos) << message;
  // Commit 1's own record damaged, with commit 2 after it.
  std::string commit_record = t.bytes;
  commit_record[t.first_end - 6] ^= 0x01;
  EXPECT_EQ(open_bytes(path, commit_record, {}, &message), ErrorCode::kCorruptData);
  EXPECT_NE(message.find("commit record checksum"), std::string::npos) << message;
}

TEST(ChunkLog, ACommitNamingAnOffsetPastTheEndOrBetweenRecordsIsCorrupt) {
  const std::string dir = temp_folder();
  const TwoCommits t = two_commits(dir + "/a.ldcs");
  const std::string path = dir + "/b.ldcs";
  const size_t commit_at = t.bytes.size() - (12 + 16 + 16);  // commit 2 names 2 chunks
  const size_t first_offset = commit_at + 8 + 16;
  std::string message;
  std::string past_end = t.bytes;
  set_u64(past_end, first_offset, uint64_t{1} << 40);
  reseal_record(past_end, commit_at);
  EXPECT_EQ(open_bytes(path, past_end, {}, &message), ErrorCode::kCorruptData);
  EXPECT_NE(message.find("past the end"), std::string::npos) << message;
  EXPECT_NE(message.find("byte " + std::to_string(commit_at)), std::string::npos) << message;

  std::string between = t.bytes;
  set_u64(between, first_offset, t.second_start + 1);
  reseal_record(between, commit_at);
  EXPECT_EQ(open_bytes(path, between, {}, &message), ErrorCode::kCorruptData);
  EXPECT_NE(message.find("not a chunk record"), std::string::npos) << message;

  std::string older = t.bytes;  // a record of commit 1: not this commit's
  set_u64(older, first_offset, t.header);
  reseal_record(older, commit_at);
  EXPECT_EQ(open_bytes(path, older, {}, &message), ErrorCode::kCorruptData);

  std::string sequence = t.bytes;
  set_u64(sequence, commit_at + 8, 7);
  reseal_record(sequence, commit_at);
  EXPECT_EQ(open_bytes(path, sequence, {}, &message), ErrorCode::kCorruptData);
  EXPECT_NE(message.find("sequence"), std::string::npos) << message;
}

TEST(ChunkLog, AbsurdRecordLengthsAreNeverAllocated) {
  const std::string dir = temp_folder();
  const TwoCommits t = two_commits(dir + "/a.ldcs");
  const std::string path = dir + "/b.ldcs";
  std::string message;
  // Past the end of the file: a torn tail.
  for (uint32_t tag : {0x4B4E4843u, 0x54494D43u}) {
    std::string absurd = t.bytes + std::string(12, '\0');
    set_u32(absurd, t.bytes.size(), tag);
    set_u32(absurd, t.bytes.size() + 4, 0xFFFFFFF0u);
    EXPECT_EQ(open_bytes(path, absurd, after_second()), ErrorCode::kOk);
  }
  // Within the file but over the limits: refused before it is read.
  EXPECT_EQ(open_bytes(path, t.bytes, {}, &message, {.max_chunk_raw_bytes = 16}), ErrorCode::kTooLarge);
  std::string huge_commit = t.bytes.substr(0, t.first_end) + std::string(5000, '\0');
  set_u32(huge_commit, t.first_end, 0x54494D43u);
  set_u32(huge_commit, t.first_end + 4, 4000);
  EXPECT_EQ(open_bytes(path, huge_commit, {}, &message), ErrorCode::kCorruptData);
  EXPECT_NE(message.find("names more than"), std::string::npos) << message;
  EXPECT_EQ(open_bytes(path, t.bytes, {}, &message, {.max_file_bytes = 100}), ErrorCode::kTooLarge);
  // Garbage after the last commit is a torn tail too.
  EXPECT_EQ(open_bytes(path, t.bytes + std::string(100, '\x5a'), after_second()), ErrorCode::kOk);
}

TEST(ChunkLog, EveryByteFlipOpensCleanlyOrFailsNamingIt) {
  const std::string dir = temp_folder();
  const TwoCommits t = two_commits(dir + "/a.ldcs");
  const std::string path = dir + "/b.ldcs";
  // Every byte of the header and the commit records, every 53rd elsewhere.
  const size_t commit_bytes = 12 + 16 + 8 * kSecond.size();
  auto in_commit = [&](size_t i) {
    return (i >= t.first_end - (12 + 16 + 8 * kFirst.size()) && i < t.first_end) || i >= t.bytes.size() - commit_bytes;
  };
  for (size_t i = 0; i < t.bytes.size(); ++i) {
    if (i >= t.header && !in_commit(i) && i % 53 != 0) continue;
    std::string b = t.bytes;
    b[i] ^= 0x41;
    write_bytes(path, b);
    Result<ChunkLog> log = ChunkLog::open(path);
    if (!log.ok()) {
      EXPECT_NE(log.status().code(), ErrorCode::kInternal);
      continue;
    }
    // Whatever opened is a committed state, whose chunks all read back valid.
    const bool known = holds(*log, after_second()) || holds(*log, after_first()) || holds(*log, {});
    EXPECT_TRUE(known) << "byte " << i;
  }
}

// --- write failures ---------------------------------------------------------------

// In a child limited to `file_limit` bytes per file (SIGXFSZ ignored, so
// writes fail with EFBIG): commit kSecond, which must fail and leave kFirst.
int commit_under_file_size_limit(const std::string& path, uint64_t file_limit) {
  const pid_t child = ::fork();
  if (child == 0) {
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{file_limit, file_limit};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(2);
    Result<ChunkLog> log = ChunkLog::open(path);
    if (!log.ok()) ::_exit(3);
    const Status s = commit_edit(*log, kSecond);
    if (s.ok() || s.code() != ErrorCode::kIoError) ::_exit(4);
    if (!holds(*log, after_first())) ::_exit(5);
    if (fs::file_size(path) != log->stats().file_bytes) ::_exit(6);
    ::_exit(0);
  }
  int wstatus = 0;
  ::waitpid(child, &wstatus, 0);
  return WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 100 + WTERMSIG(wstatus);
}

TEST(ChunkLog, AFailedWriteLeavesTheCommittedStateIntact) {
  const std::string dir = temp_folder();
  const TwoCommits t = two_commits(dir + "/a.ldcs");
  const std::string path = dir + "/b.ldcs";
  const size_t commit_record = 12 + 16 + 16;
  // Fails in the chunk records; in the commit record; in its last byte.
  for (uint64_t limit : {uint64_t(t.first_end + 30), uint64_t(t.bytes.size() - commit_record + 5),
                         uint64_t(t.bytes.size() - 1)}) {
    write_bytes(path, t.bytes.substr(0, t.first_end));
    EXPECT_EQ(commit_under_file_size_limit(path, limit), 0) << "limit " << limit;
    EXPECT_EQ(fs::file_size(path), t.first_end);  // what it appended is gone
    ChunkLog log = ChunkLog::open(path).value();
    EXPECT_TRUE(holds(log, after_first())) << "limit " << limit;
    ASSERT_TRUE(commit_edit(log, kSecond).ok());  // and it still takes commits
  }
  ChunkLog log = ChunkLog::open(path).value();
  EXPECT_TRUE(holds(log, after_second()));
}

// The body of the read-only-folder case: 0 when every check holds, else
// the number of the first that failed (it runs in a child process as root).
int compact_in_read_only_folder(const std::string& dir) {
  const std::string path = dir + "/world.ldcs";
  Result<ChunkLog> made = ChunkLog::create(path, test_layout(), "terrain seed=42 v3");
  if (!made.ok()) return 1;
  ChunkLog log = std::move(made).value();
  if (!commit_edit(log, kFirst).ok() || !commit_edit(log, kSecond).ok()) return 2;
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
  const Status s = log.compact();
  fs::permissions(dir, fs::perms::owner_all);
  if (s.code() != ErrorCode::kIoError) return 3;
  if (!holds(log, after_second())) return 4;
  { ChunkLog closed = std::move(log); }
  Result<ChunkLog> reopened = ChunkLog::open(path);
  if (!reopened.ok() || !holds(reopened.value(), after_second())) return 5;
  return 0;
}

// Root ignores folder permissions, so as root the case runs in a child
// process that has become nobody (uid and gid 65534) and owns the folder.
TEST(ChunkLog, CompactInAReadOnlyFolderFailsAndChangesNothing) {
  const std::string dir = temp_folder();
  if (::geteuid() != 0) {
    EXPECT_EQ(compact_in_read_only_folder(dir), 0);
    return;
  }
  ASSERT_EQ(::chown(dir.c_str(), 65534, 65534), 0) << std::strerror(errno);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(100);
    ::_exit(compact_in_read_only_folder(dir));
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the child died: status " << status;
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the first check that failed (100: could not become nobody)";
}

// --- compaction -------------------------------------------------------------------

TEST(ChunkLog, CompactDropsDeadRecordsAndKeepsTheState) {
  const std::string path = temp_folder() + "/world.ldcs";
  Expected e;
  ChunkLog log = create_log(path);
  EXPECT_FALSE(log.needs_compaction());
  EXPECT_TRUE(log.compact().ok());  // an empty log compacts to itself
  std::mt19937 rng(7);
  for (int i = 0; i < 30; ++i) {
    const Edit edit = random_edit(rng);
    ASSERT_TRUE(commit_edit(log, edit).ok());
    apply_edit(e, edit);
  }
  const ChunkLogStats before = log.stats();
  EXPECT_EQ(before.commits, 30u);
  EXPECT_EQ(before.live_chunks, e.size());
  EXPECT_GT(before.dead_fraction(), 0.5);
  EXPECT_TRUE(log.needs_compaction());
  ASSERT_TRUE(log.compact().ok());
  const ChunkLogStats after = log.stats();
  EXPECT_LT(after.file_bytes, before.file_bytes);
  EXPECT_EQ(after.file_bytes, fs::file_size(path));
  EXPECT_EQ(after.dead_bytes, 0u);
  EXPECT_EQ(after.live_chunks, before.live_chunks);
  EXPECT_EQ(after.live_bytes, before.live_bytes);
  EXPECT_EQ(after.sequence, before.sequence);
  EXPECT_FALSE(log.needs_compaction());
  EXPECT_TRUE(holds(log, e));
  for (const auto& entry : fs::directory_iterator(fs::path(path).parent_path())) {
    EXPECT_EQ(entry.path().filename(), "world.ldcs");  // no temp file left
  }
  const Edit more = {{6, 3}};
  ASSERT_TRUE(commit_edit(log, more).ok());
  apply_edit(e, more);
  { ChunkLog closed = std::move(log); }  // releases the lock
  ChunkLog reopened = ChunkLog::open(path).value();
  EXPECT_TRUE(holds(reopened, e));
  EXPECT_EQ(reopened.stats().commits, 2u);
  EXPECT_EQ(reopened.stats().sequence, 31u);
}

// --- figures (printed, not asserted: timings vary by machine) ------------------------

TEST(ChunkLog, FiguresForASmallDig) {
  const std::string path = temp_folder() + "/world.ldcs";
  ChunkLog log = create_log(path);
  const Edit dig = {{0, 2}, {1, 3}, {4, 4}};  // three mixed chunks
  const int commits = 20;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < commits; ++i) ASSERT_TRUE(commit_edit(log, dig).ok());
  const double commit_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / commits;
  const ChunkLogStats st = log.stats();
  { ChunkLog closed = std::move(log); }
  const auto open_start = std::chrono::steady_clock::now();
  ChunkLog reopened = ChunkLog::open(path).value();
  const double open_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - open_start).count();
  std::printf("[ figures  ] commit of 3 mixed chunks: %.3f ms (2 fdatasyncs); growth %.0f bytes/commit; "
              "open of %llu bytes (%d commits): %.3f ms\n",
              commit_ms, double(st.file_bytes - st.header_bytes) / commits,
              static_cast<unsigned long long>(st.file_bytes), commits, open_ms);
  EXPECT_EQ(reopened.stats().commits, uint64_t(commits));
}

}  // namespace
}  // namespace ldc
