// Chunk sources and the paged world (ldc/store.h): generated chunks equal the
// whole build, windows equal the same box of it under any budget, edits put
// back survive eviction, and a kilometre-wide source costs its window only.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/store.h"
#include "ldc/terrain.h"
#include "test_util.h"

namespace ldc {
namespace {

constexpr double kH = 0.25;
constexpr int kC = 16;

TerrainConfig small_terrain() {
  TerrainConfig t;
  t.size_x = 16.0;
  t.size_y = 16.0;
  return t;
}

// The whole build every test compares with, built once.
const World& whole_world() {
  static const World w = build_terrain(small_terrain(), kH, kC).value();
  return w;
}

std::shared_ptr<const ImplicitSource> small_source() {
  return make_terrain_source(small_terrain(), kH, kC).value();
}

::testing::AssertionResult same_family(const RayFamily& a, const RayFamily& b, int c) {
  if (a.is_uniform() != b.is_uniform()) return ::testing::AssertionFailure() << "uniformity differs";
  if (a.is_uniform()) {
    if (a.uniform_inside() == b.uniform_inside()) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "uniform state differs";
  }
  for (int r = 0; r < c * c; ++r) {
    const auto pa = a.points(r), pb = b.points(r);
    if (a.starts_inside(r) != b.starts_inside(r)) return ::testing::AssertionFailure() << "ray " << r << " start";
    if (pa.size() != pb.size() || (!pa.empty() && std::memcmp(pa.data(), pb.data(), pa.size_bytes()) != 0)) {
      return ::testing::AssertionFailure() << "ray " << r << " points differ";
    }
  }
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult same_chunk(ChunkKind ka, const Chunk* a, ChunkKind kb, const Chunk* b, int c) {
  if (ka != kb) return ::testing::AssertionFailure() << chunk_kind_name(ka) << " vs " << chunk_kind_name(kb);
  if (ka != ChunkKind::kMixed) return ::testing::AssertionSuccess();
  for (int ax = 0; ax < 3; ++ax) {
    auto r = same_family(a->axis[ax], b->axis[ax], c);
    if (!r) return r << " on axis " << ax;
  }
  return ::testing::AssertionSuccess();
}

// Every chunk of `part` equals the same chunk of `whole`.
::testing::AssertionResult same_chunks_as(const World& part, const World& whole) {
  bool ok = true;
  std::string first;
  part.for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk* data) {
    auto r = same_chunk(kind, data, whole.chunk_kind(ch), whole.chunk(ch), part.chunk_size());
    if (!r && ok) {
      ok = false;
      first = "chunk (" + std::to_string(ch.x) + ", " + std::to_string(ch.y) + ", " + std::to_string(ch.z) +
              "): " + r.message();
    }
  });
  return ok ? ::testing::AssertionSuccess() : ::testing::AssertionFailure() << first;
}

// Bytes the cache counts for a window's chunks.
size_t window_bytes(const World& w) {
  size_t bytes = 0;
  w.for_each_chunk([&](const glm::ivec3&, ChunkKind, const Chunk* data) {
    bytes += kPagingEntryBytes + (data ? data->memory_bytes() : 0);
  });
  return bytes;
}

glm::ivec3 box_end(const SourceBox& b) { return b.chunk_origin + b.chunk_dims; }

TEST(Store, GeneratedChunksEqualTheWholeBuild) {
  const World& whole = whole_world();
  auto source = small_source();
  const SourceLayout& lay = source->layout();
  EXPECT_EQ(lay.box.chunk_origin, whole.chunk_origin());
  EXPECT_EQ(lay.box.chunk_dims, whole.chunk_dims());
  EXPECT_EQ(lay.lattice.origin, whole.lattice().origin);
  EXPECT_EQ(lay.lattice.cell_size, whole.lattice().cell_size);
  size_t mixed = 0, compared = 0;
  whole.for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk* data) {
    Result<StoredChunk> got = source->read(ch);
    ASSERT_TRUE(got.ok()) << got.status().to_string();
    EXPECT_EQ((got->data != nullptr), (got->kind == ChunkKind::kMixed));
    EXPECT_TRUE(same_chunk(got->kind, got->data.get(), kind, data, kC)) << ch.x << " " << ch.y << " " << ch.z;
    mixed += kind == ChunkKind::kMixed;
    ++compared;
  });
  EXPECT_GT(mixed, 10u);
  EXPECT_EQ(compared, size_t(lay.box.slots()));
  // Outside the box: empty, as the whole world answers.
  Result<StoredChunk> outside = source->read(box_end(lay.box) + glm::ivec3(3));
  ASSERT_TRUE(outside.ok());
  EXPECT_EQ(outside->kind, ChunkKind::kEmpty);
}

TEST(Store, WindowsEqualTheWholeBuildAndValidate) {
  const World& whole = whole_world();
  PagedWorld paged(small_source());
  const SourceBox box = paged.layout().box;
  // A window asked larger than the box is clipped to it: the whole world again.
  Result<World> full = paged.window(box.chunk_origin - 5, box_end(box) + 5);
  ASSERT_TRUE(full.ok()) << full.status().to_string();
  EXPECT_EQ(full->chunk_dims(), whole.chunk_dims());
  EXPECT_TRUE(same_chunks_as(*full, whole));
  EXPECT_TRUE(test::is_valid(*full));
  // A window inside the box: its chunks are the whole build's; validate()
  // finds only the cuts at its faces (rays inside where the box cuts the ground).
  const glm::ivec3 lo = box.chunk_origin + glm::ivec3(1, 1, 0), hi = box_end(box) - glm::ivec3(1, 1, 0);
  Result<World> part = paged.window(lo, hi);
  ASSERT_TRUE(part.ok());
  EXPECT_EQ(part->chunk_origin(), lo);
  EXPECT_TRUE(same_chunks_as(*part, whole));
  ValidateOptions opts;
  opts.max_messages = 100000;
  const ValidationReport report = validate(*part, opts);
  for (const std::string& m : report.messages) {
    EXPECT_TRUE(m.find("world box face") != std::string::npos ||
                m.find("boundary to the next chunk") != std::string::npos)
        << m;
  }
  // Windows share the cached chunks: no copy.
  Result<World> again = paged.window(lo, hi);
  ASSERT_TRUE(again.ok());
  const glm::ivec3 mid = (lo + hi) / 2;
  for (int z = lo.z; z < hi.z; ++z) {
    const glm::ivec3 ch(mid.x, mid.y, z);
    EXPECT_EQ(again->chunk(ch), part->chunk(ch));
  }
  EXPECT_GT(paged.stats().hits, 0u);
}

TEST(Store, PagedQueriesEqualUnpagedOnes) {
  const World& whole = whole_world();
  PagedWorld paged(small_source());
  const SourceBox box = paged.layout().box;
  // Partial in x and y, whole in z: Z rays of the window are whole rays.
  const glm::ivec3 lo = box.chunk_origin + glm::ivec3(1, 1, 0);
  const glm::ivec3 hi = box_end(box) - glm::ivec3(1, 1, 0);
  Result<World> win = paged.window(lo, hi);
  ASSERT_TRUE(win.ok());
  std::mt19937 rng(7);
  auto uniform = [&](double a, double b) { return a + (b - a) * (double(rng()) / 4294967296.0); };
  const glm::dvec3 n0 = glm::dvec3(win->node_min()) + 1.0, n1 = glm::dvec3(win->node_end()) - 1.0;
  int inside = 0;
  for (int i = 0; i < 400; ++i) {
    const glm::dvec3 l(uniform(n0.x, n1.x), uniform(n0.y, n1.y), uniform(n0.z, n1.z));
    const glm::dvec3 p = win->lattice().to_world(l);
    ASSERT_EQ(win->inside(p), whole.inside(p)) << i;
    inside += whole.inside(p);
  }
  EXPECT_GT(inside, 20);
  size_t spans = 0;
  for (int i = 0; i < 200; ++i) {
    const glm::ivec2 uv(int(uniform(n0.x, n1.x)), int(uniform(n0.y, n1.y)));
    const std::vector<Span> a = win->ray_spans(2, uv), b = whole.ray_spans(2, uv);
    ASSERT_EQ(a.size(), b.size()) << i;
    for (size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].enter.depth, b[k].enter.depth);
      EXPECT_EQ(a[k].exit.depth, b[k].exit.depth);
      EXPECT_EQ(a[k].exit.material, b[k].exit.material);
    }
    spans += a.size();
  }
  EXPECT_GT(spans, 100u);
}

TEST(Store, EvictionUnderATinyBudgetChangesNoResult) {
  const World& whole = whole_world();
  PagingOptions opts;
  opts.memory_budget_bytes = 64 << 10;
  PagedWorld paged(small_source(), opts);
  const SourceBox box = paged.layout().box;
  size_t max_window = 0;
  // Walk 2 x 2 column windows across the box, twice (the second pass pages
  // evicted chunks in again).
  for (int pass = 0; pass < 2; ++pass) {
    for (int y = box.chunk_origin.y; y < box_end(box).y; y += 2) {
      for (int x = box.chunk_origin.x; x < box_end(box).x; x += 2) {
        const glm::ivec3 lo(x, y, box.chunk_origin.z), hi(x + 2, y + 2, box_end(box).z);
        Result<World> w = paged.window(lo, hi);
        ASSERT_TRUE(w.ok()) << w.status().to_string();
        EXPECT_TRUE(same_chunks_as(*w, whole)) << x << " " << y;
        const PagingStats s = paged.stats();
        EXPECT_LE(s.resident_bytes, std::max(opts.memory_budget_bytes, window_bytes(*w)));
        max_window = std::max(max_window, window_bytes(*w));
      }
    }
  }
  const PagingStats s = paged.stats();
  // While a window is made: the trimmed cache, the last window and this one.
  EXPECT_LE(s.peak_resident_bytes, opts.memory_budget_bytes + 2 * max_window);
  EXPECT_GT(s.evictions, 0u);
  EXPECT_GT(s.page_ins, size_t(box.slots()));  // some chunks read twice
  EXPECT_EQ(s.dirty, 0u);
  // A window larger than the budget is still made, and counted.
  Result<World> all = paged.window(box.chunk_origin, box_end(box));
  ASSERT_TRUE(all.ok());
  EXPECT_TRUE(same_chunks_as(*all, whole));
  EXPECT_EQ(paged.stats().windows_over_budget, 1u);
  EXPECT_EQ(paged.stats().resident_bytes, window_bytes(*all));  // pinned, not evicted
}

TEST(Store, CancelledWindowReturnsCancelled) {
  PagedWorld paged(small_source());
  Context ctx;
  ctx.cancel();
  const SourceBox box = paged.layout().box;
  Result<World> w = paged.window(box.chunk_origin, box_end(box), &ctx);
  EXPECT_EQ(w.status().code(), ErrorCode::kCancelled);
  EXPECT_EQ(paged.stats().page_ins, 0u);
}

// Digs a sphere into a window with the CSG editor and returns the edited
// world and its dirty chunks.
std::pair<World, std::vector<glm::ivec3>> dig(const World& window, const glm::dvec3& centre) {
  WorldEditor editor(window);
  Result<EditReceipt> r = editor.apply(Brush::sphere(centre, 1.2), EditOp::kSubtract);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  std::vector<glm::ivec3> chunks;
  for (const DirtyChunk& d : editor.take_dirty()) chunks.push_back(d.chunk);
  return {editor.world(), chunks};
}

TEST(Store, EditsPutBackSurviveEvictionUntilTaken) {
  const World& whole = whole_world();
  PagingOptions opts;
  opts.memory_budget_bytes = 64 << 10;
  auto source = small_source();
  PagedWorld paged(source, opts);
  const SourceBox box = paged.layout().box;
  const glm::ivec3 lo = box.chunk_origin + glm::ivec3(1, 1, 0), hi = lo + glm::ivec3(3, 3, box.chunk_dims.z);
  Result<World> win = paged.window(lo, hi);
  ASSERT_TRUE(win.ok());
  // The ground's surface near the window's middle.
  const glm::dvec3 mid = win->lattice().to_world(glm::dvec3(win->node_min() + win->node_end()) * 0.5);
  double ground = mid.z;
  for (double z = win->box().max.z; z > win->box().min.z; z -= 0.1) {
    if (win->inside({mid.x, mid.y, z})) {
      ground = z;
      break;
    }
  }
  auto [edited, dirty] = dig(*win, {mid.x, mid.y, ground});
  ASSERT_FALSE(dirty.empty());
  ASSERT_EQ(edited.chunk_origin(), win->chunk_origin());  // the dig stayed inside
  ASSERT_TRUE(paged.put(edited, dirty).ok());
  EXPECT_EQ(paged.stats().dirty, dirty.size());
  // Page everything else out: a window at the far corner under 64 KiB.
  ASSERT_TRUE(paged.window(box_end(box) - glm::ivec3(2, 2, box.chunk_dims.z), box_end(box)).ok());
  ASSERT_TRUE(paged.window(box_end(box) - glm::ivec3(1, 2, box.chunk_dims.z), box_end(box)).ok());
  EXPECT_GT(paged.stats().evictions, 0u);
  Result<World> back = paged.window(lo, hi);
  ASSERT_TRUE(back.ok());
  EXPECT_TRUE(same_chunks_as(*back, edited));
  EXPECT_FALSE(same_chunks_as(*back, whole));  // the dig is there
  // take_dirty hands them out once, sorted, and they become clean.
  std::vector<DirtyStoredChunk> taken = paged.take_dirty();
  ASSERT_EQ(taken.size(), dirty.size());
  for (size_t i = 0; i < taken.size(); ++i) {
    EXPECT_EQ(taken[i].chunk, dirty[i]);
    EXPECT_TRUE(same_chunk(taken[i].data.kind, taken[i].data.data.get(), edited.chunk_kind(dirty[i]),
                           edited.chunk(dirty[i]), kC));
  }
  EXPECT_TRUE(paged.take_dirty().empty());
  EXPECT_EQ(paged.stats().dirty, 0u);
  // Saved into an overlay over the generator, a fresh pager serves them.
  auto overlay = std::make_shared<OverlaySource>(source);
  for (const DirtyStoredChunk& d : taken) ASSERT_TRUE(overlay->set(d.chunk, d.data).ok());
  PagedWorld reopened(overlay, opts);
  Result<World> saved = reopened.window(lo, hi);
  ASSERT_TRUE(saved.ok());
  EXPECT_TRUE(same_chunks_as(*saved, edited));
}

// A worker prefetching ahead while the owner makes windows: every window
// still equals the whole build, the prefetched box is then served from the
// cache without a page-in, and an edit put() meanwhile is never replaced by
// a prefetched copy of the source's chunk.
TEST(Store, PrefetchOnAWorkerFillsTheCacheAndChangesNoResult) {
  const World& whole = whole_world();
  PagedWorld paged(small_source());
  const SourceBox box = paged.layout().box;
  const glm::ivec3 lo = box.chunk_origin, hi = box_end(box);
  std::thread worker([&] { EXPECT_TRUE(paged.prefetch(lo, hi).ok()); });
  for (int x = lo.x; x < hi.x; ++x) {
    Result<World> w = paged.window({x, lo.y, lo.z}, {x + 1, hi.y, hi.z});
    ASSERT_TRUE(w.ok()) << w.status().to_string();
    EXPECT_TRUE(same_chunks_as(*w, whole)) << x;
  }
  worker.join();
  const size_t read = paged.stats().page_ins;
  EXPECT_EQ(read, size_t(box.slots()));  // each chunk read into the cache once
  Result<World> all = paged.window(lo, hi);
  ASSERT_TRUE(all.ok());
  EXPECT_TRUE(same_chunks_as(*all, whole));
  EXPECT_EQ(paged.stats().page_ins, read);

  // An edited chunk put() back stays what was put, whatever a prefetch finds.
  PagedWorld fresh(small_source());
  Result<World> window = fresh.window(lo, hi);
  ASSERT_TRUE(window.ok());
  const glm::dvec3 centre = 0.5 * (window->box().min + window->box().max);
  auto [edited, dirty] = dig(*window, centre);
  ASSERT_FALSE(dirty.empty());
  ASSERT_TRUE(fresh.put(edited, dirty).ok());
  ASSERT_TRUE(fresh.prefetch(lo, hi).ok());
  Result<World> again = fresh.window(lo, hi);
  ASSERT_TRUE(again.ok());
  for (const glm::ivec3& c : dirty) EXPECT_EQ(again->chunk_shared(c), edited.chunk_shared(c));
  EXPECT_EQ(fresh.prefetch({-1000, -1000, -1000}, {-999, -999, -999}).code(), ErrorCode::kOk);  // outside: nothing
}

TEST(Store, PutRefusesChunksOutsideTheBoxesOrAnotherLattice) {
  PagedWorld paged(small_source());
  const SourceBox box = paged.layout().box;
  Result<World> win = paged.window(box.chunk_origin, box.chunk_origin + 2);
  ASSERT_TRUE(win.ok());
  const glm::ivec3 outside_window[] = {box.chunk_origin + 3};
  Status s = paged.put(*win, outside_window);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.message().find("edited world's box"), std::string::npos) << s.message();
  World other = build_terrain(small_terrain(), 0.5, kC).value();
  const glm::ivec3 one[] = {other.chunk_origin()};
  s = paged.put(other, one);
  EXPECT_NE(s.message().find("lattice"), std::string::npos) << s.message();
  EXPECT_EQ(paged.stats().dirty, 0u);
}

TEST(Store, OverlayLooksInItsChunksThenTheLowerLayerThenTheBase) {
  auto source = small_source();
  const SourceBox box = source->layout().box;
  const glm::ivec3 a = box.chunk_origin, b = box.chunk_origin + 1;
  int lower_calls = 0;
  ChunkFinder lower = [&](const glm::ivec3& ch) -> Result<std::optional<StoredChunk>> {
    ++lower_calls;
    if (ch == b) return std::optional<StoredChunk>(StoredChunk{ChunkKind::kSolid, nullptr});
    return std::optional<StoredChunk>();
  };
  OverlaySource overlay(source, lower);
  ASSERT_TRUE(overlay.set(a, {ChunkKind::kSolid, nullptr}).ok());
  EXPECT_EQ(overlay.read(a)->kind, ChunkKind::kSolid);
  EXPECT_EQ(lower_calls, 0);
  EXPECT_EQ(overlay.read(b)->kind, ChunkKind::kSolid);  // from the lower layer
  const glm::ivec3 c = box_end(box) - 1;
  EXPECT_EQ(overlay.read(c)->kind, source->read(c)->kind);  // from the base
  EXPECT_EQ(lower_calls, 2);
  EXPECT_EQ(overlay.set(box_end(box), {}).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(overlay.set(a, {ChunkKind::kMixed, nullptr}).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(overlay.size(), 1u);
}

size_t resident_set_bytes() {
  std::ifstream statm("/proc/self/statm");
  size_t pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * 4096;
}

TEST(Store, KilometreSourceMakesAWindowAtItsSizeOnly) {
  TerrainConfig big;
  big.size_x = 4000.0;
  big.size_y = 4000.0;
  const size_t rss_before = resident_set_bytes();
  const auto t0 = std::chrono::steady_clock::now();
  Result<std::shared_ptr<const ImplicitSource>> source = make_terrain_source(big, 0.2, 32);
  ASSERT_TRUE(source.ok()) << source.status().to_string();
  const SourceBox box = (*source)->layout().box;
  EXPECT_GE(box.chunk_dims.x, 625);  // 20000 cells + padding at h = 0.2
  PagingOptions opts;
  opts.memory_budget_bytes = 16 << 20;
  PagedWorld paged(*source, opts);
  Result<World> win = paged.window_around({2000.0, 2000.0, 6.0}, 10.0);  // 4 x 4 columns
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(win.ok()) << win.status().to_string();
  EXPECT_LE(win->chunk_dims().x * win->chunk_dims().y, 16);
  // Deterministic: a second source hands out the same chunks.
  auto again = make_terrain_source(big, 0.2, 32).value();
  win->for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk* data) {
    StoredChunk c = again->read(ch).value();
    EXPECT_TRUE(same_chunk(kind, data, c.kind, c.data.get(), 32));
  });
  const PagingStats s = paged.stats();
  std::printf("4 km source: box %d x %d x %d chunks, window %d x %d x %d in %.3f s, cache %zu bytes, "
              "RSS growth %.1f MiB\n",
              box.chunk_dims.x, box.chunk_dims.y, box.chunk_dims.z, win->chunk_dims().x,
              win->chunk_dims().y, win->chunk_dims().z, seconds, s.resident_bytes,
              double(resident_set_bytes() - std::min(rss_before, resident_set_bytes())) / 1048576.0);
  EXPECT_LT(s.resident_bytes, size_t(16) << 20);
  EXPECT_LT(resident_set_bytes(), rss_before + (size_t(96) << 20));
  EXPECT_LT(seconds, 5.0);
  // The middle of the world has ground: mixed chunks were generated.
  EXPECT_GT(s.resident_mixed, 0u);
}

TEST(Store, BadLayoutsAreRefusedNamingTheField) {
  SourceLayout good;
  good.box.chunk_dims = glm::ivec3(4);
  EXPECT_TRUE(check_source_layout(good).ok());
  auto refused = [](const SourceLayout& l, const char* field) {
    Status s = check_source_layout(l);
    EXPECT_FALSE(s.ok()) << field;
    EXPECT_NE(s.message().find(field), std::string::npos) << s.message();
  };
  SourceLayout l = good;
  l.box.chunk_dims.y = 0;
  refused(l, "box.chunk_dims.y = 0");
  l = good;
  l.lattice.cell_size = std::nan("");
  refused(l, "lattice.cell_size = nan");
  l = good;
  l.chunk_size = 7;
  refused(l, "chunk_size = 7");
  l = good;
  l.box.chunk_origin.x = 40000;  // nodes up to 1.28e6 > 2^20
  refused(l, "node range on x");
  l = good;
  l.chunk_size = 8;
  l.box.chunk_origin = glm::ivec3(-65536);
  l.box.chunk_dims = glm::ivec3(131072);  // 2^51 slots
  refused(l, "chunk slots exceeds");
  Result<std::shared_ptr<const ImplicitSource>> bad_h = make_terrain_source(small_terrain(), std::nan(""), 32);
  ASSERT_FALSE(bad_h.ok());
  EXPECT_NE(bad_h.status().message().find("cell_size"), std::string::npos);
  EXPECT_FALSE(make_terrain_source(small_terrain(), 0.2, 7).ok());
  TerrainConfig zero = small_terrain();
  zero.size_x = 0.0;
  EXPECT_NE(make_terrain_source(zero).status().message().find("size_x"), std::string::npos);
  // Windows that miss the box, and bad foci.
  PagedWorld paged(small_source());
  const SourceBox box = paged.layout().box;
  EXPECT_EQ(paged.window(box_end(box), box_end(box) + 2).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(paged.window_around(glm::dvec3(std::nan("")), 1.0).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(paged.window_around(glm::dvec3(1.0), -1.0).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(paged.window_around(glm::dvec3(1e300), 1.0).status().code(), ErrorCode::kInvalidArgument);
}

// --- Stores: descriptions, a log over its base ---------------------------------

// A description gives back the same landscape parameters, to the bit.
TEST(Store, TerrainDescriptionsRoundTripExactly) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.1, 3000.0);
  for (int i = 0; i < 50; ++i) {
    TerrainConfig c;
    c.seed = uint32_t(rng());
    c.size_x = u(rng);
    c.size_y = u(rng);
    c.floor_z = u(rng) - 1500.0;
    c.base_height = u(rng) / 100.0;
    c.relief = u(rng) / 300.0;
    c.overhang = u(rng) / 1000.0;
    c.cave_radius = u(rng) / 1000.0;
    c.arches = int(rng() % 65);
    const double h = u(rng) / 5000.0;
    Result<TerrainSourceParams> p = parse_terrain_source_description(terrain_source_description(c, h, 16));
    ASSERT_TRUE(p.ok()) << p.status().to_string();
    const TerrainConfig& d = p.value().config;
    EXPECT_EQ(d.seed, c.seed);
    EXPECT_EQ(d.size_x, c.size_x);
    EXPECT_EQ(d.size_y, c.size_y);
    EXPECT_EQ(d.floor_z, c.floor_z);
    EXPECT_EQ(d.base_height, c.base_height);
    EXPECT_EQ(d.relief, c.relief);
    EXPECT_EQ(d.overhang, c.overhang);
    EXPECT_EQ(d.cave_radius, c.cave_radius);
    EXPECT_EQ(d.arches, c.arches);
    EXPECT_EQ(p.value().cell_size, h);
    EXPECT_EQ(p.value().chunk_size, 16);
  }
}

TEST(Store, BadDescriptionsAreRefusedNamingTheKey) {
  const std::string good = terrain_source_description(small_terrain(), kH, kC);
  const std::pair<std::string, std::string> cases[] = {
      {"flythrough terrain seed 1", "not a landscape description"},
      {good + " extra=1", "unknown key 'extra'"},
      {good + " seed=2", "key 'seed' given twice"},
      {std::string(good).replace(good.find("size_x="), 7, "size_q="), "missing size_x"},
      {std::string(good).replace(good.find("cell_size=") + 10, 4, "nan "), "cell_size = 'nan' is not a finite number"},
      {std::string(good).replace(good.find("arches=") + 7, 1, "99"), "arches = 99 is not an integer in 0 .. 64"},
      {good + " x", "'x' is not key=value"},
  };
  for (const auto& [text, expected] : cases) {
    Result<TerrainSourceParams> p = parse_terrain_source_description(text);
    ASSERT_FALSE(p.ok()) << text;
    EXPECT_EQ(p.status().code(), ErrorCode::kCorruptData) << text;
    EXPECT_NE(p.status().message().find(expected), std::string::npos) << p.status().message();
  }
}

// Edits saved into a store come back after reopening it; every other chunk
// is the generator's, and a log whose layout is not its description's is refused.
TEST(Store, SavedEditsComeBackWhenTheStoreIsReopened) {
  const std::string path = ::testing::TempDir() + "store_reopen.ldcs";
  std::remove(path.c_str());
  Result<Store> made = create_terrain_store(path, small_terrain(), kH, kC);
  ASSERT_TRUE(made.ok()) << made.status().to_string();
  World edited;
  std::vector<glm::ivec3> dirty;
  {
    Store store = std::move(made).value();
    PagedWorld paged(store.source);
    Result<World> window = paged.window(store.source->layout().box.chunk_origin,
                                        box_end(store.source->layout().box));
    ASSERT_TRUE(window.ok());
    const glm::dvec3 centre = 0.5 * (window->box().min + window->box().max);
    std::tie(edited, dirty) = dig(*window, centre);
    ASSERT_FALSE(dirty.empty());
    ASSERT_TRUE(paged.put(edited, dirty).ok());
    ASSERT_TRUE(store.save(paged).ok());
    EXPECT_EQ(store.log->stats().live_chunks, dirty.size());
    EXPECT_TRUE(store.save(paged).ok());  // nothing dirty: nothing written
    EXPECT_EQ(store.log->stats().commits, 1u);
  }
  Result<Store> reopened = open_store(path);
  ASSERT_TRUE(reopened.ok()) << reopened.status().to_string();
  PagedWorld paged(reopened.value().source);
  Result<World> again = paged.window(edited.chunk_origin(), edited.chunk_origin() + edited.chunk_dims());
  ASSERT_TRUE(again.ok());
  edited.for_each_chunk([&](const glm::ivec3& c, ChunkKind kind, const Chunk* data) {
    EXPECT_TRUE(same_chunk(again->chunk_kind(c), again->chunk(c), kind, data, kC)) << c.x << " " << c.y << " " << c.z;
  });
  EXPECT_TRUE(validate(*again).ok);

  // A log whose header layout is not the one its description makes.
  const std::string wrong = ::testing::TempDir() + "store_wrong_layout.ldcs";
  SourceLayout layout = make_terrain_source(small_terrain(), kH, kC).value()->layout();
  layout.box.chunk_dims.x += 1;
  ChunkLogCreateOptions overwrite;
  overwrite.overwrite = true;
  ASSERT_TRUE(ChunkLog::create(wrong, layout, terrain_source_description(small_terrain(), kH, kC), overwrite).ok());
  Result<Store> refused = open_store(wrong);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), ErrorCode::kCorruptData);
  EXPECT_NE(refused.status().message().find("differ from those of its base description"), std::string::npos);
  std::remove(path.c_str());
  std::remove(wrong.c_str());
}

// A window cut through the ground is not a closed solid: meshing it whole is
// refused naming the face (it crashed inside meshoptimizer and marching
// cubes); the whole-box window and an ordinary world pass the check.
TEST(Store, MeshingAWindowCutThroughTheGroundIsRefused) {
  PagedWorld paged(small_source());
  const SourceBox box = paged.layout().box;
  Result<World> part = paged.window(box.chunk_origin, box.chunk_origin + glm::ivec3(2, 2, box.chunk_dims.z));
  ASSERT_TRUE(part.ok());
  const Status faces = check_box_faces_outside(*part);
  ASSERT_EQ(faces.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(faces.message().find("inside at the world box face"), std::string::npos) << faces.message();
  EXPECT_EQ(contour_world(*part).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(marching_cubes(*part).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(ChunkedMesh::create(*part).status().code(), ErrorCode::kInvalidArgument);
  Result<World> all = paged.window(box.chunk_origin, box_end(box));
  ASSERT_TRUE(all.ok());
  EXPECT_TRUE(check_box_faces_outside(*all).ok());
  EXPECT_TRUE(check_box_faces_outside(whole_world()).ok());
  EXPECT_TRUE(contour_world(*all).ok());
}

}  // namespace
}  // namespace ldc
