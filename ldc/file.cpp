// Whole-file reads and the atomic write (ldc/io.h).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <new>
#include <utility>

#include "ldc/io.h"

namespace ldc {

namespace {

Status io_error(const std::string& path, const std::string& what, int error) {
  return {ErrorCode::kIoError, path + ": " + what + ": " + std::strerror(error)};
}

// "a FIFO", "a folder", ...: what a path that is not a regular file is.
const char* kind_of(mode_t mode) {
  return S_ISDIR(mode)    ? "a folder"
         : S_ISLNK(mode)  ? "a symbolic link"
         : S_ISFIFO(mode) ? "a FIFO"
         : S_ISSOCK(mode) ? "a socket"
                          : "a device";
}

Status over_load_limit(const std::string& path, uint64_t max_bytes) {
  return {ErrorCode::kTooLarge, path + ": larger than the load limit (" + std::to_string(max_bytes) + " bytes)"};
}

}  // namespace

Result<std::string> read_file(const std::string& path, uint64_t max_bytes) {
  return read_file(path, max_bytes, HeadCheck{});
}

Result<std::string> read_file(const std::string& path, uint64_t max_bytes, const HeadCheck& check_head) {
  // O_NONBLOCK: opening a FIFO with no writer would otherwise wait for one
  // for ever. Only regular files are read (a device such as /dev/zero never
  // ends), and the size is checked before a byte is read.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return io_error(path, "cannot open", errno);
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    const int error = errno;
    ::close(fd);
    return io_error(path, "cannot read", error);
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    return Status(ErrorCode::kIoError, path + ": cannot read: it is " + std::string(kind_of(st.st_mode)) +
                                           ", not a regular file");
  }
  if (uint64_t(st.st_size) > max_bytes) {
    ::close(fd);
    return over_load_limit(path, max_bytes);
  }
  std::FILE* file = ::fdopen(fd, "rb");
  if (!file) {
    const int error = errno;
    ::close(fd);
    return io_error(path, "cannot open", error);
  }
  std::string bytes;
  char buffer[1 << 16];
  size_t got = std::fread(buffer, 1, sizeof buffer, file);
  if (check_head) {
    if (Status head = check_head(std::string_view(buffer, got), uint64_t(st.st_size)); !head.ok()) {
      std::fclose(file);
      return head;
    }
  }
  try {
    bytes.reserve(size_t(st.st_size));
    // Still bounded while reading: a file can grow after the fstat.
    for (; got > 0; got = std::fread(buffer, 1, sizeof buffer, file)) {
      if (bytes.size() + got > max_bytes) {
        std::fclose(file);
        return over_load_limit(path, max_bytes);
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

namespace {

// The existing target, if any, must be a regular file: renaming over a
// folder fails late, over a FIFO or device it silently replaces the node,
// and over a symbolic link it replaces the link, not what it points to.
Status check_target(const std::string& path) {
  struct stat st;
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return {};
    return io_error(path, "cannot write", errno);
  }
  if (S_ISREG(st.st_mode)) return {};
  return {ErrorCode::kIoError, path + ": cannot write: it is " + std::string(kind_of(st.st_mode)) + ", not a regular file"};
}

// "<folder>/.<name>.XXXXXX": hidden, in the target's folder (so the rename
// stays on one file system), unique per call.
std::string temp_template(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const std::string folder = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  return folder + "." + name + ".XXXXXX";
}

std::string folder_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// Permissions a plain fopen would have given: 0666 less the umask, read
// from /proc (umask() can only be read by setting it, which would race
// with other threads creating files); 022 where /proc does not say.
mode_t default_file_mode() {
  static const mode_t mode = [] {
    mode_t mask = 022;
    if (std::FILE* status = std::fopen("/proc/self/status", "r")) {
      char line[256];
      unsigned value = 0;
      while (std::fgets(line, sizeof line, status)) {
        if (std::sscanf(line, "Umask: %o", &value) == 1) {
          mask = mode_t(value);
          break;
        }
      }
      std::fclose(status);
    }
    return mode_t(0666 & ~mask);
  }();
  return mode;
}

}  // namespace

Result<AtomicFile> AtomicFile::create(const std::string& path) {
  if (path.empty()) return Status(ErrorCode::kInvalidArgument, "cannot write: empty output path");
  if (Status s = check_target(path); !s.ok()) return s;
  std::string tmp = temp_template(path);
  // mkostemp opens with O_CREAT | O_EXCL, which never follows a symbolic link.
  const int fd = ::mkostemp(tmp.data(), O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) return io_error(path, "cannot write (creating a temp file in " + folder_of(path) + ")", errno);
  std::FILE* stream = ::fchmod(fd, default_file_mode()) == 0 ? ::fdopen(fd, "wb") : nullptr;
  if (!stream) {
    const int error = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    return io_error(path, "cannot write", error);
  }
  return AtomicFile(path, std::move(tmp), stream);
}

// A moved-from AtomicFile owns no temp file and no stream, so its
// destructor removes nothing.
AtomicFile::AtomicFile(AtomicFile&& other) noexcept
    : path_(std::move(other.path_)), temp_(std::exchange(other.temp_, {})),
      stream_(std::exchange(other.stream_, nullptr)), stream_failed_(other.stream_failed_) {}

AtomicFile& AtomicFile::operator=(AtomicFile&& other) noexcept {
  if (this != &other) {
    discard();
    path_ = std::move(other.path_);
    temp_ = std::exchange(other.temp_, {});
    stream_ = std::exchange(other.stream_, nullptr);
    stream_failed_ = other.stream_failed_;
  }
  return *this;
}

AtomicFile::~AtomicFile() { discard(); }

void AtomicFile::discard() {
  if (stream_) std::fclose(stream_);
  stream_ = nullptr;
  if (!temp_.empty()) ::unlink(temp_.c_str());
  temp_.clear();
}

void AtomicFile::close_stream() {
  if (!stream_) return;
  stream_failed_ = std::ferror(stream_) != 0 || std::fclose(stream_) != 0;
  stream_ = nullptr;
}

Status AtomicFile::commit() {
  if (temp_.empty()) return {ErrorCode::kInvalidArgument, path_ + ": cannot write: already committed or discarded"};
  int error = EIO;
  bool ok = !stream_failed_;
  if (stream_) {
    ok = ok && std::ferror(stream_) == 0 && std::fflush(stream_) == 0 && ::fsync(::fileno(stream_)) == 0;
    if (!ok) error = errno ? errno : EIO;
    if (std::fclose(stream_) != 0 && ok) {
      ok = false;
      error = errno;
    }
    stream_ = nullptr;
  } else if (ok) {
    // Written by name (close_stream() first): make that file durable too.
    const int fd = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    ok = fd >= 0 && ::fsync(fd) == 0;
    if (!ok) error = errno;
    if (fd >= 0) ::close(fd);
  }
  if (ok && ::rename(temp_.c_str(), path_.c_str()) != 0) {
    ok = false;
    error = errno;
  }
  if (!ok) {
    discard();
    return io_error(path_, "cannot write", error);
  }
  temp_.clear();
  // The rename is durable once the folder is on disk; a failure here cannot
  // undo it, and the file is complete, so it is not an error.
  if (const int dir = ::open(folder_of(path_).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dir >= 0) {
    (void)::fsync(dir);
    ::close(dir);
  }
  return {};
}

Status write_file_atomically(const std::string& path, std::string_view bytes) {
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file.ok()) return file.status();
  if (std::fwrite(bytes.data(), 1, bytes.size(), file.value().stream()) != bytes.size()) {
    return io_error(path, "cannot write", errno);  // the temp file goes with `file`
  }
  return file.value().commit();
}

}  // namespace ldc
