#include <cstdio>

#include "live/live.h"
#include "sphere.h"

int main() {
  ldc::Result<ldc::World> w = sphere_world();
  if (!w) return 1;
  ldc::Result<ldc::LiveWorld> live = ldc::LiveWorld::create(std::move(w).value(), {.meshes = true});
  if (!live || !live->apply(ldc::Brush::sphere({1.0, 0.0, 0.0}, 0.5), ldc::EditOp::kSubtract)) return 1;
  ldc::Result<ldc::LiveUpdate> u = live->update();
  if (!u || u->meshes.empty()) return 1;
  std::printf("live: ok, %zu chunk meshes changed\n", u->meshes.size());
  return 0;
}
