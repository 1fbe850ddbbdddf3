// The boolean cases of shared/PEERS.md (see boolean_cases.h).
#include "boolean_cases.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numbers>
#include <utility>

#include "bench_common.h"
#include "meshio/meshio.h"

namespace ldc::bench {

TriangleMesh icosphere(int levels, glm::dvec3 centre, double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<glm::dvec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                               {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9},  {5, 11, 4},
                               {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6},  {3, 6, 8},
                               {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& p : v) p = glm::normalize(p);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto [it, fresh] = mid.try_emplace({key.first, key.second}, uint32_t(v.size()));
      if (fresh) v.push_back(glm::normalize(v[a] + v[b]));
      return it->second;
    };
    std::vector<glm::uvec3> g;
    g.reserve(4 * f.size());
    for (const auto& tri : f) {
      uint32_t ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]), ca = midpoint(tri[2], tri[0]);
      g.push_back({tri[0], ab, ca});
      g.push_back({tri[1], bc, ab});
      g.push_back({tri[2], ca, bc});
      g.push_back({ab, bc, ca});
    }
    f = std::move(g);
  }
  TriangleMesh m;
  for (const auto& p : v) m.positions.push_back(centre + radius * p);
  m.triangles = std::move(f);
  return m;
}

TriangleMesh cylinder_z(glm::dvec2 axis, double z0, double z1, double radius, int segments) {
  TriangleMesh m;
  const uint32_t n = uint32_t(segments);
  for (double z : {z0, z1})
    for (uint32_t i = 0; i < n; ++i) {
      double a = 2.0 * std::numbers::pi * double(i) / double(n);
      m.positions.push_back({axis.x + radius * std::cos(a), axis.y + radius * std::sin(a), z});
    }
  m.positions.push_back({axis.x, axis.y, z0});
  m.positions.push_back({axis.x, axis.y, z1});
  const uint32_t bc = 2 * n, tc = 2 * n + 1;
  for (uint32_t i = 0; i < n; ++i) {
    uint32_t j = (i + 1) % n;
    m.triangles.push_back({i, j, n + j});
    m.triangles.push_back({i, n + j, n + i});
    m.triangles.push_back({bc, j, i});
    m.triangles.push_back({tc, n + i, n + j});
  }
  return m;
}

TriangleMesh translated(TriangleMesh m, glm::dvec3 d) {
  for (auto& p : m.positions) p += d;
  return m;
}

std::vector<BooleanCase> make_boolean_cases(const std::string& data, const std::vector<std::string>& only,
                                            bool include_raw) {
  auto wanted = [&](const std::string& n) { return only.empty() || std::count(only.begin(), only.end(), n); };
  const bool raw_wanted = std::count(only.begin(), only.end(), "bunny_sphere_raw") || (only.empty() && include_raw);
  auto load = [&](const std::string& file) {
    Result<TriangleMesh> m = load_mesh(data + "/" + file);
    if (!m.ok()) {
      std::fprintf(stderr, "%s\n", m.status().to_string().c_str());
      std::exit(1);
    }
    return std::move(m).value();
  };
  std::vector<BooleanCase> cases;
  if (wanted("bunny_sphere") || raw_wanted) {
    TriangleMesh raw = load("stanford-bunny.obj");
    MeshBounds bb = mesh_bounds(raw);
    double d = bb.diagonal();
    glm::dvec3 c = 0.5 * (bb.min + bb.max);
    TriangleMesh sphere = icosphere(5, c + glm::dvec3(0.15 * d, 0, 0), 0.3 * d);
    size_t holes = 0;
    TriangleMesh filled = fill_holes(raw, &holes);
    std::fprintf(stderr, "  filled %zu holes in the bunny\n", holes);
    // The filled case comes first: the raw case is measured against its reference.
    cases.push_back({"bunny_sphere", filled, sphere, d, 69664, 20480, false, ""});
    if (raw_wanted) cases.push_back({"bunny_sphere_raw", raw, sphere, d, 69451, 20480, true, "bunny_sphere"});
  }
  if (wanted("fandisk_cylinder")) {
    TriangleMesh a = load("fandisk.obj");
    MeshBounds bb = mesh_bounds(a);
    double d = bb.diagonal();
    glm::dvec3 c = 0.5 * (bb.min + bb.max);
    TriangleMesh b = cylinder_z({c.x, c.y}, bb.min.z - 0.1 * d, bb.max.z + 0.1 * d, 0.1 * d, 128);
    cases.push_back({"fandisk_cylinder", a, b, d, 12946, 512, false, ""});
  }
  if (wanted("rocker_sphere")) {
    TriangleMesh a = load("rocker-arm.obj");
    MeshBounds bb = mesh_bounds(a);
    double d = bb.diagonal();
    glm::dvec3 c = 0.5 * (bb.min + bb.max);
    cases.push_back({"rocker_sphere", a, icosphere(5, c + glm::dvec3(0.15 * d, 0, 0), 0.2 * d), d, 20088, 20480, false, ""});
  }
  if (wanted("spot_spot")) {
    TriangleMesh a = load("spot.obj");
    double d = mesh_bounds(a).diagonal();
    TriangleMesh b = translated(a, glm::dvec3(0.15, 0.08, 0.05) * d);
    cases.push_back({"spot_spot", a, b, d, 5856, 5856, false, ""});
  }
  return cases;
}

}  // namespace ldc::bench
