// Per-ray merges: the heart of booleans and brush edits.
#include <algorithm>
#include <climits>
#include <vector>

#include "csg/detail/merge.h"
#include "ldc/internal/ray_math.h"

namespace ldc::detail {
namespace {

bool apply_op(BooleanOp op, bool a, bool b) {
  switch (op) {
    case BooleanOp::kUnion: return a || b;
    case BooleanOp::kSubtract: return a && !b;
    case BooleanOp::kIntersect: return a && b;
  }
  return false;
}

// One ray segment of a chunk family, read-only.
using RaySegment = RayPoints;

// Flips a point's sense and turns its normal around (a cutter surface that a
// difference exposes faces the other way).
PackedPoint reversed(const PackedPoint& p, uint16_t material) {
  PackedPoint q = p;
  glm::dvec3 n(decode_normal(p.normal));
  q.normal = encode_normal(-n) | (p.exits() ? 0u : kPointExitBit);
  q.material = material;
  return q;
}

// Collects output points and removes slivers: a point within `tolerance`
// steps of the previous one, between the same two nodes, cancels it.
class SliverFilter {
 public:
  SliverFilter(uint32_t tolerance, uint32_t steps_per_cell) : tol_(tolerance), q_(steps_per_cell) {}
  void reset() { out_.clear(); }
  void push(const PackedPoint& p) {
    if (!out_.empty()) {
      const PackedPoint& top = out_.back();
      if (uint32_t(p.depth - top.depth) < tol_ && p.depth / q_ == top.depth / q_) {
        out_.pop_back();
        return;
      }
    }
    out_.push_back(p);
  }
  const std::vector<PackedPoint>& points() const { return out_; }

 private:
  uint32_t tol_, q_;
  std::vector<PackedPoint> out_;
};

// The material of the span of `a` that contains depth d (for surfaces a
// difference exposes): that of the nearest point of a at or before d, else
// the next one after it.
uint16_t span_material(std::span<const PackedPoint> a, size_t next_a) {
  if (next_a > 0) return a[next_a - 1].material;
  return next_a < a.size() ? a[next_a].material : uint16_t{0};
}

// a op b along one ray segment, points into `filter`.
void merge_ray(const RaySegment& a, const RaySegment& b, BooleanOp op, int cut_material, SliverFilter& filter) {
  bool ia = a.starts_inside, ib = b.starts_inside, out = apply_op(op, ia, ib);
  size_t i = 0, j = 0;
  filter.reset();
  while (i < a.points.size() || j < b.points.size()) {
    uint16_t d = std::min(i < a.points.size() ? a.points[i].depth : uint16_t(0xFFFF),
                          j < b.points.size() ? b.points[j].depth : uint16_t(0xFFFF));
    const PackedPoint* pa = (i < a.points.size() && a.points[i].depth == d) ? &a.points[i] : nullptr;
    const PackedPoint* pb = (j < b.points.size() && b.points[j].depth == d) ? &b.points[j] : nullptr;
    const bool a_before = ia, b_before = ib;
    if (pa) ia = !ia, ++i;
    if (pb) ib = !ib, ++j;
    bool now = apply_op(op, ia, ib);
    if (now == out) continue;  // e.g. touching spans: one exits where the other enters
    out = now;
    // The point whose own move changes the result keeps its surface; a wins ties.
    bool a_alone = pa && apply_op(op, ia, b_before) != apply_op(op, a_before, b_before);
    if (a_alone || !pb) {
      filter.push(*pa);  // the result moves with a: same sense, same surface
    } else if (op == BooleanOp::kSubtract) {
      uint16_t mat = cut_material >= 0 ? uint16_t(cut_material) : span_material(a.points, i);
      filter.push(reversed(*pb, mat));  // the cutter's surface, facing out of what remains
    } else {
      filter.push(*pb);
    }
  }
}

// Is the ray inside b at depth d? (b's state after its points before d.)
struct StateWalker {
  RaySegment s;
  size_t next = 0;
  bool inside;
  explicit StateWalker(const RaySegment& seg) : s(seg), inside(seg.starts_inside) {}
  bool at(uint16_t d) {
    while (next < s.points.size() && s.points[next].depth <= d) inside = !inside, ++next;
    return inside;
  }
};

bool same_point(const PackedPoint& x, const PackedPoint& y) {
  return x.depth == y.depth && x.material == y.material && x.normal == y.normal;
}

// Adds to `box` the nodes around the points where one ray segment changed
// from `a` to `out`: the differing middle once equal heads and tails are cut off.
void note_ray_change(const RaySegment& a, const RaySegment& out, int axis, int ray, int c, ChangeBox& box) {
  const uint32_t q = depth_steps_per_cell(c);
  const bool flipped = a.starts_inside != out.starts_inside;  // every node before the first change flips
  size_t i = 0, ja = a.points.size(), jo = out.points.size();
  if (!flipped) {
    while (i < ja && i < jo && same_point(a.points[i], out.points[i])) ++i;
    if (i == ja && i == jo) return;
  }
  while (ja > i && jo > i && same_point(a.points[ja - 1], out.points[jo - 1])) --ja, --jo;
  uint32_t first = UINT32_MAX, last = 0;
  if (i < ja) first = a.points[i].depth, last = a.points[ja - 1].depth;
  if (i < jo) first = std::min<uint32_t>(first, out.points[i].depth), last = std::max<uint32_t>(last, out.points[jo - 1].depth);
  int n0 = flipped ? 0 : int(first / q);
  int n1 = i < ja || i < jo ? int(last / q) + 2 : c + 1;  // a flip with equal points: the whole segment
  glm::ivec3 lo, hi;
  lo[axis] = n0;
  hi[axis] = n1;
  lo[axis_u(axis)] = ray % c;
  hi[axis_u(axis)] = ray % c + 1;
  lo[axis_v(axis)] = ray / c;
  hi[axis_v(axis)] = ray / c + 1;
  box.add(lo, hi);
}

void note_family_change(const RayFamily& a, const RayFamily& out, int axis, int c, ChangeBox& box) {
  if (a.is_uniform() && out.is_uniform() && a.uniform_inside() == out.uniform_inside()) return;
  RayReader ra(a), rout(out);
  for (int r = 0; r < c * c; ++r) note_ray_change(ra.next(), rout.next(), axis, r, c, box);
}

// The family of a chunk view on one axis (uniform families for uniform chunks).
const RayFamily& family_of(const ChunkView& v, int axis, RayFamily& scratch) {
  if (v.data) return v.data->axis[axis];
  scratch = RayFamily::uniform(v.kind == ChunkKind::kSolid);
  return scratch;
}

RayFamily merge_family(const RayFamily& a, const RayFamily& b, BooleanOp op, const BooleanConfig& config, int c) {
  const uint32_t q = depth_steps_per_cell(c);
  SliverFilter filter(uint32_t(config.sliver * q), q);
  RayFamilyWriter wr(c);
  RayReader ra(a), rb(b);
  for (int r = 0; r < c * c; ++r) {
    RaySegment sa = ra.next(), sb = rb.next();
    wr.begin_ray(apply_op(op, sa.starts_inside, sb.starts_inside));
    if (sb.points.empty() && sa.points.empty()) continue;
    merge_ray(sa, sb, op, config.cut_material, filter);
    for (const PackedPoint& p : filter.points()) wr.add_point(p);
  }
  return wr.finish();
}

// Three result families, each either one of a's (not copied) or new.
struct FamilyChoice {
  std::array<const RayFamily*, 3> pick{};
  std::array<RayFamily, 3> owned;
  ChangeBox changed;
};

// Unchanged means no tracked change, or (untracked) every family is a's.
MergedChunk finish_chunk(FamilyChoice& f, const ChunkView& a, bool tracked) {
  MergedChunk m;
  m.changed = f.changed;
  bool unchanged = f.changed.empty();
  for (int k = 0; k < 3 && !tracked; ++k) unchanged = unchanged && f.pick[k] != &f.owned[k];
  if (unchanged) {
    m.kind = a.kind;
    m.data = a.data;
    m.changed_from_a = false;
    return m;
  }
  auto chunk = std::make_shared<Chunk>();
  for (int k = 0; k < 3; ++k) chunk->axis[k] = f.pick[k] == &f.owned[k] ? std::move(f.owned[k]) : *f.pick[k];
  bool inside = false;
  if (chunk->is_uniform(&inside)) {
    m.kind = inside ? ChunkKind::kSolid : ChunkKind::kEmpty;
  } else {
    m.kind = ChunkKind::kMixed;
    m.data = std::move(chunk);
  }
  m.changed_from_a = true;
  return m;
}

}  // namespace

ChunkView view_chunk(const World& w, const glm::ivec3& chunk) {
  return {w.chunk_kind(chunk), w.chunk_shared(chunk)};
}

MergedChunk merge_chunk(const ChunkView& a, const ChunkView& b, BooleanOp op, const BooleanConfig& config,
                        int c, bool track_changes) {
  FamilyChoice f;
  std::array<RayFamily, 3> scratch_a, scratch_b;
  for (int k = 0; k < 3; ++k) {
    const RayFamily& fa = family_of(a, k, scratch_a[k]);
    const RayFamily& fb = family_of(b, k, scratch_b[k]);
    if (fb.is_uniform()) {  // b decides alone: keep a, or make it uniform
      bool keep_a = (op == BooleanOp::kIntersect) == fb.uniform_inside();
      if (keep_a) {
        f.pick[k] = &fa;
        continue;
      }
      f.owned[k] = RayFamily::uniform(op == BooleanOp::kUnion);
    } else {
      f.owned[k] = merge_family(fa, fb, op, config, c);
    }
    if (track_changes) note_family_change(fa, f.owned[k], k, c, f.changed);
    f.pick[k] = &f.owned[k];
  }
  return finish_chunk(f, a, track_changes);
}

MergedChunk paint_chunk(const ChunkView& a, const ChunkView& b, uint16_t material, int c) {
  FamilyChoice f;
  std::array<RayFamily, 3> scratch_a, scratch_b;
  for (int k = 0; k < 3; ++k) {
    const RayFamily& fa = family_of(a, k, scratch_a[k]);
    const RayFamily& fb = family_of(b, k, scratch_b[k]);
    f.pick[k] = &fa;
    if (fa.is_uniform() || (fb.is_uniform() && !fb.uniform_inside())) continue;  // nothing to paint
    RayFamilyWriter wr(c);
    bool changed = false;
    RayReader ra(fa), rb(fb);
    for (int r = 0; r < c * c; ++r) {
      const RaySegment own = ra.next();
      wr.begin_ray(own.starts_inside);
      StateWalker inside_b(rb.next());
      for (PackedPoint p : own.points) {
        if (inside_b.at(p.depth) && p.material != material) {
          p.material = material;
          changed = true;
        }
        wr.add_point(p);
      }
    }
    if (!changed) continue;
    f.owned[k] = wr.finish();
    f.pick[k] = &f.owned[k];
    note_family_change(fa, f.owned[k], k, c, f.changed);
  }
  return finish_chunk(f, a, /*tracked=*/true);
}

void store_chunk(World& w, const glm::ivec3& chunk, const MergedChunk& m) {
  if (m.kind == ChunkKind::kMixed) w.set_chunk(chunk, m.data);
  else w.set_uniform_chunk(chunk, m.kind == ChunkKind::kSolid);
}

}  // namespace ldc::detail
