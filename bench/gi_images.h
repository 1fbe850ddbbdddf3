// bench_gi's image-space comparison with the path tracer (gi_images.cpp).
#pragma once

namespace ldc::bench {

// Prints the table of whole-image errors per view and engine; with `dir`,
// writes each view's cone-traced | path-traced pair there as a PNG.
void gi_images(int paths, const char* dir, bool with_vulkan);

}  // namespace ldc::bench
