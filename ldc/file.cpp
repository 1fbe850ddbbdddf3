// Whole-file reads and the atomic write (ldc/io.h).
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <new>

#include "ldc/io.h"

namespace ldc {

namespace {

Status io_error(const std::string& path, const std::string& what, int error) {
  return {ErrorCode::kIoError, path + ": " + what + ": " + std::strerror(error)};
}

}  // namespace

Result<std::string> read_file(const std::string& path, uint64_t max_bytes) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return io_error(path, "cannot open", errno);
  std::string bytes;
  char buffer[1 << 16];
  size_t got = 0;
  try {
    while ((got = std::fread(buffer, 1, sizeof buffer, file)) > 0) {
      if (bytes.size() + got > max_bytes) {
        std::fclose(file);
        return Status(ErrorCode::kTooLarge, path + ": larger than the load limit (" + std::to_string(max_bytes) +
                                                " bytes)");
      }
      bytes.append(buffer, got);
    }
  } catch (const std::bad_alloc&) {
    std::fclose(file);
    return Status(ErrorCode::kTooLarge, path + ": out of memory while reading");
  }
  const bool failed = std::ferror(file) != 0;
  const int error = errno;
  std::fclose(file);
  if (failed) return io_error(path, "cannot read", error);
  return bytes;
}

Status write_file_atomically(const std::string& path, std::string_view bytes) {
  const std::string tmp = path + ".tmp";
  std::FILE* file = std::fopen(tmp.c_str(), "wb");
  if (!file) return io_error(path, "cannot write (creating '" + tmp + "')", errno);
  bool ok = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size() && std::fflush(file) == 0;
  int error = errno;
  if (std::fclose(file) != 0 && ok) {
    ok = false;
    error = errno;
  }
  if (ok && std::rename(tmp.c_str(), path.c_str()) != 0) {
    ok = false;
    error = errno;
  }
  if (!ok) {
    std::remove(tmp.c_str());
    return io_error(path, "cannot write", error);
  }
  return {};
}

}  // namespace ldc
