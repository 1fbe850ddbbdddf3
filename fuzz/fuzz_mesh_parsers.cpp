// libFuzzer target for the four mesh parsers.
//
// The first byte picks the parser (OBJ, PLY, STL, OFF), the rest is the file.
// A parser must either refuse the bytes with a message or return a mesh that
// check_mesh accepts; the measures that walk the mesh run on it too, so that
// anything a loader lets through is also safe for them.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "ldc/mesh.h"
#include "meshio/meshio.h"

namespace {

[[noreturn]] void fail(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_mesh_parsers: %s: %s\n", what, detail.c_str());
  std::abort();
}

ldc::Result<ldc::TriangleMesh> parse(uint8_t selector, std::string_view bytes) {
  // A small limit keeps each input fast; the limit path itself is exercised too.
  ldc::LoadOptions options;
  options.max_triangles = 1 << 16;
  switch (selector % 4) {
    case 0: return ldc::parse_obj(bytes, "fuzz.obj", options);
    case 1: return ldc::parse_ply(bytes, "fuzz.ply", options);
    case 2: return ldc::parse_stl(bytes, "fuzz.stl", options);
    default: return ldc::parse_off(bytes, "fuzz.off", options);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  const ldc::Result<ldc::TriangleMesh> result = parse(data[0], bytes);
  if (!result.ok()) {
    if (result.status().message().empty())
      fail("error without a message", result.status().to_string());
    return 0;
  }
  const ldc::TriangleMesh& mesh = result.value();
  if (mesh.triangles.empty()) fail("success without triangles", "");
  const ldc::Status valid = ldc::check_mesh(mesh, "fuzz");
  if (!valid.ok()) fail("check_mesh rejects a parsed mesh", valid.message());
  (void)ldc::mesh_topology(mesh);
  (void)ldc::mesh_signed_volume(mesh);
  (void)ldc::mesh_bounds(mesh).diagonal();
  return 0;
}
