#include "contour/detail/region.h"

#include <algorithm>
#include <cmath>

#include "ldc/internal/ray_math.h"

namespace ldc::detail {

void Region::load(const World& world, const glm::ivec3& lo, const glm::ivec3& hi,
                  const glm::ivec3& count_lo, const glm::ivec3& count_hi, int stride) {
  // Reused between loads: clear only the edge entries the last load set.
  for (const EdgeRef& e : edges_with_crossing_) edge_[e.axis][index(e.node)] = -1;
  lo_ = lo;
  hi_ = hi;
  count_lo_ = count_lo;
  count_hi_ = count_hi;
  size_ = hi - lo;
  chunk_size_ = world.chunk_size();
  stride_ = stride;
  const size_t n = size_t(size_.x) * size_t(size_.y) * size_t(size_.z);
  signs_.assign(n, 0);
  for (auto& e : edge_) {
    if (e.size() < n) e.resize(n, -1);  // all -1 after the clearing above: any prefix is clean
  }
  crossings_.clear();
  edges_with_crossing_.clear();
  multi_ = thin_ = 0;
  cache_chunks(world);
  const int c = chunk_size_ / stride_;
  for (int a = 0; a < 3; ++a) {
    const int u = axis_u(a), v = axis_v(a);
    // Tile by tile: the rays of one chunk column share their families.
    for (int tv = floor_div(lo[v], c); tv <= floor_div(hi[v] - 1, c); ++tv) {
      for (int tu = floor_div(lo[u], c); tu <= floor_div(hi[u] - 1, c); ++tu) load_tile(a, tu, tv);
    }
  }
  // The lattice is connected: without a sign-changing edge every node agrees.
  uniform_ = crossings_.empty();
}

// The rays of axis `axis` in one chunk column (tile (tu, tv) of the u, v
// plane) that cross the region, walked row by row with running point offsets.
void Region::load_tile(int axis, int tu, int tv) {
  // c: chunk size in cells of the world; cn: in nodes of the region (cells of stride_).
  const int c = chunk_size_, cn = c / stride_, u = axis_u(axis), v = axis_v(axis);
  const int k0 = floor_div(lo_[axis], cn), k1 = floor_div(hi_[axis] - 1, cn);
  const int64_t q = int64_t(depth_steps_per_cell(c)) * stride_;  // depth steps per region cell
  const int64_t lo = int64_t(lo_[axis]) * q, hi = int64_t(hi_[axis]) * q;
  const int span = k1 - k0 + 1;  // 2 or 3 for a chunk, more for a whole world
  std::vector<const RayFamily*>& fam = tile_families_;
  std::vector<uint8_t>& uniform_inside = tile_uniform_inside_;
  std::vector<uint32_t>& offset = tile_offsets_;
  fam.assign(size_t(span), nullptr);
  uniform_inside.assign(size_t(span), 0);
  offset.assign(size_t(span), 0);
  glm::ivec3 ch;
  ch[u] = tu;
  ch[v] = tv;
  for (int k = k0; k <= k1; ++k) {
    ch[axis] = k;
    const Chunk* data = chunk_at(ch);
    fam[k - k0] = data ? &data->axis[axis] : nullptr;
    uniform_inside[k - k0] = data ? false : kind_at(ch) == ChunkKind::kSolid;
  }
  const int u_lo = std::max(lo_[u], tu * cn), u_hi = std::min(hi_[u], tu * cn + cn);
  const int v_lo = std::max(lo_[v], tv * cn), v_hi = std::min(hi_[v], tv * cn + cn);
  std::vector<RayPoint>& pts = scratch_;
  for (int rv = v_lo; rv < v_hi; ++rv) {
    const int row = (rv - tv * cn) * stride_ * c;
    int at = row + (u_lo - tu * cn) * stride_;  // the family ray `offset` points at
    for (int k = 0; k < span; ++k) offset[k] = fam[k] ? fam[k]->first_point(at) : 0;
    for (int ru = u_lo; ru < u_hi; ++ru) {
      const int ray = row + (ru - tu * cn) * stride_;
      for (; at < ray; ++at)  // rays between every stride-th one (none at stride 1)
        for (int k = 0; k < span; ++k)
          if (fam[k]) offset[k] += fam[k]->point_count(at);
      bool state = uniform_inside[0];
      pts.clear();
      for (int k = 0; k < span; ++k) {
        if (!fam[k]) continue;
        const std::span<const PackedPoint> ray_points(fam[k]->all_points().data() + offset[k], fam[k]->point_count(ray));
        offset[k] += uint32_t(ray_points.size());
        if (k == 0) state = fam[0]->starts_inside(ray, ray_points);
        const int64_t base = int64_t(k + k0) * kDepthSteps;
        for (const PackedPoint& p : ray_points) {
          int64_t d = base + p.depth;
          if (d < lo) state = !state;
          else if (d < hi) pts.push_back({double(d) / double(q), &p});
        }
      }
      at = ray + 1;
      glm::ivec3 first;
      first[axis] = lo_[axis];
      first[u] = ru;
      first[v] = rv;
      record_ray(axis, first, state, pts);
    }
  }
}

void Region::cache_chunks(const World& world) {
  const int c = chunk_size_ / stride_;  // in region nodes
  chunk_lo_ = glm::ivec3(floor_div(lo_.x, c), floor_div(lo_.y, c), floor_div(lo_.z, c));
  glm::ivec3 chunk_hi(floor_div(hi_.x - 1, c), floor_div(hi_.y - 1, c), floor_div(hi_.z - 1, c));
  chunk_dims_ = chunk_hi - chunk_lo_ + 1;
  chunks_.assign(size_t(chunk_dims_.x) * chunk_dims_.y * chunk_dims_.z, nullptr);
  kinds_.assign(chunks_.size(), ChunkKind::kEmpty);
  for (int z = 0; z < chunk_dims_.z; ++z)
    for (int y = 0; y < chunk_dims_.y; ++y)
      for (int x = 0; x < chunk_dims_.x; ++x) {
        glm::ivec3 ch = chunk_lo_ + glm::ivec3(x, y, z);
        chunks_[chunk_slot(ch)] = world.chunk(ch);
        kinds_[chunk_slot(ch)] = world.chunk_kind(ch);
      }
}

// Walks the points of one ray edge by edge: the points between nodes n and
// n + 1 form edge n. X rays also write the node signs, run by run.
void Region::record_ray(int axis, const glm::ivec3& first_node, bool start_inside,
                        const std::vector<RayPoint>& pts) {
  bool state = start_inside;
  uint8_t* signs = axis == 0 ? &signs_[index(first_node)] : nullptr;  // x is the fastest index
  int filled = 0;  // nodes [lo, lo + filled) of this ray have their sign
  glm::ivec3 node = first_node;
  for (size_t i = 0; i < pts.size();) {
    const int n = int(std::floor(pts[i].depth));
    size_t j = i;
    while (j < pts.size() && pts[j].depth < n + 1) ++j;
    const int count = int(j - i);
    if (signs) {  // nodes up to n carry the state before these points
      std::fill(signs + filled, signs + (n - lo_[axis] + 1), uint8_t(state));
      filled = n - lo_[axis] + 1;
    }
    node[axis] = n;
    if (n + 1 < hi_[axis]) record_edge(axis, node, state, &pts[i], &pts[j - 1], count);
    if (count & 1) state = !state;
    i = j;
  }
  if (signs) std::fill(signs + filled, signs + size_[0], uint8_t(state));
}

void Region::record_edge(int axis, const glm::ivec3& node, bool lower_inside,
                         const RayPoint* first, const RayPoint* last, int count) {
  bool upper_inside = lower_inside != bool(count & 1);
  if (upper_inside == lower_inside) {
    thin_ += counted(node);
    return;
  }
  if (count >= 3) multi_ += counted(node);
  // The crossing nearest the outside end: what is seen from outside.
  const RayPoint& chosen = lower_inside ? *last : *first;
  EdgeCrossing x;
  x.t = float(chosen.depth - node[axis]);
  x.normal = decode_normal(chosen.p->normal);
  x.material = chosen.p->material;
  edge_[axis][index(node)] = int32_t(crossings_.size());
  crossings_.push_back(x);
  edges_with_crossing_.push_back({node, axis});
}

}  // namespace ldc::detail
