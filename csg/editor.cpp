// WorldEditor: brush edits as chunk merges, with versions, dirty lists and undo.
#include <algorithm>
#include <sstream>
#include <string>

#include <tbb/parallel_for.h>

#include "csg/csg.h"
#include "csg/detail/merge.h"
#include "ldc/internal/build_common.h"
#include "ldc/internal/ray_math.h"

namespace ldc {

// What an edit replaced, to put it back.
struct EditSnapshot {
  struct Saved {
    glm::ivec3 chunk{0};
    ChunkKind kind = ChunkKind::kEmpty;
    std::shared_ptr<const Chunk> data;
    uint64_t previous_version = 0;  // the edit that had changed the chunk before
    glm::ivec3 node_lo{0}, node_hi{0};
  };
  uint64_t version = 0;
  std::vector<Saved> chunks;
};

namespace {

// Chunk coordinates are within +-2^17 (kMaxNodeCoordinate / kMinChunkSize):
// 21 bits each, offset to be unsigned, make a unique key that orders chunks
// by (z, y, x) as chunk_order_less does.
uint64_t chunk_key(const glm::ivec3& c) {
  auto bits = [](int v) { return uint64_t(uint32_t(v + (1 << 20))) & 0x1FFFFFu; };
  return bits(c.x) | (bits(c.y) << 21) | (bits(c.z) << 42);
}

std::string chunk_text(const glm::ivec3& c) {
  std::ostringstream s;  // (not "(" + std::to_string: GCC 12 warns falsely on it, -Wrestrict)
  s << '(' << c.x << ", " << c.y << ", " << c.z << ')';
  return s.str();
}

BooleanOp boolean_of(EditOp op) {
  switch (op) {
    case EditOp::kUnion: return BooleanOp::kUnion;
    case EditOp::kIntersect: return BooleanOp::kIntersect;
    default: return BooleanOp::kSubtract;
  }
}

// One edit, rasterized and located.
struct PreparedEdit {
  World brush;
  EditOp op = EditOp::kSubtract;
  uint16_t material = 0;
  glm::ivec3 solid_chunk_lo{0}, solid_chunk_hi{0};  // chunks where the brush holds solid (hi exclusive)
  bool empty = true;                                // the brush holds no solid on this lattice
};

// ctx: the brush's own progress and cancellation (one edit at a time only).
Result<PreparedEdit> prepare_edit(const WorldEditor::Edit& e, const World& world, Context* ctx) {
  Result<World> raster = rasterize_brush(e.brush, world.lattice(), world.chunk_size(), ctx);
  if (!raster.ok()) return raster.status();
  PreparedEdit p;
  p.brush = std::move(raster).value();
  p.op = e.op;
  p.material = e.brush.material;
  glm::ivec3 lo(INT32_MAX), hi(INT32_MIN);
  p.brush.for_each_chunk([&](const glm::ivec3& c, ChunkKind kind, const Chunk*) {
    if (kind == ChunkKind::kEmpty) return;
    lo = glm::min(lo, c);
    hi = glm::max(hi, c + 1);
  });
  p.empty = lo.x == INT32_MAX;
  if (p.empty) return p;
  p.solid_chunk_lo = lo;
  p.solid_chunk_hi = hi;
  return p;
}

// The chunks a batch may change, sorted and unique.
std::vector<glm::ivec3> chunks_to_visit(const std::vector<PreparedEdit>& edits, const World& world) {
  std::vector<glm::ivec3> out;
  bool all_of_world = false;
  for (const PreparedEdit& e : edits) {
    all_of_world = all_of_world || e.op == EditOp::kIntersect;
    if (e.empty) continue;
    glm::ivec3 lo = e.solid_chunk_lo, hi = e.solid_chunk_hi;
    if (e.op != EditOp::kUnion) {  // subtracting or painting outside the world changes nothing
      lo = glm::max(lo, world.chunk_origin());
      hi = glm::min(hi, world.chunk_origin() + world.chunk_dims());
    }
    for (int z = lo.z; z < hi.z; ++z)
      for (int y = lo.y; y < hi.y; ++y)
        for (int x = lo.x; x < hi.x; ++x) out.emplace_back(x, y, z);
  }
  if (all_of_world) world.for_each_chunk([&](const glm::ivec3& c, ChunkKind, const Chunk*) { out.push_back(c); });
  std::sort(out.begin(), out.end(), chunk_order_less);
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// One chunk after every edit of a batch.
struct ChunkOutcome {
  detail::MergedChunk merged;
  bool changed = false;
  glm::ivec3 node_lo{INT32_MAX}, node_hi{INT32_MIN};
};

ChunkOutcome edit_chunk(const World& world, const glm::ivec3& c, const std::vector<PreparedEdit>& edits,
                        const BooleanConfig& config) {
  using namespace detail;
  const int size = world.chunk_size();
  const glm::ivec3 chunk_lo = c * size;
  ChunkView current = view_chunk(world, c);
  ChunkOutcome out;
  out.merged.kind = current.kind;
  out.merged.data = current.data;
  for (const PreparedEdit& e : edits) {
    ChunkView b = view_chunk(e.brush, c);
    if (b.kind == ChunkKind::kEmpty && e.op != EditOp::kIntersect) continue;
    MergedChunk m = e.op == EditOp::kPaint ? paint_chunk(current, b, e.material, size)
                                          : merge_chunk(current, b, boolean_of(e.op), config, size, true);
    if (!m.changed_from_a) continue;
    out.changed = true;
    out.merged = m;
    current = ChunkView{m.kind, m.data};
    out.node_lo = glm::min(out.node_lo, chunk_lo + m.changed.lo);
    out.node_hi = glm::max(out.node_hi, chunk_lo + m.changed.hi);
  }
  return out;
}

void merge_dirty(std::map<uint64_t, DirtyChunk>& dirty, const glm::ivec3& chunk, uint64_t version,
                 const glm::ivec3& lo, const glm::ivec3& hi) {
  auto [it, inserted] = dirty.try_emplace(chunk_key(chunk), DirtyChunk{chunk, version, lo, hi});
  if (inserted) return;
  it->second.version = version;
  it->second.node_lo = glm::min(it->second.node_lo, lo);
  it->second.node_hi = glm::max(it->second.node_hi, hi);
}

}  // namespace

const char* edit_op_name(EditOp op) {
  switch (op) {
    case EditOp::kUnion: return "union";
    case EditOp::kSubtract: return "subtract";
    case EditOp::kIntersect: return "intersect";
    case EditOp::kPaint: return "paint";
  }
  return "unknown";
}

std::optional<EditOp> edit_op_from_name(std::string_view name) {
  for (EditOp op : {EditOp::kUnion, EditOp::kSubtract, EditOp::kIntersect, EditOp::kPaint}) {
    if (name == edit_op_name(op)) return op;
  }
  if (name == "add") return EditOp::kUnion;
  return std::nullopt;
}

WorldEditor::WorldEditor(World world, BooleanConfig config) : world_(std::move(world)), config_(config) {}

Result<WorldEditor> WorldEditor::create(World world, const BooleanConfig& config) {
  if (Status s = check_boolean_config(config); !s.ok()) return s;
  return WorldEditor(std::move(world), config);
}

Result<EditReceipt> WorldEditor::apply(const Brush& brush, EditOp op, Context* ctx) {
  const Edit one{brush, op};
  return apply_batch(std::span<const Edit>(&one, 1), ctx);
}

Result<EditReceipt> WorldEditor::apply_batch(std::span<const Edit> edits, Context* ctx) {
  ScopedTimer timer(ctx, "edit");
  Status s = check_boolean_config(config_);
  if (!s.ok()) return s;
  // Rasterize every brush first: any error leaves the world untouched.
  // Reported from the start (issue 24: a large brush rasterized for minutes
  // with nothing shown): one brush reports its own progress, several a step each.
  std::vector<Result<PreparedEdit>> prepared_or(edits.size(), Status(ErrorCode::kInternal, "not run"));
  if (ctx) ctx->report_progress("rasterize", 0.0);
  if (edits.size() == 1) {
    prepared_or[0] = prepare_edit(edits[0], world_, ctx);
  } else {
    detail::ProgressCounter rasterized(ctx, "rasterize", edits.size());
    tbb::parallel_for(size_t{0}, edits.size(), [&](size_t i) {
      prepared_or[i] = prepare_edit(edits[i], world_, nullptr);
      rasterized.step();
    });
  }
  if (ctx && ctx->cancelled()) return detail::cancelled_status("edit");
  std::vector<PreparedEdit> prepared;
  prepared.reserve(edits.size());
  for (size_t i = 0; i < edits.size(); ++i) {
    if (!prepared_or[i].ok()) {
      const Status& e = prepared_or[i].status();
      return Status(e.code(), "edit " + std::to_string(i) + " (" + edit_op_name(edits[i].op) + "): " + e.message());
    }
    prepared.push_back(std::move(prepared_or[i]).value());
  }
  // Additions may reach past the world's box: check the grown box before changing anything.
  glm::ivec3 grow_lo = world_.chunk_origin(), grow_hi = world_.chunk_origin() + world_.chunk_dims();
  for (const PreparedEdit& e : prepared) {
    if (e.op != EditOp::kUnion || e.empty) continue;
    grow_lo = glm::min(grow_lo, e.solid_chunk_lo);
    grow_hi = glm::max(grow_hi, e.solid_chunk_hi);
  }
  World grown = world_;  // cheap: chunks are shared
  s = grown.grow_to_include(grow_lo, grow_hi);
  if (!s.ok()) return Status(s.code(), "edit: the world cannot grow to hold the brush: " + s.message());

  std::vector<glm::ivec3> chunks = chunks_to_visit(prepared, grown);
  std::vector<ChunkOutcome> outcomes(chunks.size());
  detail::ProgressCounter progress(ctx, "edit", chunks.size());
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t i) {
    if (progress.cancelled()) return;
    outcomes[i] = edit_chunk(grown, chunks[i], prepared, config_);
    progress.step();
  });
  if (progress.cancelled()) return detail::cancelled_status("edit");

  // Commit.
  auto snapshot = std::make_shared<EditSnapshot>();
  snapshot->version = ++version_;
  EditReceipt receipt;
  receipt.version = version_;
  for (size_t i = 0; i < chunks.size(); ++i) {
    const ChunkOutcome& o = outcomes[i];
    if (!o.changed) continue;
    const glm::ivec3& c = chunks[i];
    uint64_t& last = chunk_version_[chunk_key(c)];
    snapshot->chunks.push_back({c, grown.chunk_kind(c), grown.chunk_shared(c), last, o.node_lo, o.node_hi});
    last = version_;
    detail::store_chunk(grown, c, o.merged);
    merge_dirty(dirty_, c, version_, o.node_lo, o.node_hi);
    receipt.changed_chunks.push_back(c);
  }
  world_ = std::move(grown);
  receipt.undo = std::move(snapshot);
  return receipt;
}

Status WorldEditor::undo(const EditReceipt& receipt) {
  if (!receipt.undo) return {ErrorCode::kInvalidArgument, "undo: the receipt holds no undo data"};
  const EditSnapshot& snap = *receipt.undo;
  for (const EditSnapshot::Saved& saved : snap.chunks) {
    auto it = chunk_version_.find(chunk_key(saved.chunk));
    uint64_t now = it == chunk_version_.end() ? 0 : it->second;
    if (now != snap.version || !world_.contains_chunk(saved.chunk)) {
      return {ErrorCode::kInvalidArgument,
              "undo: edit " + std::to_string(snap.version) + " cannot be undone: chunk " + chunk_text(saved.chunk) +
                  (now > snap.version ? " was changed by edit " + std::to_string(now) + " since; undo that first"
                                      : " no longer holds what that edit left (already undone?)")};
    }
  }
  ++version_;
  for (const EditSnapshot::Saved& saved : snap.chunks) {
    detail::store_chunk(world_, saved.chunk, detail::MergedChunk{saved.kind, saved.data, true});
    chunk_version_[chunk_key(saved.chunk)] = saved.previous_version;
    merge_dirty(dirty_, saved.chunk, version_, saved.node_lo, saved.node_hi);
  }
  return {};
}

std::vector<DirtyChunk> WorldEditor::take_dirty() {
  std::vector<DirtyChunk> out;
  out.reserve(dirty_.size());
  for (auto& [key, d] : dirty_) out.push_back(d);  // keys order the chunks by (z, y, x)
  dirty_.clear();
  return out;
}

}  // namespace ldc
