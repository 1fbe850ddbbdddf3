#include <cstdio>

#include "ldc/terrain.h"
#include "nav/nav.h"

int main() {
  ldc::TerrainConfig t;
  t.size_x = t.size_y = 10.0;
  ldc::Result<ldc::World> w = ldc::build_terrain(t, 0.4);
  if (!w) return 1;
  ldc::Result<ldc::NavMesh> nav = ldc::NavMesh::build(*w, {});
  if (!nav) return 1;
  std::printf("nav: ok, %zu walkable floors\n", nav->stats().walkable);
  return 0;
}
