// The boolean cases of shared/PEERS.md ("Booleans"), shared by bench_csg (the
// pipeline in memory) and bench_boolean_process (the commands as processes):
// the inputs are read from tests/data and the primitives generated here, as
// PEERS.md defines them.
#pragma once

#include <string>
#include <vector>

#include "ldc/mesh.h"

namespace ldc::bench {

// Icosphere: an icosahedron subdivided `levels` times (20 * 4^levels
// triangles), vertices pushed onto the sphere, outward winding.
TriangleMesh icosphere(int levels, glm::dvec3 centre, double radius);

// Capped cylinder along z: `segments` around, centre vertices on the caps
// (4 * segments triangles), outward winding.
TriangleMesh cylinder_z(glm::dvec2 axis, double z0, double z1, double radius, int segments);

TriangleMesh translated(TriangleMesh m, glm::dvec3 d);

struct BooleanCase {
  std::string name;
  TriangleMesh a, b;
  double diag = 0;                    // bounding-box diagonal of A
  size_t expect_a = 0, expect_b = 0;  // triangle counts in PEERS.md
  bool open_input = false;            // A is open: no CGAL result, VDB invalid
  std::string reference_case;         // whose CGAL result is the reference (self if empty)
};

// bunny_sphere (the bunny's holes filled by fill_holes), bunny_sphere_raw
// (only when named in `only`, or with `include_raw`), fandisk_cylinder,
// rocker_sphere and spot_spot; `only` empty = all. The meshes are read from
// `data_dir`; a file that does not load ends the program with the message.
std::vector<BooleanCase> make_boolean_cases(const std::string& data_dir, const std::vector<std::string>& only,
                                            bool include_raw = true);

}  // namespace ldc::bench
