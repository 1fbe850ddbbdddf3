// bench_gi's image-space comparison with the path tracer (gi_images.cpp).
#pragma once

namespace ldc::bench {

// Prints the table of whole-image errors per view and engine; with `dir`,
// writes each view's cone-traced | path-traced pair there as a PNG.
void gi_images(int paths, const char* dir, bool with_vulkan);

// Prints, per camera of those views, how much sky the cone tracer's cones
// let through against the part of `rays` exact rays per cone that escape.
void gi_sky_visibility(int rays);

}  // namespace ldc::bench
