// Booleans of whole worlds, and of two meshes built onto one lattice.
#include <algorithm>
#include <cmath>
#include <sstream>

#include <tbb/parallel_for.h>

#include "csg/csg.h"
#include "csg/detail/merge.h"
#include "ldc/internal/build_common.h"

namespace ldc {
namespace {

std::string describe(const Lattice& l, int chunk_size) {
  std::ostringstream s;
  s.precision(17);
  s << "origin (" << l.origin.x << ", " << l.origin.y << ", " << l.origin.z << "), h " << l.cell_size
    << ", chunk size " << chunk_size;
  return s.str();
}

Status check_same_grid(const World& a, const World& b) {
  if (a.chunk_size() == b.chunk_size() && a.lattice().cell_size == b.lattice().cell_size &&
      a.lattice().origin == b.lattice().origin) {
    return {};
  }
  return {ErrorCode::kInvalidArgument,
          "boolean: the worlds' lattices differ: " + describe(a.lattice(), a.chunk_size()) + " vs " +
              describe(b.lattice(), b.chunk_size()) +
              "; build both with one cell size and origin (GridConfig::use_origin)"};
}

// The chunk box of a op b: a difference lies within a, an intersection within both.
void result_box(const World& a, const World& b, BooleanOp op, WorldConfig& wc) {
  glm::ivec3 lo = a.chunk_origin(), hi = a.chunk_origin() + a.chunk_dims();
  glm::ivec3 blo = b.chunk_origin(), bhi = b.chunk_origin() + b.chunk_dims();
  if (op == BooleanOp::kUnion) {
    lo = glm::min(lo, blo);
    hi = glm::max(hi, bhi);
  } else if (op == BooleanOp::kIntersect) {
    lo = glm::max(lo, blo);
    hi = glm::max(glm::min(hi, bhi), lo + 1);  // disjoint boxes: one empty chunk
  }
  wc.chunk_origin = lo;
  wc.chunk_dims = hi - lo;
}

}  // namespace

const char* boolean_op_name(BooleanOp op) {
  switch (op) {
    case BooleanOp::kUnion: return "union";
    case BooleanOp::kSubtract: return "subtract";
    case BooleanOp::kIntersect: return "intersect";
  }
  return "unknown";
}

std::optional<BooleanOp> boolean_op_from_name(std::string_view name) {
  for (BooleanOp op : {BooleanOp::kUnion, BooleanOp::kSubtract, BooleanOp::kIntersect}) {
    if (name == boolean_op_name(op)) return op;
  }
  if (name == "difference") return BooleanOp::kSubtract;
  if (name == "intersection") return BooleanOp::kIntersect;
  return std::nullopt;
}

Status check_boolean_config(const BooleanConfig& c) {
  if (!(c.sliver >= 0.0 && c.sliver <= 0.5)) {
    return {ErrorCode::kInvalidArgument, "boolean: sliver = " + std::to_string(c.sliver) + " must be in 0 .. 0.5 cells"};
  }
  if (c.cut_material < -1 || c.cut_material > 65535) {
    return {ErrorCode::kInvalidArgument,
            "boolean: cut_material = " + std::to_string(c.cut_material) + " must be -1 or a material id 0 .. 65535"};
  }
  return {};
}

Result<World> boolean(const World& a, const World& b, BooleanOp op, const BooleanConfig& config, Context* ctx) {
  using namespace detail;
  ScopedTimer timer(ctx, "boolean");
  Status s = check_boolean_config(config);
  if (s.ok()) s = check_same_grid(a, b);
  if (!s.ok()) return s;
  WorldConfig wc = a.config();
  result_box(a, b, op, wc);
  Result<World> created = World::create(wc);
  if (!created.ok()) return created.status();
  World out = std::move(created).value();
  const glm::ivec3 d = out.chunk_dims();
  const size_t slots = size_t(d.x) * d.y * d.z;
  ProgressCounter progress(ctx, "boolean", slots);
  tbb::parallel_for(size_t{0}, slots, [&](size_t slot) {
    if (progress.cancelled()) return;
    glm::ivec3 c = slot_chunk(out, slot);
    // store_chunk writes only this slot: safe in parallel.
    store_chunk(out, c, merge_chunk(view_chunk(a, c), view_chunk(b, c), op, config, out.chunk_size(), false));
    progress.step();
  });
  if (progress.cancelled()) return cancelled_status("boolean");
  out.set_metadata("source", std::string("boolean ") + boolean_op_name(op));
  return out;
}

Result<World> mesh_boolean(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op, const GridConfig& grid) {
  return mesh_boolean(a, b, op, MeshBooleanOptions{.grid = grid});
}

Result<World> mesh_boolean(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op, const GridConfig& grid,
                           const BooleanConfig& config, Context* ctx, std::array<BuildReport, 2>* reports) {
  return mesh_boolean(a, b, op, MeshBooleanOptions{grid, config, ctx, reports});
}

Result<World> mesh_boolean(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op,
                           const MeshBooleanOptions& options) {
  const GridConfig& grid = options.grid;
  const BooleanConfig& config = options.boolean;
  Context* ctx = options.ctx;
  std::array<BuildReport, 2>* reports = options.reports;
  Status s = check_boolean_config(config);
  if (s.ok()) s = check_mesh(a, "first mesh");
  if (s.ok()) s = check_mesh(b, "second mesh");
  if (!s.ok()) return s;
  if (a.triangles.empty() || b.triangles.empty()) {
    return Status(ErrorCode::kInvalidArgument,
                  std::string(a.triangles.empty() ? "first" : "second") + " mesh has no triangles");
  }
  MeshBounds ba = mesh_bounds(a), bb = mesh_bounds(b);
  WorldBox joint{glm::min(ba.min, bb.min), glm::max(ba.max, bb.max)};
  // One lattice for both: h and origin from the joint bounds, as build_from_mesh would choose them.
  Result<WorldConfig> plan = detail::plan_grid(joint, grid, 0.0, "boolean");
  if (!plan.ok()) return plan.status();
  GridConfig shared = grid;
  shared.cell_size = plan.value().lattice.cell_size;
  shared.use_origin = true;
  shared.origin = plan.value().lattice.origin;
  Result<World> wa = build_from_mesh(a, shared, ctx, reports ? &(*reports)[0] : nullptr);
  if (!wa.ok()) return Status(wa.status().code(), "first mesh: " + wa.status().message());
  Result<World> wb = build_from_mesh(b, shared, ctx, reports ? &(*reports)[1] : nullptr);
  if (!wb.ok()) return Status(wb.status().code(), "second mesh: " + wb.status().message());
  return boolean(wa.value(), wb.value(), op, config, ctx);
}

}  // namespace ldc
