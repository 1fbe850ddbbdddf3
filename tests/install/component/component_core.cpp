#include <cstdio>

#include "sphere.h"

int main() {
  ldc::Result<ldc::World> w = sphere_world();
  if (!w || !ldc::validate(*w).ok) return 1;
  std::printf("core: ok, %zu points\n", w->stats().points);
  return 0;
}
