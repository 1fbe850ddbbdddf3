// Implicit solid -> LDC: node signs sampled per chunk, one point per sign-changing cell edge.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <new>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "ldc/build.h"
#include "ldc/internal/build_common.h"

namespace ldc {

glm::dvec3 ImplicitSolid::normal(const glm::dvec3& p, double step) const {
  glm::dvec3 g;
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 d(0.0);
    d[a] = step;
    g[a] = value(p + d) - value(p - d);
  }
  double len = glm::length(g);
  return len > 0.0 && std::isfinite(len) ? g / len : glm::dvec3(0.0);
}

namespace {

struct ImplicitCounts {
  size_t flips = 0;
  size_t points = 0;
};

// Root of value() on a -> b (fa, fb of opposite inside-ness) by the Illinois
// variant of regula falsi, to `tolerance` in the segment parameter.
double find_root(const ImplicitSolid& solid, const glm::dvec3& a, const glm::dvec3& b, double fa,
                 double fb, double tolerance) {
  double t_exact;
  if (solid.segment_root(a, b, &t_exact) && t_exact >= 0.0 && t_exact <= 1.0) return t_exact;
  double lo = 0.0, hi = 1.0, flo = fa, fhi = fb, t = 0.5;
  int side = 0;
  const bool lo_inside = fa < 0.0;
  for (int it = 0; it < 48 && hi - lo > tolerance; ++it) {
    double denom = fhi - flo;
    t = (std::isfinite(denom) && denom != 0.0) ? (lo * fhi - hi * flo) / denom : 0.5 * (lo + hi);
    if (!(t > lo && t < hi)) t = 0.5 * (lo + hi);
    double ft = solid.value(a + t * (b - a));
    if ((ft < 0.0) == lo_inside) {
      lo = t;
      flo = ft;
      if (side == -1) fhi *= 0.5;
      side = -1;
    } else {
      hi = t;
      fhi = ft;
      if (side == +1) flo *= 0.5;
      side = +1;
    }
  }
  return t;
}

// Chunk-local samples of value() at the nodes a chunk's rays need that lie
// in the solid's bounds: the box [lo, hi) of local nodes (within 0 .. C).
// Nodes outside the box are outside and never evaluated, so a small solid
// (a brush) costs its own size, not its chunks'.
struct NodeSamples {
  glm::ivec3 lo{0}, hi{0};
  std::vector<double> values;
  bool contains(const glm::ivec3& n) const {
    return glm::all(glm::greaterThanEqual(n, lo)) && glm::all(glm::lessThan(n, hi));
  }
  double at(const glm::ivec3& n) const {
    if (!contains(n)) return 1.0;
    glm::ivec3 r = n - lo, d = hi - lo;
    return values[(size_t(r.z) * size_t(d.y) + size_t(r.y)) * size_t(d.x) + size_t(r.x)];
  }
};

// Samples the chunk; returns -1 if some nodes are inside and some outside,
// else 0 (all outside) or 1 (all inside).
// Nodes outside solid.bounds() count as outside whatever value() says, so the
// world's box faces are outside even for a solid that breaks its contract.
int sample_chunk(const ImplicitSolid& solid, const WorldBox& bounds, const Lattice& lat,
                 const glm::ivec3& node0, int c, NodeSamples& s) {
  // The nodes that can lie in the bounds, with a node of slack for rounding;
  // each is still tested exactly below.
  glm::dvec3 blo = lat.to_lattice(bounds.min), bhi = lat.to_lattice(bounds.max);
  for (int a = 0; a < 3; ++a) {
    double lo = std::clamp(std::floor(blo[a]) - 1.0 - node0[a], 0.0, double(c + 1));
    double hi = std::clamp(std::ceil(bhi[a]) + 2.0 - node0[a], 0.0, double(c + 1));
    s.lo[a] = int(lo);
    s.hi[a] = std::max(int(hi), s.lo[a]);
  }
  const glm::ivec3 d = s.hi - s.lo;
  s.values.resize(size_t(d.x) * size_t(d.y) * size_t(d.z));
  size_t inside = 0, i = 0;
  for (int z = s.lo.z; z < s.hi.z; ++z)
    for (int y = s.lo.y; y < s.hi.y; ++y)
      for (int x = s.lo.x; x < s.hi.x; ++x, ++i) {
        glm::dvec3 p = lat.node_position(node0 + glm::ivec3(x, y, z));
        bool in_bounds = glm::all(glm::greaterThanEqual(p, bounds.min)) &&
                         glm::all(glm::lessThanEqual(p, bounds.max));
        double v = in_bounds ? solid.value(p) : 1.0;
        s.values[i] = v;
        inside += v < 0.0;
      }
  if (inside == 0) return 0;
  if (inside == size_t(c + 1) * size_t(c + 1) * size_t(c + 1)) return 1;
  return -1;
}

PackedPoint implicit_point(const ImplicitSolid& solid, const Lattice& lat, int axis,
                           const glm::ivec3& node, double fa, double fb, int local_n, int c,
                           ImplicitCounts& counts) {
  const uint32_t q = depth_steps_per_cell(c);
  glm::ivec3 next = node;
  next[axis] += 1;
  glm::dvec3 pa = lat.node_position(node), pb = lat.node_position(next);
  double t = find_root(solid, pa, pb, fa, fb, 0.25 / q);
  int64_t d = std::llround((local_n + t) * q);
  d = std::clamp<int64_t>(d, int64_t(local_n) * q + 1, int64_t(local_n + 1) * q - 1);
  glm::dvec3 p = pa + t * (pb - pa);
  bool enter = fb < 0.0;
  glm::dvec3 n = solid.normal(p, lat.cell_size * 1e-3);
  if (!std::isfinite(n.x + n.y + n.z) || glm::length(n) < 0.5) {
    n = glm::dvec3(0.0);
    n[axis] = enter ? -1.0 : 1.0;
  } else if (enter ? n[axis] > 0.0 : n[axis] < 0.0) {
    n[axis] = -n[axis];  // the sampled surface and the gradient disagree: trust the nodes
    ++counts.flips;
  }
  PackedPoint pt;
  pt.depth = uint16_t(d);
  pt.material = solid.material(p);
  pt.normal = encode_normal(n) | (enter ? 0u : kPointExitBit);
  ++counts.points;
  return pt;
}

RayFamily implicit_family(const ImplicitSolid& solid, const Lattice& lat, const glm::ivec3& node0,
                          int axis, int c, const NodeSamples& s, ImplicitCounts& counts) {
  RayFamilyWriter wr(c);
  const int u = axis_u(axis), v = axis_v(axis);
  // Only edges with an end in the sampled box can change sign.
  const int first_edge = std::max(0, s.lo[axis] - 1), end_edge = std::min(c, s.hi[axis]);
  for (int rv = 0; rv < c; ++rv) {
    for (int ru = 0; ru < c; ++ru) {
      if (ru < s.lo[u] || ru >= s.hi[u] || rv < s.lo[v] || rv >= s.hi[v]) {
        wr.begin_ray(false);  // the whole ray lies outside the bounds
        continue;
      }
      glm::ivec3 local(0);
      local[u] = ru;
      local[v] = rv;
      wr.begin_ray(s.at(local) < 0.0);
      local[axis] = first_edge;
      double prev = s.at(local);
      for (int n = first_edge; n < end_edge; ++n) {
        glm::ivec3 nl = local;
        nl[axis] = n + 1;
        double next = s.at(nl);
        if ((prev < 0.0) != (next < 0.0)) {
          glm::ivec3 node = node0 + local;
          node[axis] = node0[axis] + n;
          wr.add_point(implicit_point(solid, lat, axis, node, prev, next, n, c, counts));
        }
        prev = next;
      }
    }
  }
  return wr.finish();
}

// Fills the three families of the chunk at node0 (uniform ones when the
// chunk is all outside or all inside): the one chunk build that both
// build_from_implicit and build_implicit_chunk run, so they agree bit for bit.
void build_chunk_families(const ImplicitSolid& solid, const WorldBox& bounds, const Lattice& lat,
                          const glm::ivec3& node0, int c, NodeSamples& samples,
                          ImplicitCounts& counts, std::array<RayFamily, 3>& families) {
  WorldBox box{lat.node_position(node0), lat.node_position(node0 + glm::ivec3(c))};
  ImplicitSolid::BoxClass cls = solid.classify(box);
  int uniform = cls == ImplicitSolid::BoxClass::kOutside  ? 0
                : cls == ImplicitSolid::BoxClass::kInside ? 1
                                                          : sample_chunk(solid, bounds, lat, node0, c, samples);
  if (uniform >= 0) {
    for (RayFamily& f : families) f = RayFamily::uniform(uniform == 1);
    return;
  }
  for (int a = 0; a < 3; ++a) families[a] = implicit_family(solid, lat, node0, a, c, samples, counts);
}

}  // namespace

Chunk build_implicit_chunk(const ImplicitSolid& solid, const WorldBox& bounds, const Lattice& lattice,
                           int chunk_size, const glm::ivec3& chunk) {
  NodeSamples samples;
  ImplicitCounts counts;
  Chunk out;
  build_chunk_families(solid, bounds, lattice, chunk * chunk_size, chunk_size, samples, counts, out.axis);
  return out;
}

Result<World> build_from_implicit(const ImplicitSolid& solid, const GridConfig& grid, Context* ctx,
                                  BuildReport* report_out) {
  using namespace detail;
  ScopedTimer total(ctx, "build");
  WorldBox b = solid.bounds();
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(b.min[a]) || !std::isfinite(b.max[a]) || b.min[a] > b.max[a]) {
      return Status(ErrorCode::kInvalidArgument, "implicit solid: bounds are empty or not finite");
    }
  }
  glm::dvec3 e = b.max - b.min;
  Result<WorldConfig> plan = plan_grid(b, grid, 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x), "implicit");
  if (!plan.ok()) return plan.status();
  try {
    World world = World::create(plan.value()).value();
    const int c = world.chunk_size();
    const Lattice lat = world.lattice();
    ChunkAssembly assembly(world);
    tbb::enumerable_thread_specific<NodeSamples> samples;
    tbb::enumerable_thread_specific<ImplicitCounts> counts;
    size_t slots = size_t(world.chunk_dims().x) * world.chunk_dims().y * world.chunk_dims().z;
    ProgressCounter progress(ctx, "sample", slots);
    tbb::parallel_for(size_t{0}, slots, [&](size_t slot) {
      if (progress.cancelled()) return;
      glm::ivec3 node0 = slot_chunk(world, slot) * c;
      build_chunk_families(solid, b, lat, node0, c, samples.local(), counts.local(),
                           assembly.families(slot));
      progress.step();
    });
    if (progress.cancelled()) return cancelled_status("implicit");
    assembly.finish(world);
    BuildReport report;
    for (const ImplicitCounts& k : counts) report.normal_flips += k.flips;
    report.seconds = total.seconds();
    record_build_report(world, report);
    world.set_metadata("source", "implicit");
    if (report_out) *report_out = report;
    return world;
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, "implicit: out of memory building the LDC; use fewer cells");
  }
}

namespace detail {

Result<World> build_implicit_as(const ImplicitSolid& solid, const GridConfig& grid, Context* ctx,
                                BuildReport* report, const std::string& source) {
  Result<World> w = build_from_implicit(solid, grid, ctx, report);
  if (w.ok()) w.value().set_metadata("source", source);
  return w;
}

}  // namespace detail
}  // namespace ldc
