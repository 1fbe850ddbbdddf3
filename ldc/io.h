// .ldc files: a World on disk.
//
// Layout (little-endian), version 1:
//   header    magic "LDCW", format version, lattice, chunk size, chunk box,
//             counts and section sizes, CRC-32 of the header itself
//   metadata  key/value strings, CRC-32
//   table     one record per chunk slot: kind, and for mixed chunks the offset,
//             compressed and raw size of its payload and a CRC-32 of the
//             compressed bytes; CRC-32 of the table
//   payload   one zstd frame per mixed chunk (so chunks load independently)
// A chunk payload holds, per axis: a uniform flag, the start-inside bits, the
// point count of every ray and the 8-byte points.
//
// Loading trusts nothing: every size is checked against the file size and the
// format's limits before anything is allocated, every checksum is verified,
// every chunk is validated (sorted, alternating, in range, axes agree), the
// world's rays are checked across chunk boundaries (LoadLimits::validate_world;
// empty and solid chunk slots cost O(1) to load and check), and the first
// problem found is returned as kCorruptData naming the section,
// chunk and field.
//
// Thread safety: save/serialize only read the World (const; no edit may run
// meanwhile) and may run beside queries; loads are independent of each
// other. Files are written to a temporary path and renamed into place.
// Versions: kLdcFormatVersion is LDC_FORMAT_VERSION of ldc/version.h; a file
// of another version is refused with kUnsupported naming both numbers.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "ldc/context.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {

inline constexpr uint32_t kLdcFormatVersion = 1;

struct SaveOptions {
  int compression_level = 3;  // zstd level [Limit: 1 .. 19]
};

struct LoadLimits {
  size_t max_file_bytes = size_t{16} << 30;   // refuse larger files
  size_t max_chunk_raw_bytes = size_t{64} << 20;  // one chunk, uncompressed
  size_t max_total_raw_bytes = size_t{16} << 30;  // all chunks, uncompressed
  // The world-wide pass after the chunks load (rays continuous across chunk
  // boundaries, outside at the box faces). Off (`ldc info --no-validate`)
  // skips it; each chunk's own checks stay, as queries rely on them. Its cost
  // is O(1) per uniform chunk slot and O(C^2) per mixed one. [Default: on]
  bool validate_world = true;
};

Status save_world(const World& world, const std::string& path, const SaveOptions& options = {},
                  Context* ctx = nullptr);
Result<std::vector<uint8_t>> serialize_world(const World& world, const SaveOptions& options = {},
                                             Context* ctx = nullptr);

Result<World> load_world(const std::string& path, const LoadLimits& limits = {},
                         Context* ctx = nullptr);
// `name` is used in messages.
Result<World> deserialize_world(std::string_view bytes, std::string_view name,
                                const LoadLimits& limits = {}, Context* ctx = nullptr);

// --- Whole files: what every ldc file (worlds, meshes, images) goes through ---

// Reads the whole file. One larger than max_bytes is refused (kTooLarge)
// before any of it is read; so is anything but a regular file (a folder, a
// FIFO, which would block, or a device such as /dev/zero, which never
// ends). Errors name the path and the system's reason.
Result<std::string> read_file(const std::string& path, uint64_t max_bytes = UINT64_MAX);
// The same, but `check_head` first sees the file's first block (up to 64 KiB,
// the whole file if smaller) and its size; an error it returns is returned
// as is, before the rest is read or memory for it reserved (a format's magic:
// a 2 GB file of zeros named .ply was read whole before the parser refused it).
using HeadCheck = std::function<Status(std::string_view head, uint64_t file_size)>;
Result<std::string> read_file(const std::string& path, uint64_t max_bytes, const HeadCheck& check_head);

// Writes `bytes` to `path` so that readers see the old file or the whole
// new one, never a part: a temp file of a fresh name in the same folder
// (created with O_CREAT | O_EXCL | O_NOFOLLOW, so a planted file or symbolic
// link is never written through), every write and the close checked,
// fsync'ed, renamed over `path`, and the folder fsync'ed. The new file gets
// the usual 0666 & ~umask permissions. A failure (a full disk, a file-size
// limit, a bad folder) removes the temp file and leaves any previous file
// at `path` as it was; a process killed mid-write leaves at most a hidden
// temp file (".<name>.XXXXXX"). Refused: a `path` that exists and is not a
// regular file (a folder, a FIFO, a device, a socket, a symbolic link).
Status write_file_atomically(const std::string& path, std::string_view bytes);

// The same guarantees for a file written in pieces (streamed JSON, raw
// arrays) or by a library that opens files by name (OpenVDB):
//   Result<AtomicFile> f = AtomicFile::create(path);
//   std::fputs("...", f.value().stream());   // or write to temp_path()
//   Status s = f.value().commit();
// An AtomicFile destroyed without commit() removes its temp file, so an
// error on the way leaves any previous file at `path` as it was.
class AtomicFile {
 public:
  static Result<AtomicFile> create(const std::string& path);
  AtomicFile(AtomicFile&& other) noexcept;
  AtomicFile& operator=(AtomicFile&& other) noexcept;
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();

  // Buffered stream on the temp file; null after commit().
  std::FILE* stream() const { return stream_; }
  // For writers that open the file by name: close stream() first with
  // close_stream(), write the whole file at temp_path(), then commit().
  const std::string& temp_path() const { return temp_; }
  void close_stream();
  // Checks the stream, flushes, fsyncs and closes the temp file, then
  // renames it over the target. Errors name the target.
  Status commit();

 private:
  AtomicFile(std::string path, std::string temp, std::FILE* stream) : path_(std::move(path)), temp_(std::move(temp)), stream_(stream) {}
  void discard();
  std::string path_, temp_;
  std::FILE* stream_ = nullptr;
  bool stream_failed_ = false;
};

}  // namespace ldc
