// Marching cubes on LDC data, the baseline: vertices at the edge crossings,
// normals unused for placement. Instead of the usual 256-case table, each
// cube's polygons are traced face by face: walking a face counter-clockwise
// seen from outside the cube, every run of inside corners gives one segment
// from the crossing entering the run to the crossing leaving it (so a face
// with two diagonal inside corners separates them, the same from both cubes
// sharing the face). The segments close into loops, fanned into triangles.
#include <array>
#include <atomic>
#include <mutex>
#include <unordered_map>

#include <tbb/parallel_for.h>

#include "contour/contour.h"
#include "contour/detail/region.h"

namespace ldc {
namespace {

// Cube corners by bits (x, y, z); cube edges by (axis, offset of the lower corner).
struct CubeEdge {
  int axis;
  glm::ivec3 offset;
};

// The six faces as corner loops, counter-clockwise seen from outside the cube.
constexpr int kFaces[6][4] = {
    {0, 4, 6, 2},  // x = 0: (0,0,0) (0,0,1) (0,1,1) (0,1,0), normal -x
    {1, 3, 7, 5},  // x = 1
    {0, 1, 5, 4},  // y = 0
    {2, 6, 7, 3},  // y = 1
    {0, 2, 3, 1},  // z = 0
    {4, 5, 7, 6},  // z = 1
};

glm::ivec3 corner(int c) { return {c & 1, (c >> 1) & 1, (c >> 2) & 1}; }

// The cube edge between two corners that differ in one coordinate.
CubeEdge edge_between(int a, int b) {
  glm::ivec3 pa = corner(a), pb = corner(b);
  CubeEdge e;
  for (int i = 0; i < 3; ++i)
    if (pa[i] != pb[i]) e.axis = i;
  e.offset = glm::min(pa, pb);
  return e;
}

class CubeMesher {
 public:
  CubeMesher(const World& w, const detail::Region& r, ContourMesh& out) : w_(w), r_(r), out_(out) {}

  void cube(const glm::ivec3& cell) {
    bool in[8];
    int count = 0;
    for (int c = 0; c < 8; ++c) count += in[c] = r_.inside(cell + corner(c));
    if (count == 0 || count == 8) return;
    // next[e] = the crossing that follows crossing e on the surface loop.
    std::array<int, 12> next;
    next.fill(-1);
    std::array<uint32_t, 12> vertex_of;
    for (const auto& f : kFaces) trace_face(cell, f, in, next, vertex_of);
    emit_loops(next, vertex_of);
  }

 private:
  static int edge_slot(const CubeEdge& e) { return e.axis * 4 + e.offset[(e.axis + 1) % 3] + 2 * e.offset[(e.axis + 2) % 3]; }

  uint32_t vertex(const glm::ivec3& cell, const CubeEdge& e) {
    glm::ivec3 node = cell + e.offset;
    uint64_t key = (uint64_t(uint32_t(node.x + (1 << 20))) << 43) ^ (uint64_t(uint32_t(node.y + (1 << 20))) << 22) ^
                   (uint64_t(uint32_t(node.z + (1 << 20))) << 1) ^ uint64_t(e.axis) << 62;
    auto it = ids_.find(key);
    if (it != ids_.end()) return it->second;
    const detail::EdgeCrossing* x = r_.crossing(e.axis, node);
    glm::dvec3 p(node);
    p[e.axis] += x->t;
    uint32_t id = uint32_t(out_.positions.size());
    out_.positions.push_back(w_.lattice().to_world(p));
    out_.normals.push_back(x->normal);
    out_.vertex_material.push_back(x->material);
    ids_.emplace(key, id);
    return id;
  }

  void trace_face(const glm::ivec3& cell, const int (&f)[4], const bool* in, std::array<int, 12>& next,
                  std::array<uint32_t, 12>& vertex_of) {
    for (int k = 0; k < 4; ++k) {
      int a = f[k], b = f[(k + 1) % 4];
      if (in[a] || !in[b]) continue;  // look for an edge entering a run of inside corners
      int j = (k + 1) % 4;
      while (in[f[(j + 1) % 4]]) j = (j + 1) % 4;  // the run ends at corner f[j]
      CubeEdge enter = edge_between(a, b), leave = edge_between(f[j], f[(j + 1) % 4]);
      int s = edge_slot(enter), t = edge_slot(leave);
      vertex_of[s] = vertex(cell, enter);
      vertex_of[t] = vertex(cell, leave);
      next[s] = t;
    }
  }

  void emit_loops(std::array<int, 12>& next, const std::array<uint32_t, 12>& vertex_of) {
    for (int start = 0; start < 12; ++start) {
      if (next[start] < 0) continue;
      std::array<uint32_t, 12> loop;
      int n = 0;
      for (int e = start; e >= 0 && n < 12;) {
        loop[n++] = vertex_of[e];
        int following = next[e];
        next[e] = -1;
        e = following == start ? -1 : following;
      }
      for (int i = 1; i + 1 < n; ++i) {
        out_.triangles.push_back({loop[0], loop[i], loop[i + 1]});
        out_.triangle_material.push_back(out_.vertex_material[loop[0]]);
      }
    }
  }

  const World& w_;
  const detail::Region& r_;
  ContourMesh& out_;
  std::unordered_map<uint64_t, uint32_t> ids_;
};

}  // namespace

Result<ContourMesh> marching_cubes(const World& world, Context* ctx) {
  const int c = world.chunk_size();
  std::vector<glm::ivec3> chunks;
  const glm::ivec3 lo = world.chunk_origin() - 1, hi = world.chunk_origin() + world.chunk_dims();
  for (int z = lo.z; z < hi.z; ++z)
    for (int y = lo.y; y < hi.y; ++y)
      for (int x = lo.x; x < hi.x; ++x) chunks.emplace_back(x, y, z);
  std::vector<ContourMesh> parts(chunks.size());
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t i) {
    if (ctx && ctx->cancelled()) return;
    glm::ivec3 cell_lo = chunks[i] * c, cell_hi = cell_lo + c;
    bool quiet = true;  // the chunk and its upper neighbours, whose nodes its cells read
    for (int k = 0; k < 8; ++k) quiet = quiet && world.chunk_kind(chunks[i] + corner(k)) == world.chunk_kind(chunks[i]);
    if (quiet && world.chunk_kind(chunks[i]) != ChunkKind::kMixed) return;
    detail::Region region;
    region.load(world, cell_lo, cell_hi + 1, cell_lo, cell_hi);
    if (region.uniform()) return;
    CubeMesher mesher(world, region, parts[i]);
    for (int z = cell_lo.z; z < cell_hi.z; ++z)
      for (int y = cell_lo.y; y < cell_hi.y; ++y)
        for (int x = cell_lo.x; x < cell_hi.x; ++x) mesher.cube({x, y, z});
  });
  if (ctx && ctx->cancelled()) return Status(ErrorCode::kCancelled, "marching cubes: cancelled");
  ContourMesh out;  // chunk parts concatenated; vertices on chunk borders appear in both parts
  for (const ContourMesh& p : parts) {
    uint32_t base = uint32_t(out.positions.size());
    out.positions.insert(out.positions.end(), p.positions.begin(), p.positions.end());
    out.normals.insert(out.normals.end(), p.normals.begin(), p.normals.end());
    out.vertex_material.insert(out.vertex_material.end(), p.vertex_material.begin(), p.vertex_material.end());
    for (const glm::uvec3& t : p.triangles) out.triangles.push_back(t + glm::uvec3(base));
    out.triangle_material.insert(out.triangle_material.end(), p.triangle_material.begin(), p.triangle_material.end());
  }
  return out;
}

}  // namespace ldc
