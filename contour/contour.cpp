// Dual contouring of a World: per chunk in parallel, assembled into one mesh.
#include "contour/contour.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <new>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "contour/detail/mesh_patch.h"
#include "contour/detail/region_mesher.h"
#include "ldc/internal/huge_pages.h"
#include "ldc/internal/ray_math.h"

namespace ldc {

const char* placement_name(Placement p) {
  switch (p) {
    case Placement::kIterative: return "iterative";
    case Placement::kQef: return "qef";
    case Placement::kMassPoint: return "masspoint";
  }
  return "?";
}

Status check_contour_config(const ContourConfig& c) {
  auto bad = [](const std::string& field, double value, const char* rule) {
    return Status(ErrorCode::kInvalidArgument,
                  "contour: " + field + " = " + std::to_string(value) + " must be " + rule);
  };
  if (c.iterations < 0 || c.iterations > 1000) return bad("iterations", c.iterations, "in 0 .. 1000");
  if (!(c.step > 0.0 && c.step < 2.0)) return bad("step", c.step, "in (0, 2)");
  if (!(c.qef_truncation >= 0.0 && c.qef_truncation < 1.0)) return bad("qef_truncation", c.qef_truncation, "in [0, 1)");
  if (!(c.cell_slack >= 0.0 && c.cell_slack <= 1.0)) return bad("cell_slack", c.cell_slack, "in [0, 1]");
  if (c.relax_iterations < 0 || c.relax_iterations > 16) return bad("relax_iterations", c.relax_iterations, "in 0 .. 16");
  if (!(c.relax_strength >= 0.0 && c.relax_strength <= 1.0)) return bad("relax_strength", c.relax_strength, "in [0, 1]");
  if (!(c.relax_plane_pull >= 0.0 && c.relax_plane_pull <= 1.0)) return bad("relax_plane_pull", c.relax_plane_pull, "in [0, 1]");
  return {};
}

bool chunk_is_quiet(const World& w, const glm::ivec3& ch) {
  ChunkKind kind = w.chunk_kind(ch);
  if (kind == ChunkKind::kMixed) return false;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (w.chunk_kind(ch + glm::ivec3(dx, dy, dz)) != kind) return false;
  return true;
}

std::vector<glm::ivec3> chunks_to_mesh(const World& w) {
  std::vector<glm::ivec3> out;
  const glm::ivec3 lo = w.chunk_origin() - 1, hi = w.chunk_origin() + w.chunk_dims();
  for (int z = lo.z; z < hi.z; ++z)
    for (int y = lo.y; y < hi.y; ++y)
      for (int x = lo.x; x < hi.x; ++x) out.emplace_back(x, y, z);
  return out;
}

namespace {

// Meshes `chunks` in parallel; empty results are dropped. Sorted by chunk.
Result<std::vector<ChunkMesh>> mesh_chunks(const World& w, const std::vector<glm::ivec3>& chunks,
                                           const ContourConfig& config, Context* ctx, ContourStats& stats) {
  std::vector<ChunkMesh> meshes(chunks.size());
  // One mesher per thread, so its buffers are allocated once per thread.
  tbb::enumerable_thread_specific<detail::RegionMesher> meshers(detail::RegionMesher(w, config));
  std::mutex mutex;
  std::atomic<size_t> done{0};
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t i) {
    if (ctx && ctx->cancelled()) return;
    ContourStats local;
    meshes[i].chunk = chunks[i];
    if (!chunk_is_quiet(w, chunks[i])) {
      const int c = w.chunk_size();
      meshers.local().mesh(chunks[i] * c, chunks[i] * c + c, meshes[i], local);
      local.chunks_meshed = 1;
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      stats.add_counts(local);
    }
    size_t n = done.fetch_add(1) + 1;
    if (ctx && n % 16 == 0) ctx->report_progress("contour", double(n) / double(chunks.size()));
  });
  if (ctx && ctx->cancelled()) return Status(ErrorCode::kCancelled, "contour: cancelled");
  std::vector<ChunkMesh> kept;
  for (ChunkMesh& m : meshes) {
    if (!m.mesh.positions.empty()) kept.push_back(std::move(m));
  }
  return kept;
}

// The boxes to re-mesh for a dirty list: each dirty node box grown to the
// cells and edges it can affect, overlapping boxes merged (an edit's boxes
// come one per chunk and meet).
std::vector<std::pair<glm::ivec3, glm::ivec3>> patch_boxes(std::span<const DirtyChunk> dirty, int reach) {
  std::vector<std::pair<glm::ivec3, glm::ivec3>> boxes;
  for (const DirtyChunk& d : dirty) {
    glm::ivec3 lo, hi;
    detail::patch_box(d.node_lo, d.node_hi, reach, &lo, &hi);
    boxes.emplace_back(lo, hi);
  }
  auto overlap = [](const auto& a, const auto& b) {
    return glm::all(glm::lessThan(a.first, b.second)) && glm::all(glm::lessThan(b.first, a.second));
  };
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t i = 0; i < boxes.size() && !merged; ++i)
      for (size_t j = i + 1; j < boxes.size() && !merged; ++j) {
        if (!overlap(boxes[i], boxes[j])) continue;
        boxes[i] = {glm::min(boxes[i].first, boxes[j].first), glm::max(boxes[i].second, boxes[j].second)};
        boxes.erase(boxes.begin() + long(j));
        merged = true;
      }
  }
  return boxes;
}

// The chunks a cell box [lo, hi) lies in (hi exclusive).
void chunks_of_box(const glm::ivec3& lo, const glm::ivec3& hi, int chunk_size, std::vector<glm::ivec3>& out) {
  glm::ivec3 first, last;
  for (int a = 0; a < 3; ++a) {
    first[a] = detail::floor_div(lo[a], chunk_size);
    last[a] = detail::floor_div(hi[a] - 1, chunk_size);
  }
  for (int z = first.z; z <= last.z; ++z)
    for (int y = first.y; y <= last.y; ++y)
      for (int x = first.x; x <= last.x; ++x) out.emplace_back(x, y, z);
}

void sort_unique_chunks(std::vector<glm::ivec3>& chunks) {
  std::sort(chunks.begin(), chunks.end(), chunk_order_less);
  chunks.erase(std::unique(chunks.begin(), chunks.end()), chunks.end());
}

// The mesh of `chunk` among chunks[0, end), which are sorted by chunk; null if absent.
template <class Chunks>
auto find_sorted(Chunks& chunks, const glm::ivec3& chunk, size_t end) -> decltype(chunks.data()) {
  const auto last = chunks.begin() + long(end);
  const auto it = std::lower_bound(chunks.begin(), last, chunk, [](const ChunkMesh& m, const glm::ivec3& k) {
    return chunk_order_less(m.chunk, k);
  });
  return it != last && it->chunk == chunk ? &*it : nullptr;
}

bool same_chunk_mesh(const ChunkMesh& a, const ChunkMesh& b) {
  return a.own_vertices == b.own_vertices && a.vertex_cell == b.vertex_cell && a.vertex_sheet == b.vertex_sheet &&
         a.mesh.positions == b.mesh.positions &&
         a.mesh.normals == b.mesh.normals && a.mesh.vertex_material == b.mesh.vertex_material &&
         a.mesh.triangles == b.mesh.triangles && a.mesh.triangle_material == b.mesh.triangle_material;
}

}  // namespace

std::vector<glm::ivec3> chunks_a_remesh_may_change(std::span<const DirtyChunk> dirty, const ContourConfig& config,
                                                   int chunk_size) {
  std::vector<glm::ivec3> chunks;
  for (const DirtyChunk& d : dirty) {
    glm::ivec3 lo, hi;
    detail::patch_box(d.node_lo, d.node_hi, detail::RegionMesher::vertex_reach(config), &lo, &hi);
    chunks_of_box(lo, hi, chunk_size, chunks);
  }
  sort_unique_chunks(chunks);
  return chunks;
}

Result<ChunkMesh> contour_chunk(const World& world, const glm::ivec3& chunk, const ContourConfig& config,
                                ContourStats* stats) {
  Status s = check_contour_config(config);
  if (!s.ok()) return s;
  // The face chunks of the world's box within the chunk's reach (a window cut
  // through the ground crashed the mesher there): cells read reach past the
  // placement reach by the quads' and sheets' cells and the load margin.
  const int c = world.chunk_size(), reach = detail::RegionMesher::vertex_reach(config) + 4;
  if (s = check_box_faces_outside(world, chunk * c - reach, (chunk + 1) * c + reach); !s.ok()) return s;
  ContourStats local;
  Result<std::vector<ChunkMesh>> r = mesh_chunks(world, {chunk}, config, nullptr, local);
  if (stats) stats->add_counts(local);
  if (!r.ok()) return r.status();
  if (r.value().empty()) {
    ChunkMesh empty;
    empty.chunk = chunk;
    return empty;
  }
  return std::move(r.value().front());
}

Result<ChunkedMesh> ChunkedMesh::create(const World& world, const ContourConfig& config, Context* ctx) {
  ChunkedMesh mesh(config);
  if (Status s = mesh.build(world, ctx); !s.ok()) return s;
  return mesh;
}

Status ChunkedMesh::build(const World& world, Context* ctx) {
  Status s = check_contour_config(config_);
  if (s.ok()) s = check_box_faces_outside(world);
  if (!s.ok()) return s;
  ScopedTimer timer(ctx, "contour");
  ContourStats stats;
  Result<std::vector<ChunkMesh>> r = mesh_chunks(world, chunks_to_mesh(world), config_, ctx, stats);
  if (!r.ok()) return r.status();
  chunks_ = std::move(r.value());
  chunk_size_ = world.chunk_size();
  ++version_;
  for (ChunkMesh& m : chunks_) m.version = version_;
  stats.seconds = timer.seconds();
  stats_ = stats;
  return {};
}

const ChunkMesh* ChunkedMesh::find(const glm::ivec3& chunk) const {
  return find_sorted(chunks_, chunk, chunks_.size());
}

Result<MeshUpdate> ChunkedMesh::update(const World& world, std::span<const glm::ivec3> changed, Context* ctx) {
  // Anything in the chunk's rays may have changed: its nodes and the edges up to the next chunk's first node.
  const int c = world.chunk_size();
  std::vector<DirtyChunk> whole;
  whole.reserve(changed.size());
  for (const glm::ivec3& ch : changed) whole.push_back({ch, 0, ch * c, ch * c + c + 1});
  return update(world, whole, ctx);
}

Result<MeshUpdate> ChunkedMesh::update(const World& world, std::span<const DirtyChunk> dirty, Context* ctx) {
  if (world.chunk_size() != chunk_size_) {
    return Status(ErrorCode::kInvalidArgument, "contour: update with a world of another chunk size");
  }
  ScopedTimer timer(ctx, "contour update");
  ContourStats stats;
  MeshUpdate result;
  std::vector<glm::ivec3> changed;
  for (const auto& [lo, hi] : patch_boxes(dirty, detail::RegionMesher::vertex_reach(config_))) {
    if (ctx && ctx->cancelled()) return Status(ErrorCode::kCancelled, "contour: cancelled");
    detail::MeshPatch patch = detail::mesh_patch(world, config_, lo, hi, stats);
    result.chunks_remeshed += splice(patch, changed);
  }
  sort_unique_chunks(changed);
  if (!changed.empty()) ++version_;
  for (const glm::ivec3& ch : changed) {
    ChunkMesh* m = find_sorted(chunks_, ch, chunks_.size());
    if (m) m->version = version_;
    result.changes.push_back({ch, m ? version_ : 0});
  }
  stats.seconds = timer.seconds();
  stats_.add_counts(stats);
  return result;
}

// Splices a patch into every chunk mesh whose cells or edges it overlaps, in
// parallel; appends the chunks whose mesh content changed to `changed`.
size_t ChunkedMesh::splice(const detail::MeshPatch& patch, std::vector<glm::ivec3>& changed) {
  const int c = chunk_size_;
  std::vector<glm::ivec3> targets;
  chunks_of_box(patch.lo, patch.hi, c, targets);
  auto less = [](const ChunkMesh& a, const ChunkMesh& b) { return chunk_order_less(a.chunk, b.chunk); };
  const size_t kept = chunks_.size();  // the sorted part; chunks new to the mesh are appended below
  auto find_kept = [&](const glm::ivec3& ch) { return find_sorted(chunks_, ch, kept); };
  std::vector<ChunkMesh> spliced(targets.size());
  std::vector<char> differs(targets.size(), 0);
  tbb::parallel_for(size_t{0}, targets.size(), [&](size_t i) {
    const ChunkMesh* old = find_kept(targets[i]);
    spliced[i] = detail::splice_patch(old ? *old : ChunkMesh{}, patch, targets[i], c);
    if (old) spliced[i].version = old->version;
    differs[i] = old ? !same_chunk_mesh(*old, spliced[i]) : !spliced[i].mesh.positions.empty();
  });
  // Replace in place; chunks new to the mesh are merged in, and chunks left
  // without vertices dropped, keeping chunks_ sorted.
  for (size_t i = 0; i < targets.size(); ++i) {
    if (differs[i]) changed.push_back(targets[i]);
    if (ChunkMesh* old = find_kept(targets[i])) *old = std::move(spliced[i]);
    else if (!spliced[i].mesh.positions.empty()) chunks_.push_back(std::move(spliced[i]));
  }
  std::inplace_merge(chunks_.begin(), chunks_.begin() + long(kept), chunks_.end(), less);
  std::erase_if(chunks_, [](const ChunkMesh& m) { return m.mesh.positions.empty(); });
  return targets.size();
}

// Chunk by chunk in parallel: each chunk's own vertices and triangles go to
// fixed offsets (prefix sums), so the result does not depend on the threads.
ContourMesh ChunkedMesh::assemble() const {
  const size_t n = chunks_.size();
  std::vector<size_t> vbase(n + 1, 0), tbase(n + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    vbase[i + 1] = vbase[i] + chunks_[i].own_vertices;
    tbase[i + 1] = tbase[i] + chunks_[i].mesh.triangles.size();
  }
  auto global_index = [&](const glm::ivec3& cell, uint8_t sheet) -> uint32_t {
    glm::ivec3 owner(detail::floor_div(cell.x, chunk_size_), detail::floor_div(cell.y, chunk_size_),
                     detail::floor_div(cell.z, chunk_size_));
    const ChunkMesh& m = *find_sorted(chunks_, owner, n);  // the owner always has this vertex: its cell has a sign change
    auto begin = m.vertex_cell.begin(), end = begin + long(m.own_vertices);
    auto v = std::lower_bound(begin, end, cell, [](const glm::ivec3& a, const glm::ivec3& b) { return chunk_order_less(a, b); });
    return uint32_t(vbase[size_t(&m - chunks_.data())] + size_t(v - begin) + sheet);  // a cell's sheets are consecutive
  };
  ContourMesh out;
  // Fresh arrays of tens of MB on a big world: advised onto huge pages first.
  detail::assign_on_huge_pages(out.positions, vbase[n]);
  detail::assign_on_huge_pages(out.normals, vbase[n]);
  detail::assign_on_huge_pages(out.triangles, tbase[n]);
  out.vertex_material.resize(vbase[n]);
  out.triangle_material.resize(tbase[n]);
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    const ChunkMesh& m = chunks_[i];
    std::copy_n(m.mesh.positions.begin(), m.own_vertices, out.positions.begin() + long(vbase[i]));
    std::copy_n(m.mesh.normals.begin(), m.own_vertices, out.normals.begin() + long(vbase[i]));
    std::copy_n(m.mesh.vertex_material.begin(), m.own_vertices, out.vertex_material.begin() + long(vbase[i]));
    std::vector<uint32_t> map(m.mesh.positions.size());
    for (size_t v = 0; v < map.size(); ++v) {
      map[v] = v < m.own_vertices ? uint32_t(vbase[i] + v) : global_index(m.vertex_cell[v], m.vertex_sheet[v]);
    }
    for (size_t t = 0; t < m.mesh.triangles.size(); ++t) {
      const glm::uvec3& tri = m.mesh.triangles[t];
      out.triangles[tbase[i] + t] = {map[tri.x], map[tri.y], map[tri.z]};
    }
    std::copy(m.mesh.triangle_material.begin(), m.mesh.triangle_material.end(),
              out.triangle_material.begin() + long(tbase[i]));
  });
  return out;
}

namespace {

// The whole world as one box: for tests of the chunked path.
Result<ContourMesh> contour_one_piece(const World& world, const ContourConfig& config, ContourStats& stats) {
  const glm::ivec3 lo = world.node_min() - 1, hi = world.node_end();
  glm::ivec3 size = hi - lo;
  if (size.x > 256 || size.y > 256 || size.z > 256) {
    return Status(ErrorCode::kTooLarge, "contour: one-piece meshing is limited to 256^3 cells; use chunked");
  }
  detail::RegionMesher mesher(world, config);
  ChunkMesh m;
  mesher.mesh(lo, hi, m, stats);
  stats.chunks_meshed = 1;
  return std::move(m.mesh);
}

}  // namespace

void ContourStats::add_counts(const ContourStats& s) {
  chunks_meshed += s.chunks_meshed;
  cells += s.cells;
  quads += s.quads;
  multi_crossing_edges += s.multi_crossing_edges;
  thin_edges += s.thin_edges;
  clamped_vertices += s.clamped_vertices;
  relaxed_vertices += s.relaxed_vertices;
  untangled_vertices += s.untangled_vertices;
  for (int i = 0; i < 4; ++i) qef_rank[i] += s.qef_rank[i];
}

Result<ContourMesh> contour_world(const World& world, const ContourConfig& config, Context* ctx,
                                  ContourStats* stats) {
  Status s = check_contour_config(config);
  if (!s.ok()) return s;
  try {
    ScopedTimer timer(ctx, "contour");
    if (!config.chunked) {
      if (s = check_box_faces_outside(world); !s.ok()) return s;  // chunked: ChunkedMesh::build checks
      ContourStats local;
      Result<ContourMesh> m = contour_one_piece(world, config, local);
      local.seconds = timer.seconds();
      if (stats) *stats = local;
      return m;
    }
    ChunkedMesh chunked(config);
    s = chunked.build(world, ctx);
    if (!s.ok()) return s;
    ContourMesh mesh = chunked.assemble();
    if (stats) {
      *stats = chunked.stats();
      stats->seconds = timer.seconds();
    }
    return mesh;
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kTooLarge, "contour: out of memory");
  }
}

}  // namespace ldc
