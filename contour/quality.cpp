// mesh_quality: topology (edges, fans), self-intersections and shape
// (angles, area, volume).
//
// Topology is read vertex by vertex from a vertex -> triangles table (built
// with a counting sort, so linear): the edges at a vertex are named by their
// other end, and a short sort of the 2k edge ends of a vertex's k triangles
// groups the triangles sharing each edge. Each undirected edge is counted
// once, at its smaller end. A union-find over the vertex's triangles joined
// through shared edges counts its fans. A vertex is non-manifold when its
// triangles form more than one fan or it has an edge used by more than two
// triangles (then the triangles around that edge are fans of their own): the
// same vertices CGAL's orient_polygon_soup finds singular, on a consistently
// oriented mesh.
//
// Self-intersections: every triangle's bounding box goes into the cells of a
// uniform grid it overlaps (cells about twice the mean box size); the (cell,
// triangle) entries are sorted by cell, and the cells are scanned in
// parallel. A pair whose boxes overlap is tested only in the cell that holds
// the low corner of the overlap, so once, and with exact predicates
// (contour/detail/triangle_intersection.h), so the count is the same for any
// thread count.
//
// Triangles with an index out of range or a repeated index have no edges
// and no area: they are counted as degenerate and left out of the topology
// (their edges would cancel each other and make clean neighbours look broken)
// and of the self-intersection test, as are triangles whose corners are
// exactly collinear.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include "contour/contour.h"
#include "contour/detail/grid_cell.h"
#include "contour/detail/incidence.h"
#include "contour/detail/self_intersections.h"
#include "contour/detail/triangle_intersection.h"

namespace ldc {
namespace {

bool has_edges(const ContourMesh& mesh, const glm::uvec3& tri) {
  const size_t n = mesh.vertex_count();
  return tri.x < n && tri.y < n && tri.z < n && tri.x != tri.y && tri.y != tri.z && tri.x != tri.z;
}

using detail::Incidence;
using detail::incidence;

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

// --- Self-intersections -------------------------------------------------------

struct Box {
  glm::dvec3 lo, hi;
};

bool boxes_overlap(const Box& a, const Box& b) {
  return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y && a.lo.z <= b.hi.z &&
         b.lo.z <= a.hi.z;
}

// A uniform grid over the mesh's box; cell() is monotone in each coordinate,
// so a point inside a triangle's box falls in one of the box's cells.
struct Grid {
  glm::dvec3 origin{0.0};
  double size = 1.0;
  glm::ivec3 dims{1};

  glm::ivec3 cell(const glm::dvec3& p) const { return detail::clamped_grid_cell(p, origin, size, dims); }
  uint64_t key(const glm::ivec3& c) const {
    return (uint64_t(c.z) * uint64_t(dims.y) + uint64_t(c.y)) * uint64_t(dims.x) + uint64_t(c.x);
  }
  uint64_t cells_of(const Box& b) const {
    const glm::ivec3 lo = cell(b.lo), hi = cell(b.hi);
    return uint64_t(hi.x - lo.x + 1) * uint64_t(hi.y - lo.y + 1) * uint64_t(hi.z - lo.z + 1);
  }
};

struct Entry {
  uint64_t cell;
  uint32_t triangle;
  bool single_cell;  // the triangle's box lies in this one cell
  bool operator<(const Entry& e) const { return cell != e.cell ? cell < e.cell : triangle < e.triangle; }
};

// The triangles to test and their boxes: every triangle with edges and
// corners not on one line, or with `hot`, only those that are hot or whose
// box meets the box around the hot ones (the rest cannot meet a hot one).
struct TriangleBoxes {
  std::vector<uint32_t> ids;   // the triangles to test, ascending
  std::unique_ptr<Box[]> box;  // by triangle index; not zeroed: written for ids
};

TriangleBoxes triangle_boxes(const ContourMesh& mesh, const std::vector<uint8_t>* hot) {
  const size_t n = mesh.triangle_count();
  TriangleBoxes out{{}, std::unique_ptr<Box[]>(new Box[n])};
  std::vector<uint8_t> take(n, 0);
  auto box_of = [&](size_t t) {
    const glm::uvec3& tri = mesh.triangles[t];
    const glm::dvec3 &a = mesh.positions[tri.x], &b = mesh.positions[tri.y], &c = mesh.positions[tri.z];
    return Box{glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))};
  };
  Box around{glm::dvec3(-INFINITY), glm::dvec3(INFINITY)};  // everything, without hot
  if (hot) {
    around = {glm::dvec3(INFINITY), glm::dvec3(-INFINITY)};
    for (size_t t = 0; t < n; ++t)
      if ((*hot)[t] && has_edges(mesh, mesh.triangles[t])) {
        const Box b = box_of(t);
        around = {glm::min(around.lo, b.lo), glm::max(around.hi, b.hi)};
      }
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      const glm::uvec3& tri = mesh.triangles[t];
      if (!has_edges(mesh, tri)) continue;
      out.box[t] = box_of(t);
      if (!boxes_overlap(out.box[t], around)) continue;
      take[t] = !detail::collinear(mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z]);
    }
  });
  for (size_t t = 0; t < n; ++t)
    if (take[t]) out.ids.push_back(static_cast<uint32_t>(t));
  return out;
}

// Cells about twice the mean box, at most 2^20 along an axis; grown while
// big triangles would put more than 16 entries per triangle in the grid.
// False when there is nothing finite to grid.
bool size_grid(const std::vector<uint32_t>& ids, const Box* boxes, Grid& grid) {
  Box all{glm::dvec3(INFINITY), glm::dvec3(-INFINITY)};
  double extent_sum = 0.0;
  for (uint32_t t : ids) {
    all.lo = glm::min(all.lo, boxes[t].lo);
    all.hi = glm::max(all.hi, boxes[t].hi);
    const glm::dvec3 e = boxes[t].hi - boxes[t].lo;
    extent_sum += std::max(e.x, std::max(e.y, e.z));
  }
  if (!std::isfinite(extent_sum) || !std::isfinite(all.hi.x - all.lo.x) || !std::isfinite(all.hi.y - all.lo.y) ||
      !std::isfinite(all.hi.z - all.lo.z))
    return false;
  grid.origin = all.lo;
  const double span = std::max(all.hi.x - all.lo.x, std::max(all.hi.y - all.lo.y, all.hi.z - all.lo.z));
  grid.size = std::max({2.0 * extent_sum / double(ids.size()), span / double(1 << 20), 1e-300});
  for (;;) {
    for (int k = 0; k < 3; ++k) grid.dims[k] = static_cast<int>(std::floor((all.hi[k] - all.lo[k]) / grid.size)) + 1;
    const uint64_t entries = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, ids.size(), 4096), uint64_t{0},
        [&](const tbb::blocked_range<size_t>& r, uint64_t sum) {
          for (size_t i = r.begin(); i != r.end(); ++i) sum += grid.cells_of(boxes[ids[i]]);
          return sum;
        },
        [](uint64_t a, uint64_t b) { return a + b; });
    if (entries <= 16 * uint64_t(ids.size()) + 1024) return true;
    grid.size *= 2.0;
  }
}

// The grid's (cell, triangle) entries sorted by cell. With `hot`, a triangle
// that is not hot enters only the cells some hot triangle's box touches.
std::vector<Entry> grid_entries(const std::vector<uint32_t>& ids, const Box* boxes, const Grid& grid,
                                const std::vector<uint8_t>* hot) {
  std::vector<uint64_t> hot_cells;
  if (hot) {
    for (uint32_t t : ids) {
      if (!(*hot)[t]) continue;
      const glm::ivec3 lo = grid.cell(boxes[t].lo), hi = grid.cell(boxes[t].hi);
      for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
          for (int x = lo.x; x <= hi.x; ++x) hot_cells.push_back(grid.key({x, y, z}));
    }
    std::sort(hot_cells.begin(), hot_cells.end());
    hot_cells.erase(std::unique(hot_cells.begin(), hot_cells.end()), hot_cells.end());
  }
  tbb::enumerable_thread_specific<std::vector<Entry>> local;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, ids.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<Entry>& out = local.local();
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const uint32_t t = ids[i];
      const glm::ivec3 lo = grid.cell(boxes[t].lo), hi = grid.cell(boxes[t].hi);
      const bool single = lo == hi, filter = hot && !(*hot)[t];
      for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
          for (int x = lo.x; x <= hi.x; ++x) {
            const uint64_t key = grid.key({x, y, z});
            if (filter && !std::binary_search(hot_cells.begin(), hot_cells.end(), key)) continue;
            out.push_back({key, t, single});
          }
    }
  });
  std::vector<Entry> entries;
  for (const std::vector<Entry>& part : local) entries.insert(entries.end(), part.begin(), part.end());
  tbb::parallel_sort(entries.begin(), entries.end());
  return entries;
}

}  // namespace

namespace detail {

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

std::vector<TrianglePair> self_intersecting_pairs(const ContourMesh& mesh, const std::vector<uint8_t>* hot) {
  const TriangleBoxes boxes = triangle_boxes(mesh, hot);
  const std::vector<uint32_t>& ids = boxes.ids;
  Grid grid;
  if (ids.size() < 2 || !size_grid(ids, boxes.box.get(), grid)) return {};  // not finite: nothing meaningful
  const std::vector<Entry> entries = grid_entries(ids, boxes.box.get(), grid, hot);
  std::vector<size_t> runs;  // entries[runs[k] .. runs[k + 1]) share a cell
  for (size_t i = 0; i < entries.size(); ++i)
    if (i == 0 || entries[i].cell != entries[i - 1].cell) runs.push_back(i);
  runs.push_back(entries.size());

  tbb::enumerable_thread_specific<std::vector<TrianglePair>> found;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, runs.size() - 1, 64), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<Box> cell_boxes;  // the run's boxes side by side
    std::vector<TrianglePair>& out = found.local();
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const Entry* run = entries.data() + runs[k];
      const size_t size = runs[k + 1] - runs[k];
      cell_boxes.resize(size);
      for (size_t i = 0; i < size; ++i) cell_boxes[i] = boxes.box[run[i].triangle];
      for (size_t i = 0; i < size; ++i) {
        const Box& bt = cell_boxes[i];
        for (size_t j = i + 1; j < size; ++j) {
          const Box& bu = cell_boxes[j];
          if (!boxes_overlap(bt, bu)) continue;
          if (hot && !(*hot)[run[i].triangle] && !(*hot)[run[j].triangle]) continue;
          // Tested once: in the cell of the overlap's low corner (which
          // lies in both boxes, so in this cell if either box has no other).
          if (!run[i].single_cell && !run[j].single_cell && grid.key(grid.cell(glm::max(bt.lo, bu.lo))) != run[0].cell)
            continue;
          if (triangle_pair_intersects(mesh.positions.data(), mesh.triangles[run[i].triangle],
                                       mesh.triangles[run[j].triangle]))
            out.push_back({run[i].triangle, run[j].triangle});
        }
      }
    }
  });
  std::vector<TrianglePair> pairs;
  for (const std::vector<TrianglePair>& part : found) pairs.insert(pairs.end(), part.begin(), part.end());
  std::sort(pairs.begin(), pairs.end());  // the same order for any thread count
  return pairs;
}

}  // namespace detail

namespace {

// A power of two that brings the mesh's largest coordinate near 1 when it is
// beyond 1e60 or below 1e-60, else 1: there the predicates' products (a
// coordinate cubed) and a squared cross product (an edge length to the
// fourth) would overflow or underflow. Exact, so every predicate and angle
// sees the same triangles.
double extreme_scale(const ContourMesh& mesh) {
  double largest = 0.0;
  for (const glm::dvec3& p : mesh.positions) {
    const glm::dvec3 a = glm::abs(p);
    if (std::isfinite(a.x + a.y + a.z)) largest = std::max({largest, a.x, a.y, a.z});
  }
  if (largest == 0.0 || (largest > 1e-60 && largest < 1e60)) return 1.0;
  return std::ldexp(1.0, -std::ilogb(largest));
}

}  // namespace

MeshQuality mesh_quality(const ContourMesh& mesh, const QualityOptions& options) {
  if (const double scale = extreme_scale(mesh); scale != 1.0) {
    ContourMesh scaled = mesh;
    for (glm::dvec3& p : scaled.positions) p *= scale;
    MeshQuality quality = mesh_quality(scaled, options);
    // Back to world units: beyond a double's range (a mesh at 1e200 m) inf, never NaN.
    quality.area = quality.area / scale / scale;
    quality.volume = quality.volume / scale / scale / scale;
    return quality;
  }
  MeshQuality quality;
  quality.triangles = mesh.triangle_count();
  quality.vertices = mesh.vertex_count();
  add_topology(mesh, quality);
  add_shape(mesh, quality);
  quality.self_intersecting_pairs = options.known_self_intersecting_pairs
                                        ? *options.known_self_intersecting_pairs
                                        : detail::self_intersecting_pairs(mesh).size();
  return quality;
}

std::string quality_failures(const MeshQuality& q) {
  std::string out;
  auto add = [&](size_t count, const char* one, const char* many) {
    if (count == 0) return;
    if (!out.empty()) out += ", ";
    out += std::to_string(count) + " " + (count == 1 ? one : many);
  };
  add(q.boundary_edges, "boundary edge", "boundary edges");
  add(q.unpaired_edges - std::min(q.unpaired_edges, q.boundary_edges), "edge not used once in each direction",
      "edges not used once in each direction");
  add(q.nonmanifold_edges, "non-manifold edge", "non-manifold edges");
  add(q.nonmanifold_vertices, "non-manifold vertex", "non-manifold vertices");
  add(q.self_intersecting_pairs, "self-intersecting triangle pair", "self-intersecting triangle pairs");
  add(q.degenerate_triangles, "degenerate triangle", "degenerate triangles");
  return out;
}

}  // namespace ldc
