#include "test_util.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include "meshio/meshio.h"

namespace ldc::test {

std::string data_path(const std::string& name) { return std::string(LDC_TEST_DATA_DIR) + "/" + name; }

TriangleMesh load_test_mesh(const std::string& name) {
  Result<TriangleMesh> m = load_mesh(data_path(name));
  if (!m.ok()) {
    ADD_FAILURE() << "cannot load " << name << ": " << m.status().to_string();
    return {};
  }
  return std::move(m.value());
}

TriangleMesh box_mesh(const glm::dvec3& lo, const glm::dvec3& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) {
    m.positions.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
  }
  // Two triangles per face, counter-clockwise seen from outside.
  const unsigned faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

TriangleMesh sphere_mesh(const glm::dvec3& centre, double radius, int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<glm::dvec3> v = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0},
                               {0, -1, t}, {0, 1, t},  {0, -1, -t}, {0, 1, -t},
                               {t, 0, -1}, {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                               {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                               {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                               {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : v) p = glm::normalize(p);
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<unsigned, unsigned>, unsigned> mid;
    auto midpoint = [&](unsigned a, unsigned b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(v[a] + v[b]));
      return mid[key] = unsigned(v.size() - 1);
    };
    std::vector<glm::uvec3> next;
    for (const auto& tri : f) {
      unsigned a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), c = midpoint(tri[2], tri[0]);
      next.insert(next.end(), {{tri[0], a, c}, {tri[1], b, a}, {tri[2], c, b}, {a, b, c}});
    }
    f = std::move(next);
  }
  TriangleMesh m;
  for (const auto& p : v) m.positions.push_back(centre + radius * p);
  m.triangles = std::move(f);
  return m;
}

GridConfig lattice_at_origin(double h) {
  GridConfig g;
  g.cell_size = h;
  g.use_origin = true;
  g.origin = glm::dvec3(0.0);
  g.chunk_size = 16;
  return g;
}

void append_mesh(TriangleMesh& a, const TriangleMesh& b) {
  unsigned base = unsigned(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  bool materials = !a.triangle_material.empty() || !b.triangle_material.empty();
  if (materials) a.triangle_material.resize(a.triangles.size(), 0);
  for (size_t i = 0; i < b.triangles.size(); ++i) {
    a.triangles.push_back(b.triangles[i] + glm::uvec3(base));
    if (materials) a.triangle_material.push_back(b.material_of(i));
  }
}

::testing::AssertionResult is_valid(const World& world) {
  ValidationReport r = validate(world);
  if (r.ok) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << r.summary();
}

// Chunk meshes equal: the same chunks, own vertices (in order), vertex data
// per cell, and triangles by their cells (the order of copies and triangles may differ).
::testing::AssertionResult same_chunk_meshes(const ChunkedMesh& a, const ChunkedMesh& b) {
  if (a.chunks().size() != b.chunks().size()) {
    return ::testing::AssertionFailure() << a.chunks().size() << " vs " << b.chunks().size() << " chunk meshes";
  }
  // Vertices are named by cell and sheet (a cell crossed by several sheets has a vertex per sheet).
  using Name = std::array<int, 4>;
  auto name = [](const ChunkMesh& m, uint32_t v) {
    const glm::ivec3& c = m.vertex_cell[v];
    return Name{c.z, c.y, c.x, m.vertex_sheet[v]};
  };
  using Key = std::array<int, 13>;
  auto triangles = [&](const ChunkMesh& m) {
    std::vector<Key> out;
    for (size_t t = 0; t < m.mesh.triangles.size(); ++t) {
      const glm::uvec3& tri = m.mesh.triangles[t];
      Name c[3] = {name(m, tri.x), name(m, tri.y), name(m, tri.z)};
      int first = 0;  // rotate the smallest name first: same triangle, same key
      for (int j = 1; j < 3; ++j) {
        if (c[j] < c[first]) first = j;
      }
      Key k;
      for (int j = 0; j < 3; ++j)
        for (int d = 0; d < 4; ++d) k[size_t(j * 4 + d)] = c[(first + j) % 3][size_t(d)];
      k[12] = m.mesh.triangle_material[t];
      out.push_back(k);
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  auto vertices = [&](const ChunkMesh& m) {
    std::map<Name, std::tuple<glm::dvec3, glm::vec3, uint16_t>> out;
    for (uint32_t v = 0; v < m.vertex_cell.size(); ++v) {
      out[name(m, v)] = {m.mesh.positions[v], m.mesh.normals[v], m.mesh.vertex_material[v]};
    }
    return out;
  };
  for (size_t i = 0; i < a.chunks().size(); ++i) {
    const ChunkMesh &x = a.chunks()[i], &y = b.chunks()[i];
    bool same_own = x.own_vertices == y.own_vertices &&
                    std::equal(x.vertex_cell.begin(), x.vertex_cell.begin() + long(x.own_vertices), y.vertex_cell.begin()) &&
                    std::equal(x.vertex_sheet.begin(), x.vertex_sheet.begin() + long(x.own_vertices), y.vertex_sheet.begin());
    if (x.chunk != y.chunk || !same_own || vertices(x) != vertices(y) || triangles(x) != triangles(y)) {
      return ::testing::AssertionFailure() << "chunk mesh " << i << " differs";
    }
  }
  return ::testing::AssertionSuccess();
}

namespace {
bool position_less(const glm::dvec3& p, const glm::dvec3& q) { return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z); }
}  // namespace

bool triangle_positions_less(const TrianglePositions& a, const TrianglePositions& b) {
  for (int i = 0; i < 3; ++i)
    if (a[i] != b[i]) return position_less(a[i], b[i]);
  return false;
}

std::vector<TrianglePositions> sorted_triangle_positions(const ContourMesh& mesh) {
  std::vector<TrianglePositions> out;
  for (const glm::uvec3& t : mesh.triangles) {
    TrianglePositions c{mesh.positions[t.x], mesh.positions[t.y], mesh.positions[t.z]};
    while (position_less(c[1], c[0]) || position_less(c[2], c[0])) c = {c[1], c[2], c[0]};
    out.push_back(c);
  }
  std::sort(out.begin(), out.end(), triangle_positions_less);
  return out;
}

}  // namespace ldc::test
