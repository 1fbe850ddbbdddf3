// Adaptive engine chunk meshes (issue 19 item 4): simplify_mesh on a copy of
// each chunk's mesh never moves the chunk's boundary vertices (the seams
// with its neighbours), so chunks simplified one by one, each on its own
// schedule, still meet without a crack.
#include <gtest/gtest.h>

#include <map>
#include <tuple>

#include "contour/contour.h"
#include "ldc/build.h"
#include "test_util.h"

namespace ldc {
namespace {

// One mesh from chunk meshes, vertices welded by exact position.
ContourMesh weld(const std::vector<ContourMesh>& pieces) {
  ContourMesh out;
  std::map<std::tuple<double, double, double>, uint32_t> index;
  for (const ContourMesh& m : pieces) {
    std::vector<uint32_t> remap(m.vertex_count());
    for (size_t v = 0; v < m.vertex_count(); ++v) {
      const glm::dvec3& p = m.positions[v];
      auto [it, added] = index.try_emplace({p.x, p.y, p.z}, uint32_t(out.positions.size()));
      if (added) out.positions.push_back(p);
      remap[v] = it->second;
    }
    for (const glm::uvec3& t : m.triangles) out.triangles.push_back({remap[t.x], remap[t.y], remap[t.z]});
  }
  return out;
}

TEST(ChunkAdaptive, ChunksSimplifiedOneByOneMeetWithoutACrack) {
  World w = build_from_mesh(test::load_test_mesh("fandisk.obj"), {.cells = 96, .chunk_size = 16}).value();
  const ChunkedMesh meshes = ChunkedMesh::create(w).value();
  std::vector<ContourMesh> uniform, adaptive;
  size_t before = 0, after = 0;
  for (const ChunkMesh& chunk : meshes.chunks()) {
    uniform.push_back(chunk.mesh);
    ContourMesh copy = chunk.mesh;
    ASSERT_TRUE(simplify_mesh(copy, {.max_error = 0.2 * w.lattice().cell_size}).ok());
    before += chunk.mesh.triangle_count();
    after += copy.triangle_count();
    adaptive.push_back(std::move(copy));
  }
  ASSERT_GT(meshes.chunks().size(), 8u);
  const MeshQuality whole_uniform = mesh_quality(weld(uniform));
  ASSERT_TRUE(whole_uniform.watertight()) << quality_failures(whole_uniform);
  const MeshQuality whole = mesh_quality(weld(adaptive));
  EXPECT_TRUE(whole.watertight()) << quality_failures(whole);
  EXPECT_EQ(whole.nonmanifold_edges + whole.nonmanifold_vertices, 0u);
  EXPECT_LE(whole.self_intersecting_pairs, whole_uniform.self_intersecting_pairs);
  EXPECT_LT(after * 3, before) << after << " of " << before << " triangles left";
  EXPECT_NEAR(whole.volume, whole_uniform.volume, 1e-3 * whole_uniform.volume);
}

}  // namespace
}  // namespace ldc
