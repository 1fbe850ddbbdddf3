// Untangling: dual contouring's placement (sharp features, several sheets in
// one cell) can fold a vertex's triangles through its neighbours'. Placed
// at its mass point (the mean of its crossings) instead, a vertex sits in the
// middle of its crossings, where such folds all but vanish (on the shared
// meshes at 256 cells, an all-mass-point mesh has no self-intersection).
//
// So, in one round: every pair of triangles that intersect (exact
// predicates, detail/triangle_intersection.h) marks its six vertices as
// tangled; every vertex whose cell lies within one cell of a tangled
// vertex's cell moves to its mass point, except corners (planes of three
// independent directions), which stay where the features meet: moving them
// loses the corner and, on the shared meshes, clears no more intersections.
// Sharp features survive everywhere else. On the shared meshes at 256 cells
// this clears every pair that the quad split rule (detail::split_along_02)
// and keep_to_own_sheet leave (fandisk 21 -> 0, spot 11 -> 0, bunny 23 -> 0,
// rocker-arm 2 -> 0), moving 0.01 to 0.1% of the vertices.
//
// Locality: a triangle lies in the 2 x 2 x 1 cells around its edge (grown
// by cell_slack), so two triangles that meet have edge nodes at most
// 2 + 2 slack apart; a vertex's decision reads placed positions at most
// untangle_reach = 4 + ceil(2 slack) cells away. The region is loaded
// with that margin, so every box computes the same bits, and
// patches grow by it (vertex_reach). What one round leaves is counted by
// mesh_quality.
#include <algorithm>
#include <cmath>

#include "contour/detail/region_mesher.h"
#include "contour/detail/triangle_intersection.h"

namespace ldc::detail {
namespace {

// Eigenvalue cut-off (relative to the largest) for a corner: the one kQef uses.
constexpr double kCornerRank = 0.1;

struct Box {
  glm::dvec3 lo, hi;
};

Box box_of(const glm::dvec3* p, const glm::uvec3& t) {
  return {glm::min(glm::min(p[t.x], p[t.y]), p[t.z]), glm::max(glm::max(p[t.x], p[t.y]), p[t.z])};
}

// True when the corners of u that t does not share lie clearly on one side
// of t's plane (a margin far above double rounding for lattice coordinates
// below 2^20), so the pair cannot meet beyond what it shares: most
// neighbouring triangles are dismissed here, without exact arithmetic.
bool clearly_apart(const glm::dvec3* p, const glm::uvec3& t, const glm::uvec3& u) {
  const glm::dvec3 n = glm::cross(p[t.y] - p[t.x], p[t.z] - p[t.x]);
  const double margin = 1e-7 * (std::abs(n.x) + std::abs(n.y) + std::abs(n.z));
  int above = 0, below = 0, other = 0, shared[2] = {0, 0}, n_shared = 0;
  uint32_t third = 0;
  for (int j = 0; j < 3; ++j) {
    if (u[j] == t.x || u[j] == t.y || u[j] == t.z) {
      if (n_shared < 2) shared[n_shared] = int(u[j]);
      ++n_shared;
    } else {
      third = u[j];
    }
  }
  if (n_shared == 2) {
    // Two triangles on one edge a-b meet beyond it only when folded onto
    // each other: their third corners on the same side of a-b. Clearly on
    // opposite sides (the normals of a-b-c and a-b-d point apart) they do not.
    const glm::dvec3 &a = p[shared[0]], &b = p[shared[1]];
    uint32_t c = t.x;
    if (c == uint32_t(shared[0]) || c == uint32_t(shared[1])) c = t.y;
    if (c == uint32_t(shared[0]) || c == uint32_t(shared[1])) c = t.z;
    const glm::dvec3 nc = glm::cross(b - a, p[c] - a), nd = glm::cross(b - a, p[third] - a);
    if (glm::dot(nc, nd) < -1e-7 * glm::length(nc) * glm::length(nd)) return true;
  }
  for (int j = 0; j < 3; ++j) {
    if (u[j] == t.x || u[j] == t.y || u[j] == t.z) continue;
    ++other;
    const double d = glm::dot(n, p[u[j]] - p[t.x]);
    above += d > margin;
    below += d < -margin;
  }
  return other > 0 && (above == other || below == other);
}

bool overlap(const Box& a, const Box& b) {
  return glm::all(glm::lessThanEqual(a.lo, b.hi)) && glm::all(glm::lessThanEqual(b.lo, a.hi));
}

}  // namespace

int RegionMesher::untangle_reach(const ContourConfig& config) {
  if (!config.untangle || config.placement == Placement::kMassPoint) return 0;
  // Vertices leave their cells by up to cell_slack, so triangles that meet
  // can lie 2 * slack further apart.
  return 4 + int(std::ceil(2.0 * config.cell_slack));
}

int RegionMesher::vertex_reach(const ContourConfig& config) {
  return 1 + config.relax_iterations + untangle_reach(config);  // 1: sheets read the face neighbours' corners
}

// Cells (over the cell box) holding a vertex of an intersecting triangle
// pair; only triangles on edges whose node lies in [test_lo, test_hi) are
// tested (against every triangle of the region).
std::vector<uint8_t> RegionMesher::tangled_cells(const glm::ivec3& test_lo, const glm::ivec3& test_hi) const {
  std::vector<uint8_t> tangled(cell_vertex_.size(), 0);
  // Every triangle whose four quad cells have vertices, in lattice coordinates.
  std::vector<glm::dvec3> at(verts_.size());
  for (size_t i = 0; i < verts_.size(); ++i) {
    at[i] = glm::dvec3(verts_[i].cell) + verts_[i].x;
  }
  const glm::ivec3 node_lo = cell_lo_, node_dims = cell_hi_ - cell_lo_ + 1;
  auto node_slot = [&](const glm::ivec3& n, int axis) {
    glm::ivec3 r = n - node_lo;
    return ((size_t(r.z) * size_t(node_dims.y) + size_t(r.y)) * size_t(node_dims.x) + size_t(r.x)) * 3 + size_t(axis);
  };
  std::vector<int32_t> first(size_t(node_dims.x) * node_dims.y * node_dims.z * 3, -1);
  std::vector<glm::uvec3> tris;
  std::vector<glm::ivec3> tri_node;
  for (const Region::EdgeRef& e : region_.crossing_edges()) {
    Quad q;
    if (!edge_quad(e.axis, e.node, &q)) continue;
    int32_t vi[4];
    bool complete = true;
    for (int k = 0; k < 4; ++k) {
      vi[k] = in_cell_box(q.cell[k]) ? vertex_index(q.cell[k], q.sheet[k]) : -1;
      complete = complete && vi[k] >= 0;
    }
    if (!complete) continue;
    int tri[2][3];
    split(q, tri);
    first[node_slot(e.node, e.axis)] = int32_t(tris.size());
    for (const auto& t : tri) {
      tris.push_back(glm::uvec3(uint32_t(vi[t[0]]), uint32_t(vi[t[1]]), uint32_t(vi[t[2]])));
      tri_node.push_back(e.node);
    }
  }
  auto mark = [&](const glm::uvec3& t) {
    for (int j = 0; j < 3; ++j) tangled[cell_index(verts_[t[j]].cell)] = 1;
  };
  std::vector<Box> boxes(tris.size());
  for (size_t a = 0; a < tris.size(); ++a) boxes[a] = box_of(at.data(), tris[a]);
  const glm::ivec3 node_hi = node_lo + node_dims - 1;  // inclusive
  for (size_t a = 0; a < tris.size(); ++a) {
    if (!in_box(tri_node[a], test_lo, test_hi)) continue;
    const Box& tb = boxes[a];
    // A triangle on the edge from node m along `axis` spans [m, m + 1] along
    // it and [m - 1, m + 1] across (each grown by the slack): only these
    // nodes can hold one whose box meets tb.
    const double slack = config_.cell_slack;
    const glm::ivec3 m_lo = glm::max(glm::ivec3(glm::ceil(tb.lo - 1.0 - slack)), node_lo);
    for (int axis = 0; axis < 3; ++axis) {
      glm::dvec3 reach_hi = tb.hi + 1.0 + slack;
      reach_hi[axis] = tb.hi[axis] + slack;
      const glm::ivec3 m_hi = glm::min(glm::ivec3(glm::floor(reach_hi)), node_hi);
      for (int mz = m_lo.z; mz <= m_hi.z; ++mz)
        for (int my = m_lo.y; my <= m_hi.y; ++my)
          for (int mx = m_lo.x; mx <= m_hi.x; ++mx) {
            const int32_t f = first[node_slot({mx, my, mz}, axis)];
            if (f < 0) continue;
            for (size_t b = size_t(f); b < size_t(f) + 2; ++b) {
              // Each pair once: from its first triangle, unless that one is not tested.
              if (b == a || (b < a && in_box(tri_node[b], test_lo, test_hi))) continue;
              if (!overlap(tb, boxes[b]) || clearly_apart(at.data(), tris[a], tris[b]) ||
                  clearly_apart(at.data(), tris[b], tris[a]) || !triangle_pair_intersects(at.data(), tris[a], tris[b])) {
                continue;
              }
              mark(tris[a]);
              mark(tris[b]);
            }
          }
    }
  }
  return tangled;
}

void RegionMesher::untangle(const glm::ivec3& decide_lo, const glm::ivec3& decide_hi) {
  if (untangle_reach(config_) == 0) return;
  // Vertices in the decide box look one cell around; the triangles holding
  // the vertices there have their nodes in [decide_lo - 1, decide_hi + 2).
  const std::vector<uint8_t> tangled = tangled_cells(decide_lo - 1, decide_hi + 2);
  for (CellVertex& v : verts_) {
    if (!in_box(v.cell, decide_lo, decide_hi)) continue;
    bool near = false;
    for (int dz = -1; dz <= 1 && !near; ++dz)
      for (int dy = -1; dy <= 1 && !near; ++dy)
        for (int dx = -1; dx <= 1 && !near; ++dx) {
          const glm::ivec3 c = v.cell + glm::ivec3(dx, dy, dz);
          near = in_cell_box(c) && tangled[cell_index(c)];
        }
    if (!near || qef_rank(v.qef, kCornerRank) == 3) continue;
    v.untangled = v.x != v.mass;
    v.x = v.mass;
  }
}

}  // namespace ldc::detail
