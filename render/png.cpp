// write_png(): stb_image_write encodes into memory; the core's atomic writer
// (ldc/io.h) puts it at the path, as every ldc file is written.
#include <string>

#include <stb_image_write.h>  // the implementation is in libstb (PkgConfig::STB)

#include "ldc/io.h"
#include "render/render.h"

namespace ldc {

namespace {

void append_bytes(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
}

}  // namespace

Status write_png(const Image& image, const std::string& path) {
  if (image.width < 1 || image.height < 1 ||
      image.rgb.size() != size_t(image.width) * size_t(image.height) * 3) {
    return Status(ErrorCode::kInvalidArgument, path + ": the image is " + std::to_string(image.width) + " x " +
                                                   std::to_string(image.height) + " pixels with " +
                                                   std::to_string(image.rgb.size()) + " bytes: not an RGB image");
  }
  std::string png;
  if (!stbi_write_png_to_func(append_bytes, &png, image.width, image.height, 3, image.rgb.data(), image.width * 3)) {
    return Status(ErrorCode::kInternal, path + ": the PNG encoder failed");
  }
  return write_file_atomically(path, png);
}

}  // namespace ldc
