// Chunk sources: the layout check, the implicit (procedural) source and the overlay (see store.h).
#include <cmath>
#include <cstdio>
#include <mutex>
#include <new>
#include <shared_mutex>
#include <string>
#include <utility>

#include "ldc/chunk_source.h"
#include "ldc/internal/lattice_range.h"
#include "ldc/internal/vec_text.h"
#include "ldc/store.h"

namespace ldc {
namespace {

Status bad_layout(const std::string& field, const std::string& value, const char* rule) {
  return {ErrorCode::kInvalidArgument, "source: " + field + " = " + value + " " + rule};
}

bool is_allowed_chunk_size(int c) { return c == 8 || c == 16 || c == 32 || c == 64; }

Status check_lattice(const Lattice& lat) {
  if (!(lat.cell_size > 0.0) || !std::isfinite(lat.cell_size)) {
    return bad_layout("lattice.cell_size", detail::number_g(lat.cell_size), "must be finite and > 0");
  }
  if (!detail::is_finite(lat.origin)) {
    return bad_layout("lattice.origin", detail::vec_text(lat.origin), "must be finite");
  }
  return {};
}

// Box dims >= 1, node coordinates within +-kMaxNodeCoordinate, and at most
// kMaxSourceChunkSlots slots.
Status check_box(const SourceBox& box, int c) {
  for (int a = 0; a < 3; ++a) {
    const std::string axis = axis_name(a);
    const int64_t dim = box.chunk_dims[a];
    if (dim < 1) return bad_layout("box.chunk_dims." + axis, std::to_string(dim), "must be >= 1");
    const int64_t lo = int64_t{box.chunk_origin[a]} * c, hi = (int64_t{box.chunk_origin[a]} + dim) * c;
    if (lo < -kMaxNodeCoordinate || hi > kMaxNodeCoordinate) {
      return {ErrorCode::kTooLarge, "source: box node range on " + axis + " [" + std::to_string(lo) +
                                        ", " + std::to_string(hi) + ") exceeds +-" +
                                        std::to_string(kMaxNodeCoordinate)};
    }
  }
  if (box.slots() > kMaxSourceChunkSlots) {
    return {ErrorCode::kTooLarge, "source: box of " + std::to_string(box.slots()) +
                                      " chunk slots exceeds the limit of " +
                                      std::to_string(kMaxSourceChunkSlots)};
  }
  return {};
}

// The chunk box build_from_implicit's plan_grid (ldc/build_grid.cpp) gives
// bounds `b` on a lattice with origin b.min - padding h. Must stay in step
// with it: the equality tests of tests/test_store.cpp compare the two.
Result<SourceBox> planned_box(const WorldBox& b, const Lattice& lat, int c, int padding) {
  SourceBox box;
  const double h = lat.cell_size;
  for (int a = 0; a < 3; ++a) {
    const double lo = (b.min[a] - lat.origin[a]) / h - padding;
    const double hi = (b.max[a] - lat.origin[a]) / h + padding;
    if (!(std::abs(lo) <= double(kMaxNodeCoordinate)) || !(std::abs(hi) <= double(kMaxNodeCoordinate))) {
      return Status(ErrorCode::kTooLarge, "source: " + detail::number_g(hi - lo) + " cells along " +
                                              axis_name(a) + " exceed the limit of " +
                                              std::to_string(kMaxNodeCoordinate) +
                                              "; use a larger cell_size");
    }
    const int first = int(std::floor(lo / c)), end = int(std::floor(hi / c)) + 1;
    box.chunk_origin[a] = first;
    box.chunk_dims[a] = end - first;
  }
  return box;
}

Status check_bounds(const WorldBox& b) {
  if (!detail::is_finite(b.min) || !detail::is_finite(b.max) || b.min.x > b.max.x ||
      b.min.y > b.max.y || b.min.z > b.max.z) {
    return {ErrorCode::kInvalidArgument, "source: the solid's bounds " + detail::vec_text(b.min) +
                                             " .. " + detail::vec_text(b.max) +
                                             " are empty or not finite"};
  }
  return {};
}

StoredChunk stored(Chunk&& chunk) {
  bool inside = false;
  if (chunk.is_uniform(&inside)) return {inside ? ChunkKind::kSolid : ChunkKind::kEmpty, nullptr};
  return {ChunkKind::kMixed, std::make_shared<const Chunk>(std::move(chunk))};
}



}  // namespace

Status check_source_layout(const SourceLayout& layout) {
  if (Status s = check_lattice(layout.lattice); !s.ok()) return s;
  if (!is_allowed_chunk_size(layout.chunk_size)) {
    return bad_layout("chunk_size", std::to_string(layout.chunk_size), "must be 8, 16, 32 or 64");
  }
  if (Status s = check_box(layout.box, layout.chunk_size); !s.ok()) return s;
  WorldConfig whole;  // only for the range check: never allocated
  whole.lattice = layout.lattice;
  whole.chunk_size = layout.chunk_size;
  whole.chunk_origin = layout.box.chunk_origin;
  whole.chunk_dims = layout.box.chunk_dims;
  return detail::check_lattice_range(whole, "source");
}

// --- ImplicitSource --------------------------------------------------------------

Result<SourceLayout> implicit_source_layout(const ImplicitSolid& solid, double cell_size, int chunk_size,
                                            int padding) {
  const WorldBox b = solid.bounds();
  if (Status s = check_bounds(b); !s.ok()) return s;
  if (!(cell_size > 0.0) || !std::isfinite(cell_size)) {
    return bad_layout("cell_size", detail::number_g(cell_size), "must be finite and > 0");
  }
  if (!is_allowed_chunk_size(chunk_size)) {
    return bad_layout("chunk_size", std::to_string(chunk_size), "must be 8, 16, 32 or 64");
  }
  if (padding < 1 || padding > 64) return bad_layout("padding", std::to_string(padding), "must be in 1 .. 64");
  SourceLayout layout;
  layout.chunk_size = chunk_size;
  layout.lattice.cell_size = cell_size;
  layout.lattice.origin = b.min - double(padding) * cell_size;  // as plan_grid
  Result<SourceBox> box = planned_box(b, layout.lattice, chunk_size, padding);
  if (!box.ok()) return box.status();
  layout.box = box.value();
  if (Status s = check_source_layout(layout); !s.ok()) return s;
  return layout;
}

ImplicitSource::ImplicitSource(std::shared_ptr<const ImplicitSolid> solid, const SourceLayout& layout)
    : solid_(std::move(solid)), bounds_(solid_->bounds()), layout_(layout) {}

Result<std::shared_ptr<const ImplicitSource>> ImplicitSource::create(
    std::shared_ptr<const ImplicitSolid> solid, const SourceLayout& layout) {
  if (!solid) return Status(ErrorCode::kInvalidArgument, "source: solid is null");
  if (Status s = check_bounds(solid->bounds()); !s.ok()) return s;
  if (Status s = check_source_layout(layout); !s.ok()) return s;
  return std::shared_ptr<const ImplicitSource>(new ImplicitSource(std::move(solid), layout));
}

Result<StoredChunk> ImplicitSource::read(const glm::ivec3& chunk) const {
  if (!layout_.box.contains(chunk)) return StoredChunk{};
  try {
    return stored(build_implicit_chunk(*solid_, bounds_, layout_.lattice, layout_.chunk_size, chunk));
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, "source: out of memory building chunk " + detail::chunk_text(chunk));
  }
}

Result<std::shared_ptr<const ImplicitSource>> make_terrain_source(const TerrainConfig& config,
                                                                  double cell_size, int chunk_size) {
  if (Status s = check_terrain(config); !s.ok()) return s;
  std::shared_ptr<const ImplicitSolid> solid = make_terrain_solid(config);
  // build_terrain builds with padding 2.
  Result<SourceLayout> layout = implicit_source_layout(*solid, cell_size, chunk_size, 2);
  if (!layout.ok()) return layout.status();
  return ImplicitSource::create(std::move(solid), layout.value());
}

// --- OverlaySource ---------------------------------------------------------------

OverlaySource::OverlaySource(std::shared_ptr<const ChunkSource> base, ChunkFinder lower)
    : base_(std::move(base)), lower_(std::move(lower)) {}

Result<StoredChunk> OverlaySource::read(const glm::ivec3& chunk) const {
  {
    std::shared_lock lock(mutex_);
    auto it = chunks_.find(detail::source_chunk_key(chunk));
    if (it != chunks_.end()) return it->second;
  }
  if (lower_ && layout().box.contains(chunk)) {
    Result<std::optional<StoredChunk>> found = lower_(chunk);
    if (!found.ok()) return found.status();
    if (found.value().has_value()) return *found.value();
  }
  return base_->read(chunk);
}

Status OverlaySource::set(const glm::ivec3& chunk, StoredChunk data) {
  const std::string where = "overlay: chunk " + detail::chunk_text(chunk);
  if (!layout().box.contains(chunk)) {
    return {ErrorCode::kInvalidArgument, where + " is outside the source's box"};
  }
  if ((data.kind == ChunkKind::kMixed) != (data.data != nullptr)) {
    return {ErrorCode::kInvalidArgument, where + ": kind " + chunk_kind_name(data.kind) +
                                             (data.data ? " with" : " without") + " chunk data"};
  }
  if (data.data) {
    bool inside = false;
    if (data.data->is_uniform(&inside)) {
      return {ErrorCode::kInvalidArgument, where + ": a uniform chunk given as mixed"};
    }
    if (Status s = validate_chunk(*data.data, layout().chunk_size, false); !s.ok()) {
      return {ErrorCode::kInvalidArgument, where + ": " + s.message()};
    }
  }
  std::unique_lock lock(mutex_);
  chunks_[detail::source_chunk_key(chunk)] = std::move(data);
  return {};
}

size_t OverlaySource::size() const {
  std::shared_lock lock(mutex_);
  return chunks_.size();
}

}  // namespace ldc
