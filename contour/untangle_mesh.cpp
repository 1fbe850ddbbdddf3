// untangle_mesh: clears self-intersections on a whole mesh.
//
// Dual contouring's placement for sharp features folds a few triangles
// through their neighbours (fandisk at 256 cells: 21 pairs in 159,940
// triangles; the tools contour without the local mass-point round of
// untangle.cpp and come here instead), or, after that round, what it leaves:
// tiny blobs around single lattice nodes, saddles, two sheets in one cell.
// Each is a crease of a few triangles folded through a neighbour.
// Smoothing those vertices towards the centroid of their neighbours (the
// umbrella operator) opens the crease, as it removes any fold, so in rounds:
//   1. every vertex of an intersecting pair is marked, and with each
//      further round one more ring of neighbours (a wider, gentler fix where
//      the narrow one was not enough: up to kMaxRing rings);
//   2. every marked vertex whose edges each have exactly two triangles
//      moves to the centroid of its neighbours (all from the old positions,
//      so the result does not depend on the order);
//   3. a move that would turn one of its triangles from facing along its
//      corners' normals to facing away, or make it degenerate, is halved,
//      up to kHalvings times, then undone (a triangle already facing away
//      may turn back: that is the fold opening);
//   4. only the triangles around moved vertices are tested again (the pair
//      finder of mesh_quality, restricted to them); pairs whose triangles
//      did not move are carried over.
// It stops when no pair is left, nothing moved, or after max_rounds, and
// returns the positions of the round that left the fewest pairs. Then
// small closed components still intersecting themselves (specks around one
// or two lattice nodes, see contour.h) are removed. Otherwise the topology
// never changes; boundary and non-manifold vertices never move.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "contour/contour.h"
#include "contour/detail/incidence.h"
#include "contour/detail/remove_triangles.h"
#include "contour/detail/self_intersections.h"
#include "contour/detail/triangle_intersection.h"

namespace ldc {
namespace {

constexpr int kMaxRing = 3;    // widest ring of neighbours a round moves
constexpr int kHalvings = 3;   // tries at half the step before a move is undone

// A compressed table: items[offset[v] .. offset[v + 1]).
struct Table {
  std::vector<size_t> offset;
  std::vector<uint32_t> items;
  size_t begin(size_t v) const { return offset[v]; }
  size_t end(size_t v) const { return offset[v + 1]; }
};

// The triangles around each vertex (mesh_quality's table).
Table vertex_triangles(const ContourMesh& mesh) {
  detail::Incidence in = detail::incidence(mesh);
  return {std::move(in.offset), std::move(in.triangle)};
}

// Each vertex's neighbours (sorted, once each), and whether the vertex may
// move: every edge at it used by exactly two triangles, in opposite
// directions (inside a closed, oriented fan).
struct Neighbourhood {
  Table neighbours;
  std::vector<uint8_t> movable;
};

Neighbourhood neighbourhood(const ContourMesh& mesh, const Table& tris) {
  Neighbourhood nb;
  nb.neighbours.offset.assign(mesh.vertex_count() + 1, 0);
  nb.movable.assign(mesh.vertex_count(), 0);
  std::vector<std::pair<uint32_t, int>> ends;  // (other end, +1 leaving v / -1 entering v)
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    ends.clear();
    for (size_t i = tris.begin(v); i < tris.end(v); ++i) {
      const glm::uvec3& t = mesh.triangles[tris.items[i]];
      for (int k = 0; k < 3; ++k) {
        if (t[k] != v) continue;
        ends.push_back({t[(k + 1) % 3], +1});
        ends.push_back({t[(k + 2) % 3], -1});
      }
    }
    std::sort(ends.begin(), ends.end());
    bool ok = !ends.empty();
    for (size_t i = 0; i < ends.size(); i += 2) {
      const bool paired = i + 1 < ends.size() && ends[i].first == ends[i + 1].first &&
                          ends[i].second != ends[i + 1].second && (i + 2 >= ends.size() || ends[i + 2].first != ends[i].first);
      ok = ok && paired && ends[i].first != v;
      if (!paired) break;
    }
    nb.movable[v] = ok;
    for (size_t i = 0; i < ends.size(); ++i)
      if (i == 0 || ends[i].first != ends[i - 1].first) nb.neighbours.items.push_back(ends[i].first);
    nb.neighbours.offset[v + 1] = nb.neighbours.items.size();
  }
  return nb;
}

glm::dvec3 normal_of(const std::vector<glm::dvec3>& p, const glm::uvec3& t) {
  return glm::cross(p[t.y] - p[t.x], p[t.z] - p[t.x]);
}

// The vertices of the pairs, grown by `rings` rings of neighbours.
std::vector<uint32_t> marked_vertices(const ContourMesh& mesh, const std::vector<detail::TrianglePair>& pairs,
                                      const Table& neighbours, int rings) {
  std::vector<uint8_t> in(mesh.vertex_count(), 0);
  std::vector<uint32_t> marked;
  for (const auto& [a, b] : pairs)
    for (uint32_t t : {a, b})
      for (int k = 0; k < 3; ++k)
        if (!in[mesh.triangles[t][k]]) in[mesh.triangles[t][k]] = 1, marked.push_back(mesh.triangles[t][k]);
  size_t ring_begin = 0;
  for (int r = 0; r < rings; ++r) {
    const size_t ring_end = marked.size();
    for (size_t i = ring_begin; i < ring_end; ++i)
      for (size_t j = neighbours.begin(marked[i]); j < neighbours.end(marked[i]); ++j)
        if (!in[neighbours.items[j]]) in[neighbours.items[j]] = 1, marked.push_back(neighbours.items[j]);
    ring_begin = ring_end;
  }
  std::sort(marked.begin(), marked.end());
  return marked;
}

// Which way each triangle should face: the sum of its corners' normals (the
// surface normals contouring gives), or its own normal before any move for
// a mesh without normals.
std::vector<glm::dvec3> facing(const ContourMesh& mesh) {
  std::vector<glm::dvec3> f(mesh.triangle_count());
  const bool normals = mesh.normals.size() == mesh.vertex_count();
  for (size_t i = 0; i < f.size(); ++i) {
    const glm::uvec3& t = mesh.triangles[i];
    f[i] = normals ? glm::dvec3(mesh.normals[t.x]) + glm::dvec3(mesh.normals[t.y]) + glm::dvec3(mesh.normals[t.z])
                   : normal_of(mesh.positions, t);
  }
  return f;
}

// Whether moving v (to where it is now, from `before`) turns none of its
// triangles from facing its way to facing away, and leaves none
// degenerate. A triangle already facing away may turn back: that unfolds.
bool fan_keeps_side(const ContourMesh& mesh, const Table& tris, const std::vector<glm::dvec3>& facing, uint32_t v,
                    const std::vector<glm::dvec3>& before) {
  for (size_t i = tris.begin(v); i < tris.end(v); ++i) {
    const glm::uvec3& t = mesh.triangles[tris.items[i]];
    const glm::dvec3& f = facing[tris.items[i]];
    if (glm::dot(normal_of(before, t), f) > 0.0 && glm::dot(normal_of(mesh.positions, t), f) <= 0.0) return false;
    if (detail::collinear(mesh.positions[t.x], mesh.positions[t.y], mesh.positions[t.z])) return false;
  }
  return true;
}

// One round of umbrella moves; returns the vertices that moved.
// A vertex goes at most max_move (0: no limit) from where it started
// (`original`): a target further away is pulled back onto that sphere.
std::vector<uint32_t> smooth(ContourMesh& mesh, const Table& tris, const Neighbourhood& nb,
                             const std::vector<glm::dvec3>& facing, const std::vector<uint32_t>& marked,
                             const std::vector<glm::dvec3>& original, double max_move) {
  const std::vector<glm::dvec3> before = mesh.positions;
  std::vector<uint32_t> moving;
  std::vector<glm::dvec3> step;
  for (uint32_t v : marked) {
    if (!nb.movable[v] || nb.neighbours.begin(v) == nb.neighbours.end(v)) continue;
    glm::dvec3 centroid(0.0);
    for (size_t j = nb.neighbours.begin(v); j < nb.neighbours.end(v); ++j) centroid += before[nb.neighbours.items[j]];
    centroid /= double(nb.neighbours.end(v) - nb.neighbours.begin(v));
    if (max_move > 0.0) {
      const glm::dvec3 away = centroid - original[v];
      const double length = glm::length(away);
      if (length > max_move) centroid = original[v] + away * (max_move / length);
    }
    if (centroid == before[v]) continue;
    moving.push_back(v);
    step.push_back(centroid - before[v]);
  }
  for (size_t i = 0; i < moving.size(); ++i) mesh.positions[moving[i]] = before[moving[i]] + step[i];
  // Halve the moves whose fans turn over, until every fan keeps its side.
  for (int tries = 0; tries <= kHalvings; ++tries) {
    bool all_good = true;
    for (size_t i = 0; i < moving.size(); ++i) {
      if (fan_keeps_side(mesh, tris, facing, moving[i], before)) continue;
      all_good = false;
      step[i] = tries < kHalvings ? 0.5 * step[i] : glm::dvec3(0.0);
      mesh.positions[moving[i]] = before[moving[i]] + step[i];
    }
    if (all_good) break;
  }
  std::vector<uint32_t> moved;
  for (size_t i = 0; i < moving.size(); ++i)
    if (mesh.positions[moving[i]] != before[moving[i]]) moved.push_back(moving[i]);
  return moved;
}

// The pairs after a round: pairs among the triangles around moved vertices
// found again, the others carried over.
std::vector<detail::TrianglePair> pairs_after(const ContourMesh& mesh, const Table& tris,
                                              const std::vector<uint32_t>& moved,
                                              const std::vector<detail::TrianglePair>& old_pairs) {
  std::vector<uint8_t> hot(mesh.triangle_count(), 0);
  for (uint32_t v : moved)
    for (size_t i = tris.begin(v); i < tris.end(v); ++i) hot[tris.items[i]] = 1;
  std::vector<detail::TrianglePair> pairs = detail::self_intersecting_pairs(mesh, &hot);
  for (const detail::TrianglePair& p : old_pairs)
    if (!hot[p.first] && !hot[p.second]) pairs.push_back(p);
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

// Connected components of the triangles (sharing a vertex joins them): the
// component of each triangle, numbered from 0.
std::vector<uint32_t> triangle_components(const ContourMesh& mesh, const Table& tris, uint32_t* count) {
  constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> component(mesh.triangle_count(), kNone);
  std::vector<uint32_t> stack;
  uint32_t next = 0;
  for (uint32_t seed = 0; seed < mesh.triangle_count(); ++seed) {
    if (component[seed] != kNone) continue;
    component[seed] = next;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const glm::uvec3 t = mesh.triangles[stack.back()];
      stack.pop_back();
      for (int k = 0; k < 3; ++k)
        for (size_t i = tris.begin(t[k]); i < tris.end(t[k]); ++i)
          if (component[tris.items[i]] == kNone) component[tris.items[i]] = next, stack.push_back(tris.items[i]);
    }
    ++next;
  }
  *count = next;
  return component;
}

// Removes the closed components of at most max_vertices vertices that hold
// a triangle of `pairs`; the pairs left are those of other components (by
// the old triangle numbers: the caller reads only how many are left).
void remove_specks(ContourMesh& mesh, const Table& tris, const Neighbourhood& nb, int max_vertices,
                   std::vector<detail::TrianglePair>& pairs, UntangleMeshStats& stats) {
  uint32_t count = 0;
  const std::vector<uint32_t> component = triangle_components(mesh, tris, &count);
  std::vector<uint32_t> vertices(count, 0);
  std::vector<uint8_t> closed(count, 1);  // every vertex inside a closed fan
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    if (tris.begin(v) == tris.end(v)) continue;
    const uint32_t c = component[tris.items[tris.begin(v)]];
    ++vertices[c];
    closed[c] = closed[c] && nb.movable[v];
  }
  std::vector<uint8_t> speck(count, 0);
  for (const auto& [a, b] : pairs)
    for (uint32_t t : {a, b})
      if (closed[component[t]] && vertices[component[t]] <= size_t(max_vertices)) speck[component[t]] = 1;
  std::vector<uint8_t> gone(mesh.triangle_count(), 0);
  for (uint32_t t = 0; t < mesh.triangle_count(); ++t) gone[t] = speck[component[t]];
  for (uint8_t s : speck) stats.specks_removed += s;
  if (stats.specks_removed == 0) return;
  for (uint8_t g : gone) stats.speck_triangles_removed += g;
  std::erase_if(pairs, [&](const detail::TrianglePair& p) { return gone[p.first] || gone[p.second]; });
  detail::remove_triangles(mesh, gone);
}

}  // namespace

Status check_untangle_mesh_options(const UntangleMeshOptions& o) {
  if (o.max_rounds < 0 || o.max_rounds > 1000)
    return Status(ErrorCode::kInvalidArgument,
                  "untangle_mesh: max_rounds = " + std::to_string(o.max_rounds) + " must be in [0, 1000]");
  if (!(o.max_move >= 0.0 && std::isfinite(o.max_move)))
    return Status(ErrorCode::kInvalidArgument,
                  "untangle_mesh: max_move = " + std::to_string(o.max_move) + " must be finite and >= 0");
  if (o.max_speck_vertices < 0 || o.max_speck_vertices > 64)
    return Status(ErrorCode::kInvalidArgument, "untangle_mesh: max_speck_vertices = " +
                                                   std::to_string(o.max_speck_vertices) + " must be in [0, 64]");
  return {};
}

Result<UntangleMeshStats> untangle_mesh(ContourMesh& mesh, const UntangleMeshOptions& options, Context* ctx) {
  ScopedTimer timer(ctx, "untangle_mesh");
  if (Status s = check_untangle_mesh_options(options); !s.ok()) return s;
  for (const glm::uvec3& t : mesh.triangles)
    if (t.x >= mesh.vertex_count() || t.y >= mesh.vertex_count() || t.z >= mesh.vertex_count())
      return Status(ErrorCode::kInvalidArgument, "untangle_mesh: a triangle has a vertex index out of range");
  UntangleMeshStats stats;
  std::vector<detail::TrianglePair> pairs = detail::self_intersecting_pairs(mesh);
  stats.pairs_before = stats.pairs_after = pairs.size();
  if (pairs.empty() || options.max_rounds == 0) return stats;

  const Table tris = vertex_triangles(mesh);
  const Neighbourhood nb = neighbourhood(mesh, tris);
  const std::vector<glm::dvec3> face = facing(mesh);
  const std::vector<glm::dvec3> original = mesh.positions;
  // The round that left the fewest pairs (on a coarse, simplified mesh a
  // move to the centroid of far neighbours can make more than it clears):
  // what is returned if the last round is worse.
  size_t best = pairs.size();
  std::vector<detail::TrianglePair> best_pairs = pairs;
  std::vector<glm::dvec3> best_positions;  // empty while the start is the best
  for (int round = 0; round < options.max_rounds && !pairs.empty(); ++round) {
    if (ctx && ctx->cancelled()) {
      mesh.positions = original;
      return Status(ErrorCode::kCancelled, "untangle_mesh: cancelled");
    }
    const std::vector<uint32_t> marked = marked_vertices(mesh, pairs, nb.neighbours, std::min(round, kMaxRing));
    const std::vector<uint32_t> moved = smooth(mesh, tris, nb, face, marked, original, options.max_move);
    ++stats.rounds;
    if (moved.empty()) {
      if (round >= kMaxRing) break;
      continue;  // a wider ring may still help
    }
    pairs = pairs_after(mesh, tris, moved, pairs);
    if (pairs.size() < best) best = pairs.size(), best_pairs = pairs, best_positions = mesh.positions;
  }
  if (pairs.size() > best) {
    mesh.positions = best_positions.empty() ? original : std::move(best_positions);
    pairs = std::move(best_pairs);
  }
  for (size_t v = 0; v < mesh.vertex_count(); ++v) stats.vertices_moved += mesh.positions[v] != original[v];
  if (!pairs.empty() && options.max_speck_vertices > 0 && options.max_rounds > 0)
    remove_specks(mesh, tris, nb, options.max_speck_vertices, pairs, stats);
  stats.pairs_after = pairs.size();
  return stats;
}

namespace {

// simplify_mesh then untangle_mesh on `mesh`: their stats into `simple` and
// `untangled`, their times added to `stats`.
Status simplify_then_untangle(ContourMesh& mesh, const SimplifyOptions& simplify, const UntangleMeshOptions& untangle,
                              Context* ctx, SimplifyUntangleStats& stats, SimplifyStats& simple,
                              UntangleMeshStats& untangled) {
  ScopedTimer s(nullptr, "");
  Result<SimplifyStats> simplified = simplify_mesh(mesh, simplify, ctx);
  stats.simplify_seconds += s.seconds();
  if (!simplified.ok()) return simplified.status();
  simple = simplified.value();
  ScopedTimer u(nullptr, "");
  Result<UntangleMeshStats> done = untangle_mesh(mesh, untangle, ctx);
  stats.untangle_seconds += u.seconds();
  if (!done.ok()) return done.status();
  untangled = done.value();
  return {};
}

}  // namespace

Result<SimplifyUntangleStats> simplify_and_untangle(ContourMesh& mesh, const SimplifyOptions& simplify,
                                                    const UntangleMeshOptions& untangle, Context* ctx) {
  if (Status s = check_untangle_mesh_options(untangle); !s.ok()) return s;
  SimplifyUntangleStats stats;
  ContourMesh uniform = mesh;
  if (Status s = simplify_then_untangle(mesh, simplify, untangle, ctx, stats, stats.simplify, stats.untangle); !s.ok())
    return s;
  stats.first_pairs_after = stats.untangle.pairs_after;
  if (stats.first_pairs_after == 0) return stats;
  stats.retried = true;
  UntangleMeshOptions uncapped = untangle;
  uncapped.max_move = 0.0;
  ScopedTimer u(nullptr, "");
  Result<UntangleMeshStats> first = untangle_mesh(uniform, uncapped, ctx);
  stats.untangle_seconds += u.seconds();
  if (!first.ok()) return first.status();
  stats.uniform_untangle = first.value();
  SimplifyStats simple;
  UntangleMeshStats untangled;
  if (Status s = simplify_then_untangle(uniform, simplify, untangle, ctx, stats, simple, untangled); !s.ok()) return s;
  if (untangled.pairs_after >= stats.first_pairs_after) return stats;
  stats.retry_used = true;
  stats.simplify = simple;
  stats.untangle = untangled;
  mesh = std::move(uniform);
  return stats;
}

}  // namespace ldc
