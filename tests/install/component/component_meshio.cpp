#include <cstdio>
#include <filesystem>

#include "meshio/meshio.h"
#include "sphere.h"

int main() {
  ldc::Result<ldc::World> w = sphere_world();
  if (!w) return 1;
  ldc::Result<ldc::ContourMesh> mesh = ldc::contour_world(*w);
  if (!mesh) return 1;
  const std::string path = (std::filesystem::temp_directory_path() / "ldc_component_meshio.drc").string();
  if (!ldc::save_mesh(*mesh, path).ok()) return 1;
  ldc::Result<ldc::TriangleMesh> back = ldc::load_mesh(path);
  std::filesystem::remove(path);
  if (!back || back->triangle_count() != mesh->triangle_count()) return 1;
  std::printf("meshio: ok, %zu triangles through Draco\n", back->triangle_count());
  return 0;
}
