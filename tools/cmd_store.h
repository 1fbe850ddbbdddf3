// Large worlds stored as .ldcs chunk logs (ldc/store.h): what `ldc terrain`,
// `info`, `contour`, `edit` and `compact` share when their file is a store.
#pragma once

#include <cstdint>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "common.h"
#include "ldc/store.h"

namespace ldc::tool {

// The most chunk slots one --region or one edit's window may page, margin
// included (checked before anything is paged): 2^16, e.g. 64 x 64 x 16
// chunks, 410 x 410 x 102 m at h = 0.2 m and C = 32.
inline constexpr int64_t kMaxStoreWindowSlots = int64_t{1} << 16;

// Chunks [lo, hi) (exclusive) of a store's box.
struct ChunkRange {
  glm::ivec3 lo{0};
  glm::ivec3 hi{0};
  int64_t slots() const { return int64_t(hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z); }
};

// The chunks the box [min, max] (m) meets, grown by `margin` chunks on every
// side, clipped to the layout's box. Errors (kInvalidArgument) start with
// `what`: the box outside the store's box, or over kMaxStoreWindowSlots.
Result<ChunkRange> chunks_of_box(const SourceLayout& layout, const glm::dvec3& min, const glm::dvec3& max,
                                 int margin, const std::string& what);
// `wanted` grown by `margin` chunks on every side and clipped to the
// layout's box; errors as chunks_of_box's.
Result<ChunkRange> clip_chunks(const SourceLayout& layout, const ChunkRange& wanted, int margin,
                               const std::string& what);
// --region X0,Y0,Z0,X1,Y1,Z1 (m): six finite numbers with X0 < X1, Y0 < Y1,
// Z0 < Z1, then chunks_of_box without margin. Errors name the text.
Result<ChunkRange> parse_region(const SourceLayout& layout, const std::string& text);
// {"chunk_origin", "chunk_dims", "slots", "min_m", "max_m"} of a range.
nlohmann::json range_json(const SourceLayout& layout, const ChunkRange& range);
// "a x b x c chunks (N slots) from (x, y, z) m to (x, y, z) m".
std::string range_text(const nlohmann::json& range);

// What `ldc info` prints for a store: its base, layout and log statistics
// (nothing is generated), as JSON and as text.
nlohmann::json store_info_json(const Store& store, const std::string& path);
std::string store_info_text(const nlohmann::json& info);

// Whether a path ends in .ldcs (any case): `ldc terrain -o` writes a store.
bool has_ldcs_extension(const std::string& path);

void add_compact_command(CLI::App& app, CommonOptions& common);

}  // namespace ldc::tool
