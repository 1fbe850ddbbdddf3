// Chunk logs (.ldcs): crash-safe incremental saves of a large world's edits.
//
// A chunk log holds only the chunks a game changed; every other chunk comes
// from a base (a procedural generator) that the file names by a free-form
// description. Saving appends the changed chunks and a commit record, so a
// save costs what it changed, not the size of the world.
//
// Layout (little-endian), version 1:
//   header   magic "LDCS", format version, header size, chunk size, lattice
//            origin and cell size (f64), chunk box origin and dims (i32),
//            description length, flags (0), the base description (at most
//            kMaxBaseDescriptionBytes), CRC-32 of all of it
//   records  appended one after another, each
//              tag (u32: "CHNK" or "CMIT"), payload length (u32), payload,
//              CRC-32 of tag, length and payload
//   chunk record payload: chunk coordinate (3 x i32), kind (u8), 3 zero
//            bytes, raw size (u32), and for a mixed chunk one zstd frame of
//            the chunk's raw payload exactly as .ldc files hold it (io.h);
//            uniform chunks have raw size 0 and no frame
//   commit record payload: sequence number (u64, each commit the previous
//            one's + 1), count (u32), 0 (u32), the byte offsets of the count
//            chunk records it commits, all written since the previous commit
// A chunk's current state is its record in the latest commit that names it;
// chunks no commit names are not in the log (find() gives nullopt).
//
// Guarantees. commit() writes the chunk records, fsyncs, then writes the
// commit record and fsyncs: a commit that returned ok survives a crash or a
// kill, and one cut short is, once reopened, whole (its commit record was
// complete) or absent (the state is the previous commit). open() scans the records from the header on and
// takes the state of the last commit whose record and chunk records are all
// complete with good checksums; what follows it (a torn tail: a record cut
// short, a bad checksum, garbage) is not an error, and the next commit first
// truncates the file back to the end of that commit. Damage that a crash
// cannot explain is kCorruptData naming what and the byte offset: a bad
// header; a commit naming an offset past the end or not at a chunk record of
// its own; a damaged record followed by a good commit (committed data lost);
// a chunk record whose checksum holds but whose fields do not. A record over
// the limits is kTooLarge. Every length read from the file is checked
// against the file size and the limits before anything is allocated. A
// damaged tag or a length running past the end ends the scan as a torn tail
// does: damage there in the middle of a file hides the commits after it.
// find() re-checks the record's checksum and runs
// validate_chunk on each mixed chunk it decodes.
//
// Thread safety: const methods (find, layout, stats, ...) may run
// concurrently with each other; commit() and compact() may not run beside
// any other call on the same ChunkLog. One ChunkLog per file: create() and
// open() take an exclusive lock (flock) on it and refuse (kIoError) a file
// another ChunkLog holds, in this process or another.
//
// Versions: a file of another format version is refused with kUnsupported
// naming both numbers.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>

#include <glm/glm.hpp>

#include "ldc/chunk_source.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {

namespace detail {
struct ChunkLogState;  // the file and its index (chunk_log.cpp)
}  // namespace detail

inline constexpr uint32_t kChunkLogFormatVersion = 1;
inline constexpr size_t kMaxBaseDescriptionBytes = size_t{64} << 10;

struct ChunkLogLimits {
  uint64_t max_file_bytes = uint64_t{64} << 30;    // open() refuses larger files; commit() will not grow past it
  size_t max_chunk_raw_bytes = size_t{64} << 20;  // one chunk, uncompressed
};

struct ChunkLogCreateOptions {
  bool overwrite = false;  // replace an existing file at the path (otherwise kIoError)
  ChunkLogLimits limits;
};

struct ChunkLogStats {
  uint64_t file_bytes = 0;
  uint64_t header_bytes = 0;
  uint64_t live_chunks = 0;       // chunks the log holds (records of the current state)
  uint64_t live_bytes = 0;        // bytes of those chunk records
  // Bytes compact() would drop: superseded chunk records, all commit records
  // but the last, a torn tail.
  uint64_t dead_bytes = 0;
  uint64_t commits = 0;           // commit records in the current state
  uint64_t sequence = 0;          // the last commit's sequence number (0: none yet)
  double dead_fraction() const { return file_bytes ? double(dead_bytes) / double(file_bytes) : 0.0; }
};

class ChunkLog {
 public:
  // A new, empty log (header only, fsynced). Refuses an existing file unless
  // options.overwrite; refuses (kInvalidArgument) a bad layout (chunk size,
  // cell size, box: the rules of check_source_layout) or a description over
  // kMaxBaseDescriptionBytes.
  static Result<ChunkLog> create(const std::string& path, const SourceLayout& layout,
                                 const std::string& base_description,
                                 const ChunkLogCreateOptions& options = {});
  // Opens an existing log (read-write, locked) in its last committed state.
  static Result<ChunkLog> open(const std::string& path, const ChunkLogLimits& limits = {});

  ChunkLog(ChunkLog&&) noexcept;
  ChunkLog& operator=(ChunkLog&&) noexcept;
  ~ChunkLog();

  const std::string& path() const;
  const SourceLayout& layout() const;
  const std::string& base_description() const;

  // The chunk's committed state, or nullopt when the log holds nothing for
  // it. A mixed chunk is read from disk now (pread), its checksum checked,
  // decompressed and validated; errors name the chunk and byte offset.
  Result<std::optional<StoredChunk>> find(const glm::ivec3& chunk) const;

  // Commits the chunks atomically: after a crash the log reopens with all of
  // them or none. A chunk listed twice keeps the later entry; an empty list
  // writes nothing. Refused (kInvalidArgument, nothing written): a chunk
  // outside the layout's box, a kind and data that disagree, data of another
  // chunk size. On a write or fsync failure (full disk, EIO, file size
  // limit) returns kIoError, truncates back what it appended and leaves the
  // committed state as it was.
  Status commit(std::span<const std::pair<glm::ivec3, StoredChunk>> chunks);

  // Rewrites the file with only the live chunk records and one commit record
  // (same state, same sequence number): a temp file in the same folder,
  // fsynced, renamed over the log, folder fsynced, so that a crash leaves
  // the old file or the new one. On failure the log stays as it was.
  Status compact();

  ChunkLogStats stats() const;
  bool needs_compaction(double max_dead_fraction = 0.5) const {
    return stats().dead_fraction() > max_dead_fraction;
  }

 private:
  explicit ChunkLog(std::unique_ptr<detail::ChunkLogState> state);
  std::unique_ptr<detail::ChunkLogState> state_;
};

}  // namespace ldc
