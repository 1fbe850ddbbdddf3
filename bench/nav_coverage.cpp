// Diagnostic: where ldc::nav and Recast/Detour disagree about walkable ground
// on the default landscape. Writes a top-down PPM (x right, y up): green both,
// red ldc only, blue Detour only, grey a floor neither keeps, black no floor;
// and prints the counts.
#include <cstdio>
#include <string>
#include <vector>

#include "contour/contour.h"
#include "detour_peer.h"
#include "ldc/terrain.h"
#include "nav/nav.h"

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "nav_coverage.ppm";
  const ldc::World world = ldc::build_terrain(ldc::TerrainConfig{}, 0.2).value();
  const ldc::ContourMesh mesh = ldc::contour_world(world).value();
  std::vector<float> verts;
  std::vector<int> tris;
  for (const glm::dvec3& p : mesh.positions) verts.insert(verts.end(), {float(p.x), float(p.z), float(-p.y)});
  for (const glm::uvec3& t : mesh.triangles) tris.insert(tris.end(), {int(t.x), int(t.y), int(t.z)});
  std::string error;
  auto detour = ldc::bench::detour_build(verts, tris, {}, nullptr, &error);
  if (!detour) {
    std::fprintf(stderr, "Detour: %s\n", error.c_str());
    return 1;
  }
  const ldc::NavMesh nav = ldc::NavMesh::build(world, {}).value();
  ldc::NavQuery query(nav);
  const double h = world.lattice().cell_size;
  const glm::ivec3 lo = world.node_min(), hi = world.node_end();
  const int w = hi.x - lo.x, ht = hi.y - lo.y;
  std::vector<unsigned char> img(size_t(w) * size_t(ht) * 3, 0);
  size_t both = 0, ours = 0, theirs = 0, none = 0;
  for (int y = 0; y < ht; ++y) {
    for (int x = 0; x < w; ++x) {
      const glm::dvec3 top = world.lattice().node_position({lo.x + x, lo.y + y, hi.z});
      // Our floor: the walkable floor in this column's square nearest half-way up.
      ldc::Result<ldc::NavPoint> p = query.nearest_walkable({top.x, top.y, top.z / 2}, {0.5 * h, 0.5 * h, top.z});
      const std::vector<ldc::SurfacePoint> pts = world.ray_points(2, {lo.x + x, lo.y + y});
      if (pts.empty()) continue;
      const double ground = world.lattice().origin.z + h * pts.back().depth;
      glm::vec3 near;
      const bool d = ldc::bench::detour_nearest_point(*detour, glm::vec3(float(top.x), float(ground), float(-top.y)),
                                                      glm::vec3(float(0.5 * h), 0.6f, float(0.5 * h)), &near);
      const bool o = p.ok() && std::abs(p->position.z - ground) < 0.6;
      unsigned char* c = &img[(size_t(ht - 1 - y) * size_t(w) + size_t(x)) * 3];
      if (o && d) { c[1] = 200; ++both; }
      else if (o) { c[0] = 230; ++ours; }
      else if (d) { c[2] = 230; ++theirs; }
      else { c[0] = c[1] = c[2] = 90; ++none; }
    }
  }
  std::FILE* f = std::fopen(out.c_str(), "wb");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", out.c_str());
    return 1;
  }
  std::fprintf(f, "P6 %d %d 255\n", w, ht);
  std::fwrite(img.data(), 1, img.size(), f);
  std::fclose(f);
  std::printf("top floors: both %zu, ldc only %zu, Detour only %zu, neither %zu; wrote %s\n", both, ours, theirs,
              none, out.c_str());
  return 0;
}
