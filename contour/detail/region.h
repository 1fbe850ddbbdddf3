// A box of lattice nodes read out of a World: each node's sign and, for every
// edge from a node to its +axis neighbour whose ends differ, the crossing
// that edge contributes (see the rules in contour.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/world.h"

namespace ldc::detail {

// The unit lattice step along `axis`.
inline glm::ivec3 axis_unit(int axis) {
  glm::ivec3 e(0);
  e[axis] = 1;
  return e;
}

// lo <= p < hi in every coordinate (written out: glm's vector compares
// were left as calls in the meshers' inner loops).
inline bool in_box(const glm::ivec3& p, const glm::ivec3& lo, const glm::ivec3& hi) {
  return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x < hi.x && p.y < hi.y && p.z < hi.z;
}

struct EdgeCrossing {
  float t = 0.0f;           // position along the edge from its lower node, in (0, 1)
  glm::vec3 normal{0.0f};   // unit, out of the solid
  uint16_t material = 0;
};

class Region {
 public:
  // Reads nodes [lo, hi) (global node coordinates, hi exclusive). Edge counts
  // (multi-crossing, thin) cover only edges whose lower node is in [count_lo, count_hi).
  // With a stride s (a power of two dividing the chunk size), the region's
  // node n is the world's node s n and its edges are s cells long: the
  // lattice of coarsen(world, log2 s), read from `world` as that world's
  // Region would read it (the same signs and crossings).
  void load(const World& world, const glm::ivec3& lo, const glm::ivec3& hi,
            const glm::ivec3& count_lo, const glm::ivec3& count_hi, int stride = 1);

  glm::ivec3 lo() const { return lo_; }
  glm::ivec3 hi() const { return hi_; }
  bool contains(const glm::ivec3& node) const {
    return in_box(node, lo_, hi_);
  }
  size_t index(const glm::ivec3& node) const {
    glm::ivec3 r = node - lo_;
    return (size_t(r.z) * size_.y + size_t(r.y)) * size_.x + size_t(r.x);
  }
  bool inside(const glm::ivec3& node) const { return signs_[index(node)] != 0; }
  // Bit c set when corner c (bits x, y, z) of the cell whose lowest node is
  // `cell` is inside: the index of detail::cell_sheets. Its 8 nodes must be in the region.
  unsigned cell_corners(const glm::ivec3& cell) const {
    unsigned bits = 0;
    for (int c = 0; c < 8; ++c) bits |= unsigned(inside(cell + glm::ivec3(c & 1, (c >> 1) & 1, c >> 2))) << c;
    return bits;
  }
  size_t stride(int axis) const {
    return axis == 0 ? 1 : axis == 1 ? size_t(size_.x) : size_t(size_.x) * size_t(size_.y);
  }
  // The crossing of the edge from `node` along `axis`, or nullptr when the
  // edge's ends agree. Requires node and node + e_axis in the region.
  const EdgeCrossing* crossing(int axis, const glm::ivec3& node) const {
    int32_t i = edge_[axis][index(node)];
    return i < 0 ? nullptr : &crossings_[size_t(i)];
  }

  // The lower node and axis of every edge with a crossing, in load order.
  struct EdgeRef {
    glm::ivec3 node;
    int axis;
  };
  const std::vector<EdgeRef>& crossing_edges() const { return edges_with_crossing_; }

  // The crossings of the four edges along `axis` of the cell whose lowest
  // node is `cell`, at offsets (0,0), (1,0), (0,1), (1,1) in (u, v).
  void cell_edges(int axis, const glm::ivec3& cell, const EdgeCrossing* out[4]) const {
    const size_t base = index(cell);
    const size_t su = stride(axis_u(axis)), sv = stride(axis_v(axis));
    const std::vector<int32_t>& e = edge_[axis];
    const size_t at[4] = {base, base + su, base + sv, base + su + sv};
    for (int k = 0; k < 4; ++k) out[k] = e[at[k]] < 0 ? nullptr : &crossings_[size_t(e[at[k]])];
  }

  size_t multi_crossing_edges() const { return multi_; }
  size_t thin_edges() const { return thin_; }
  // True when no node differs from the first: nothing to mesh.
  bool uniform() const { return uniform_; }

 private:
  struct RayPoint {
    double depth;
    const PackedPoint* p;
  };
  void load_tile(int axis, int tu, int tv);
  void cache_chunks(const World& world);
  // The chunk data covering chunk coordinate ch (within the region's chunks), or nullptr.
  size_t chunk_slot(const glm::ivec3& ch) const {
    glm::ivec3 r = ch - chunk_lo_;
    return (size_t(r.z) * chunk_dims_.y + size_t(r.y)) * chunk_dims_.x + size_t(r.x);
  }
  const Chunk* chunk_at(const glm::ivec3& ch) const { return chunks_[chunk_slot(ch)]; }
  ChunkKind kind_at(const glm::ivec3& ch) const { return kinds_[chunk_slot(ch)]; }
  void record_ray(int axis, const glm::ivec3& first_node, bool start_inside,
                  const std::vector<RayPoint>& pts);
  void record_edge(int axis, const glm::ivec3& node, bool lower_inside,
                   const RayPoint* first, const RayPoint* last, int count);

  bool counted(const glm::ivec3& node) const {
    return in_box(node, count_lo_, count_hi_);
  }

  glm::ivec3 lo_{0}, hi_{0}, size_{0}, count_lo_{0}, count_hi_{0};
  int chunk_size_ = 32;  // of the world, in its cells
  int stride_ = 1;
  // The chunks the region overlaps, so rays need no lookups in the world's table.
  glm::ivec3 chunk_lo_{0}, chunk_dims_{0};
  std::vector<const Chunk*> chunks_;
  std::vector<ChunkKind> kinds_;
  std::vector<uint8_t> signs_;
  std::array<std::vector<int32_t>, 3> edge_;
  std::vector<EdgeCrossing> crossings_;
  std::vector<EdgeRef> edges_with_crossing_;
  std::vector<RayPoint> scratch_;
  std::vector<const RayFamily*> tile_families_;
  std::vector<uint8_t> tile_uniform_inside_;
  std::vector<uint32_t> tile_offsets_;
  size_t multi_ = 0, thin_ = 0;
  bool uniform_ = true;
};

}  // namespace ldc::detail
