// The .vdb export read back through OpenVDB's own reader.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/resource.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>

#include <openvdb/openvdb.h>

#include "ldc/build.h"
#include "ldc/terrain.h"
#include "voxelize/vdb.h"
#include "voxelize/voxelize.h"

namespace ldc {
namespace {

std::string temp_path(const std::string& name) { return ::testing::TempDir() + name; }

World small_terrain() {
  return build_terrain(TerrainConfig{.size_x = 8.0, .size_y = 8.0, .cave_radius = 0.0, .arches = 1}, 0.25, 16).value();
}

openvdb::GridPtrVecPtr read_all(const std::string& path) {
  openvdb::initialize();
  openvdb::io::File file(path);
  file.open();
  openvdb::GridPtrVecPtr grids = file.getGrids();
  file.close();
  return grids;
}

openvdb::GridBase::Ptr find(const openvdb::GridPtrVec& grids, const std::string& name) {
  for (const auto& g : grids) {
    if (g->getName() == name) return g;
  }
  return nullptr;
}

TEST(Vdb, OccupancyNormalAndAlbedoRoundTripThroughOpenVdb) {
  World w = small_terrain();
  VoxelizeOptions opt;
  opt.faces = true;
  Result<VoxelGrid> g = voxelize(w, VoxelConfig{.voxel_size = 0.5}, opt);
  ASSERT_TRUE(g.ok());
  const std::string path = temp_path("ldc_roundtrip.vdb");
  ASSERT_TRUE(save_vdb(g.value(), path, "test").ok());
  openvdb::GridPtrVecPtr grids = read_all(path);
  ASSERT_EQ(grids->size(), 3u);
  auto occ = openvdb::gridPtrCast<openvdb::FloatGrid>(find(*grids, "occupancy"));
  auto normal = openvdb::gridPtrCast<openvdb::Vec3SGrid>(find(*grids, "normal"));
  auto albedo = openvdb::gridPtrCast<openvdb::Vec3SGrid>(find(*grids, "albedo"));
  ASSERT_TRUE(occ && normal && albedo);
  EXPECT_NEAR(occ->voxelSize()[0], 0.5, 1e-12);
  // Index (i, j, k) is voxel (i, j, k); its centre in world space.
  const openvdb::Vec3d centre = occ->indexToWorld(openvdb::Coord(2, 3, 4));
  const glm::dvec3 expect = g.value().voxel_min({2, 3, 4}) + 0.25;
  EXPECT_NEAR(centre.x(), expect.x, 1e-9);
  EXPECT_NEAR(centre.z(), expect.z, 1e-9);
  auto acc = occ->getConstAccessor();
  const VoxelBox& box = g.value().box;
  double sum = 0.0;
  for (int z = 0; z < box.dims.z; ++z) {
    for (int y = 0; y < box.dims.y; ++y) {
      for (int x = 0; x < box.dims.x; ++x) {
        const glm::ivec3 v = box.lo + glm::ivec3(x, y, z);
        ASSERT_EQ(acc.getValue(openvdb::Coord(v.x, v.y, v.z)), g.value().at(v));
        sum += acc.getValue(openvdb::Coord(v.x, v.y, v.z));
      }
    }
  }
  EXPECT_NEAR(sum * 0.125, g.value().volume(), 1e-6 * g.value().volume());
  size_t with_normal = 0;
  auto n_acc = normal->getConstAccessor();
  auto a_acc = albedo->getConstAccessor();
  for (const glm::ivec3& v : g.value().surface) {
    const openvdb::Coord c(v.x, v.y, v.z);
    if (!n_acc.isValueOn(c)) continue;
    ++with_normal;
    EXPECT_NEAR(n_acc.getValue(c).length(), 1.0, 1e-5);
    const openvdb::Vec3s a = a_acc.getValue(c);
    EXPECT_TRUE(a.x() > 0.0f && a.x() <= 1.0f);
  }
  EXPECT_GT(with_normal, g.value().surface.size() / 2);
  std::remove(path.c_str());
}

TEST(Vdb, CascadeLevelsBecomeGridsPerLevel) {
  World w = small_terrain();
  CascadeConfig cfg;
  cfg.levels = 3;
  cfg.resolution = 8;
  cfg.voxel_size = 0.25;
  Cascades c = Cascades::create(w.lattice(), cfg).value();
  ASSERT_TRUE(c.update_all(w, {4.0, 4.0, 6.0}).ok());
  const std::string path = temp_path("ldc_cascades.vdb");
  ASSERT_TRUE(save_vdb(c, path).ok());
  openvdb::GridPtrVecPtr grids = read_all(path);
  ASSERT_EQ(grids->size(), 9u);
  for (int k = 0; k < 3; ++k) {
    auto occ = openvdb::gridPtrCast<openvdb::FloatGrid>(find(*grids, "occupancy_L" + std::to_string(k)));
    ASSERT_TRUE(occ);
    EXPECT_NEAR(occ->voxelSize()[0], 0.25 * (1 << k), 1e-12);
  }
  std::remove(path.c_str());
}

TEST(Vdb, UnwritablePathIsAnErrorNotAnException) {
  VoxelGrid g;
  g.voxel_size = 1.0;
  Status s = save_vdb(g, "/no/such/dir/out.vdb");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("/no/such/dir/out.vdb"), std::string::npos);
}

// OpenVDB writes by name, so save_vdb has it write a temp file that is
// renamed only once whole: a write that fails part way (RLIMIT_FSIZE, as a
// full disk) leaves the previous .vdb readable and no temp file beside it.
TEST(Vdb, AFailedSaveLeavesThePreviousFileReadable) {
  const std::string folder = temp_path("vdb_failed_save");
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  const std::string path = folder + "/world.vdb";
  VoxelizeOptions opt;
  opt.faces = true;
  Result<VoxelGrid> g = voxelize(small_terrain(), VoxelConfig{.voxel_size = 0.25}, opt);
  ASSERT_TRUE(g.ok());
  VoxelGrid tiny;
  tiny.voxel_size = 1.0;
  ASSERT_TRUE(save_vdb(tiny, path, "old").ok());
  const uintmax_t old_size = std::filesystem::file_size(path);
  struct rlimit old_limit;
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  struct rlimit small = old_limit;
  small.rlim_cur = old_size + 512;
  auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  Status s = save_vdb(g.value(), path, "new");
  ::setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  ASSERT_FALSE(s.ok()) << old_size << " -> " << std::filesystem::file_size(path);
  EXPECT_NE(s.message().find(path + ": cannot write the .vdb file: "), std::string::npos) << s.message();
  EXPECT_EQ(std::filesystem::file_size(path), old_size);
  EXPECT_EQ(read_all(path)->size(), 1u);  // the old file's one grid
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(folder)) ++entries;
  EXPECT_EQ(entries, 1u);
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace ldc
