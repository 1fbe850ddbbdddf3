#include <cstdio>

#include "sphere.h"
#include "voxelize/voxelize.h"

int main() {
  ldc::Result<ldc::World> w = sphere_world();
  if (!w) return 1;
  ldc::VoxelConfig config;
  config.voxel_size = w->lattice().cell_size * 2;
  ldc::Result<ldc::VoxelGrid> grid = ldc::voxelize(*w, config);
  if (!grid) return 1;
  std::printf("voxelize: ok, %zu surface voxels\n", grid->surface.size());
  return 0;
}
