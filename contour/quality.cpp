// mesh_quality: topology (edges, fans) and shape (angles, area, volume).
//
// Topology is read vertex by vertex from a vertex -> triangles table (built
// with a counting sort, so linear): the edges at a vertex are named by their
// other end, and a short sort of the 2k edge ends of a vertex's k triangles
// groups the triangles sharing each edge. Each undirected edge is counted
// once, at its smaller end. A union-find over the vertex's triangles joined
// through shared edges counts its fans.
//
// Triangles with an index out of range or a repeated index have no edges
// and no area: they are counted as degenerate and left out of the topology
// (their edges would cancel each other and make clean neighbours look broken).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "contour/contour.h"

namespace ldc {
namespace {

bool has_edges(const ContourMesh& mesh, const glm::uvec3& tri) {
  const size_t n = mesh.vertex_count();
  return tri.x < n && tri.y < n && tri.z < n && tri.x != tri.y && tri.y != tri.z && tri.x != tri.z;
}

// Triangles around each vertex: triangle[offset[v] .. offset[v + 1]).
struct Incidence {
  std::vector<size_t> offset;
  std::vector<uint32_t> triangle;
};

Incidence incidence(const ContourMesh& mesh) {
  Incidence table;
  table.offset.assign(mesh.vertex_count() + 1, 0);
  for (const glm::uvec3& tri : mesh.triangles) {
    if (!has_edges(mesh, tri)) continue;
    for (int k = 0; k < 3; ++k) ++table.offset[tri[k] + 1];
  }
  for (size_t v = 0; v < mesh.vertex_count(); ++v) table.offset[v + 1] += table.offset[v];
  table.triangle.resize(table.offset.back());
  std::vector<size_t> next(table.offset.begin(), table.offset.end() - 1);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const glm::uvec3& tri = mesh.triangles[t];
    if (!has_edges(mesh, tri)) continue;
    for (int k = 0; k < 3; ++k) table.triangle[next[tri[k]]++] = static_cast<uint32_t>(t);
  }
  return table;
}

// One end of an edge at the vertex being scanned: the edge's other end, the
// triangle (local index among the vertex's triangles) and the direction in
// which that triangle walks the edge.
struct EdgeEnd {
  uint32_t other;
  uint32_t local;
  bool outgoing;  // vertex -> other
  bool operator<(const EdgeEnd& e) const { return other < e.other; }
};

class FanScanner {
 public:
  FanScanner(const ContourMesh& mesh, MeshQuality& quality) : mesh_(mesh), quality_(quality) {}

  // Counts the edges from v to larger vertices and whether v is non-manifold.
  void scan(uint32_t v, const uint32_t* triangles, size_t count) {
    ends_.clear();
    parent_.resize(count);
    for (uint32_t i = 0; i < count; ++i) {
      parent_[i] = i;
      const glm::uvec3& tri = mesh_.triangles[triangles[i]];
      const int k = tri.x == v ? 0 : tri.y == v ? 1 : 2;
      ends_.push_back({tri[(k + 1) % 3], i, true});
      ends_.push_back({tri[(k + 2) % 3], i, false});
    }
    std::sort(ends_.begin(), ends_.end());
    bool nonmanifold = false;
    for (size_t i = 0; i < ends_.size();) {
      size_t j = i;
      size_t outgoing = 0;
      for (; j < ends_.size() && ends_[j].other == ends_[i].other; ++j) {
        outgoing += ends_[j].outgoing ? 1 : 0;
        unite(ends_[i].local, ends_[j].local);
      }
      const size_t uses = j - i;
      nonmanifold = nonmanifold || uses > 2;
      if (ends_[i].other > v) count_edge(uses, outgoing);
      i = j;
    }
    size_t fans = 0;
    for (uint32_t i = 0; i < count; ++i) fans += find(i) == i ? 1 : 0;
    if (nonmanifold || fans > 1) ++quality_.nonmanifold_vertices;
  }

 private:
  void count_edge(size_t uses, size_t outgoing) {
    if (uses == 1) ++quality_.boundary_edges;
    if (uses > 2) ++quality_.nonmanifold_edges;
    if (2 * outgoing != uses) ++quality_.unpaired_edges;  // a->b used as often as b->a?
  }
  uint32_t find(uint32_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void unite(uint32_t a, uint32_t b) { parent_[find(a)] = find(b); }

  const ContourMesh& mesh_;
  MeshQuality& quality_;
  std::vector<EdgeEnd> ends_;
  std::vector<uint32_t> parent_;
};

void add_topology(const ContourMesh& mesh, MeshQuality& quality) {
  const Incidence table = incidence(mesh);
  FanScanner scanner(mesh, quality);
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const size_t count = table.offset[v + 1] - table.offset[v];
    if (count == 0) {
      ++quality.unused_vertices;
      continue;
    }
    scanner.scan(v, table.triangle.data() + table.offset[v], count);
  }
}

// The smallest angle is the one opposite the shortest edge; |cross| is twice
// the area whichever corner it is taken at, so one atan2 per triangle does.
double min_angle_deg(const glm::dvec3 (&p)[3], double cross_length) {
  int shortest = 0;  // edge k joins p[k] and p[(k + 1) % 3]
  double best = INFINITY;
  for (int k = 0; k < 3; ++k) {
    const double length = glm::dot(p[(k + 1) % 3] - p[k], p[(k + 1) % 3] - p[k]);
    if (length < best) {
      best = length;
      shortest = k;
    }
  }
  const glm::dvec3& apex = p[(shortest + 2) % 3];
  const double dot = glm::dot(p[shortest] - apex, p[(shortest + 1) % 3] - apex);
  return std::atan2(cross_length, dot) * (180.0 / std::numbers::pi);
}

void add_shape(const ContourMesh& mesh, MeshQuality& quality) {
  const glm::dvec3 origin = mesh.positions.empty() ? glm::dvec3(0.0) : mesh.positions.front();
  double six_volume = 0.0;
  double min_angle = INFINITY;
  for (const glm::uvec3& tri : mesh.triangles) {
    if (!has_edges(mesh, tri)) {
      ++quality.degenerate_triangles;
      ++quality.min_angle_histogram[0];
      min_angle = 0.0;
      continue;
    }
    // Relative to a point of the mesh: far from the world origin the
    // per-triangle volume terms would be huge and cancel badly.
    const glm::dvec3 p[3] = {mesh.positions[tri.x] - origin, mesh.positions[tri.y] - origin,
                             mesh.positions[tri.z] - origin};
    const glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const glm::dvec3 cross = glm::cross(e1, e2);
    const double cross2 = glm::dot(cross, cross);
    // Zero area, also relative to the edges: sin(angle) below 1e-15 is rounding.
    if (cross2 <= 1e-30 * glm::dot(e1, e1) * glm::dot(e2, e2)) ++quality.degenerate_triangles;
    quality.area += 0.5 * std::sqrt(cross2);
    six_volume += glm::dot(p[0], glm::cross(p[1], p[2]));
    const double angle = min_angle_deg(p, std::sqrt(cross2));
    min_angle = std::min(min_angle, angle);
    ++quality.min_angle_histogram[std::clamp(static_cast<int>(angle / 10.0), 0, 5)];
  }
  quality.volume = six_volume / 6.0;
  quality.min_angle_deg = mesh.triangles.empty() ? 0.0 : min_angle;
}

}  // namespace

MeshQuality mesh_quality(const ContourMesh& mesh) {
  MeshQuality quality;
  quality.triangles = mesh.triangle_count();
  quality.vertices = mesh.vertex_count();
  add_topology(mesh, quality);
  add_shape(mesh, quality);
  return quality;
}

}  // namespace ldc
