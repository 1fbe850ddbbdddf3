// Chunk logs: see chunk_log.h for the layout and the guarantees.
#include "ldc/chunk_log.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>
#include <new>
#include <vector>

#include <zstd.h>

#include "ldc/detail/crc32.h"
#include "ldc/internal/chunk_codec.h"
#include "ldc/io.h"

namespace ldc {
namespace {

constexpr char kMagic[4] = {'L', 'D', 'C', 'S'};
constexpr uint32_t kFixedHeaderBytes = 80;  // up to the description
constexpr uint32_t kChunkTag = 0x4B4E4843;   // "CHNK" as little-endian bytes
constexpr uint32_t kCommitTag = 0x54494D43;  // "CMIT"
constexpr uint64_t kRecordHeadBytes = 8;     // tag, payload length
constexpr uint64_t kRecordOverhead = 12;     // head and CRC
constexpr uint32_t kChunkFieldsBytes = 20;   // chunk payload before the frame
constexpr uint32_t kCommitFieldsBytes = 16;  // commit payload before the offsets
constexpr int kCompressionLevel = 3;         // as save_world's default

// --- little-endian bytes --------------------------------------------------------

void put_u32(std::vector<uint8_t>& b, uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void put_u64(std::vector<uint8_t>& b, uint64_t v) {
  for (int i = 0; i < 8; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
void put_f64(std::vector<uint8_t>& b, double d) {
  uint64_t u;
  std::memcpy(&u, &d, 8);
  put_u64(b, u);
}
uint32_t get_u32(const uint8_t* p) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(p[i]) << (8 * i);
  return v;
}
uint64_t get_u64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t(p[i]) << (8 * i);
  return v;
}
double get_f64(const uint8_t* p) {
  const uint64_t u = get_u64(p);
  double d;
  std::memcpy(&d, &u, 8);
  return d;
}

std::string coord_text(const glm::ivec3& c) {
  return "(" + std::to_string(c.x) + "," + std::to_string(c.y) + "," + std::to_string(c.z) + ")";
}

Status io_error(const std::string& path, const std::string& what, int error) {
  return {ErrorCode::kIoError, path + ": " + what + ": " + std::strerror(error)};
}
Status corrupt_at(const std::string& path, uint64_t offset, const std::string& what) {
  return {ErrorCode::kCorruptData, path + ": byte " + std::to_string(offset) + ": " + what};
}

// --- whole reads and writes at an offset ------------------------------------------

// 0, or the errno of the failure (EIO for a read cut short by the file's end).
int read_at(int fd, uint8_t* p, size_t n, uint64_t offset) {
  while (n > 0) {
    const ssize_t got = ::pread(fd, p, n, off_t(offset));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return errno;
    if (got == 0) return EIO;
    p += got, n -= size_t(got), offset += uint64_t(got);
  }
  return 0;
}

int write_at(int fd, const uint8_t* p, size_t n, uint64_t offset) {
  while (n > 0) {
    const ssize_t put = ::pwrite(fd, p, n, off_t(offset));
    if (put < 0 && errno == EINTR) continue;
    if (put < 0) return errno;
    if (put == 0) return ENOSPC;
    p += put, n -= size_t(put), offset += uint64_t(put);
  }
  return 0;
}

int sync_data(int fd) { return ::fdatasync(fd) == 0 ? 0 : errno; }

std::string folder_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// A new file's name is durable once its folder is.
void sync_folder(const std::string& path) {
  if (const int dir = ::open(folder_of(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dir >= 0) {
    (void)::fsync(dir);
    ::close(dir);
  }
}

// One writer per file: a second ChunkLog on it would interleave appends.
Status lock_file(int fd, const std::string& path) {
  if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return {};
  if (errno == EWOULDBLOCK) return {ErrorCode::kIoError, path + ": the chunk log is open elsewhere (locked)"};
  return io_error(path, "cannot lock", errno);
}

// --- layout and header ----------------------------------------------------------------

// "" or what is wrong; the rules of check_source_layout.
std::string layout_problem(const SourceLayout& l) {
  const int c = l.chunk_size;
  if (c != 8 && c != 16 && c != 32 && c != 64) return "chunk_size = " + std::to_string(c) + " must be 8, 16, 32 or 64";
  if (!std::isfinite(l.lattice.cell_size) || l.lattice.cell_size <= 0) return "cell_size must be finite and > 0";
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(l.lattice.origin[a])) return "lattice origin must be finite";
  }
  int64_t slots = 1;
  for (int a = 0; a < 3; ++a) {
    const int64_t d = l.box.chunk_dims[a];
    if (d < 1) return std::string("box.chunk_dims.") + axis_name(a) + " = " + std::to_string(d) + " must be >= 1";
    slots *= d;
    if (slots > kMaxSourceChunkSlots) return "the box holds more than 2^40 chunk slots";
    const int64_t end = (int64_t(l.box.chunk_origin[a]) + d) * c, begin = int64_t(l.box.chunk_origin[a]) * c;
    if (begin < INT32_MIN || end > INT32_MAX) return "the box's node coordinates overflow 32 bits";
  }
  return "";
}

std::vector<uint8_t> encode_header(const SourceLayout& l, const std::string& description) {
  std::vector<uint8_t> b(kMagic, kMagic + 4);
  put_u32(b, kChunkLogFormatVersion);
  put_u32(b, uint32_t(kFixedHeaderBytes + description.size() + 4));
  put_u32(b, uint32_t(l.chunk_size));
  for (int a = 0; a < 3; ++a) put_f64(b, l.lattice.origin[a]);
  put_f64(b, l.lattice.cell_size);
  for (int a = 0; a < 3; ++a) put_u32(b, uint32_t(l.box.chunk_origin[a]));
  for (int a = 0; a < 3; ++a) put_u32(b, uint32_t(l.box.chunk_dims[a]));
  put_u32(b, uint32_t(description.size()));
  put_u32(b, 0);  // flags
  b.insert(b.end(), description.begin(), description.end());
  put_u32(b, detail::crc32(b.data(), b.size()));
  return b;
}

struct Header {
  SourceLayout layout;
  std::string description;
  uint64_t bytes = 0;
};

Result<Header> read_header(int fd, uint64_t file_bytes, const std::string& path) {
  if (file_bytes < kFixedHeaderBytes + 4) {
    return corrupt_at(path, 0, "file of " + std::to_string(file_bytes) + " bytes is shorter than a chunk log header");
  }
  uint8_t fixed[kFixedHeaderBytes];
  if (int e = read_at(fd, fixed, sizeof fixed, 0)) return io_error(path, "cannot read", e);
  if (std::memcmp(fixed, kMagic, 4) != 0) return corrupt_at(path, 0, "not a chunk log (bad magic)");
  if (const uint32_t v = get_u32(fixed + 4); v != kChunkLogFormatVersion) {
    return Status(ErrorCode::kUnsupported, path + ": chunk log format version " + std::to_string(v) +
                                               ", this build reads " + std::to_string(kChunkLogFormatVersion));
  }
  const uint32_t description_bytes = get_u32(fixed + 72);
  if (description_bytes > kMaxBaseDescriptionBytes) {
    return corrupt_at(path, 72, "base description of " + std::to_string(description_bytes) + " bytes, over the limit");
  }
  Header h;
  h.bytes = kFixedHeaderBytes + uint64_t(description_bytes) + 4;
  if (get_u32(fixed + 8) != h.bytes) return corrupt_at(path, 8, "header size disagrees with the description length");
  if (h.bytes > file_bytes) return corrupt_at(path, 0, "truncated header");
  std::vector<uint8_t> all(h.bytes);
  if (int e = read_at(fd, all.data(), all.size(), 0)) return io_error(path, "cannot read", e);
  if (detail::crc32(all.data(), all.size() - 4) != get_u32(all.data() + all.size() - 4)) {
    return corrupt_at(path, h.bytes - 4, "header checksum mismatch");
  }
  if (get_u32(fixed + 76) != 0) return corrupt_at(path, 76, "unknown header flags");
  h.layout.chunk_size = int(get_u32(fixed + 12));
  for (int a = 0; a < 3; ++a) h.layout.lattice.origin[a] = get_f64(fixed + 16 + 8 * a);
  h.layout.lattice.cell_size = get_f64(fixed + 40);
  for (int a = 0; a < 3; ++a) h.layout.box.chunk_origin[a] = int32_t(get_u32(fixed + 48 + 4 * a));
  for (int a = 0; a < 3; ++a) h.layout.box.chunk_dims[a] = int32_t(get_u32(fixed + 60 + 4 * a));
  if (std::string bad = layout_problem(h.layout); !bad.empty()) return corrupt_at(path, 12, "header: " + bad);
  h.description.assign(reinterpret_cast<const char*>(all.data()) + kFixedHeaderBytes, description_bytes);
  return h;
}

// --- records --------------------------------------------------------------------------

void begin_record(std::vector<uint8_t>& b, uint32_t tag, uint32_t payload_bytes) {
  put_u32(b, tag);
  put_u32(b, payload_bytes);
}
// Appends the CRC of the record that starts at `start`.
void end_record(std::vector<uint8_t>& b, size_t start) { put_u32(b, detail::crc32(b.data() + start, b.size() - start)); }

// The largest chunk record payload the limits allow: the fields and a zstd
// frame of the largest raw payload.
uint64_t max_chunk_payload(const ChunkLogLimits& limits) {
  return kChunkFieldsBytes + uint64_t(ZSTD_compressBound(limits.max_chunk_raw_bytes));
}

// A chunk record's fields, parsed from a record whose checksum holds.
struct ChunkFields {
  glm::ivec3 coord{0};
  ChunkKind kind = ChunkKind::kEmpty;
  uint32_t raw_bytes = 0;
  const uint8_t* frame = nullptr;
  size_t frame_bytes = 0;
};

// "" or what is wrong with the chunk record `payload`.
std::string parse_chunk_fields(const uint8_t* payload, uint32_t size, const SourceLayout& layout,
                               const ChunkLogLimits& limits, ChunkFields& f) {
  if (size < kChunkFieldsBytes) return "chunk record of " + std::to_string(size) + " bytes is too short";
  for (int a = 0; a < 3; ++a) f.coord[a] = int32_t(get_u32(payload + 4 * a));
  const uint8_t kind = payload[12];
  f.raw_bytes = get_u32(payload + 16);
  f.frame = payload + kChunkFieldsBytes;
  f.frame_bytes = size - kChunkFieldsBytes;
  if (!layout.box.contains(f.coord)) return "chunk " + coord_text(f.coord) + " outside the log's box";
  if (kind > uint8_t(ChunkKind::kMixed) || payload[13] || payload[14] || payload[15]) {
    return "chunk " + coord_text(f.coord) + ": bad kind " + std::to_string(kind);
  }
  f.kind = ChunkKind(kind);
  if (f.kind != ChunkKind::kMixed) {
    if (f.raw_bytes || f.frame_bytes) return "uniform chunk " + coord_text(f.coord) + " with a payload";
    return "";
  }
  if (f.raw_bytes == 0 || f.raw_bytes > limits.max_chunk_raw_bytes) {
    return "chunk " + coord_text(f.coord) + " claims " + std::to_string(f.raw_bytes) +
           " bytes uncompressed (limit " + std::to_string(limits.max_chunk_raw_bytes) + ")";
  }
  if (ZSTD_getFrameContentSize(f.frame, f.frame_bytes) != f.raw_bytes) {
    return "chunk " + coord_text(f.coord) + ": compressed frame size disagrees with the record";
  }
  return "";
}

// The data of a mixed chunk must be a non-uniform chunk of the log's size.
std::string stored_chunk_problem(const StoredChunk& s, int c) {
  if ((s.kind == ChunkKind::kMixed) != bool(s.data)) return "kind and data disagree (data iff mixed)";
  if (s.kind > ChunkKind::kMixed) return "bad kind";
  if (!s.data) return "";
  if (s.data->is_uniform(nullptr)) return "a mixed chunk holds a uniform one";
  for (const RayFamily& f : s.data->axis) {
    if (!f.is_uniform() && f.size() != c) return "data of another chunk size";
  }
  return "";
}

// Appends a whole chunk record; "" or what went wrong.
std::string append_chunk_record(std::vector<uint8_t>& b, const glm::ivec3& coord, const StoredChunk& s, int c,
                                ZSTD_CCtx* cctx) {
  std::vector<uint8_t> frame;
  uint32_t raw_bytes = 0;
  if (s.data) {
    const std::vector<uint8_t> raw = detail::chunk_raw_bytes(*s.data, c);
    frame.resize(ZSTD_compressBound(raw.size()));
    const size_t n = ZSTD_compressCCtx(cctx, frame.data(), frame.size(), raw.data(), raw.size(), kCompressionLevel);
    if (ZSTD_isError(n)) return std::string("zstd: ") + ZSTD_getErrorName(n);
    frame.resize(n);
    raw_bytes = uint32_t(raw.size());
  }
  const size_t start = b.size();
  begin_record(b, kChunkTag, uint32_t(kChunkFieldsBytes + frame.size()));
  for (int a = 0; a < 3; ++a) put_u32(b, uint32_t(coord[a]));
  b.push_back(uint8_t(s.kind));
  b.insert(b.end(), 3, 0);
  put_u32(b, raw_bytes);
  b.insert(b.end(), frame.begin(), frame.end());
  end_record(b, start);
  return "";
}

void append_commit_record(std::vector<uint8_t>& b, uint64_t sequence, const std::vector<uint64_t>& offsets) {
  const size_t start = b.size();
  begin_record(b, kCommitTag, uint32_t(kCommitFieldsBytes + 8 * offsets.size()));
  put_u64(b, sequence);
  put_u32(b, uint32_t(offsets.size()));
  put_u32(b, 0);
  for (uint64_t o : offsets) put_u64(b, o);
  end_record(b, start);
}

}  // namespace

// --- state ----------------------------------------------------------------------------

namespace detail {

struct ChunkLogOrder {
  bool operator()(const glm::ivec3& a, const glm::ivec3& b) const { return chunk_order_less(a, b); }
};

// Where the current state of one chunk lies.
struct ChunkLogEntry {
  ChunkKind kind = ChunkKind::kEmpty;
  uint64_t offset = 0;        // of its record
  uint64_t record_bytes = 0;  // head, payload and CRC
};

using ChunkLogIndex = std::map<glm::ivec3, ChunkLogEntry, ChunkLogOrder>;

struct ChunkLogState {
  std::string path;
  int fd = -1;
  ChunkLogLimits limits;
  SourceLayout layout;
  std::string description;
  uint64_t header_bytes = 0;
  ChunkLogIndex live;
  uint64_t live_bytes = 0;
  uint64_t good_end = 0;    // end of the last good commit (or the header)
  uint64_t file_bytes = 0;  // what is on disk, torn tail included
  uint64_t sequence = 0;
  uint64_t commits = 0;
  uint64_t last_commit_bytes = 0;
  // Kept across commits: a fresh zstd context per chunk costs more than
  // compressing a small chunk.
  ZSTD_CCtx* cctx = nullptr;

  ~ChunkLogState() {
    if (fd >= 0) ::close(fd);
    ZSTD_freeCCtx(cctx);
  }

  // A committed record becomes the chunk's state.
  void set_live(const glm::ivec3& chunk, const ChunkLogEntry& entry) {
    auto [it, fresh] = live.try_emplace(chunk);
    if (!fresh) live_bytes -= it->second.record_bytes;
    it->second = entry;
    live_bytes += entry.record_bytes;
  }
};

}  // namespace detail

namespace {

// A chunk record seen since the last commit.
struct PendingRecord {
  uint64_t offset = 0;
  uint64_t record_bytes = 0;
  glm::ivec3 coord{0};
  ChunkKind kind = ChunkKind::kEmpty;
  bool intact = false;  // its checksum holds
};

// Open's walk over the records.
class Scanner {
 public:
  explicit Scanner(detail::ChunkLogState& s) : s_(s) {}

  Status run() {
    uint64_t pos = s_.header_bytes;
    for (;;) {
      uint8_t head[kRecordHeadBytes];
      if (s_.file_bytes - pos < kRecordOverhead) return {};  // torn tail (or the end)
      if (int e = read_at(s_.fd, head, sizeof head, pos)) return io_error(s_.path, "cannot read", e);
      const uint32_t tag = get_u32(head), payload_bytes = get_u32(head + 4);
      if (tag != kChunkTag && tag != kCommitTag) return {};                  // garbage: torn tail
      if (payload_bytes > s_.file_bytes - pos - kRecordOverhead) return {};  // cut short: torn tail
      if (Status st = check_length(tag, payload_bytes, pos); !st.ok()) return st;
      const uint64_t record_bytes = kRecordOverhead + payload_bytes;
      record_.resize(size_t(record_bytes));
      if (int e = read_at(s_.fd, record_.data(), record_.size(), pos)) return io_error(s_.path, "cannot read", e);
      const bool intact = detail::crc32(record_.data(), kRecordHeadBytes + payload_bytes) ==
                          get_u32(record_.data() + kRecordHeadBytes + payload_bytes);
      Status st = tag == kChunkTag ? on_chunk(pos, record_bytes, intact) : on_commit(pos, record_bytes, intact);
      if (!st.ok()) return st;
      pos += record_bytes;
    }
  }

 private:
  // Bounds a record's length before its bytes are read.
  Status check_length(uint32_t tag, uint32_t payload_bytes, uint64_t pos) const {
    if (tag == kChunkTag && payload_bytes > max_chunk_payload(s_.limits)) {
      return {ErrorCode::kTooLarge, s_.path + ": byte " + std::to_string(pos) + ": chunk record of " +
                                        std::to_string(payload_bytes) + " bytes, over the limit"};
    }
    // A commit names only chunk records written since the previous one.
    if (tag == kCommitTag && payload_bytes > kCommitFieldsBytes + 8 * uint64_t(pending_.size())) {
      return corrupt_at(s_.path, pos, "commit record of " + std::to_string(payload_bytes) + " bytes names more than the " +
                                          std::to_string(pending_.size()) + " chunk records before it");
    }
    return {};
  }

  const uint8_t* payload() const { return record_.data() + kRecordHeadBytes; }
  uint32_t payload_bytes() const { return uint32_t(record_.size() - kRecordOverhead); }

  Status on_chunk(uint64_t pos, uint64_t record_bytes, bool intact) {
    // A damaged one is judged by the commit after it, if any.
    PendingRecord p{pos, record_bytes, glm::ivec3(0), ChunkKind::kEmpty, intact};
    if (intact) {
      ChunkFields f;
      if (std::string bad = parse_chunk_fields(payload(), payload_bytes(), s_.layout, s_.limits, f); !bad.empty()) {
        return corrupt_at(s_.path, pos, bad);
      }
      p.coord = f.coord;
      p.kind = f.kind;
    }
    pending_.push_back(p);
    return {};
  }

  Status on_commit(uint64_t pos, uint64_t record_bytes, bool intact) {
    if (!intact) {
      note_damage("commit record checksum mismatch at byte " + std::to_string(pos));
      return {};
    }
    const uint8_t* p = payload();
    const uint64_t sequence = get_u64(p);
    const uint32_t count = get_u32(p + 8);
    if (payload_bytes() != kCommitFieldsBytes + 8 * uint64_t(count) || get_u32(p + 12) != 0) {
      return corrupt_at(s_.path, pos, "commit record size disagrees with its count " + std::to_string(count));
    }
    // A crash only ever damages the tail: a good commit after damage means
    // committed data was lost.
    if (!damage_.empty()) return corrupt_at(s_.path, pos, "a commit follows damage (" + damage_ + ")");
    if (s_.commits > 0 && sequence != s_.sequence + 1) {
      return corrupt_at(s_.path, pos, "commit sequence " + std::to_string(sequence) + " follows " +
                                          std::to_string(s_.sequence));
    }
    std::vector<const PendingRecord*> named;
    for (uint32_t i = 0; i < count; ++i) {
      const uint64_t offset = get_u64(p + kCommitFieldsBytes + 8 * i);
      const PendingRecord* r = find_pending(offset);
      if (!r) return corrupt_at(s_.path, pos, "commit " + std::to_string(sequence) + " names " + where(offset));
      if (!r->intact) {  // not all of it reached the disk: not a good commit
        note_damage("commit " + std::to_string(sequence) + " at byte " + std::to_string(pos) +
                    " names the damaged chunk record at byte " + std::to_string(offset));
        return {};
      }
      named.push_back(r);
    }
    for (const PendingRecord& r : pending_) {
      if (!r.intact) {
        return corrupt_at(s_.path, r.offset, "damaged chunk record before the good commit at byte " + std::to_string(pos));
      }
    }
    apply(named, sequence, pos + record_bytes, record_bytes);
    return {};
  }

  std::string where(uint64_t offset) const {
    const std::string at = "byte " + std::to_string(offset);
    if (offset >= s_.file_bytes) return at + ", past the end of the file (" + std::to_string(s_.file_bytes) + " bytes)";
    return at + ", which is not a chunk record written since the previous commit";
  }

  const PendingRecord* find_pending(uint64_t offset) const {
    auto it = std::lower_bound(pending_.begin(), pending_.end(), offset,
                               [](const PendingRecord& r, uint64_t o) { return r.offset < o; });
    return it != pending_.end() && it->offset == offset ? &*it : nullptr;
  }

  void apply(const std::vector<const PendingRecord*>& named, uint64_t sequence, uint64_t end, uint64_t commit_bytes) {
    for (const PendingRecord* r : named) s_.set_live(r->coord, {r->kind, r->offset, r->record_bytes});
    pending_.clear();
    s_.sequence = sequence;
    s_.commits += 1;
    s_.good_end = end;
    s_.last_commit_bytes = commit_bytes;
  }

  void note_damage(const std::string& what) {
    if (damage_.empty()) damage_ = what;
  }

  detail::ChunkLogState& s_;
  std::vector<PendingRecord> pending_;  // in file order
  std::vector<uint8_t> record_;
  std::string damage_;  // the first damage after the last good commit
};

Result<int> open_locked(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC | O_NOFOLLOW, 0666);
  if (fd < 0) return io_error(path, "cannot open", errno);
  if (Status s = lock_file(fd, path); !s.ok()) {
    ::close(fd);
    return s;
  }
  return fd;
}

Result<uint64_t> regular_file_size(int fd, const std::string& path) {
  struct stat st;
  if (::fstat(fd, &st) != 0) return io_error(path, "cannot read", errno);
  if (!S_ISREG(st.st_mode)) return Status(ErrorCode::kIoError, path + ": not a regular file");
  return uint64_t(st.st_size);
}

}  // namespace

// --- ChunkLog -------------------------------------------------------------------------

ChunkLog::ChunkLog(std::unique_ptr<detail::ChunkLogState> state) : state_(std::move(state)) {}
ChunkLog::ChunkLog(ChunkLog&&) noexcept = default;
ChunkLog& ChunkLog::operator=(ChunkLog&&) noexcept = default;
ChunkLog::~ChunkLog() = default;

const std::string& ChunkLog::path() const { return state_->path; }
const SourceLayout& ChunkLog::layout() const { return state_->layout; }
const std::string& ChunkLog::base_description() const { return state_->description; }

Result<ChunkLog> ChunkLog::create(const std::string& path, const SourceLayout& layout,
                                  const std::string& base_description, const ChunkLogCreateOptions& options) {
  if (std::string bad = layout_problem(layout); !bad.empty()) {
    return Status(ErrorCode::kInvalidArgument, path + ": layout: " + bad);
  }
  if (base_description.size() > kMaxBaseDescriptionBytes) {
    return Status(ErrorCode::kInvalidArgument, path + ": base description over " +
                                                   std::to_string(kMaxBaseDescriptionBytes) + " bytes");
  }
  const std::vector<uint8_t> header = encode_header(layout, base_description);
  const std::string_view bytes(reinterpret_cast<const char*>(header.data()), header.size());
  if (options.overwrite) {
    if (Status s = write_file_atomically(path, bytes); !s.ok()) return s;
  } else {
    // O_EXCL: never replaces a file, even one created meanwhile. A crash
    // here leaves a file whose header open() refuses; create never returned.
    Result<int> fd = open_locked(path, O_RDWR | O_CREAT | O_EXCL);
    if (!fd.ok()) return fd.status();
    int e = write_at(fd.value(), header.data(), header.size(), 0);
    if (!e) e = sync_data(fd.value());
    ::close(fd.value());
    if (e) {
      ::unlink(path.c_str());
      return io_error(path, "cannot write", e);
    }
    sync_folder(path);
  }
  return open(path, options.limits);
}

Result<ChunkLog> ChunkLog::open(const std::string& path, const ChunkLogLimits& limits) {
  Result<int> fd = open_locked(path, O_RDWR);
  if (!fd.ok()) return fd.status();
  auto s = std::make_unique<detail::ChunkLogState>();
  s->path = path;
  s->fd = fd.value();
  s->limits = limits;
  Result<uint64_t> size = regular_file_size(s->fd, path);
  if (!size.ok()) return size.status();
  s->file_bytes = size.value();
  if (s->file_bytes > limits.max_file_bytes) {
    return Status(ErrorCode::kTooLarge, path + ": larger than the load limit (" +
                                            std::to_string(limits.max_file_bytes) + " bytes)");
  }
  try {
    Result<Header> header = read_header(s->fd, s->file_bytes, path);
    if (!header.ok()) return header.status();
    s->layout = header->layout;
    s->description = std::move(header->description);
    s->header_bytes = s->good_end = header->bytes;
    if (Status st = Scanner(*s).run(); !st.ok()) return st;
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, path + ": out of memory opening");
  }
  return ChunkLog(std::move(s));
}

Result<std::optional<StoredChunk>> ChunkLog::find(const glm::ivec3& chunk) const {
  const detail::ChunkLogState& s = *state_;
  auto it = s.live.find(chunk);
  if (it == s.live.end()) return std::optional<StoredChunk>();
  const detail::ChunkLogEntry& entry = it->second;
  if (entry.kind != ChunkKind::kMixed) return std::optional<StoredChunk>(StoredChunk{entry.kind, nullptr});
  const std::string at = "chunk " + coord_text(chunk);
  try {
    // The record's size was bounded by the limits when open() or commit() indexed it.
    std::vector<uint8_t> record(entry.record_bytes);
    if (int e = read_at(s.fd, record.data(), record.size(), entry.offset)) return io_error(s.path, at, e);
    const size_t crc_at = record.size() - 4;
    if (detail::crc32(record.data(), crc_at) != get_u32(record.data() + crc_at)) {
      return corrupt_at(s.path, entry.offset, at + ": checksum mismatch");
    }
    ChunkFields f;
    const uint32_t payload_bytes = uint32_t(record.size() - kRecordOverhead);
    std::string bad = parse_chunk_fields(record.data() + kRecordHeadBytes, payload_bytes, s.layout, s.limits, f);
    if (bad.empty() && (f.coord != chunk || f.kind != ChunkKind::kMixed)) bad = "record holds another chunk";
    if (!bad.empty()) return corrupt_at(s.path, entry.offset, at + ": " + bad);
    std::vector<uint8_t> raw(f.raw_bytes);
    const size_t got = ZSTD_decompress(raw.data(), raw.size(), f.frame, f.frame_bytes);
    if (ZSTD_isError(got) || got != raw.size()) {
      return corrupt_at(s.path, entry.offset, at + ": zstd: " + (ZSTD_isError(got) ? ZSTD_getErrorName(got) : "short frame"));
    }
    auto data = std::make_shared<Chunk>();
    Status st = detail::decode_chunk(raw.data(), raw.size(), s.layout.chunk_size, *data, at);
    if (!st.ok()) return corrupt_at(s.path, entry.offset, st.message());
    if (data->is_uniform(nullptr)) return corrupt_at(s.path, entry.offset, at + ": mixed chunk holds a uniform one");
    return std::optional<StoredChunk>(StoredChunk{ChunkKind::kMixed, std::move(data)});
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, s.path + ": " + at + ": out of memory reading");
  }
}

namespace {

// Checks the chunks and encodes their records for the file position `at`.
Status encode_chunks(detail::ChunkLogState& s, std::span<const std::pair<glm::ivec3, StoredChunk>> chunks,
                     uint64_t at, std::vector<uint8_t>& bytes, std::vector<PendingRecord>& records) {
  for (const auto& [coord, stored] : chunks) {
    const std::string name = s.path + ": commit: chunk " + coord_text(coord);
    if (!s.layout.box.contains(coord)) return {ErrorCode::kInvalidArgument, name + " is outside the log's box"};
    if (std::string bad = stored_chunk_problem(stored, s.layout.chunk_size); !bad.empty()) {
      return {ErrorCode::kInvalidArgument, name + ": " + bad};
    }
    const size_t start = bytes.size();
    if (stored.data && !s.cctx && !(s.cctx = ZSTD_createCCtx())) throw std::bad_alloc();
    if (std::string bad = append_chunk_record(bytes, coord, stored, s.layout.chunk_size, s.cctx); !bad.empty()) {
      return {ErrorCode::kInternal, name + ": " + bad};
    }
    const uint64_t payload_bytes = bytes.size() - start - kRecordOverhead;
    if (stored.data && get_u32(bytes.data() + start + kRecordHeadBytes + 16) > s.limits.max_chunk_raw_bytes) {
      return {ErrorCode::kTooLarge, name + ": over the limit of " + std::to_string(s.limits.max_chunk_raw_bytes) +
                                        " bytes uncompressed"};
    }
    records.push_back({at + start, kRecordOverhead + payload_bytes, coord, stored.kind, true});
  }
  return {};
}

// Writes and fsyncs `bytes` at `at`; 0 or the errno.
int append_durably(int fd, const std::vector<uint8_t>& bytes, uint64_t at) {
  if (int e = write_at(fd, bytes.data(), bytes.size(), at)) return e;
  return sync_data(fd);
}

}  // namespace

Status ChunkLog::commit(std::span<const std::pair<glm::ivec3, StoredChunk>> chunks) {
  detail::ChunkLogState& s = *state_;
  if (chunks.empty()) return {};
  std::vector<uint8_t> records, commit_record;
  std::vector<PendingRecord> pending;
  try {
    if (Status st = encode_chunks(s, chunks, s.good_end, records, pending); !st.ok()) return st;
    std::vector<uint64_t> offsets;
    for (const PendingRecord& r : pending) offsets.push_back(r.offset);
    append_commit_record(commit_record, s.sequence + 1, offsets);
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, s.path + ": commit: out of memory");
  }
  const uint64_t end = s.good_end + records.size() + commit_record.size();
  if (end > s.limits.max_file_bytes) {
    return {ErrorCode::kTooLarge, s.path + ": commit would grow the log past " +
                                      std::to_string(s.limits.max_file_bytes) + " bytes (compact it, or raise the limit)"};
  }
  // Drop a torn tail first, so that the new records follow the last commit.
  int e = s.file_bytes > s.good_end && ::ftruncate(s.fd, off_t(s.good_end)) != 0 ? errno : 0;
  if (!e) e = append_durably(s.fd, records, s.good_end);
  if (!e) e = append_durably(s.fd, commit_record, s.good_end + records.size());
  if (e) {
    // Best effort: the next commit truncates again if this fails too.
    s.file_bytes = ::ftruncate(s.fd, off_t(s.good_end)) == 0 ? s.good_end : end;
    return io_error(s.path, "commit", e);
  }
  for (const PendingRecord& r : pending) s.set_live(r.coord, {r.kind, r.offset, r.record_bytes});
  s.good_end = s.file_bytes = end;
  s.sequence += 1;
  s.commits += 1;
  s.last_commit_bytes = commit_record.size();
  return {};
}

namespace {

// Copies the live records into `out` (after its header), filling their new offsets.
Status copy_live_records(const detail::ChunkLogState& s, std::FILE* out, detail::ChunkLogIndex& moved,
                         std::vector<uint64_t>& offsets) {
  std::vector<uint8_t> record;
  uint64_t at = s.header_bytes;
  for (const auto& [coord, entry] : s.live) {
    record.resize(entry.record_bytes);
    if (int e = read_at(s.fd, record.data(), record.size(), entry.offset)) return io_error(s.path, "compact", e);
    // Copied verbatim: a record is independent of its position.
    if (std::fwrite(record.data(), 1, record.size(), out) != record.size()) return io_error(s.path, "compact", errno);
    moved[coord] = {entry.kind, at, entry.record_bytes};
    offsets.push_back(at);
    at += entry.record_bytes;
  }
  return {};
}

}  // namespace

Status ChunkLog::compact() {
  detail::ChunkLogState& s = *state_;
  try {
    Result<AtomicFile> file = AtomicFile::create(s.path);
    if (!file.ok()) return file.status();
    std::FILE* out = file->stream();
    const std::vector<uint8_t> header = encode_header(s.layout, s.description);
    if (std::fwrite(header.data(), 1, header.size(), out) != header.size()) return io_error(s.path, "compact", errno);
    detail::ChunkLogIndex moved;
    std::vector<uint64_t> offsets;
    if (Status st = copy_live_records(s, out, moved, offsets); !st.ok()) return st;
    std::vector<uint8_t> commit_record;
    if (!offsets.empty()) append_commit_record(commit_record, s.sequence, offsets);
    // An empty log has no commit record: fwrite must not get its null data().
    if (!commit_record.empty() &&
        std::fwrite(commit_record.data(), 1, commit_record.size(), out) != commit_record.size()) {
      return io_error(s.path, "compact", errno);
    }
    // Lock the new file before it takes the log's name.
    Result<int> fd = open_locked(file->temp_path(), O_RDWR);
    if (!fd.ok()) return fd.status();
    if (Status st = file->commit(); !st.ok()) {
      ::close(fd.value());
      return st;
    }
    ::close(s.fd);
    s.fd = fd.value();
    s.live = std::move(moved);
    s.good_end = s.file_bytes = s.header_bytes + s.live_bytes + commit_record.size();
    s.commits = offsets.empty() ? 0 : 1;
    s.last_commit_bytes = commit_record.size();
    return {};
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, s.path + ": compact: out of memory");
  }
}

ChunkLogStats ChunkLog::stats() const {
  const detail::ChunkLogState& s = *state_;
  ChunkLogStats st;
  st.file_bytes = s.file_bytes;
  st.header_bytes = s.header_bytes;
  st.live_chunks = s.live.size();
  st.live_bytes = s.live_bytes;
  st.dead_bytes = s.file_bytes - s.header_bytes - s.live_bytes - s.last_commit_bytes;
  st.commits = s.commits;
  st.sequence = s.sequence;
  return st;
}

}  // namespace ldc
