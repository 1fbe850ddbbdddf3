// The per-block walk: the rays of one family through a block of voxels, span
// by span, into integer occupancy sums (trapezoid weights) and float face sums.
#include "voxelize/detail/block.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "ldc/internal/ray_math.h"

namespace ldc::detail {
namespace {

// The voxel columns (of the block) one ray feeds, with its trapezoid weight in each.
struct RayColumns {
  int count = 0;
  std::array<size_t, 4> base{};  // voxel index of the column's bin 0
  std::array<int, 4> column{};   // column index (for the diff arrays)
  std::array<int, 4> weight{};
};

// One ray family walked through one block.
class AxisPass {
 public:
  AxisPass(const VoxelSource& src, BlockScratch& s, int axis, BlockCounters* counters)
      : src_(src), s_(s), counters_(counters), a_(axis), u_(axis_u(axis)), v_(axis_v(axis)) {
    const World& w = *src.world;
    c_ = w.chunk_size();
    shift_ = w.chunk_shift();
    m_ = src.m;
    stride_ = src.stride;
    const glm::ivec3 d = s.box.dims;
    step_ = glm::ivec3(1, d.x, d.x * d.y);
    bins_ = d[a_];
    cols_u_ = d[u_];
    cols_v_ = d[v_];
    bin_steps_ = int64_t(m_) * int64_t(depth_steps_per_cell(c_));
    d0_ = int64_t(s.box.lo[a_]) * bin_steps_;
    d1_ = int64_t(s.box.hi()[a_]) * bin_steps_;
    volume_on_ = axis == src.occ_axis;
    faces_on_ = s.faces;
    if (faces_on_) s_.coverage_diff.assign(size_t(cols_u_) * size_t(cols_v_) * size_t(bins_ + 1), 0);
  }

  void run() {
    const int64_t u0 = int64_t(m_) * s_.box.lo[u_], u1 = int64_t(m_) * s_.box.hi()[u_];
    const int64_t v0 = int64_t(m_) * s_.box.lo[v_], v1 = int64_t(m_) * s_.box.hi()[v_];
    const int cd0 = int(detail::floor_div64(int64_t(m_) * s_.box.lo[a_], c_));
    const int cd1 = int(detail::floor_div64(int64_t(m_) * s_.box.hi()[a_] - 1, c_));
    column_.resize(size_t(cd1 - cd0 + 1));
    for (int64_t cv = detail::floor_div64(v0, c_); cv <= detail::floor_div64(v1, c_); ++cv) {
      for (int64_t cu = detail::floor_div64(u0, c_); cu <= detail::floor_div64(u1, c_); ++cu) {
        glm::ivec3 c;
        c[u_] = int(cu);
        c[v_] = int(cv);
        bool any_mixed = false, any_solid = false;
        for (int cd = cd0; cd <= cd1; ++cd) {
          c[a_] = cd;
          ChunkKind k = src_.world->chunk_kind(c);
          column_[size_t(cd - cd0)] = {k, k == ChunkKind::kMixed ? src_.world->chunk(c) : nullptr};
          any_mixed |= k == ChunkKind::kMixed;
          any_solid |= k == ChunkKind::kSolid;
        }
        cd0_ = cd0;
        const int64_t ru0 = std::max(cu * c_, u0), ru1 = std::min(cu * c_ + c_ - 1, u1);
        const int64_t rv0 = std::max(cv * c_, v0), rv1 = std::min(cv * c_ + c_ - 1, v1);
        if (!any_mixed) {
          if (counters_) ++counters_->closed;
          if (any_solid) closed_form(ru0, ru1, rv0, rv1);
          continue;
        }
        if (counters_) ++counters_->walked;
        walk_rays(ru0, ru1, rv0, rv1);
      }
    }
    if (faces_on_) resolve_coverage();
  }

 private:
  struct ColumnChunk {
    ChunkKind kind;
    const Chunk* data;
  };

  int64_t align_up(int64_t x) const { return detail::floor_div64(x + stride_ - 1, stride_) * stride_; }

  // The block columns ray (ru, rv) lies in, with their weights.
  RayColumns columns_of(int64_t ru, int64_t rv) const {
    int cu[2], wu[2], nu = 0, cv[2], wv[2], nv = 0;
    auto side = [&](int64_t r, int lo, int dims, int* col, int* w, int* n) {
      const int64_t g = detail::floor_div64(r, m_);
      if (r == g * m_) {
        if (g - 1 >= lo && g - 1 < lo + dims) col[*n] = int(g - 1 - lo), w[(*n)++] = 1;
        if (g >= lo && g < lo + dims) col[*n] = int(g - lo), w[(*n)++] = 1;
      } else if (g >= lo && g < lo + dims) {
        col[*n] = int(g - lo), w[(*n)++] = 2;
      }
    };
    side(ru, s_.box.lo[u_], cols_u_, cu, wu, &nu);
    side(rv, s_.box.lo[v_], cols_v_, cv, wv, &nv);
    RayColumns out;
    for (int j = 0; j < nv; ++j) {
      for (int i = 0; i < nu; ++i) {
        out.base[size_t(out.count)] = size_t(cu[i]) * size_t(step_[u_]) + size_t(cv[j]) * size_t(step_[v_]);
        out.column[size_t(out.count)] = cv[j] * cols_u_ + cu[i];
        out.weight[size_t(out.count)] = wu[i] * wv[j];
        ++out.count;
      }
    }
    return out;
  }

  // Sum of the weights of the sampled rays in [r0, r1] that voxel column g (global) holds.
  int weight_sum(int64_t g, int64_t r0, int64_t r1) const {
    const int64_t lo = std::max(r0, g * m_), hi = std::min(r1, g * m_ + m_);
    if (lo > hi) return 0;
    const int64_t first = align_up(lo), last = detail::floor_div64(hi, stride_) * stride_;
    if (first > last) return 0;
    const int64_t count = (last - first) / stride_ + 1;
    return int(2 * count - (first == g * m_) - (last == g * m_ + m_));
  }

  // Adds the solid interval [s0, s1) (global steps, within [d0, d1)) of weight w to one column.
  void add_span(size_t base, int column, int w, int64_t s0, int64_t s1, int* last_covered) {
    const int64_t r0 = s0 - d0_, r1 = s1 - d0_;
    const int b0 = int(r0 / bin_steps_), b1 = int((r1 - 1) / bin_steps_);
    if (volume_on_) {
      int64_t* vol = s_.volume.data() + base;
      const size_t sa = size_t(step_[a_]);
      if (b0 == b1) {
        vol[size_t(b0) * sa] += w * (r1 - r0);
      } else {
        vol[size_t(b0) * sa] += w * ((b0 + 1) * bin_steps_ - r0);
        vol[size_t(b1) * sa] += w * (r1 - b1 * bin_steps_);
        if (b1 > b0 + 1) {
          // Bin-major (bin * columns + column): the resolve reads it in voxel order.
          const size_t cols = size_t(cols_u_) * size_t(cols_v_);
          s_.volume_diff[size_t(b0 + 1) * cols + size_t(column)] += w;
          s_.volume_diff[size_t(b1) * cols + size_t(column)] -= w;
        }
      }
    }
    if (faces_on_) {
      const int first = std::max(b0, *last_covered + 1);
      if (first <= b1) {
        int32_t* diff = s_.coverage_diff.data() + size_t(column) * size_t(bins_ + 1);
        diff[first] += w;
        diff[b1 + 1] -= w;
        *last_covered = b1;
      }
    }
  }

  void emit_span(const RayColumns& rc, int64_t s0, int64_t s1, int* last_covered) {
    if (s1 <= s0) return;
    int last = *last_covered;
    for (int i = 0; i < rc.count; ++i) {
      int l = *last_covered;
      add_span(rc.base[size_t(i)], rc.column[size_t(i)], rc.weight[size_t(i)], s0, s1, &l);
      last = l;
    }
    *last_covered = last;
  }

  // Chunk columns with no mixed chunk: merged solid runs added per voxel column.
  void closed_form(int64_t ru0, int64_t ru1, int64_t rv0, int64_t rv1) {
    std::vector<std::pair<int64_t, int64_t>>& runs = runs_;
    runs.clear();
    for (size_t i = 0; i < column_.size(); ++i) {
      if (column_[i].kind != ChunkKind::kSolid) continue;
      const int64_t lo = std::max(int64_t(cd0_ + int(i)) * kDepthSteps, d0_);
      const int64_t hi = std::min(int64_t(cd0_ + int(i) + 1) * kDepthSteps, d1_);
      if (!runs.empty() && runs.back().second == lo) {
        runs.back().second = hi;
      } else {
        runs.emplace_back(lo, hi);
      }
    }
    for (int cv = 0; cv < cols_v_; ++cv) {
      const int wv = weight_sum(s_.box.lo[v_] + cv, rv0, rv1);
      if (wv == 0) continue;
      for (int cu = 0; cu < cols_u_; ++cu) {
        const int wu = weight_sum(s_.box.lo[u_] + cu, ru0, ru1);
        if (wu == 0) continue;
        const size_t base = size_t(cu) * size_t(step_[u_]) + size_t(cv) * size_t(step_[v_]);
        int last = -1;
        for (const auto& [lo, hi] : runs) add_span(base, cv * cols_u_ + cu, wu * wv, lo, hi, &last);
      }
    }
  }

  // The rays of one chunk column, in ray order: each chunk's rays are read
  // in order (RayReader), not located one by one (which sums offsets along
  // the ray's row: a sixth of a coarse cascade level's time).
  void walk_rays(int64_t ru0, int64_t ru1, int64_t rv0, int64_t rv1) {
    readers_.clear();
    for (const ColumnChunk& cc : column_) {
      if (cc.data) readers_.emplace_back(cc.data->axis[size_t(a_)]);
    }
    rays_.resize(column_.size());
    for (int64_t rv = align_up(rv0); rv <= rv1; rv += stride_) {
      for (int64_t ru = align_up(ru0); ru <= ru1; ru += stride_) {
        const int ray = int((rv & (c_ - 1)) * c_ + (ru & (c_ - 1)));
        size_t reader = 0;
        for (size_t i = 0; i < column_.size(); ++i) {
          rays_[i] = column_[i].data ? readers_[reader++].next_at(ray)
                                     : RayPoints{column_[i].kind == ChunkKind::kSolid, {}};
        }
        walk_ray(ru, rv);
      }
    }
  }

  // Face -a from the first enter point per bin, +a from the last exit point.
  struct FaceState {
    int last_enter_bin = -1;
    int exit_bin = -1;
    PackedPoint exit_point{};
  };

  void record_face(const RayColumns& rc, int face, int bin, const PackedPoint& p) {
    const VoxelMaterial& mat = (*src_.materials)[uint16_t(p.material + src_.material_offset)];
    const glm::vec3 n = decode_normal(p.normal);
    for (int i = 0; i < rc.count; ++i) {
      const size_t vox = rc.base[size_t(i)] + size_t(bin) * size_t(step_[a_]);
      FaceAccum& f = s_.face[vox * kFaces + size_t(face)];
      const float w = float(rc.weight[size_t(i)]);
      if (!(s_.touched[vox] & (1u << face))) {
        s_.touched[vox] = uint8_t(s_.touched[vox] | (1u << face));
        f = FaceAccum{0.0f, glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
      }
      f.weight += w;
      f.albedo += w * mat.albedo;
      f.normal += w * n;
      f.emission += w * mat.emission;
    }
  }

  void mark_surface(const RayColumns& rc, int bin) {
    for (int i = 0; i < rc.count; ++i) s_.surface[rc.base[size_t(i)] + size_t(bin) * size_t(step_[a_])] = 1;
  }

  void on_point(const RayColumns& rc, const PackedPoint& p, int64_t depth, FaceState* fs) {
    const int bin = int((depth - d0_) / bin_steps_);
    mark_surface(rc, bin);
    if (!faces_on_) return;
    if (p.enters()) {
      if (bin != fs->last_enter_bin) record_face(rc, 2 * a_ + 1, bin, p);
      fs->last_enter_bin = bin;
    } else {
      if (fs->exit_bin >= 0 && fs->exit_bin != bin) record_face(rc, 2 * a_, fs->exit_bin, fs->exit_point);
      fs->exit_bin = bin;
      fs->exit_point = p;
    }
  }

  void walk_ray(int64_t ru, int64_t rv) {
    const RayColumns rc = columns_of(ru, rv);
    if (rc.count == 0) return;
    if (counters_) ++counters_->rays;
    bool inside = false;
    int64_t span_start = 0;
    int last_covered = -1;
    FaceState fs;
    for (size_t i = 0; i < column_.size(); ++i) {
      const int64_t seg = int64_t(cd0_ + int(i)) * kDepthSteps;
      const int64_t lo = std::max(seg, d0_), hi = std::min(seg + kDepthSteps, d1_);
      const std::span<const PackedPoint> pts = rays_[i].points;  // empty for a uniform family
      bool state = rays_[i].starts_inside;
      size_t k = 0;
      for (; k < pts.size() && seg + pts[k].depth < lo; ++k) state = pts[k].enters();
      if (state != inside) {  // the segment's state at lo (a new ray, or the block's first segment)
        if (state) span_start = lo;
        if (!state) emit_span(rc, span_start, lo, &last_covered);
        inside = state;
      }
      for (; k < pts.size(); ++k) {
        const int64_t depth = seg + pts[k].depth;
        if (depth >= hi) break;
        if (pts[k].enters()) {
          if (!inside) span_start = depth;
          inside = true;
        } else {
          if (inside) emit_span(rc, span_start, depth, &last_covered);
          inside = false;
        }
        on_point(rc, pts[k], depth, &fs);
      }
    }
    if (inside) emit_span(rc, span_start, d1_, &last_covered);
    if (fs.exit_bin >= 0) record_face(rc, 2 * a_, fs.exit_bin, fs.exit_point);
  }

  void resolve_coverage() {
    const size_t vox = s_.voxels();
    float* out = s_.coverage.data() + size_t(a_) * vox;
    const double full = double(4 * int64_t(s_.full_n) * s_.full_n);
    for (int cv = 0; cv < cols_v_; ++cv) {
      for (int cu = 0; cu < cols_u_; ++cu) {
        const int32_t* diff = s_.coverage_diff.data() + size_t(cv * cols_u_ + cu) * size_t(bins_ + 1);
        const size_t base = size_t(cu) * size_t(step_[u_]) + size_t(cv) * size_t(step_[v_]);
        int64_t run = 0;
        for (int b = 0; b < bins_; ++b) {
          run += diff[b];
          out[base + size_t(b) * size_t(step_[a_])] = float(double(run) / full);
        }
      }
    }
  }

  const VoxelSource& src_;
  BlockScratch& s_;
  BlockCounters* counters_;
  int a_, u_, v_;
  int c_ = 32, shift_ = 5, m_ = 1, stride_ = 1;
  glm::ivec3 step_{1};
  int bins_ = 0, cols_u_ = 0, cols_v_ = 0;
  int64_t bin_steps_ = 1, d0_ = 0, d1_ = 0;
  bool volume_on_ = false, faces_on_ = false;
  int cd0_ = 0;
  std::vector<ColumnChunk> column_;
  std::vector<RayReader> readers_;  // the mixed chunks' of the column walked
  std::vector<RayPoints> rays_;     // the ray walked, per chunk of column_
  std::vector<std::pair<int64_t, int64_t>> runs_;
};

// Occupancy = the inside steps added per voxel plus the runs crossing it
// whole (the running sum of volume_diff along its column), over full. Voxels
// are visited in memory order (x fastest) with one running sum per column:
// walking each column along the axis instead (4 KB apart for the z axis)
// made this loop half of a mesh's voxelization.
template <int A>
void resolve_volume_along(BlockScratch& s, int64_t bin_steps, int64_t full) {
  constexpr int U = axis_u(A), V = axis_v(A);
  const glm::ivec3 d = s.box.dims;
  const size_t cols = size_t(d[U]) * size_t(d[V]);
  const double inv_full = 1.0 / double(full);
  s.volume_run.assign(cols, 0);
  int64_t* run = s.volume_run.data();
  const int64_t* diff = s.volume_diff.data();
  const int64_t* volume = s.volume.data();
  float* occupancy = s.occupancy.data();
  size_t i = 0;
  glm::ivec3 g;
  for (g.z = 0; g.z < d.z; ++g.z) {
    for (g.y = 0; g.y < d.y; ++g.y) {
      for (g.x = 0; g.x < d.x; ++g.x, ++i) {
        const size_t col = size_t(g[V]) * size_t(d[U]) + size_t(g[U]);
        run[col] += diff[size_t(g[A]) * cols + col];
        const int64_t inside = volume[i] + run[col] * bin_steps;
        occupancy[i] = inside == full ? 1.0f : float(double(inside) * inv_full);  // exactly 1 when full
      }
    }
  }
}

void resolve_volume(const VoxelSource& src, BlockScratch& s) {
  const int64_t bin_steps = int64_t(src.m) * int64_t(depth_steps_per_cell(src.world->chunk_size()));
  const int64_t n = s.full_n;
  const int64_t full = 4 * n * n * bin_steps;
  switch (src.occ_axis) {
    case 0: resolve_volume_along<0>(s, bin_steps, full); break;
    case 1: resolve_volume_along<1>(s, bin_steps, full); break;
    default: resolve_volume_along<2>(s, bin_steps, full); break;
  }
}

void resolve_faces(BlockScratch& s) {
  const float full = float(4 * int64_t(s.full_n) * s.full_n);
  const size_t vox = s.voxels();
  for (size_t i = 0; i < vox; ++i) {
    if (!s.touched[i]) continue;
    for (int f = 0; f < kFaces; ++f) {
      if (!(s.touched[i] & (1u << f))) continue;
      FaceAccum& a = s.face[i * kFaces + size_t(f)];
      const float inv = 1.0f / a.weight;
      a.albedo *= inv;
      a.emission *= inv;
      const float len = glm::length(a.normal);
      a.normal = len > 0.0f ? a.normal / len : glm::vec3(0.0f);
      a.weight /= full;
    }
  }
}

}  // namespace

int sample_stride(int m, int supersampling) {
  int stride = 1;
  while (m % (2 * stride) == 0 && m / (2 * stride) >= supersampling) stride *= 2;
  return stride;
}

void BlockScratch::reset(const VoxelBox& b, bool with_faces) {
  box = b;
  faces = with_faces;
  uniform = ChunkKind::kMixed;
  const size_t n = b.count();
  volume.resize(n);
  surface.resize(n);
  occupancy.resize(n);
  if (faces) {
    touched.resize(n);
    face.resize(n * kFaces);
    coverage.resize(3 * n);
  }
}

namespace {

// Empty or solid when every chunk holding one of the block's nodes [m*lo, m*hi] is so; else kMixed.
ChunkKind block_kind(const VoxelSource& src, const VoxelBox& box) {
  const World& w = *src.world;
  const int c = w.chunk_size();
  glm::ivec3 c0, c1;
  for (int a = 0; a < 3; ++a) {
    c0[a] = int(detail::floor_div64(int64_t(src.m) * box.lo[a], c));
    c1[a] = int(detail::floor_div64(int64_t(src.m) * box.hi()[a], c));
  }
  const ChunkKind first = w.chunk_kind(c0);
  if (first == ChunkKind::kMixed) return first;
  for (int z = c0.z; z <= c1.z; ++z) {
    for (int y = c0.y; y <= c1.y; ++y) {
      for (int x = c0.x; x <= c1.x; ++x) {
        if (w.chunk_kind({x, y, z}) != first) return ChunkKind::kMixed;
      }
    }
  }
  return first;
}

void fill_uniform(BlockScratch* s, bool solid) {
  const size_t n = s->voxels();
  std::fill(s->occupancy.begin(), s->occupancy.begin() + std::ptrdiff_t(n), solid ? 1.0f : 0.0f);
  std::fill(s->surface.begin(), s->surface.begin() + std::ptrdiff_t(n), uint8_t{0});
  if (!s->faces) return;
  std::fill(s->touched.begin(), s->touched.begin() + std::ptrdiff_t(n), uint8_t{0});
  std::fill(s->coverage.begin(), s->coverage.begin() + std::ptrdiff_t(3 * n), solid ? 1.0f : 0.0f);
}

}  // namespace

void voxelize_block(const VoxelSource& source, BlockScratch* s, BlockCounters* counters) {
  assert(source.m % source.stride == 0);
  s->full_n = source.m / source.stride;
  s->uniform = block_kind(source, s->box);
  if (s->uniform != ChunkKind::kMixed) {
    if (counters) ++counters->closed;
    fill_uniform(s, s->uniform == ChunkKind::kSolid);
    return;
  }
  const size_t vox = s->voxels();
  std::fill(s->volume.begin(), s->volume.begin() + std::ptrdiff_t(vox), int64_t{0});
  std::fill(s->surface.begin(), s->surface.begin() + std::ptrdiff_t(vox), uint8_t{0});
  if (s->faces) std::fill(s->touched.begin(), s->touched.begin() + std::ptrdiff_t(vox), uint8_t{0});
  const glm::ivec3 d = s->box.dims;
  const int a = source.occ_axis;
  s->volume_diff.assign(size_t(d[axis_u(a)]) * size_t(d[axis_v(a)]) * size_t(d[a] + 1), 0);
  for (int axis = 0; axis < 3; ++axis) {
    if (!s->faces && axis != a) continue;
    AxisPass(source, *s, axis, counters).run();
  }
  resolve_volume(source, *s);
  if (s->faces) resolve_faces(*s);
}

void combine_blocks(BlockScratch* into, const BlockScratch& other) {
  const size_t vox = into->voxels();
  if (other.uniform != ChunkKind::kEmpty) into->uniform = ChunkKind::kMixed;  // may hold surface now
  for (size_t i = 0; i < vox; ++i) {
    into->occupancy[i] = std::min(1.0f, into->occupancy[i] + other.occupancy[i]);
    into->surface[i] = uint8_t(into->surface[i] | other.surface[i]);
  }
  if (!into->faces) return;
  for (size_t i = 0; i < 3 * vox; ++i) into->coverage[i] = std::min(1.0f, into->coverage[i] + other.coverage[i]);
  for (size_t i = 0; i < vox; ++i) {
    if (!other.touched[i]) continue;
    for (int f = 0; f < kFaces; ++f) {
      if (!(other.touched[i] & (1u << f))) continue;
      const FaceAccum& b = other.face[i * kFaces + size_t(f)];
      FaceAccum& a = into->face[i * kFaces + size_t(f)];
      if (!(into->touched[i] & (1u << f))) {
        a = b;
        into->touched[i] = uint8_t(into->touched[i] | (1u << f));
        continue;
      }
      const float w = a.weight + b.weight;
      a.albedo = (a.weight * a.albedo + b.weight * b.albedo) / w;
      a.emission = (a.weight * a.emission + b.weight * b.emission) / w;
      const glm::vec3 n = a.weight * a.normal + b.weight * b.normal;
      const float len = glm::length(n);
      a.normal = len > 0.0f ? n / len : glm::vec3(0.0f);
      a.weight = std::min(1.0f, w);
    }
  }
}

std::vector<VoxelBox> split_blocks(const VoxelBox& box, int edge) {
  std::vector<VoxelBox> out;
  if (box.empty()) return out;
  const glm::ivec3 hi = box.hi();
  auto first = [&](int lo) { return int(detail::floor_div64(lo, edge) * edge); };
  for (int z = first(box.lo.z); z < hi.z; z += edge) {
    for (int y = first(box.lo.y); y < hi.y; y += edge) {
      for (int x = first(box.lo.x); x < hi.x; x += edge) {
        const glm::ivec3 lo = glm::max(glm::ivec3(x, y, z), box.lo);
        const glm::ivec3 end = glm::min(glm::ivec3(x, y, z) + edge, hi);
        out.push_back({lo, end - lo});
      }
    }
  }
  return out;
}

FaceSample face_sample(const BlockScratch& b, size_t i, int f) {
  FaceSample out;
  out.occupancy = b.coverage[size_t(face_axis(f)) * b.voxels() + i];
  if (!(b.touched[i] & (1u << f))) return out;
  const FaceAccum& a = b.face[i * kFaces + size_t(f)];
  out.albedo = glm::vec4(a.albedo, a.weight);
  out.normal = a.normal;
  out.emission = a.emission;
  out.flags = kFaceOwn;
  return out;
}

}  // namespace ldc::detail
