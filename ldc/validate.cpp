// validate(): every invariant of the LDC, checked chunk by chunk in parallel.
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <tuple>
#include <cmath>
#include <mutex>
#include <span>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ldc/internal/ray_math.h"
#include "ldc/internal/validate_work.h"
#include "ldc/internal/vec_text.h"
#include "ldc/world.h"

namespace ldc {
namespace {

// A normal may lean this far to the wrong side of the ray's plane before it
// counts as pointing into the solid; covers the octahedral quantization error.
constexpr float kNormalSideTolerance = 1e-3f;

// Collects error messages from many threads, keeping the first few.
class ErrorSink {
 public:
  explicit ErrorSink(size_t max_messages) : max_(max_messages) {}
  // `errors` errors counted under one message (a uniform chunk face: every ray alike).
  void add(std::string message, size_t errors = 1) {
    size_t n = count_.fetch_add(errors);
    if (n >= max_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.push_back(std::move(message));
  }
  size_t count() const { return count_.load(); }
  // Work counters (detail::ValidateWork).
  std::atomic<size_t> rays_visited{0};
  std::atomic<size_t> uniform_faces{0};
  std::vector<std::string> take() { return std::move(messages_); }

 private:
  size_t max_;
  std::atomic<size_t> count_{0};
  std::mutex mutex_;
  std::vector<std::string> messages_;
};

std::string where(const glm::ivec3& chunk, int axis, int ray) {
  std::ostringstream s;
  s << "chunk (" << chunk.x << "," << chunk.y << "," << chunk.z << ") axis " << axis_name(axis);
  if (ray >= 0) s << " ray " << ray;
  return s.str();
}

// Structure of one family's arrays.
bool check_family_arrays(const RayFamily& f, int c, const glm::ivec3& coord, int axis,
                         ErrorSink& sink) {
  if (f.is_uniform()) return true;
  std::string why = f.check_structure();
  if (!why.empty()) {
    sink.add(where(coord, axis, -1) + ": " + why);
    return false;
  }
  bool any_in = false, any_out = false;
  RayReader rays(f);
  for (int r = 0; r < c * c; ++r) (rays.next().starts_inside ? any_in : any_out) = true;
  if (f.all_points().empty() && !(any_in && any_out)) {
    sink.add(where(coord, axis, -1) + ": family holds no points and uniform rays but is not stored as uniform");
  }
  return true;
}

// Order, range, sense and normals of one ray segment. Messages are built only
// for errors: this runs for every ray of every mixed chunk.
// `pts` are the ray's points: callers walk the family's rays in order and
// slice all_points() by point_count(), so a ray costs its own points, not the
// O(C) offset sum RayFamily::points() makes (issue 24: a 277 MB world took
// 41 s to load, most of it summing row offsets).
void check_ray(const RayFamily& f, std::span<const PackedPoint> pts, int axis, int ray, int c,
               const glm::ivec3& coord, ErrorSink& sink) {
  const uint32_t q = depth_steps_per_cell(c);
  bool expect_enter = !f.starts_inside(ray, pts);
  uint32_t prev = 0;
  auto fail = [&](size_t i, const std::string& what) {
    sink.add(where(coord, axis, ray) + " point " + std::to_string(i) + ": " + what);
  };
  for (size_t i = 0; i < pts.size(); ++i) {
    const PackedPoint& p = pts[i];
    if (p.depth % q == 0) fail(i, "depth " + std::to_string(p.depth) + " lies on a node");
    if (i > 0 && p.depth <= prev) {
      fail(i, "depth " + std::to_string(p.depth) + " not after " + std::to_string(prev));
    }
    if (p.normal & kPointReservedBit) fail(i, "reserved bit set");
    if (p.enters() != expect_enter) {
      fail(i, expect_enter ? "exit where an enter was due" : "enter where an exit was due");
    }
    glm::vec3 n = decode_normal(p.normal);
    float len = glm::length(n);
    if (!std::isfinite(len) || std::abs(len - 1.0f) > 1e-3f) fail(i, "normal not unit");
    float side = p.enters() ? n[axis] : -n[axis];  // must be <= 0: pointing out of the solid
    if (side > kNormalSideTolerance) fail(i, "normal points into the solid");
    prev = p.depth;
    expect_enter = !expect_enter;
  }
}

// Node words of one family in the X layout: out[z*64 + y], bit x.
void family_node_words(const RayFamily& f, int axis, int c, std::vector<uint64_t>& out) {
  std::vector<uint64_t> fam(size_t(c) * c);
  RayReader rays(f);
  for (int r = 0; r < c * c; ++r) {
    const RayPoints ray = rays.next();
    fam[r] = detail::node_word(ray.starts_inside, ray.points, c);
  }
  out.assign(size_t(c) * 64, 0);
  detail::convert_layout(axis, c, fam.data(), out.data(), false);
}

size_t check_cross_axis(const Chunk& chunk, int c, const glm::ivec3& coord, ErrorSink& sink) {
  std::array<std::vector<uint64_t>, 3> words;
  for (int a = 0; a < 3; ++a) family_node_words(chunk.axis[a], a, c, words[a]);
  size_t bad = 0;
  for (int z = 0; z < c; ++z) {
    for (int y = 0; y < c; ++y) {
      uint64_t x = words[0][z * 64 + y];
      uint64_t diff = (x ^ words[1][z * 64 + y]) | (x ^ words[2][z * 64 + y]);
      if (diff == 0) continue;
      ++bad;
      int xi = std::countr_zero(diff);
      sink.add(where(coord, 0, -1) + ": axes disagree at local node (" + std::to_string(xi) + "," +
               std::to_string(y) + "," + std::to_string(z) + ")");
    }
  }
  return bad;
}

void check_chunk(const Chunk& chunk, const glm::ivec3& coord, int c, bool cross_axis,
                 ErrorSink& sink) {
  bool arrays_ok = true;
  for (int a = 0; a < 3; ++a) {
    if (!check_family_arrays(chunk.axis[a], c, coord, a, sink)) {
      arrays_ok = false;
      continue;
    }
    const RayFamily& f = chunk.axis[a];
    if (f.is_uniform()) continue;
    RayReader rays(f);
    for (int r = 0; r < c * c; ++r) check_ray(f, rays.next().points, a, r, c, coord, sink);
    sink.rays_visited.fetch_add(size_t(c) * size_t(c), std::memory_order_relaxed);
  }
  if (arrays_ok && cross_axis) check_cross_axis(chunk, c, coord, sink);
}

// One side of a chunk boundary: the chunk's family along the axis, or its
// uniform state, looked up once per face instead of once per ray.
struct FaceSide {
  const RayFamily* family = nullptr;  // null: uniform slot (or outside the box)
  bool solid = false;
  FaceSide(const World& w, const glm::ivec3& ch, int axis) {
    ChunkKind kind = w.chunk_kind(ch);
    if (kind == ChunkKind::kMixed) family = &w.chunk(ch)->axis[axis];
    solid = kind == ChunkKind::kSolid;
  }
  bool starts_inside(int ray) const { return family ? family->starts_inside(ray) : solid; }
  // End state of a ray segment: start state flipped once per point.
  bool ends_inside(int ray) const {
    return family ? family->starts_inside(ray) != (family->point_count(ray) % 2 == 1) : solid;
  }
};

// Continuity between two uniform chunk slots: every ray of the face is alike,
// so one comparison stands for all C^2 (issue 24: an all-empty world of
// 512 x 512 chunks of 64^3 took 40 s to validate ray by ray).
void check_uniform_face(const World& w, const glm::ivec3& ch, int a, const glm::ivec3& next, ErrorSink& sink) {
  const size_t rays = size_t(w.chunk_size()) * size_t(w.chunk_size());
  const bool inside = w.chunk_kind(ch) == ChunkKind::kSolid;
  if (ch[a] == w.chunk_origin()[a] && inside) {
    sink.add(where(ch, a, -1) + ": all rays start inside at the world box face", rays);
  }
  if (inside != (w.chunk_kind(next) == ChunkKind::kSolid)) {
    sink.add(where(ch, a, -1) + ": all rays' state breaks at the boundary to the next chunk", rays);
  }
}

// Each ray leaves chunk ch in the state it enters the next chunk along the axis;
// rays start and end outside at the world box.
void check_continuity(const World& w, const glm::ivec3& ch, ErrorSink& sink) {
  const int c = w.chunk_size();
  for (int a = 0; a < 3; ++a) {
    glm::ivec3 next = ch;
    next[a] += 1;
    if (w.chunk_kind(ch) != ChunkKind::kMixed && w.chunk_kind(next) != ChunkKind::kMixed) {
      check_uniform_face(w, ch, a, next, sink);
      sink.uniform_faces.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    bool first_in_box = ch[a] == w.chunk_origin()[a];
    const FaceSide here(w, ch, a), there(w, next, a);
    sink.rays_visited.fetch_add(size_t(c) * size_t(c), std::memory_order_relaxed);
    for (int r = 0; r < c * c; ++r) {
      if (first_in_box && here.starts_inside(r)) {
        sink.add(where(ch, a, r) + ": ray starts inside at the world box face");
      }
      if (here.ends_inside(r) != there.starts_inside(r)) {
        sink.add(where(ch, a, r) + ": ray state breaks at the boundary to the next chunk");
      }
    }
  }
}

void check_slot(const World& w, const glm::ivec3& ch, ChunkKind kind, const Chunk* data,
                bool cross_axis, ErrorSink& sink) {
  if ((kind == ChunkKind::kMixed) != (data != nullptr)) {
    sink.add(where(ch, 0, -1) + ": kind " + chunk_kind_name(kind) + " disagrees with its data");
    return;
  }
  if (data) {
    if (data->is_uniform(nullptr)) sink.add(where(ch, 0, -1) + ": uniform chunk stored as mixed");
    check_chunk(*data, ch, w.chunk_size(), cross_axis, sink);
  }
  check_continuity(w, ch, sink);
}

}  // namespace

std::string ValidationReport::summary() const {
  std::ostringstream s;
  s << (ok ? "valid" : "INVALID") << " (" << errors << " errors, " << nodes_checked
    << " nodes checked across axes)";
  for (const std::string& m : messages) s << "\n  " << m;
  if (errors > messages.size()) s << "\n  ...";
  return s.str();
}

ValidationReport validate(const World& world, const ValidateOptions& options) {
  return detail::validate_with_progress(world, options, nullptr);
}

namespace detail {

ValidationReport validate_with_progress(const World& world, const ValidateOptions& options, Context* ctx,
                                        ValidateWork* work) {
  ErrorSink sink(options.max_messages);
  // Slots by index, in slot order (x fastest): no list of all slots is built
  // (4M slots made a 100 MB one).
  const glm::ivec3 d = world.chunk_dims();
  const size_t slots = size_t(d.x) * size_t(d.y) * size_t(d.z);
  if (ctx) ctx->report_progress("validate", 0.0);
  std::atomic<size_t> mixed{0};
  std::atomic<size_t> done{0};
  const size_t grain = std::max<size_t>(1, slots / 1024);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, slots, grain), [&](const tbb::blocked_range<size_t>& range) {
    size_t mixed_here = 0;
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const glm::ivec3 ch = world.chunk_origin() + glm::ivec3(int(i % size_t(d.x)), int((i / size_t(d.x)) % size_t(d.y)),
                                                               int(i / (size_t(d.x) * size_t(d.y))));
      const ChunkKind kind = world.chunk_kind(ch);
      mixed_here += kind == ChunkKind::kMixed;
      check_slot(world, ch, kind, world.chunk(ch), options.check_cross_axis, sink);
    }
    mixed.fetch_add(mixed_here, std::memory_order_relaxed);
    const size_t n = done.fetch_add(range.size(), std::memory_order_relaxed) + range.size();
    if (ctx && n < slots) ctx->report_progress("validate", double(n) / double(slots));
  });
  if (ctx) ctx->report_progress("validate", 1.0);
  ValidationReport report;
  report.errors = sink.count();
  report.ok = report.errors == 0;
  report.messages = sink.take();
  const size_t c = size_t(world.chunk_size());
  report.nodes_checked = options.check_cross_axis ? mixed.load() * c * c * c : 0;
  if (work) {
    work->slots += slots;
    work->rays_visited += sink.rays_visited.load();
    work->uniform_faces += sink.uniform_faces.load();
  }
  return report;
}

}  // namespace detail

namespace {

Status face_inside(const glm::ivec3& chunk, int axis, bool high, int ray) {
  std::string where = std::string("chunk ") + detail::chunk_text(chunk) + ", " + axis_name(axis) + " ray ";
  where += std::to_string(ray);
  return {ErrorCode::kInvalidArgument,
          where + (high ? " end" : " start") + " inside at the world box face (" + (high ? "high" : "low") +
              " " + axis_name(axis) +
              "): the solid is cut open there, as in a paged window cut through the ground; intersect it with a "
              "box inside the window first"};
}

// The rays holding points of one chunk on a box face: inside at that face?
// Uniform chunks and families are left alone: meshing gives a solid face
// of them no triangles, as it always has (a world of solid chunks meshes
// to nothing), and only a surface cut open by the face breaks it.
Status check_face_chunk(const World& w, const glm::ivec3& ch, int a, bool high) {
  if (w.chunk_kind(ch) != ChunkKind::kMixed) return {};
  const RayFamily& f = w.chunk(ch)->axis[size_t(a)];
  if (f.is_uniform()) return {};
  const int rays = w.chunk_size() * w.chunk_size();
  for (int r = 0; r < rays; ++r) {
    const bool ends_flipped = high && f.point_count(r) % 2 == 1;
    if (f.starts_inside(r) != ends_flipped) return face_inside(ch, a, high, r);
  }
  return {};
}

}  // namespace

Status check_box_faces_outside(const World& w) {
  return check_box_faces_outside(w, w.node_min(), w.node_end());
}

Status check_box_faces_outside(const World& w, const glm::ivec3& node_lo, const glm::ivec3& node_hi) {
  const glm::ivec3 box_lo = w.chunk_origin(), box_hi = box_lo + w.chunk_dims();
  // The chunks the node range meets, within the box.
  glm::ivec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::max(box_lo[a], detail::floor_div(node_lo[a], w.chunk_size()));
    hi[a] = std::min(box_hi[a], detail::floor_div(node_hi[a] - 1, w.chunk_size()) + 1);
  }
  if (glm::any(glm::greaterThanEqual(lo, hi))) return {};
  for (int a = 0; a < 3; ++a) {
    const int u = axis_u(a), v = axis_v(a);
    for (const bool high : {false, true}) {
      // Only a face the range reaches: a cut deeper in the face chunk is not read.
      if (high ? node_hi[a] < w.node_end()[a] : node_lo[a] > w.node_min()[a]) continue;
      glm::ivec3 ch;
      ch[a] = high ? box_hi[a] - 1 : box_lo[a];
      for (ch[v] = lo[v]; ch[v] < hi[v]; ++ch[v])
        for (ch[u] = lo[u]; ch[u] < hi[u]; ++ch[u])
          if (Status s = check_face_chunk(w, ch, a, high); !s.ok()) return s;
    }
  }
  return {};
}

Status validate_chunk(const Chunk& chunk, int chunk_size, bool check_cross_axis) {
  ErrorSink sink(1);
  check_chunk(chunk, glm::ivec3(0), chunk_size, check_cross_axis, sink);
  if (sink.count() == 0) return {};
  return {ErrorCode::kCorruptData, sink.take().front()};
}

}  // namespace ldc
