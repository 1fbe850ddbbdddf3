// Surface error by sampling, with CGAL AABB trees (see meshdist.h for the
// definitions). CGAL stays in this translation unit.
#include "meshdist.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <CGAL/AABB_segment_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <tbb/parallel_for.h>

namespace ldc::bench {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using Segment = Kernel::Segment_3;
using TriangleTree = CGAL::AABB_tree<
    CGAL::AABB_traits<Kernel, CGAL::AABB_triangle_primitive<Kernel, std::vector<Triangle>::const_iterator>>>;
using SegmentTree = CGAL::AABB_tree<
    CGAL::AABB_traits<Kernel, CGAL::AABB_segment_primitive<Kernel, std::vector<Segment>::const_iterator>>>;

// Samples per block of the parallel loops. Fixed, so that the blocks' partial
// sums, added in block order, do not depend on the thread count.
constexpr size_t kBlock = 4096;

Point to_point(const glm::dvec3& p) { return Point(p.x, p.y, p.z); }
glm::dvec3 to_glm(const Point& p) { return {p.x(), p.y(), p.z()}; }

// Angle between two unit vectors in degrees, in [0, 180]. atan2 keeps
// precision near 0 and 180 where acos(dot) loses half the digits.
double angle_deg(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * (180.0 / std::numbers::pi);
}

// One surface ready for sampling and closest-point queries. Triangles with no
// area are dropped: they have no normal, are never sampled and cannot be closest
// in a way that matters. Not movable: the tree points into `triangles`.
struct Surface {
  std::vector<Triangle> triangles;
  std::vector<glm::dvec3> normals;  // unit, one per kept triangle
  std::vector<double> area_cdf;     // running sum of the kept triangles' areas
  TriangleTree tree;

  explicit Surface(const TriangleMesh& mesh);
  Surface(const Surface&) = delete;
  Surface& operator=(const Surface&) = delete;
  double area() const { return area_cdf.empty() ? 0.0 : area_cdf.back(); }
  size_t index(TriangleTree::Primitive_id id) const { return size_t(id - triangles.cbegin()); }
};

// Spreads the low 21 bits of v to every third bit (for a 63-bit Morton code).
uint64_t spread3(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

// Triangles in Morton order of their centroids. Samples are drawn in area-CDF
// order (see draw), so consecutive queries then lie close together whatever
// the input order, and the trees' nodes stay in cache: on the bunny this
// more than halves the time against independent draws in file order.
std::vector<uint32_t> spatial_order(const TriangleMesh& mesh) {
  const MeshBounds b = mesh_bounds(mesh);
  const glm::dvec3 scale = double(1 << 21) / glm::max(b.extent(), glm::dvec3(1e-300));
  std::vector<std::pair<uint64_t, uint32_t>> keyed(mesh.triangles.size());
  for (size_t f = 0; f < keyed.size(); ++f) {
    const glm::uvec3& t = mesh.triangles[f];
    const glm::dvec3 c = (mesh.positions[t.x] + mesh.positions[t.y] + mesh.positions[t.z]) / 3.0;
    const glm::dvec3 g = glm::clamp((c - b.min) * scale, 0.0, double((1 << 21) - 1));
    keyed[f] = {spread3(uint64_t(g.x)) | spread3(uint64_t(g.y)) << 1 | spread3(uint64_t(g.z)) << 2, uint32_t(f)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<uint32_t> order(keyed.size());
  for (size_t k = 0; k < keyed.size(); ++k) order[k] = keyed[k].second;
  return order;
}

Surface::Surface(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) return;
  double total = 0.0;
  for (uint32_t f : spatial_order(mesh)) {
    const glm::uvec3& t = mesh.triangles[f];
    const glm::dvec3 &a = mesh.positions[t.x], &b = mesh.positions[t.y], &c = mesh.positions[t.z];
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double len = glm::length(n);
    Triangle tri(to_point(a), to_point(b), to_point(c));
    if (!(len > 0.0) || !std::isfinite(len) || tri.is_degenerate()) continue;
    triangles.push_back(tri);
    normals.push_back(n / len);
    total += 0.5 * len;
    area_cdf.push_back(total);
  }
  if (triangles.empty()) return;
  tree.insert(triangles.cbegin(), triangles.cend());
  // Build the tree and its distance-query k-d tree now: both are built lazily
  // on the first query otherwise, and the queries below run in parallel.
  tree.build();
  tree.accelerate_distance_queries();
}

// splitmix64: a per-sample hash, so sample i is the same whatever thread draws it.
uint64_t mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
double unit(uint64_t h) { return double(h >> 11) * 0x1.0p-53; }  // [0, 1)

struct Sample {
  glm::dvec3 position;
  size_t triangle;  // index into Surface::triangles
};

// Sample i of n on a surface. Stratified along the area CDF: sample i falls
// uniformly in the i-th n-th of the total area, so the samples together are
// area-uniform (with less variance than independent draws), and consecutive
// samples lie on nearby triangles (see spatial_order), so the queries walk the
// trees coherently. Within the triangle: square-root barycentric mapping.
// `stream` separates the two sides.
Sample draw(const Surface& s, uint64_t seed, uint64_t stream, size_t i, size_t n) {
  const uint64_t key = mix(mix(seed) ^ mix(stream) ^ uint64_t(i));
  const double u0 = unit(key), u1 = unit(mix(key ^ 1)), u2 = unit(mix(key ^ 2));
  const double target = (double(i) + u0) / double(n) * s.area();
  size_t t = size_t(std::upper_bound(s.area_cdf.begin(), s.area_cdf.end(), target) - s.area_cdf.begin());
  t = std::min(t, s.triangles.size() - 1);
  const double r = std::sqrt(u1), wa = 1.0 - r, wb = r * (1.0 - u2), wc = r * u2;
  const Triangle& tri = s.triangles[t];
  return {wa * to_glm(tri[0]) + wb * to_glm(tri[1]) + wc * to_glm(tri[2]), t};
}

// Weld vertices by exact position: id per vertex, equal positions equal ids.
std::vector<uint32_t> weld(const std::vector<glm::dvec3>& positions) {
  std::vector<uint32_t> order(positions.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = uint32_t(i);
  auto less = [&](uint32_t a, uint32_t b) {
    const glm::dvec3 &p = positions[a], &q = positions[b];
    return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z);
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<uint32_t> id(positions.size());
  for (size_t k = 0; k < order.size(); ++k) {
    const bool same = k > 0 && positions[order[k]] == positions[order[k - 1]];
    id[order[k]] = same ? id[order[k - 1]] : order[k];
  }
  return id;
}

// Reference edges shared by exactly two faces whose normals differ by more
// than `angle_deg_limit`. Boundary and non-manifold edges are not sharp: they have
// no single dihedral. Faces without area take no part.
std::vector<Segment> sharp_edges(const TriangleMesh& mesh, double angle_deg_limit) {
  const std::vector<uint32_t> id = weld(mesh.positions);
  struct Use {
    uint32_t a, b, face;
  };
  std::vector<Use> uses;
  std::vector<glm::dvec3> normal(mesh.triangles.size(), glm::dvec3(0.0));
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const glm::uvec3& t = mesh.triangles[f];
    const glm::dvec3 n = glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]);
    if (!(glm::length(n) > 0.0) || !std::isfinite(glm::length(n))) continue;
    normal[f] = glm::normalize(n);
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = id[t[k]], b = id[t[(k + 1) % 3]];
      if (a != b) uses.push_back({std::min(a, b), std::max(a, b), uint32_t(f)});
    }
  }
  std::sort(uses.begin(), uses.end(),
            [](const Use& x, const Use& y) { return std::tie(x.a, x.b, x.face) < std::tie(y.a, y.b, y.face); });
  std::vector<Segment> out;
  for (size_t i = 0; i < uses.size();) {
    size_t j = i;
    while (j < uses.size() && uses[j].a == uses[i].a && uses[j].b == uses[i].b) ++j;
    if (j - i == 2 && angle_deg(normal[uses[i].face], normal[uses[i + 1].face]) > angle_deg_limit)
      out.emplace_back(to_point(mesh.positions[uses[i].a]), to_point(mesh.positions[uses[i].b]));
    i = j;
  }
  return out;
}

// Sums over one block of samples; blocks are added in order at the end.
struct Partial {
  double dist_sum = 0, dist_max = 0;
  double normal_sum = 0, near_normal_sum = 0;
  size_t over10 = 0, near = 0, near_over10 = 0;

  void add(const Partial& o) {
    dist_sum += o.dist_sum;
    dist_max = std::max(dist_max, o.dist_max);
    normal_sum += o.normal_sum;
    near_normal_sum += o.near_normal_sum;
    over10 += o.over10;
    near += o.near;
    near_over10 += o.near_over10;
  }
};

// Runs `block(begin, end)` over fixed blocks of samples 0..n-1 in parallel and
// adds the blocks' partials in block order (deterministic for any thread count).
template <class Block>
Partial sample_blocks(size_t n, const Block& block) {
  const size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<Partial> partial(blocks);
  tbb::parallel_for(size_t{0}, blocks,
                    [&](size_t b) { partial[b] = block(b * kBlock, std::min(n, (b + 1) * kBlock)); });
  Partial total;
  for (const Partial& p : partial) total.add(p);
  return total;
}

double distance(const Point& a, const Point& b) { return std::sqrt(CGAL::to_double(CGAL::squared_distance(a, b))); }

// Distances from samples of `from` to the surface `to` (no normals).
Partial distances(const Surface& from, const Surface& to, const MeshDistOptions& o, uint64_t stream) {
  return sample_blocks(o.samples, [&](size_t begin, size_t end) {
    Partial acc;
    for (size_t i = begin; i < end; ++i) {
      const Point p = to_point(draw(from, o.seed, stream, i, o.samples).position);
      const double d = distance(p, to.tree.closest_point(p));
      acc.dist_sum += d;
      acc.dist_max = std::max(acc.dist_max, d);
    }
    return acc;
  });
}

// Test samples against the reference: distance, normal error, near-sharp split.
Partial test_side(const Surface& test, const Surface& ref, const SegmentTree* sharp, const MeshDistOptions& o) {
  return sample_blocks(o.samples, [&](size_t begin, size_t end) {
    Partial acc;
    for (size_t i = begin; i < end; ++i) {
      const Sample s = draw(test, o.seed, 0, i, o.samples);
      const Point p = to_point(s.position);
      const auto [q, id] = ref.tree.closest_point_and_primitive(p);
      const double d = distance(p, q);
      const double err = angle_deg(test.normals[s.triangle], ref.normals[ref.index(id)]);
      acc.dist_sum += d;
      acc.dist_max = std::max(acc.dist_max, d);
      acc.normal_sum += err;
      acc.over10 += err > 10.0;
      if (sharp && distance(p, sharp->closest_point(p)) <= o.near_sharp_distance) {
        ++acc.near;
        acc.near_normal_sum += err;
        acc.near_over10 += err > 10.0;
      }
    }
    return acc;
  });
}

Status check_inputs(const TriangleMesh& test, const TriangleMesh& ref, const MeshDistOptions& o) {
  if (o.samples < 1) return {ErrorCode::kInvalidArgument, "mesh_distance: samples must be >= 1"};
  if (!(o.sharp_angle_deg >= 0.0 && o.sharp_angle_deg <= 180.0))
    return {ErrorCode::kInvalidArgument,
            "mesh_distance: sharp_angle_deg " + std::to_string(o.sharp_angle_deg) + " not in [0, 180]"};
  if (!(o.near_sharp_distance >= 0.0 && std::isfinite(o.near_sharp_distance)))
    return {ErrorCode::kInvalidArgument, "mesh_distance: near_sharp_distance " +
                                             std::to_string(o.near_sharp_distance) + " must be finite and >= 0"};
  if (Status s = check_mesh(test, "test mesh"); !s.ok()) return s;
  return check_mesh(ref, "reference mesh");
}

// Fills the normal figures of `r` from the test side's sums.
void set_normal_figures(const Partial& t, size_t samples, bool split, MeshDistResult& r) {
  const double n = double(samples);
  r.normal_mean_deg = t.normal_sum / n;
  r.normal_over10 = double(t.over10) / n;
  r.away_normal_deg = r.normal_mean_deg;
  if (!split) return;
  r.near_fraction = double(t.near) / n;
  if (t.near > 0) {
    r.near_normal_deg = t.near_normal_sum / double(t.near);
    r.near_over10 = double(t.near_over10) / double(t.near);
  }
  const size_t away = samples - t.near;
  r.away_normal_deg = away > 0 ? (t.normal_sum - t.near_normal_sum) / double(away) : 0.0;
}

}  // namespace

MeshDistResult mesh_distance(const TriangleMesh& test, const TriangleMesh& reference,
                             const MeshDistOptions& options) {
  MeshDistResult r;
  r.status = check_inputs(test, reference, options);
  if (!r.status.ok()) return r;
  const Surface ts(test), rs(reference);
  if (ts.triangles.empty() || rs.triangles.empty()) {
    r.status = {ErrorCode::kInvalidArgument,
                std::string("mesh_distance: ") + (ts.triangles.empty() ? "test" : "reference") +
                    " mesh has no triangle with area"};
    return r;
  }
  r.diagonal = mesh_bounds(reference).diagonal();

  const std::vector<Segment> sharp = sharp_edges(reference, options.sharp_angle_deg);
  r.sharp_edges = sharp.size();
  const bool split = options.near_sharp_distance > 0.0 && !sharp.empty();
  SegmentTree sharp_tree;
  if (split) {
    sharp_tree.insert(sharp.cbegin(), sharp.cend());
    sharp_tree.build();  // before the parallel queries (lazy otherwise)
    sharp_tree.accelerate_distance_queries();
  }

  const Partial t = test_side(ts, rs, split ? &sharp_tree : nullptr, options);
  const Partial f = distances(rs, ts, options, 1);
  const double n = double(options.samples);
  r.mean_rel = 0.5 * (t.dist_sum / n + f.dist_sum / n) / r.diagonal;
  r.hausdorff_rel = std::max(t.dist_max, f.dist_max) / r.diagonal;
  set_normal_figures(t, options.samples, split, r);
  const double ref_volume = mesh_signed_volume(reference);
  r.volume_ratio = ref_volume != 0.0 ? mesh_signed_volume(test) / ref_volume : 0.0;
  return r;
}

}  // namespace ldc::bench
