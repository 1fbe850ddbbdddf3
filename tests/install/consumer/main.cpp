// Links every C++ module of the installed package and uses each once.
#include <cstdio>

#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/query.h"
#include "ldc/build.h"
#include "ldc/terrain.h"
#include "ldc/version.h"
#include "nav/nav.h"
#include "voxelize/voxelize.h"

int main() {
  ldc::TerrainConfig terrain;
  terrain.size_x = terrain.size_y = 12.0;
  ldc::Result<ldc::World> world = ldc::build_terrain(terrain, 0.4);
  if (!world.ok()) return std::printf("terrain: %s\n", world.status().to_string().c_str()), 1;
  ldc::WorldEditor editor(std::move(world).value());
  if (!editor.apply(ldc::Brush::sphere({6, 6, 6}, 2.0), ldc::EditOp::kSubtract).ok()) return 1;
  ldc::Result<ldc::ContourMesh> mesh = ldc::contour_world(editor.world());
  ldc::Result<ldc::NavMesh> nav = ldc::NavMesh::build(editor.world(), {});
  ldc::Queries queries(editor.world());
  ldc::Result<ldc::RayHit> hit = queries.ray_cast({{3, 3, 40}, {0, 0, -1}});
  ldc::VoxelConfig voxels;
  voxels.voxel_size = 0.8;
  ldc::Result<ldc::VoxelGrid> grid = ldc::voxelize(editor.world(), voxels);
  // A missing file must fail cleanly; linking this pulls in the stb image code.
  if (ldc::load_heightfield_png("no-such-heightfield.png", 0.5, 10.0, 1.0, 0.0).ok()) return 1;
  if (!mesh.ok() || !nav.ok() || !hit.ok() || !hit->hit || !grid.ok()) return 1;
  std::printf("consumer: ok: ldc %s, %zu triangles, %zu walkable floors, ground at z = %.2f, %zu surface voxels\n",
              LDC_VERSION_STRING, mesh->triangle_count(), nav->stats().walkable, hit->point.z,
              grid->surface.size());
  return 0;
}
