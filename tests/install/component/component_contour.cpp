#include <cstdio>

#include "contour/contour.h"
#include "sphere.h"

int main() {
  ldc::Result<ldc::World> w = sphere_world();
  if (!w) return 1;
  ldc::Result<ldc::ContourMesh> mesh = ldc::contour_world(*w);
  if (!mesh || !ldc::mesh_quality(*mesh).watertight()) return 1;
  std::printf("contour: ok, %zu triangles\n", mesh->triangle_count());
  return 0;
}
