// Ground truth for walkable floors on analytic terrains (issue 20 item 5).
//
// Each terrain is a heightfield z = f(x, y) with a closed-form gradient over a
// rectangle, solid down to a flat bottom, optionally united with axis-aligned
// boxes (the overhang). ldc gets it exactly as an ImplicitSolid (exact
// crossings on the vertical rays, analytic normals there); Detour gets a fine
// triangulation of the same surface (0.1 m grid, with vertices on every kink
// line and a vertical face at every step) plus the boxes as closed meshes.
//
// The truth applies the agent rules of nav/nav.h's top comment (RecastDemo's
// agent: height 2, radius 0.6, climb 0.9, slope 45) to the exact surface,
// sampled on a fine grid of columns (0.05 m; cell centres, so no sample lies
// on a feature line; every floor of a column is a node):
//   1. slope: a floor is a candidate when its exact normal is within 45° of up
//      (|grad f| <= tan 45°; box tops are flat);
//   2. clearance: and the free height above it (to the next solid span, or
//      unbounded) is >= agent_height;
//   3. links: floors of side-by-side columns are linked when the step between
//      them is <= max_climb and min(ceilings) - max(floors) >= agent_height;
//   4. erosion: a candidate floor is walkable unless a border lies within
//      agent_radius of it, horizontal Euclidean distance, over the candidate
//      floors reachable from it by links inside that disc. A border is an
//      unlinked side: a candidate whose neighbour column holds no linked
//      candidate (a steeper or low floor, a wall, a drop deeper than
//      max_climb, the terrain's edge). Its position: where the slope or
//      clearance rule switches along the segment between the two column
//      centres (bisection on the exact surface), or the midpoint for a step,
//      wall or edge (every such feature lies on a midpoint of the grid);
//   5. reachability: flood fill over walkable floors through links (steps
//      <= max_climb), 4-connected.
// The ledge filter (a drop > max_climb on a side) and the low-height filter
// are rules 4 and 2; low-hanging obstacles never occur here (no column holds a
// steep floor within max_climb above a walkable one). The implementation
// details of either peer (ldc's slope leniency next to a flat neighbour,
// Recast's area merging of the flattest triangle within climb, chamfer
// erosion) are not rules of the truth.
//
// Rasterization of a peer's walkable set onto the truth's floors: ldc,
// NavQuery::nearest_walkable with half extents (1e-4, 1e-4, 1) m at the
// centre of each part of the floor's cell that ldc's column sides cut it
// into: walkable when the hit is that point itself horizontally (it lies in
// the h x h square of a kept column, nav.h's cell rule, within 1 m
// vertically); the parts' areas add up, so ldc's area is exact on the truth's
// cells. Detour, findNearestPoly with half extents (1e-4, 1, 1e-4): walkable
// when the nearest point is the query point horizontally (the point lies
// inside a polygon's xz projection, so closestPointOnPoly returns it).
//
// Two more rows per terrain: "(truth on h 0.2 cells: bound)", ldc's columns
// each kept exactly when the truth keeps its centre, the best a walkable set
// of whole 0.2 m cells can score; and the default landscape (bench_nav's
// scene), its truth sampled from the landscape's ImplicitSolid (every 0.05 m up
// each column of a 0.1 m grid), ldc on build_terrain's world and Detour on
// its contoured triangles, as bench_nav runs them.
#include "nav_truth.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <tbb/parallel_for.h>

#include "contour/contour.h"
#include "detour_peer.h"
#include "ldc/build.h"
#include "ldc/terrain.h"
#include "nav/nav.h"

namespace ldc::bench {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;
constexpr double kRasterReach = 1.0;  // vertical half extent of the rasterization lookups [m]

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

double tan_deg(double d) { return std::tan(d * kPi / 180.0); }

std::string fmt(const char* f, double a) {
  char buf[96];
  std::snprintf(buf, sizeof buf, f, a);
  return buf;
}

struct Box {
  glm::dvec3 lo{0.0}, hi{0.0};
};

struct Terrain {
  std::string name, description;
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;  // the rectangle the heightfield covers
  double zfloor = -1.0;                    // solid down to here
  double zmax = 0.0;                       // highest point of the solid
  std::function<double(double, double)> f;
  std::function<glm::dvec2(double, double)> grad;
  std::vector<Box> boxes;        // solid boxes united with the heightfield
  std::vector<double> xbreaks;   // kink lines x = c: mesh vertices on them
  std::vector<double> xsteps;    // discontinuities x = c: a vertical face in the mesh
};

// ---- the terrains -------------------------------------------------------------
//
// Rectangles start at -N.05 so that the features (integers, 0.15) lie on the
// truth grid's cell sides, and neither ldc's lattice (origin offset below) nor
// Recast's cells (from the mesh bounds) line up with them.

Terrain planes(double lower_deg, double upper_deg) {
  Terrain t;
  char name[128];
  std::snprintf(name, sizeof name, "planes %g°/%g°", lower_deg, upper_deg);
  t.name = name;
  const double a = tan_deg(lower_deg), b = tan_deg(upper_deg);
  std::snprintf(name, sizeof name, "flat x<-6, %g° for -6<x<0, %g° for 0<x<4, flat x>4", lower_deg, upper_deg);
  t.description = name;
  t.x0 = -10.05, t.x1 = 9.95, t.y0 = -5.05, t.y1 = 4.95;
  t.f = [a, b](double x, double) {
    if (x < -6) return 0.0;
    if (x < 0) return a * (x + 6);
    if (x < 4) return 6 * a + b * x;
    return 6 * a + 4 * b;
  };
  t.grad = [a, b](double x, double) {
    if (x < -6) return glm::dvec2(0.0);
    if (x < 0) return glm::dvec2(a, 0.0);
    if (x < 4) return glm::dvec2(b, 0.0);
    return glm::dvec2(0.0);
  };
  t.zmax = 6 * a + 4 * b;
  t.xbreaks = {-6.0, 0.0, 4.0};
  return t;
}

Terrain hill() {
  Terrain t;
  t.name = "paraboloid hill";
  const double a = 0.1, r_foot = 8.0, top = a * r_foot * r_foot;
  t.description = "z = 6.4 - 0.1 r^2 for r < 8, flat beyond: 45° on r = 5, 58° at the foot";
  t.x0 = -12.05, t.x1 = 11.95, t.y0 = -12.05, t.y1 = 11.95;
  t.f = [=](double x, double y) { return std::max(0.0, top - a * (x * x + y * y)); };
  t.grad = [=](double x, double y) {
    return x * x + y * y < r_foot * r_foot ? glm::dvec2(-2 * a * x, -2 * a * y) : glm::dvec2(0.0);
  };
  t.zmax = top;
  return t;
}

Terrain ledges() {
  Terrain t;
  t.name = "ledges 0.5 m + 1.5 m";
  t.description = "flat terraces z = 0 (x<-3), 0.5 (-3<x<3), 2.0 (x>3): a 0.5 m step, then a 1.5 m one";
  t.x0 = -10.05, t.x1 = 9.95, t.y0 = -5.05, t.y1 = 4.95;
  t.f = [](double x, double) { return x < -3 ? 0.0 : x < 3 ? 0.5 : 2.0; };
  t.grad = [](double, double) { return glm::dvec2(0.0); };
  t.zmax = 2.0;
  t.xsteps = {-3.0, 3.0};
  return t;
}

Terrain groove() {
  Terrain t;
  t.name = "V-groove 0.3 m";
  t.description = "flat, with a V-groove along y: 0.3 m wide, 60° walls, 0.26 m deep";
  const double s = tan_deg(60.0), half = 0.15;
  t.x0 = -6.05, t.x1 = 5.95, t.y0 = -5.05, t.y1 = 4.95;
  t.f = [=](double x, double) { return std::abs(x) < half ? -s * (half - std::abs(x)) : 0.0; };
  t.grad = [=](double x, double) {
    return std::abs(x) < half ? glm::dvec2(x < 0 ? -s : s, 0.0) : glm::dvec2(0.0);
  };
  t.zmax = 0.0;
  t.xbreaks = {-half, 0.0, half};
  return t;
}

Terrain overhang() {
  Terrain t;
  t.name = "overhang slab";
  t.description = "flat ground under a slab (top 3.0) x in [-5, 5], y in [-3, 3]: underside 1.5 for x<0, 2.5 for x>0";
  t.x0 = -8.05, t.x1 = 7.95, t.y0 = -6.05, t.y1 = 5.95;
  t.f = [](double, double) { return 0.0; };
  t.grad = [](double, double) { return glm::dvec2(0.0); };
  t.boxes = {Box{{-5, -3, 1.5}, {0, 3, 3.0}}, Box{{0, -3, 2.5}, {5, 3, 3.0}}};
  t.zmax = 3.0;
  return t;
}

Terrain sine_hills() {
  Terrain t;
  t.name = "sine hills";
  const double amp = 1.8, k = 2 * kPi / 10.0;
  t.description = "z = 1.8 sin(2 pi x / 10) sin(2 pi y / 10): slopes up to 48.5°, hills joined along the "
                  "diagonals (walkable corridors >= 1.9 m wide before erosion)";
  t.x0 = -12.05, t.x1 = 11.95, t.y0 = -12.05, t.y1 = 11.95;
  t.zfloor = -3.0;
  t.f = [=](double x, double y) { return amp * std::sin(k * x) * std::sin(k * y); };
  t.grad = [=](double x, double y) {
    return glm::dvec2(amp * k * std::cos(k * x) * std::sin(k * y), amp * k * std::sin(k * x) * std::cos(k * y));
  };
  t.zmax = amp;
  return t;
}

std::vector<Terrain> all_terrains() {
  return {planes(40, 50), hill(), ledges(), groove(), overhang(), sine_hills()};
}

// ---- columns of the exact solid ------------------------------------------------

struct Span {
  double lo = 0, hi = 0;
  bool ground_top = false;  // the top is the heightfield's surface (else a box's flat top)
};

bool in_rect(const Terrain& t, double x, double y) { return x >= t.x0 && x <= t.x1 && y >= t.y0 && y <= t.y1; }

// The solid spans of the column at (x, y), bottom to top, merged.
void column_spans(const Terrain& t, double x, double y, std::vector<Span>& out) {
  out.clear();
  if (in_rect(t, x, y)) out.push_back({t.zfloor, t.f(x, y), true});
  for (const Box& b : t.boxes) {
    if (x >= b.lo.x && x <= b.hi.x && y >= b.lo.y && y <= b.hi.y) out.push_back({b.lo.z, b.hi.z, false});
  }
  std::sort(out.begin(), out.end(), [](const Span& a, const Span& b) { return a.lo < b.lo; });
  size_t n = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    if (n > 0 && out[i].lo <= out[n - 1].hi) {
      if (out[i].hi > out[n - 1].hi) out[n - 1] = {out[n - 1].lo, out[i].hi, out[i].ground_top};
      continue;
    }
    out[n++] = out[i];
  }
  out.resize(n);
}

class TerrainSolid : public ImplicitSolid {
 public:
  explicit TerrainSolid(const Terrain& t) : t_(t) {}

  double value(const glm::dvec3& p) const override {
    double v = std::max({p.z - t_.f(p.x, p.y), t_.zfloor - p.z, t_.x0 - p.x, p.x - t_.x1, t_.y0 - p.y, p.y - t_.y1});
    for (const Box& b : t_.boxes) {
      v = std::min(v, std::max({b.lo.x - p.x, p.x - b.hi.x, b.lo.y - p.y, p.y - b.hi.y, b.lo.z - p.z, p.z - b.hi.z}));
    }
    return v;
  }

  // The analytic normal on the heightfield's top; central differences elsewhere.
  glm::dvec3 normal(const glm::dvec3& p, double step) const override {
    const bool on_top = p.x > t_.x0 && p.x < t_.x1 && p.y > t_.y0 && p.y < t_.y1 &&
                        std::abs(p.z - t_.f(p.x, p.y)) < 1e-6;
    bool in_box = false;
    for (const Box& b : t_.boxes) {
      in_box = in_box || (p.x >= b.lo.x - 1e-6 && p.x <= b.hi.x + 1e-6 && p.y >= b.lo.y - 1e-6 &&
                          p.y <= b.hi.y + 1e-6 && p.z >= b.lo.z - 1e-6 && p.z <= b.hi.z + 1e-6);
    }
    if (on_top && !in_box) {
      const glm::dvec2 g = t_.grad(p.x, p.y);
      return glm::normalize(glm::dvec3(-g.x, -g.y, 1.0));
    }
    return ImplicitSolid::normal(p, step);
  }

  WorldBox bounds() const override {
    WorldBox b{{t_.x0, t_.y0, t_.zfloor}, {t_.x1, t_.y1, t_.zmax}};
    for (const Box& x : t_.boxes) {
      b.min = glm::min(b.min, x.lo);
      b.max = glm::max(b.max, x.hi);
    }
    return b;
  }

  // Exact on vertical segments: the first span boundary between a and b.
  bool segment_root(const glm::dvec3& a, const glm::dvec3& b, double* t) const override {
    if (a.x != b.x || a.y != b.y || a.z == b.z) return false;
    thread_local std::vector<Span> spans;
    column_spans(t_, a.x, a.y, spans);
    const bool up = b.z > a.z;
    double best = up ? kInf : -kInf;
    for (const Span& s : spans) {
      for (double z : {s.lo, s.hi}) {
        if (up ? (z > a.z && z < b.z && z < best) : (z < a.z && z > b.z && z > best)) best = z;
      }
    }
    if (!std::isfinite(best)) return false;
    *t = (best - a.z) / (b.z - a.z);
    return true;
  }

 private:
  const Terrain& t_;
};

// ---- column sources for the truth ------------------------------------------------

// One solid span of a column and the exact slope (tan) of the floor on top.
struct TSpan {
  double lo = 0, hi = 0, slope_tan = 0;
};
// The spans of the column at (x, y), bottom to top; a source may leave out
// what lies outside [zlo, zhi] (and clip spans to it).
using SpanFn = std::function<void(double x, double y, double zlo, double zhi, std::vector<TSpan>& out)>;

SpanFn analytic_spans(const Terrain& t) {
  return [&t](double x, double y, double, double, std::vector<TSpan>& out) {
    thread_local std::vector<Span> spans;
    column_spans(t, x, y, spans);
    out.clear();
    for (const Span& s : spans) out.push_back({s.lo, s.hi, s.ground_top ? glm::length(t.grad(x, y)) : 0.0});
  };
}

// Any implicit solid: value() sampled every dz along the column, each sign
// change refined by bisection (to 1e-6 m), the floor's slope from
// solid.normal() at the crossing with ldc's own step (h / 1000).
SpanFn sampled_spans(const ImplicitSolid& solid, double dz, double normal_step) {
  const WorldBox b = solid.bounds();
  return [&solid, b, dz, normal_step](double x, double y, double zlo, double zhi, std::vector<TSpan>& out) {
    out.clear();
    zlo = std::max(zlo, b.min.z - dz), zhi = std::min(zhi, b.max.z + dz);
    auto inside = [&](double z) { return solid.value({x, y, z}) < 0.0; };
    auto root = [&](double a, double c) {  // inside(a) != inside(c)
      const bool ia = inside(a);
      while (c - a > 1e-6) {
        const double m = 0.5 * (a + c);
        (inside(m) == ia ? a : c) = m;
      }
      return 0.5 * (a + c);
    };
    bool in = inside(zlo);
    double start = zlo;
    for (double z = zlo; z < zhi;) {
      const double next = std::min(zhi, z + dz);
      const bool in_next = inside(next);
      if (in_next != in) {
        const double c = root(z, next);
        if (in_next) {
          start = c;
        } else {
          const glm::dvec3 n = solid.normal({x, y, c}, normal_step);
          out.push_back({start, c, n.z > 0.0 ? std::hypot(n.x, n.y) / n.z : kInf});
        }
        in = in_next;
      }
      z = next;
    }
    if (in) out.push_back({start, zhi, 0.0});  // clipped at the window's top
  };
}

// ---- Detour's input ---------------------------------------------------------------

glm::vec3 to_detour(const glm::dvec3& p) { return {float(p.x), float(p.z), float(-p.y)}; }

struct Triangles {
  std::vector<float> verts;
  std::vector<int> tris;
};

// The heightfield on a fine grid (vertices on the kink lines, a vertical face
// of width 2 mm at each step) and the boxes as closed meshes; y up.
Triangles detour_mesh(const Terrain& t, double spacing) {
  std::vector<double> xs, ys;
  const int nx = int(std::ceil((t.x1 - t.x0) / spacing - 1e-9)), ny = int(std::ceil((t.y1 - t.y0) / spacing - 1e-9));
  for (int i = 0; i <= nx; ++i) xs.push_back(std::min(t.x1, t.x0 + i * spacing));
  for (int j = 0; j <= ny; ++j) ys.push_back(std::min(t.y1, t.y0 + j * spacing));
  for (double b : t.xbreaks) xs.push_back(b);
  constexpr double kFace = 1e-3;
  xs.erase(std::remove_if(xs.begin(), xs.end(),
                          [&](double x) {
                            for (double s : t.xsteps) {
                              if (std::abs(x - s) <= kFace) return true;
                            }
                            return false;
                          }),
           xs.end());
  for (double s : t.xsteps) xs.insert(xs.end(), {s - kFace, s + kFace});
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end(), [](double a, double b) { return std::abs(a - b) < 1e-9; }), xs.end());
  Triangles m;
  auto vertex = [&](const glm::dvec3& p) {
    const glm::vec3 q = to_detour(p);
    m.verts.insert(m.verts.end(), {q.x, q.y, q.z});
    return int(m.verts.size() / 3 - 1);
  };
  const int w = int(xs.size());
  for (double y : ys) {
    for (double x : xs) vertex({x, y, t.f(x, y)});
  }
  for (int j = 0; j + 1 < int(ys.size()); ++j) {
    for (int i = 0; i + 1 < w; ++i) {
      const int a = j * w + i, b = a + 1, c = a + w + 1, d = a + w;  // counter-clockwise seen from +z
      m.tris.insert(m.tris.end(), {a, b, c, a, c, d});
    }
  }
  for (const Box& bx : t.boxes) {
    int v[8];
    for (int k = 0; k < 8; ++k) {
      v[k] = vertex({(k & 1) ? bx.hi.x : bx.lo.x, (k & 2) ? bx.hi.y : bx.lo.y, (k & 4) ? bx.hi.z : bx.lo.z});
    }
    // Corners as bits (x, y, z) = (1, 2, 4); outward faces.
    const int faces[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                              {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    for (const auto& f : faces) m.tris.insert(m.tris.end(), {v[f[0]], v[f[1]], v[f[2]]});
  }
  return m;
}

// ---- the truth ---------------------------------------------------------------------

struct TFloor {
  double z = 0, ceiling = kInf, slope_tan = 0;
  bool candidate = false;  // rules 1 and 2
  bool walkable = false;   // and rule 4
  int component = -1;
};

const glm::ivec2 kDir[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};

struct Truth {
  NavConfig agent;
  int nx = 0, ny = 0;
  double x0 = 0, y0 = 0, g = 0;
  std::vector<uint32_t> first;  // per column, into floors
  std::vector<TFloor> floors;
  std::vector<int> column_of;   // per floor
  int components = 0;
  size_t walkable = 0;

  glm::dvec2 centre(int col) const { return {x0 + (col % nx + 0.5) * g, y0 + (col / nx + 0.5) * g}; }
  int column(int i, int j) const { return i < 0 || j < 0 || i >= nx || j >= ny ? -1 : j * nx + i; }
  bool candidate_rule(double slope_tan, double z, double ceiling) const {
    return slope_tan <= std::tan(agent.max_slope_degrees * kPi / 180.0) + 1e-12 &&
           ceiling - z >= agent.agent_height;
  }
  bool linked(const TFloor& a, const TFloor& b) const {
    return std::abs(a.z - b.z) <= agent.max_climb &&
           std::min(a.ceiling, b.ceiling) - std::max(a.z, b.z) >= agent.agent_height;
  }
  // Calls fn(floor index) for every floor of the side-d column linked to floor n.
  template <class F>
  void for_links(int n, int d, F&& fn) const {
    const int c = column_of[size_t(n)];
    const int side = column(c % nx + kDir[d].x, c / nx + kDir[d].y);
    if (side < 0) return;
    for (uint32_t k = first[size_t(side)]; k < first[size_t(side) + 1]; ++k) {
      if (linked(floors[size_t(n)], floors[k])) fn(int(k));
    }
  }
};

// The truth on the rectangle [x0, x1] x [y0, y1]: columns every g, their
// floors from `spans`; an unlinked side where the rule switches is placed by
// `bisections` halvings of the segment between the column centres (0: the
// cell side).
Truth build_truth(const SpanFn& spans_at, const glm::dvec4& rect, const NavConfig& agent, double g,
                  int bisections) {
  Truth T;
  T.agent = agent;
  T.g = g;
  T.x0 = rect.x, T.y0 = rect.y;
  T.nx = int(std::lround((rect.z - T.x0) / g)), T.ny = int(std::lround((rect.w - T.y0) / g));
  T.first.assign(size_t(T.nx) * size_t(T.ny) + 1, 0);
  // Columns in parallel (a sampled solid costs ~100 evaluations per column).
  std::vector<std::vector<TSpan>> column(size_t(T.nx) * size_t(T.ny));
  tbb::parallel_for(0, T.ny, [&](int j) {
    for (int i = 0; i < T.nx; ++i) {
      const int col = j * T.nx + i;
      const glm::dvec2 c = T.centre(col);
      spans_at(c.x, c.y, -kInf, kInf, column[size_t(col)]);
    }
  });
  for (int col = 0; col < T.nx * T.ny; ++col) {
    T.first[size_t(col)] = uint32_t(T.floors.size());
    const std::vector<TSpan>& spans = column[size_t(col)];
    for (size_t k = 0; k < spans.size(); ++k) {
      TFloor f;
      f.z = spans[k].hi;
      f.ceiling = k + 1 < spans.size() ? spans[k + 1].lo : kInf;
      f.slope_tan = spans[k].slope_tan;
      f.candidate = T.candidate_rule(f.slope_tan, f.z, f.ceiling);
      T.floors.push_back(f);
      T.column_of.push_back(col);
    }
  }
  T.first.back() = uint32_t(T.floors.size());
  column.clear();
  column.shrink_to_fit();
  std::vector<TSpan> spans;

  // Borders (rule 4): per candidate floor, the positions of its unlinked sides.
  std::vector<uint32_t> site_first(T.floors.size() + 1, 0);
  std::vector<glm::dvec2> sites;
  const double r = agent.agent_radius;
  for (size_t n = 0; n < T.floors.size(); ++n) {
    site_first[n] = uint32_t(sites.size());
    const TFloor& f = T.floors[n];
    if (!f.candidate) continue;
    const glm::dvec2 c = T.centre(T.column_of[n]);
    for (int d = 0; d < 4; ++d) {
      bool any = false, any_candidate = false;
      T.for_links(int(n), d, [&](int k) {
        any = true;
        any_candidate = any_candidate || T.floors[size_t(k)].candidate;
      });
      if (any_candidate) continue;
      double s = 0.5;  // a step, wall, drop or edge: on the cell side
      if (any) {       // the slope or the clearance changes: where exactly
        double lo = 0.0, hi = 1.0;
        for (int it = 0; it < bisections; ++it) {
          const double mid = 0.5 * (lo + hi);
          const glm::dvec2 p = c + mid * g * glm::dvec2(kDir[d]);
          spans_at(p.x, p.y, f.z - agent.max_climb - 0.2, f.z + agent.max_climb + agent.agent_height + 0.2, spans);
          bool ok = false;
          double best = kInf;
          for (size_t k = 0; k < spans.size(); ++k) {
            const double dz = std::abs(spans[k].hi - f.z);
            if (dz >= best) continue;
            best = dz;
            const double ceiling = k + 1 < spans.size() ? spans[k + 1].lo : kInf;
            const double slope = spans[k].slope_tan;
            ok = dz <= agent.max_climb && T.candidate_rule(slope, spans[k].hi, ceiling);
          }
          (ok ? lo : hi) = mid;
        }
        s = 0.5 * (lo + hi);
      }
      sites.push_back(c + s * g * glm::dvec2(kDir[d]));
    }
  }
  site_first.back() = uint32_t(sites.size());

  // Columns within reach of some border: only their floors need the disc search.
  std::vector<uint8_t> near(size_t(T.nx) * size_t(T.ny), 0);
  const double reach = r + g;
  for (const glm::dvec2& s : sites) {
    const int i0 = int(std::floor((s.x - reach - T.x0) / g)), i1 = int(std::ceil((s.x + reach - T.x0) / g));
    const int j0 = int(std::floor((s.y - reach - T.y0) / g)), j1 = int(std::ceil((s.y + reach - T.y0) / g));
    for (int j = std::max(0, j0); j <= std::min(T.ny - 1, j1); ++j) {
      for (int i = std::max(0, i0); i <= std::min(T.nx - 1, i1); ++i) near[size_t(j * T.nx + i)] = 1;
    }
  }
  std::vector<int> stamp(T.floors.size(), -1), queue;
  for (size_t n = 0; n < T.floors.size(); ++n) {
    TFloor& f = T.floors[n];
    if (!f.candidate) continue;
    if (!near[size_t(T.column_of[n])]) {
      f.walkable = true;
      continue;
    }
    const glm::dvec2 c = T.centre(T.column_of[n]);
    bool eroded = false;
    queue.assign(1, int(n));
    stamp[n] = int(n);
    for (size_t q = 0; q < queue.size() && !eroded; ++q) {
      const int m = queue[q];
      for (uint32_t s = site_first[size_t(m)]; s < site_first[size_t(m) + 1]; ++s) {
        if (glm::length(sites[s] - c) < r) eroded = true;
      }
      for (int d = 0; d < 4 && !eroded; ++d) {
        T.for_links(m, d, [&](int k) {
          if (stamp[size_t(k)] == int(n) || !T.floors[size_t(k)].candidate) return;
          if (glm::length(T.centre(T.column_of[size_t(k)]) - c) > reach) return;
          stamp[size_t(k)] = int(n);
          queue.push_back(k);
        });
      }
    }
    f.walkable = !eroded;
  }

  // Components (rule 5).
  for (size_t n = 0; n < T.floors.size(); ++n) {
    if (!T.floors[n].walkable || T.floors[n].component >= 0) continue;
    ++T.walkable;
    const int id = T.components++;
    T.floors[n].component = id;
    queue.assign(1, int(n));
    for (size_t q = 0; q < queue.size(); ++q) {
      const int m = queue[q];
      for (int d = 0; d < 4; ++d) {
        T.for_links(m, d, [&](int k) {
          TFloor& o = T.floors[size_t(k)];
          if (!o.walkable || o.component >= 0) return;
          o.component = id;
          ++T.walkable;
          queue.push_back(k);
        });
      }
    }
  }
  return T;
}

// ---- measuring a peer ----------------------------------------------------------------

struct PeerResult {
  std::string name;
  std::vector<float> walkable;  // per truth floor: the fraction of its cell the peer keeps
  std::vector<uint8_t> complete;  // per pair
  double build_ms = 0;
  std::string size;
};

struct Pair {
  glm::dvec3 a{0.0}, b{0.0};
  bool reachable = false;
};

std::vector<Pair> truth_pairs(const Truth& T, int count, uint32_t seed) {
  std::vector<int> walk;
  for (size_t n = 0; n < T.floors.size(); ++n) {
    if (T.floors[n].walkable) walk.push_back(int(n));
  }
  std::vector<Pair> pairs;
  if (walk.empty()) return pairs;
  std::mt19937 rng(seed);
  auto point = [&](int n) {
    const glm::dvec2 c = T.centre(T.column_of[size_t(n)]);
    return glm::dvec3(c, T.floors[size_t(n)].z);
  };
  for (int i = 0; i < count; ++i) {
    const int a = walk[rng() % walk.size()], b = walk[rng() % walk.size()];
    pairs.push_back({point(a), point(b), T.floors[size_t(a)].component == T.floors[size_t(b)].component});
  }
  return pairs;
}

glm::dvec3 ldc_origin(const Terrain& t) { return {t.x0 - 0.07, t.y0 - 0.07, t.zfloor - 0.07}; }

// ldc's world for an analytic terrain: the exact ImplicitSolid at h 0.2.
Result<World> analytic_world(const Terrain& t) {
  const TerrainSolid solid(t);
  GridConfig grid;
  grid.cell_size = 0.2;
  grid.use_origin = true;  // lattice nodes off the terrain's feature lines
  grid.origin = ldc_origin(t);
  return build_from_implicit(solid, grid);
}

// The parts of truth floor n's g x g cell that the column sides of `lattice`
// cut it into (at most 2 x 2, as g < h): their centres and area fractions.
// ldc's walkable set is a union of whole column squares, so reading it at
// these centres gives its exact area on the truth's cells.
struct Piece {
  glm::dvec2 centre{0.0};
  double weight = 0;
};
int cell_pieces(const Truth& T, size_t n, const Lattice& lattice, Piece out[4]) {
  const glm::dvec2 c = T.centre(T.column_of[n]);
  double cuts[2][3];
  int count[2];
  for (int a = 0; a < 2; ++a) {
    const double lo = c[a] - 0.5 * T.g, hi = c[a] + 0.5 * T.g, o = lattice.origin[a], h = lattice.cell_size;
    const double side = o + (std::floor((lo - o) / h - 0.5) + 1.5) * h;  // first column side above lo
    count[a] = 0;
    cuts[a][count[a]++] = lo;
    if (side > lo + 1e-9 && side < hi - 1e-9) cuts[a][count[a]++] = side;
    cuts[a][count[a]] = hi;
  }
  int k = 0;
  for (int j = 0; j < count[1]; ++j) {
    for (int i = 0; i < count[0]; ++i) {
      out[k].centre = {0.5 * (cuts[0][i] + cuts[0][i + 1]), 0.5 * (cuts[1][j] + cuts[1][j + 1])};
      out[k++].weight = (cuts[0][i + 1] - cuts[0][i]) * (cuts[1][j + 1] - cuts[1][j]) / (T.g * T.g);
    }
  }
  return k;
}

// The best any walkable set made of whole h x h cells can do: ldc's columns
// (same lattice), each kept exactly when the truth keeps its centre (the truth
// node nearest the centre, the floor of that node nearest in height).
PeerResult column_bound(const Lattice& lattice, const Truth& T) {
  PeerResult out;
  out.name = "(truth on h 0.2 cells: bound)";
  out.walkable.assign(T.floors.size(), 0.0f);
  const glm::dvec2 origin(lattice.origin);
  const double h = lattice.cell_size;
  Piece pieces[4];
  for (size_t n = 0; n < T.floors.size(); ++n) {
    const int count = cell_pieces(T, n, lattice, pieces);
    double sum = 0;
    for (int i = 0; i < count; ++i) {
      const glm::dvec2 centre = origin + h * glm::round((pieces[i].centre - origin) / h);
      const int col = T.column(int(std::floor((centre.x - T.x0) / T.g)), int(std::floor((centre.y - T.y0) / T.g)));
      if (col < 0) continue;
      double best = kInf;
      bool walkable = false;
      for (uint32_t k = T.first[size_t(col)]; k < T.first[size_t(col) + 1]; ++k) {
        const double dz = std::abs(T.floors[k].z - T.floors[n].z);
        if (dz < best && dz <= kRasterReach) {
          best = dz;
          walkable = T.floors[k].walkable;
        }
      }
      sum += walkable ? pieces[i].weight : 0.0;
    }
    out.walkable[n] = float(sum);
  }
  return out;
}

PeerResult measure_ldc(const World& world, const Truth& T, const std::vector<Pair>& pairs, const NavConfig& config,
                       std::string* note) {
  PeerResult out;
  out.name = "**ldc** (h " + fmt("%.1f", world.lattice().cell_size) + ")";
  const auto t1 = Clock::now();
  Result<NavMesh> nav = NavMesh::build(world, config);
  out.build_ms = ms_since(t1);
  if (!nav.ok()) {
    *note = "ldc nav build failed: " + nav.status().to_string();
    return out;
  }
  const NavStats stats = nav->stats();
  out.size = std::to_string(stats.walkable) + " walkable floors, " + std::to_string(stats.regions) +
             " regions, " + std::to_string(stats.components) + " islands";
  NavQuery query(nav.value());
  out.walkable.assign(T.floors.size(), 0.0f);
  Piece pieces[4];
  for (size_t n = 0; n < T.floors.size(); ++n) {
    const int count = cell_pieces(T, n, world.lattice(), pieces);
    double sum = 0;
    for (int i = 0; i < count; ++i) {
      const glm::dvec3 p(pieces[i].centre, T.floors[n].z);
      Result<NavPoint> hit = query.nearest_walkable(p, {1e-4, 1e-4, kRasterReach});
      if (hit.ok() && glm::length(glm::dvec2(hit->position) - pieces[i].centre) < 1e-6) sum += pieces[i].weight;
    }
    out.walkable[n] = float(sum);
  }
  for (const Pair& pair : pairs) {
    Result<NavPath> path = query.find_path(pair.a, pair.b);
    out.complete.push_back(path.ok() && path->status == PathStatus::kComplete);
  }
  return out;
}

PeerResult measure_detour(const Triangles& mesh, const Truth& T, const std::vector<Pair>& pairs,
                          const DetourParams& params, std::string* note) {
  PeerResult out;
  char name[96];
  std::snprintf(name, sizeof name, "Detour (cs %.1f, ch %.1f)", params.cell_size, params.cell_height);
  out.name = name;
  DetourBuildStats stats;
  std::string error;
  std::unique_ptr<DetourNav> nav = detour_build(mesh.verts, mesh.tris, params, &stats, &error);
  if (!nav) {
    *note = out.name + " build failed: " + error;
    out.walkable.assign(T.floors.size(), 0.0f);
    out.complete.assign(pairs.size(), 0);
    return out;
  }
  out.build_ms = stats.build_ms;
  out.size = std::to_string(stats.polys) + " polys";
  out.walkable.assign(T.floors.size(), 0.0f);
  const glm::vec3 half(1e-4f, float(kRasterReach), 1e-4f);
  for (size_t n = 0; n < T.floors.size(); ++n) {
    const glm::dvec2 c = T.centre(T.column_of[n]);
    const glm::vec3 p = to_detour(glm::dvec3(c, T.floors[n].z));
    glm::vec3 nearest;
    out.walkable[n] = detour_nearest_point(*nav, p, half, &nearest) &&
                              std::hypot(nearest.x - p.x, nearest.z - p.z) < 1e-5f
                          ? 1.0f
                          : 0.0f;
  }
  for (const Pair& pair : pairs) {
    out.complete.push_back(detour_find_path(*nav, to_detour(pair.a), to_detour(pair.b)).found);
  }
  return out;
}

// ---- reporting ---------------------------------------------------------------------------


// The largest 4-connected clusters of floors where the peer and the truth
// disagree (false: peer only; missed: truth only), as lines of text.
std::vector<std::string> clusters(const Truth& T, const PeerResult& peer, bool false_walkable, int top) {
  const size_t n = T.floors.size();
  std::vector<int> label(n, -1);
  struct Cluster {
    size_t count = 0;
    glm::dvec2 lo{kInf}, hi{-kInf};
    double zmin = kInf, zmax = -kInf, slope_min = kInf, slope_max = 0;
  };
  std::vector<Cluster> out;
  auto bad = [&](size_t k) {
    const bool p = peer.walkable[k] > 0.5f;
    return false_walkable ? (p && !T.floors[k].walkable) : (!p && T.floors[k].walkable);
  };
  std::vector<int> queue;
  for (size_t s = 0; s < n; ++s) {
    if (!bad(s) || label[s] >= 0) continue;
    Cluster c;
    label[s] = int(out.size());
    queue.assign(1, int(s));
    for (size_t q = 0; q < queue.size(); ++q) {
      const size_t m = size_t(queue[q]);
      const glm::dvec2 p = T.centre(T.column_of[m]);
      ++c.count;
      c.lo = glm::min(c.lo, p), c.hi = glm::max(c.hi, p);
      c.zmin = std::min(c.zmin, T.floors[m].z), c.zmax = std::max(c.zmax, T.floors[m].z);
      const double deg = std::atan(T.floors[m].slope_tan) * 180.0 / kPi;
      c.slope_min = std::min(c.slope_min, deg), c.slope_max = std::max(c.slope_max, deg);
      const int col = T.column_of[m];
      for (int d = 0; d < 4; ++d) {  // any floor of the side column within max_climb (links or not)
        const int side = T.column(col % T.nx + kDir[d].x, col / T.nx + kDir[d].y);
        if (side < 0) continue;
        for (uint32_t k = T.first[size_t(side)]; k < T.first[size_t(side) + 1]; ++k) {
          if (label[k] >= 0 || !bad(k) || std::abs(T.floors[k].z - T.floors[m].z) > T.agent.max_climb) continue;
          label[k] = int(out.size());
          queue.push_back(int(k));
        }
      }
    }
    out.push_back(c);
  }
  std::sort(out.begin(), out.end(), [](const Cluster& a, const Cluster& b) { return a.count > b.count; });
  std::vector<std::string> lines;
  for (int i = 0; i < top && i < int(out.size()); ++i) {
    const Cluster& c = out[size_t(i)];
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "%s %.3f m² in x [%.3f, %.3f] y [%.3f, %.3f] z [%.2f, %.2f], exact slope %.1f°..%.1f°",
                  false_walkable ? "false" : "missed", double(c.count) * T.g * T.g, c.lo.x, c.hi.x, c.lo.y, c.hi.y,
                  c.zmin, c.zmax, c.slope_min, c.slope_max);
    lines.push_back(buf);
  }
  return lines;
}

// Top-down image (x right, y up), one pixel per truth column: green both,
// red peer only (false walkable), blue truth only (missed), grey a floor
// neither keeps, black no floor. A column shows its first disagreeing floor.
void write_ppm(const std::string& path, const Truth& T, const PeerResult& peer) {
  std::vector<unsigned char> img(size_t(T.nx) * size_t(T.ny) * 3, 0);
  for (int col = 0; col < T.nx * T.ny; ++col) {
    int code = -1;  // 0 neither, 1 both, 2 false, 3 missed
    for (uint32_t k = T.first[size_t(col)]; k < T.first[size_t(col) + 1]; ++k) {
      const bool p = peer.walkable[k] > 0.5f, t = T.floors[k].walkable;
      const int c = p && t ? 1 : p ? 2 : t ? 3 : 0;
      if (c >= 2) {
        code = c;
        break;
      }
      code = std::max(code, c);
    }
    unsigned char* px = &img[(size_t(T.ny - 1 - col / T.nx) * size_t(T.nx) + size_t(col % T.nx)) * 3];
    if (code == 0) px[0] = px[1] = px[2] = 90;
    if (code == 1) px[1] = 200;
    if (code == 2) px[0] = 230;
    if (code == 3) px[2] = 230;
  }
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fprintf(f, "P6 %d %d 255\n", T.nx, T.ny);
    std::fwrite(img.data(), 1, img.size(), f);
    std::fclose(f);
  }
}

std::string file_name(std::string s) {
  for (char& c : s) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return s;
}

}  // namespace

std::vector<NavTruthRow> run_nav_truth(const NavTruthOptions& options) {
  const NavConfig agent;  // RecastDemo's agent: height 2, radius 0.6, climb 0.9, slope 45
  std::vector<NavTruthRow> rows;
  std::vector<std::string> notes, details;
  DetourParams coarse;   // bench_nav's: cs 0.3, ch 0.2
  DetourParams fine = coarse;
  fine.cell_size = 0.2;  // ldc's h
  auto wanted = [&](const std::string& name) {
    return options.only.empty() || std::any_of(options.only.begin(), options.only.end(), [&](const std::string& o) {
             return name.compare(0, o.size(), o) == 0;
           });
  };
  // One scene: the truth's column source and rectangle, ldc's world, Detour's triangles.
  struct Scene {
    std::string name, description;
    SpanFn spans;
    glm::dvec4 rect{0.0};
    double grid = 0.05;
    int bisections = 40;
    std::optional<World> world;
    Triangles mesh;
    std::string inputs;
  };
  const std::vector<Terrain> terrains = all_terrains();
  std::unique_ptr<ImplicitSolid> landscape_solid;
  std::vector<Scene> scenes;
  for (const Terrain& t : terrains) {
    if (!wanted(t.name)) continue;
    Scene sc;
    sc.name = t.name;
    sc.description = t.description;
    sc.spans = analytic_spans(t);
    sc.rect = {t.x0, t.y0, t.x1, t.y1};
    sc.grid = options.grid;
    Result<World> world = analytic_world(t);
    if (!world.ok()) {
      notes.push_back(t.name + ": ldc world build failed: " + world.status().to_string());
      continue;
    }
    sc.world.emplace(std::move(world.value()));
    sc.mesh = detour_mesh(t, 0.1);
    scenes.push_back(std::move(sc));
  }
  if (options.landscape && wanted("landscape")) {
    // bench_nav's landscape scene: ldc's world from build_terrain at h 0.2,
    // Detour's triangles contoured from it; the truth from the exact solid.
    Scene sc;
    sc.name = "landscape (bench_nav's)";
    const TerrainConfig config;
    landscape_solid = make_terrain_solid(config);
    const WorldBox b = landscape_solid->bounds();
    sc.description = "the default landscape (TerrainConfig{}: hills, ridges, caves, leaning cliffs, arches), "
                     "the truth sampled from its ImplicitSolid every 0.05 m up each column (sign changes refined "
                     "to 1e-6 m, normals by the solid's normal() with ldc's step h / 1000), unlinked sides on "
                     "the cell side";
    sc.spans = sampled_spans(*landscape_solid, 0.05, 0.2 * 1e-3);
    sc.rect = {b.min.x, b.min.y, b.max.x, b.max.y};
    sc.grid = std::max(options.grid, 0.1);
    sc.bisections = 0;
    Result<World> world = build_terrain(config, 0.2);
    if (world.ok()) {
      sc.world.emplace(std::move(world.value()));
      Result<ContourMesh> contour = contour_world(*sc.world);
      if (contour.ok()) {
        for (const glm::dvec3& p : contour->positions) {
          const glm::vec3 q = to_detour(p);
          sc.mesh.verts.insert(sc.mesh.verts.end(), {q.x, q.y, q.z});
        }
        for (const glm::uvec3& tri : contour->triangles) {
          sc.mesh.tris.insert(sc.mesh.tris.end(), {int(tri.x), int(tri.y), int(tri.z)});
        }
      }
      scenes.push_back(std::move(sc));
    } else {
      notes.push_back("landscape: ldc world build failed: " + world.status().to_string());
    }
  }
  for (const Scene& sc : scenes) {
    const auto t0 = Clock::now();
    const Truth T = build_truth(sc.spans, sc.rect, agent, sc.grid, sc.bisections);
    const double truth_ms = ms_since(t0);
    const std::vector<Pair> pairs = truth_pairs(T, options.pairs, options.seed);
    int truth_reachable = 0;
    for (const Pair& p : pairs) truth_reachable += p.reachable;
    const Triangles& mesh = sc.mesh;
    std::string note;
    std::vector<PeerResult> peers;
    peers.push_back(measure_ldc(*sc.world, T, pairs, agent, &note));
    if (!note.empty()) notes.push_back(sc.name + ": " + note), note.clear();
    peers.push_back(measure_detour(mesh, T, pairs, coarse, &note));
    if (!note.empty()) notes.push_back(sc.name + ": " + note), note.clear();
    peers.push_back(measure_detour(mesh, T, pairs, fine, &note));
    if (!note.empty()) notes.push_back(sc.name + ": " + note), note.clear();
    peers.push_back(column_bound(sc.world->lattice(), T));
    const double cell = T.g * T.g;
    std::string sizes;
    for (const PeerResult& peer : peers) {
      const bool reference = peer.complete.empty() && !pairs.empty();  // the bound: no paths
      if (peer.walkable.size() != T.floors.size() || (!reference && peer.complete.size() != pairs.size())) continue;
      NavTruthRow row;
      row.terrain = sc.name;
      row.peer = peer.name;
      double both = 0, either = 0, fp = 0, fn = 0, mine = 0;  // in floor cells (fractions)
      for (size_t n = 0; n < T.floors.size(); ++n) {
        const double p = peer.walkable[n];
        const bool w = T.floors[n].walkable;
        both += w ? p : 0.0, either += w ? 1.0 : p, fp += w ? 0.0 : p, fn += w ? 1.0 - p : 0.0, mine += p;
      }
      row.truth_m2 = double(T.walkable) * cell;
      row.peer_m2 = mine * cell;
      row.iou = either > 0 ? both / either : 1.0;
      row.false_m2 = fp * cell;
      row.missed_m2 = fn * cell;
      int agree = 0;
      for (size_t i = 0; i < peer.complete.size(); ++i) agree += bool(peer.complete[i]) == pairs[i].reachable;
      row.pairs = int(pairs.size());
      row.truth_reachable = truth_reachable;
      row.agreement = reference ? -1.0 : pairs.empty() ? 1.0 : double(agree) / double(pairs.size());
      rows.push_back(row);
      if (reference) continue;
      int complete = 0;
      for (uint8_t c : peer.complete) complete += c;
      sizes += "; " + peer.name + " " + peer.size + " (build " + fmt("%.0f", peer.build_ms) + " ms), " +
               std::to_string(complete) + " pairs complete";
      if (options.detail) {
        for (bool fw : {true, false}) {
          for (const std::string& line : clusters(T, peer, fw, 4)) {
            details.push_back(sc.name + " · " + peer.name + ": " + line);
          }
        }
      }
      if (!options.ppm_dir.empty()) {
        write_ppm(options.ppm_dir + "/" + file_name(sc.name + "_" + peer.name) + ".ppm", T, peer);
      }
    }
    notes.push_back(sc.name + ": " + sc.description + ". Truth (grid " + fmt("%.2f", T.g) + " m): " +
                    fmt("%.2f", double(T.walkable) * cell) + " m² walkable in " + std::to_string(T.components) +
                    " component(s); " + std::to_string(truth_reachable) + " of " + std::to_string(pairs.size()) +
                    " pairs reachable (" + fmt("%.0f", truth_ms) + " ms)" + sizes + "; " +
                    std::to_string(mesh.tris.size() / 3) + " triangles for Detour");
  }
  std::printf("\n### Ground truth on analytic terrains\n\n");
  std::printf(
      "| terrain | peer | walkable IoU | reachability agreement with truth | false walkable area m² | missed walkable "
      "area m² |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (const NavTruthRow& r : rows) {
    const std::string agreement = r.agreement < 0 ? "—" : fmt("%.1f%%", 100.0 * r.agreement);
    std::printf("| %s | %s | %.4f | %s | %.2f | %.2f |\n", r.terrain.c_str(), r.peer.c_str(), r.iou,
                agreement.c_str(), r.false_m2, r.missed_m2);
  }
  std::printf("\n");
  for (const std::string& n : notes) std::printf("- %s\n", n.c_str());
  std::printf(
      "- Truth (bench/nav_truth.cpp): the agent rules of nav/nav.h (height 2, radius 0.6, climb 0.9, slope 45; "
      "NavConfig defaults) on the exact surface, sampled on a %.2f m grid of columns (every floor of a column is a "
      "node): a floor is a candidate when its exact normal is within 45° of up and >= 2 m is free above it; floors "
      "of side-by-side columns are linked when the step is <= 0.9 m and the gap between the higher floor and the "
      "lower ceiling is >= 2 m; a candidate is walkable unless an unlinked side (no linked candidate beyond it: a "
      "steep or low floor, a wall, a drop, the edge) lies within 0.6 m of it, horizontal Euclidean distance, over "
      "the candidates linked to it inside that disc, the side placed where the rule switches on the exact surface "
      "(bisection) or on the cell side for steps and edges; reachability is a flood fill over walkable floors "
      "through links.\n",
      options.grid);
  std::printf(
      "- Walkable sets are read at every truth floor: ldc by NavQuery::nearest_walkable with half extents (1e-4, "
      "1e-4, 1) m at the centre of each part of the floor's cell cut by ldc's column sides, walkable when the hit is "
      "that point itself horizontally (it lies in the h x h square of a kept column; the parts' areas add up, so "
      "ldc's area is exact); Detour by findNearestPoly with half extents (1e-4, 1, 1e-4), walkable when the nearest "
      "point "
      "is the point itself horizontally (inside a polygon). Pairs: %d per terrain, drawn uniformly (seed %u) on the "
      "truth's walkable floors; agreement = a complete path (ldc kComplete; Detour: the path ends in the goal's "
      "polygon; search boxes (2, 2, 4) / (2, 4, 2) m as bench_nav) exactly when the truth connects the two.\n",
      options.pairs, options.seed);
  std::printf(
      "- Inputs (analytic terrains): ldc builds the terrain as an ImplicitSolid (exact crossings on vertical rays, "
      "analytic normals) "
      "at h = 0.2 with the lattice origin 0.07 m off the rectangle's corner; Detour gets the surface triangulated "
      "on a 0.1 m grid (vertices on every kink line, a 2 mm vertical face at each step, the slab as closed boxes), "
      "RecastDemo's parameters as bench_nav (ch 0.2, edge error 1.3, detail sample 6 / 1) at cs 0.3 (bench_nav's) "
      "and 0.2 (ldc's h). Features lie on multiples of 0.05 m from the rectangle's corner; ldc's columns are offset "
      "0.07 m so that none lies on a column centre or side.\n");
  std::printf(
      "- (truth on h 0.2 cells: bound): not a peer; ldc's columns (same lattice), each kept exactly when the truth "
      "keeps its centre. The error left is the quantization of a walkable set made of whole 0.2 m cells (about "
      "h/4 on average along every border), the best ldc's cell model can score here.\n");
  for (const std::string& d : details) std::printf("- %s\n", d.c_str());
  return rows;
}

}  // namespace ldc::bench
