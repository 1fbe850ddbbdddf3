#include <cstdio>

#include "render/render.h"
#include "sphere.h"

int main() {
  ldc::Result<ldc::World> w = sphere_world();
  if (!w) return 1;
  ldc::CameraConfig config;
  config.width = 32;
  config.height = 24;
  ldc::Result<ldc::Camera> camera = ldc::Camera::make(config, &*w);
  if (!camera) return 1;
  ldc::Queries queries(*w);
  ldc::Result<ldc::Image> image = ldc::render(queries, *camera, {});
  if (!image || image->rgb.size() != 32u * 24u * 3u) return 1;
  std::printf("render: ok, %d x %d\n", image->width, image->height);
  return 0;
}
