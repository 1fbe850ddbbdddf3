#include <cstdio>

#include "csg/csg.h"
#include "sphere.h"

int main() {
  ldc::Result<ldc::World> w = sphere_world();
  if (!w) return 1;
  ldc::WorldEditor editor(std::move(w).value());
  if (!editor.apply(ldc::Brush::sphere({1.0, 0.0, 0.0}, 0.5), ldc::EditOp::kSubtract).ok()) return 1;
  std::printf("csg: ok, version %llu\n", static_cast<unsigned long long>(editor.version()));
  return 0;
}
