// .ldc files: see io.h for the layout. Every read is bounds-checked; nothing is
// allocated before the sizes that justify it have been checked against the file.
#include "ldc/io.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <new>
#include <tuple>

#include <tbb/parallel_for.h>
#include <zstd.h>

#include "ldc/detail/crc32.h"
#include "ldc/internal/chunk_codec.h"
#include "ldc/internal/validate_work.h"

namespace ldc {

// Defined below, outside the anonymous namespace: the chunk log shares them.
using detail::chunk_raw_bytes;
using detail::decode_chunk;

namespace {

// Whether `size` bytes at p have the stored CRC-32. Fuzzing builds accept
// every checksum, so that mutations reach the parsers behind it instead of
// stopping at the CRC (libFuzzer's convention).
bool checksum_matches(const uint8_t* p, size_t size, uint32_t stored) {
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
  (void)p, (void)size, (void)stored;
  return true;
#else
  return detail::crc32(p, size) == stored;
#endif
}


constexpr char kMagic[4] = {'L', 'D', 'C', 'W'};
constexpr size_t kHeaderBytes = 128;
constexpr size_t kRecordBytes = 24;

// --- little-endian writing and bounds-checked reading -------------------------

class Writer {
 public:
  void u8(uint8_t v) { bytes.push_back(v); }
  void u16(uint16_t v) { put(v, 2); }
  void u32(uint32_t v) { put(v, 4); }
  void u64(uint64_t v) { put(v, 8); }
  void i32(int32_t v) { put(uint32_t(v), 4); }
  void f64(double v) {
    uint64_t u;
    std::memcpy(&u, &v, 8);
    put(u, 8);
  }
  void raw(const void* p, size_t n) {
    const uint8_t* b = static_cast<const uint8_t*>(p);
    bytes.insert(bytes.end(), b, b + n);
  }
  std::vector<uint8_t> bytes;

 private:
  void put(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) bytes.push_back(uint8_t(v >> (8 * i)));
  }
};

class Reader {
 public:
  Reader(const uint8_t* p, size_t n) : p_(p), n_(n) {}
  bool has(size_t k) const { return k <= n_ - pos_; }
  size_t pos() const { return pos_; }
  size_t left() const { return n_ - pos_; }
  uint8_t u8() { return uint8_t(get(1)); }
  uint16_t u16() { return uint16_t(get(2)); }
  uint32_t u32() { return uint32_t(get(4)); }
  uint64_t u64() { return get(8); }
  int32_t i32() { return int32_t(uint32_t(get(4))); }
  double f64() {
    uint64_t u = get(8);
    double d;
    std::memcpy(&d, &u, 8);
    return d;
  }
  const uint8_t* take(size_t k) {
    const uint8_t* q = p_ + pos_;
    pos_ += k;
    return q;
  }

 private:
  uint64_t get(int k) {  // callers check has() first
    uint64_t v = 0;
    for (int i = 0; i < k; ++i) v |= uint64_t(p_[pos_ + i]) << (8 * i);
    pos_ += size_t(k);
    return v;
  }
  const uint8_t* p_;
  size_t n_;
  size_t pos_ = 0;
};

Status corrupt(std::string_view name, const std::string& what) {
  return {ErrorCode::kCorruptData, std::string(name) + ": " + what};
}

// --- chunk payloads -------------------------------------------------------------

void write_family(Writer& w, const RayFamily& f, int c) {
  if (f.is_uniform()) {
    w.u8(f.uniform_inside() ? 3 : 1);
    return;
  }
  w.u8(0);
  for (uint64_t word : f.start_bits()) w.u64(word);
  RayReader rays(f);
  for (int r = 0; r < c * c; ++r) w.u16(uint16_t(rays.next().points.size()));
  for (const PackedPoint& p : f.all_points()) {
    w.u16(p.depth);
    w.u16(p.material);
    w.u32(p.normal);
  }
}

}  // namespace

std::vector<uint8_t> detail::chunk_raw_bytes(const Chunk& chunk, int c) {
  Writer w;
  for (const RayFamily& f : chunk.axis) write_family(w, f, c);
  return std::move(w.bytes);
}

namespace {

Status read_family(Reader& r, int c, RayFamily& out, const std::string& at) {
  if (!r.has(1)) return {ErrorCode::kCorruptData, at + ": truncated family flags"};
  uint8_t flags = r.u8();
  if (flags == 1 || flags == 3) {
    out = RayFamily::uniform(flags == 3);
    return {};
  }
  if (flags != 0) return {ErrorCode::kCorruptData, at + ": bad family flags " + std::to_string(flags)};
  const size_t rays = size_t(c) * c, words = (rays + 63) / 64;
  if (!r.has(words * 8 + rays * 2)) return {ErrorCode::kCorruptData, at + ": truncated ray table"};
  std::vector<uint64_t> inside(words);
  for (uint64_t& word : inside) word = r.u64();
  std::vector<uint16_t> counts(rays);
  size_t total = 0;
  for (uint16_t& n : counts) total += (n = r.u16());
  if (!r.has(total * 8)) return {ErrorCode::kCorruptData, at + ": point counts exceed the payload"};
  RayFamilyWriter wr(c);
  for (size_t ray = 0; ray < rays; ++ray) {
    wr.begin_ray((inside[ray >> 6] >> (ray & 63)) & 1u);
    for (uint16_t k = 0; k < counts[ray]; ++k) {
      PackedPoint p;
      p.depth = r.u16();
      p.material = r.u16();
      p.normal = r.u32();
      wr.add_point(p);
    }
  }
  out = wr.finish();
  return {};
}

}  // namespace

Status detail::decode_chunk(const uint8_t* data, size_t size, int c, Chunk& chunk, const std::string& at) {
  Reader r(data, size);
  for (int a = 0; a < 3; ++a) {
    Status s = read_family(r, c, chunk.axis[a], at + " axis " + axis_name(a));
    if (!s.ok()) return s;
  }
  if (r.left() != 0) return {ErrorCode::kCorruptData, at + ": " + std::to_string(r.left()) + " stray bytes"};
  return validate_chunk(chunk, c, true);
}

namespace {

// --- header ---------------------------------------------------------------------

struct Header {
  uint32_t version = kLdcFormatVersion;
  WorldConfig config;
  uint64_t metadata_bytes = 0, table_bytes = 0, payload_bytes = 0, total_points = 0;
};

std::vector<uint8_t> header_bytes(const Header& h) {
  Writer w;
  w.raw(kMagic, 4);
  w.u32(h.version);
  w.u32(uint32_t(kHeaderBytes));
  w.u32(uint32_t(h.config.chunk_size));
  for (int a = 0; a < 3; ++a) w.f64(h.config.lattice.origin[a]);
  w.f64(h.config.lattice.cell_size);
  for (int a = 0; a < 3; ++a) w.i32(h.config.chunk_origin[a]);
  for (int a = 0; a < 3; ++a) w.i32(h.config.chunk_dims[a]);
  w.u64(h.metadata_bytes);
  w.u64(h.table_bytes);
  w.u64(h.payload_bytes);
  w.u64(h.total_points);
  w.u32(0);  // flags
  while (w.bytes.size() < kHeaderBytes - 4) w.u8(0);
  w.u32(detail::crc32(w.bytes.data(), w.bytes.size()));
  return std::move(w.bytes);
}

Status parse_header(std::string_view bytes, std::string_view name, Header& h) {
  if (bytes.size() < kHeaderBytes) {
    return corrupt(name, "file of " + std::to_string(bytes.size()) + " bytes is shorter than the " +
                             std::to_string(kHeaderBytes) + "-byte header");
  }
  const uint8_t* p = reinterpret_cast<const uint8_t*>(bytes.data());
  if (std::memcmp(p, kMagic, 4) != 0) return corrupt(name, "not an .ldc file (bad magic)");
  Reader r(p + 4, kHeaderBytes - 4);
  h.version = r.u32();
  if (h.version != kLdcFormatVersion) {
    return {ErrorCode::kUnsupported, std::string(name) + ": format version " +
                                         std::to_string(h.version) + ", this build reads " +
                                         std::to_string(kLdcFormatVersion)};
  }
  uint32_t stored_crc;
  std::memcpy(&stored_crc, p + kHeaderBytes - 4, 4);  // little-endian hosts only (x86, ARM)
  if (!checksum_matches(p, kHeaderBytes - 4, stored_crc)) return corrupt(name, "header checksum mismatch");
  if (r.u32() != kHeaderBytes) return corrupt(name, "unexpected header size");
  h.config.chunk_size = int(r.u32());
  for (int a = 0; a < 3; ++a) h.config.lattice.origin[a] = r.f64();
  h.config.lattice.cell_size = r.f64();
  for (int a = 0; a < 3; ++a) h.config.chunk_origin[a] = r.i32();
  for (int a = 0; a < 3; ++a) h.config.chunk_dims[a] = r.i32();
  h.metadata_bytes = r.u64();
  h.table_bytes = r.u64();
  h.payload_bytes = r.u64();
  h.total_points = r.u64();
  if (r.u32() != 0) return corrupt(name, "unknown header flags");
  return {};
}

// --- metadata -------------------------------------------------------------------

std::vector<uint8_t> metadata_bytes(const World& w) {
  Writer m;
  m.u32(uint32_t(w.metadata().size()));
  for (const auto& [k, v] : w.metadata()) {
    m.u32(uint32_t(k.size()));
    m.raw(k.data(), k.size());
    m.u32(uint32_t(v.size()));
    m.raw(v.data(), v.size());
  }
  return std::move(m.bytes);
}

Status parse_metadata(const uint8_t* p, size_t n, std::string_view name, World& w) {
  Reader r(p, n);
  if (!r.has(4)) return corrupt(name, "truncated metadata");
  uint32_t count = r.u32();
  if (count > n / 8) return corrupt(name, "metadata claims " + std::to_string(count) + " entries");
  for (uint32_t i = 0; i < count; ++i) {
    std::string kv[2];
    for (std::string& s : kv) {
      if (!r.has(4)) return corrupt(name, "truncated metadata entry " + std::to_string(i));
      uint32_t len = r.u32();
      if (!r.has(len)) return corrupt(name, "metadata entry " + std::to_string(i) + " overruns its section");
      const uint8_t* q = r.take(len);
      s.assign(reinterpret_cast<const char*>(q), len);
    }
    w.set_metadata(kv[0], kv[1]);
  }
  if (r.left() != 0) return corrupt(name, "stray bytes after metadata");
  return {};
}

// --- chunk table ------------------------------------------------------------------

struct ChunkRecord {
  uint8_t kind = 0;
  uint32_t crc = 0;
  uint64_t offset = 0;
  uint32_t compressed = 0;
  uint32_t raw = 0;
};

Status parse_table(const uint8_t* p, size_t slots, uint64_t payload_bytes, std::string_view name,
                   const LoadLimits& limits, std::vector<ChunkRecord>& out) {
  Reader r(p, slots * kRecordBytes);
  out.resize(slots);
  uint64_t total_raw = 0;
  for (size_t i = 0; i < slots; ++i) {
    ChunkRecord& rec = out[i];
    rec.kind = r.u8();
    r.take(3);
    rec.crc = r.u32();
    rec.offset = r.u64();
    rec.compressed = r.u32();
    rec.raw = r.u32();
    // Named only on error: a uniform slot costs O(1) to read (issue 24).
    auto at = [i] { return "chunk record " + std::to_string(i); };
    if (rec.kind > uint8_t(ChunkKind::kMixed)) return corrupt(name, at() + ": bad kind " + std::to_string(rec.kind));
    if (rec.kind != uint8_t(ChunkKind::kMixed)) {
      if (rec.offset || rec.compressed || rec.raw || rec.crc) return corrupt(name, at() + ": uniform chunk with payload");
      continue;
    }
    if (rec.compressed == 0 || rec.offset > payload_bytes || rec.compressed > payload_bytes - rec.offset) {
      return corrupt(name, at() + ": payload range outside the file");
    }
    if (rec.raw > limits.max_chunk_raw_bytes) {
      return {ErrorCode::kTooLarge, std::string(name) + ": " + at() + " claims " +
                                        std::to_string(rec.raw) + " bytes uncompressed, over the limit"};
    }
    total_raw += rec.raw;
    if (total_raw > limits.max_total_raw_bytes) {
      return {ErrorCode::kTooLarge, std::string(name) + ": chunks claim more than " +
                                        std::to_string(limits.max_total_raw_bytes) + " bytes uncompressed"};
    }
  }
  return {};
}

Status load_chunks(const uint8_t* payload, const std::vector<ChunkRecord>& table, World& world,
                   std::string_view name, Context* ctx) {
  std::mutex mutex;
  Status first_error;
  std::atomic<bool> failed{false};
  std::atomic<size_t> done{0};
  const size_t report_every = std::max<size_t>(1, table.size() / 256);
  tbb::parallel_for(size_t{0}, table.size(), [&](size_t i) {
    if (failed.load() || (ctx && ctx->cancelled())) return;
    const ChunkRecord& rec = table[i];
    glm::ivec3 d = world.chunk_dims();
    glm::ivec3 coord = world.chunk_origin() +
                       glm::ivec3(int(i % size_t(d.x)), int((i / size_t(d.x)) % size_t(d.y)),
                                  int(i / (size_t(d.x) * size_t(d.y))));
    Status s;
    if (rec.kind == uint8_t(ChunkKind::kEmpty)) {
      // World::create left the slot empty: nothing to store (nor a stamp to renew).
    } else if (rec.kind == uint8_t(ChunkKind::kSolid)) {
      world.set_uniform_chunk(coord, true);
    } else {
      std::string at = "chunk (" + std::to_string(coord.x) + "," + std::to_string(coord.y) + "," +
                       std::to_string(coord.z) + ")";
      const uint8_t* src = payload + rec.offset;
      std::vector<uint8_t> raw;
      auto chunk = std::make_shared<Chunk>();
      if (!checksum_matches(src, rec.compressed, rec.crc)) {
        s = corrupt(name, at + ": checksum mismatch");
      } else if (ZSTD_getFrameContentSize(src, rec.compressed) != rec.raw) {
        s = corrupt(name, at + ": compressed frame size disagrees with the table");
      } else {
        raw.resize(rec.raw);
        size_t got = ZSTD_decompress(raw.data(), raw.size(), src, rec.compressed);
        if (ZSTD_isError(got) || got != rec.raw) {
          s = corrupt(name, at + ": zstd: " + (ZSTD_isError(got) ? ZSTD_getErrorName(got) : "short frame"));
        } else {
          s = decode_chunk(raw.data(), raw.size(), world.chunk_size(), *chunk, at);
          if (!s.ok()) s = corrupt(name, s.message());
          else if (chunk->is_uniform(nullptr)) s = corrupt(name, at + ": mixed chunk holds a uniform one");
        }
      }
      if (s.ok()) world.set_chunk(coord, std::move(chunk));
    }
    if (!s.ok()) {
      std::lock_guard<std::mutex> lock(mutex);
      if (!failed.exchange(true)) first_error = s;
    }
    size_t n = done.fetch_add(1) + 1;
    if (ctx && (n % report_every == 0 || n == table.size())) {
      ctx->report_progress("load", double(n) / double(table.size()));
    }
  });
  if (failed.load()) return first_error;
  if (ctx && ctx->cancelled()) return {ErrorCode::kCancelled, std::string(name) + ": load cancelled"};
  return {};
}

}  // namespace

namespace {

// Reports ("save", fraction) as chunks are compressed, up to `last_fraction`:
// save_world reports 100% only once the file is written (issue 24: 'save
// 100%' was printed before the write, and then an error).
Result<std::vector<uint8_t>> serialize_with_progress(const World& world, const SaveOptions& options,
                                                     Context* ctx, double last_fraction) {
  if (options.compression_level < 1 || options.compression_level > 19) {
    return Status(ErrorCode::kInvalidArgument,
                  "save: compression_level = " + std::to_string(options.compression_level) + " must be in 1 .. 19");
  }
  std::vector<std::tuple<glm::ivec3, ChunkKind, const Chunk*>> slots;
  world.for_each_chunk([&](const glm::ivec3& c, ChunkKind k, const Chunk* d) { slots.emplace_back(c, k, d); });
  std::vector<std::vector<uint8_t>> frames(slots.size());
  std::vector<uint32_t> raw_sizes(slots.size(), 0);
  if (ctx) ctx->report_progress("save", 0.0);
  std::atomic<size_t> done{0};
  const size_t report_every = std::max<size_t>(1, slots.size() / 256);
  tbb::parallel_for(size_t{0}, slots.size(), [&](size_t i) {
    if (const Chunk* d = std::get<2>(slots[i])) {
      std::vector<uint8_t> raw = chunk_raw_bytes(*d, world.chunk_size());
      raw_sizes[i] = uint32_t(raw.size());
      frames[i].resize(ZSTD_compressBound(raw.size()));
      size_t n = ZSTD_compress(frames[i].data(), frames[i].size(), raw.data(), raw.size(),
                               options.compression_level);
      frames[i].resize(ZSTD_isError(n) ? 0 : n);
    }
    const size_t finished = done.fetch_add(1, std::memory_order_relaxed) + 1;
    if (ctx && finished % report_every == 0) {
      ctx->report_progress("save", last_fraction * 0.9 * double(finished) / double(slots.size()));
    }
  });
  Header h;
  h.config = world.config();
  std::vector<uint8_t> meta = metadata_bytes(world);
  Writer table;
  uint64_t offset = 0;
  for (size_t i = 0; i < slots.size(); ++i) {
    const auto& [coord, kind, data] = slots[i];
    if (data && frames[i].empty()) return Status(ErrorCode::kInternal, "save: zstd failed on a chunk");
    table.u8(uint8_t(kind));
    table.u8(0), table.u8(0), table.u8(0);
    table.u32(data ? detail::crc32(frames[i].data(), frames[i].size()) : 0);
    table.u64(data ? offset : 0);
    table.u32(uint32_t(frames[i].size()));
    table.u32(raw_sizes[i]);
    offset += frames[i].size();
    if (data) h.total_points += data->point_count();
  }
  h.metadata_bytes = meta.size();
  h.table_bytes = table.bytes.size();
  h.payload_bytes = offset;
  Writer out;
  out.bytes = header_bytes(h);
  out.raw(meta.data(), meta.size());
  out.u32(detail::crc32(meta.data(), meta.size()));
  out.raw(table.bytes.data(), table.bytes.size());
  out.u32(detail::crc32(table.bytes.data(), table.bytes.size()));
  for (const auto& f : frames) out.raw(f.data(), f.size());
  if (ctx) ctx->report_progress("save", last_fraction);
  return std::move(out.bytes);
}

}  // namespace

Result<std::vector<uint8_t>> serialize_world(const World& world, const SaveOptions& options,
                                             Context* ctx) {
  return serialize_with_progress(world, options, ctx, 1.0);
}

Status save_world(const World& world, const std::string& path, const SaveOptions& options,
                  Context* ctx) {
  Result<std::vector<uint8_t>> bytes = serialize_with_progress(world, options, ctx, 0.95);
  if (!bytes.ok()) return bytes.status();
  const std::vector<uint8_t>& b = bytes.value();
  Status s = write_file_atomically(path, std::string_view(reinterpret_cast<const char*>(b.data()), b.size()));
  if (s.ok() && ctx) ctx->report_progress("save", 1.0);
  return s;
}

Result<World> deserialize_world(std::string_view bytes, std::string_view name,
                                const LoadLimits& limits, Context* ctx) {
  try {
    Header h;
    Status s = parse_header(bytes, name, h);
    if (!s.ok()) return s;
    const uint64_t size = bytes.size();
    const uint64_t body = size - kHeaderBytes;
    if (h.metadata_bytes > body || h.table_bytes > body || h.payload_bytes > body ||
        h.metadata_bytes + h.table_bytes + h.payload_bytes + 8 != body) {
      return corrupt(name, "section sizes do not add up to the file size " + std::to_string(size));
    }
    // The table holds one record per chunk slot, so the file size bounds the
    // allocation World::create makes for the slots.
    uint64_t slots = 1;
    for (int a = 0; a < 3; ++a) {
      int32_t d = h.config.chunk_dims[a];
      if (d < 1 || slots * uint64_t(d) > uint64_t(kMaxChunkSlots)) {
        return corrupt(name, std::string("header: chunk_dims.") + axis_name(a) + " = " + std::to_string(d) + " out of range");
      }
      slots *= uint64_t(d);
    }
    if (h.table_bytes != slots * kRecordBytes) return corrupt(name, "chunk table size disagrees with the chunk box");
    Result<World> created = World::create(h.config);
    if (!created.ok()) return corrupt(name, "header: " + created.status().message());
    World world = std::move(created.value());
    const uint8_t* p = reinterpret_cast<const uint8_t*>(bytes.data()) + kHeaderBytes;
    auto section_crc = [](const uint8_t* q) { uint32_t v; std::memcpy(&v, q, 4); return v; };
    if (!checksum_matches(p, h.metadata_bytes, section_crc(p + h.metadata_bytes))) {
      return corrupt(name, "metadata checksum mismatch");
    }
    s = parse_metadata(p, h.metadata_bytes, name, world);
    if (!s.ok()) return s;
    const uint8_t* tp = p + h.metadata_bytes + 4;
    if (!checksum_matches(tp, h.table_bytes, section_crc(tp + h.table_bytes))) {
      return corrupt(name, "chunk table checksum mismatch");
    }
    if (ctx) ctx->report_progress("load", 0.0);
    std::vector<ChunkRecord> table;
    s = parse_table(tp, slots, h.payload_bytes, name, limits, table);
    if (!s.ok()) return s;
    s = load_chunks(tp + h.table_bytes + 4, table, world, name, ctx);
    if (!s.ok()) return s;
    if (world.stats().points != h.total_points) return corrupt(name, "point count disagrees with the header");
    if (!limits.validate_world) return world;
    ValidationReport v = detail::validate_with_progress(world, {.check_cross_axis = false, .max_messages = 1}, ctx);
    if (!v.ok) return corrupt(name, v.messages.empty() ? "invalid world" : v.messages.front());
    return world;
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, std::string(name) + ": out of memory loading");
  }
}

Result<World> load_world(const std::string& path, const LoadLimits& limits, Context* ctx) {
  if (ctx) ctx->report_progress("read", 0.0);
  // The header (magic, version, checksum) is checked before the rest is read:
  // a 300 MB file of zeros was read whole before "bad magic".
  Result<std::string> bytes = read_file(path, limits.max_file_bytes, [&](std::string_view head, uint64_t) {
    Header header;
    return parse_header(head, path, header);
  });
  if (!bytes.ok()) return bytes.status();
  return deserialize_world(bytes.value(), path, limits, ctx);
}

}  // namespace ldc
