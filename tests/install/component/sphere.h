// A small sphere world every component's check starts from.
#pragma once

#include "ldc/build.h"

inline ldc::Result<ldc::World> sphere_world() {
  ldc::Primitive sphere;  // radius 1 at the origin
  return ldc::build_from_primitive(sphere, {.cells = 24});
}
