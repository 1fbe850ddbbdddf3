// Recast/Detour peer: the RecastDemo build pipeline (Sample_SoloMesh for a
// solo mesh, Sample_TileMesh for a tiled one) and Detour path queries.
#include "detour_peer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <random>

#include <recastnavigation/DetourNavMesh.h>
#include <recastnavigation/DetourNavMeshBuilder.h>
#include <recastnavigation/DetourNavMeshQuery.h>
#include <recastnavigation/Recast.h>

namespace ldc::bench {
namespace {

constexpr int kMaxPathPolys = 2048;
constexpr unsigned short kWalkFlag = 1;
constexpr float kHalfExtents[3] = {2.0f, 4.0f, 2.0f};

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Tile index bits as Sample_TileMesh::handleBuild.
unsigned next_pow2(unsigned v) {
  v--;
  v |= v >> 1; v |= v >> 2; v |= v >> 4; v |= v >> 8; v |= v >> 16;
  return v + 1;
}
unsigned ilog2(unsigned v) {
  unsigned r = 0;
  while (v >>= 1) ++r;
  return r;
}

}  // namespace

namespace detour_detail {  // named: DetourNav::Impl holds these
struct HeightfieldDel { void operator()(rcHeightfield* p) const { rcFreeHeightField(p); } };
struct CompactDel { void operator()(rcCompactHeightfield* p) const { rcFreeCompactHeightfield(p); } };
struct ContourDel { void operator()(rcContourSet* p) const { rcFreeContourSet(p); } };
struct PolyMeshDel { void operator()(rcPolyMesh* p) const { rcFreePolyMesh(p); } };
struct DetailDel { void operator()(rcPolyMeshDetail* p) const { rcFreePolyMeshDetail(p); } };
struct NavMeshDel { void operator()(dtNavMesh* p) const { dtFreeNavMesh(p); } };
struct QueryDel { void operator()(dtNavMeshQuery* p) const { dtFreeNavMeshQuery(p); } };
}  // namespace detour_detail
using namespace detour_detail;

struct DetourNav::Impl {
  DetourParams params;
  std::vector<float> verts;
  std::vector<int> tris;
  float bmin[3] = {0, 0, 0}, bmax[3] = {0, 0, 0};  // bounds of the first build (tile grid)
  rcConfig cfg{};  // shared part (tile fields set per tile)
  int grid_w = 0, grid_h = 0, tiles_w = 0, tiles_h = 0;
  std::unique_ptr<dtNavMesh, NavMeshDel> mesh;
  std::unique_ptr<dtNavMeshQuery, QueryDel> query;
  dtQueryFilter filter;  // default: include all flags, area costs 1
  rcContext ctx{false};  // no logs, no timers

  // Scratch for the tile triangle gathering.
  std::vector<int> tile_tris;
  std::vector<unsigned char> areas;
};

DetourNav::DetourNav(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
DetourNav::~DetourNav() = default;

namespace {

// Recast build of one (tile) area into Detour navmesh data: cfg already holds
// width/height/borderSize/bmin/bmax; tris the triangles to rasterize.
// Returns false with *error on failure; *data null and true when the area has
// no polygons.
bool build_nav_data(DetourNav::Impl& nav, const rcConfig& cfg_in, const int* tris, int ntris,
                    int tile_x, int tile_y, unsigned char** data, int* data_size, int* polys,
                    std::string* error) {
  rcContext* ctx = &nav.ctx;
  rcConfig cfg = cfg_in;
  *data = nullptr;
  *data_size = 0;
  *polys = 0;
  auto fail = [&](const char* what) {
    if (error) *error = std::string("Recast/Detour: ") + what;
    return false;
  };
  const float* verts = nav.verts.data();
  const int nverts = static_cast<int>(nav.verts.size() / 3);

  std::unique_ptr<rcHeightfield, HeightfieldDel> solid(rcAllocHeightfield());
  if (!solid || !rcCreateHeightfield(ctx, *solid, cfg.width, cfg.height, cfg.bmin, cfg.bmax, cfg.cs, cfg.ch))
    return fail("rcCreateHeightfield failed");
  nav.areas.assign(static_cast<size_t>(ntris), 0);
  rcMarkWalkableTriangles(ctx, cfg.walkableSlopeAngle, verts, nverts, tris, ntris, nav.areas.data());
  if (!rcRasterizeTriangles(ctx, verts, nverts, tris, nav.areas.data(), ntris, *solid, cfg.walkableClimb))
    return fail("rcRasterizeTriangles failed");

  rcFilterLowHangingWalkableObstacles(ctx, cfg.walkableClimb, *solid);
  rcFilterLedgeSpans(ctx, cfg.walkableHeight, cfg.walkableClimb, *solid);
  rcFilterWalkableLowHeightSpans(ctx, cfg.walkableHeight, *solid);

  std::unique_ptr<rcCompactHeightfield, CompactDel> chf(rcAllocCompactHeightfield());
  if (!chf || !rcBuildCompactHeightfield(ctx, cfg.walkableHeight, cfg.walkableClimb, *solid, *chf))
    return fail("rcBuildCompactHeightfield failed");
  solid.reset();
  if (!rcErodeWalkableArea(ctx, cfg.walkableRadius, *chf)) return fail("rcErodeWalkableArea failed");
  // Watershed partition.
  if (!rcBuildDistanceField(ctx, *chf)) return fail("rcBuildDistanceField failed");
  if (!rcBuildRegions(ctx, *chf, cfg.borderSize, cfg.minRegionArea, cfg.mergeRegionArea))
    return fail("rcBuildRegions failed");

  std::unique_ptr<rcContourSet, ContourDel> cset(rcAllocContourSet());
  if (!cset || !rcBuildContours(ctx, *chf, cfg.maxSimplificationError, cfg.maxEdgeLen, *cset))
    return fail("rcBuildContours failed");
  if (cset->nconts == 0) return true;  // nothing walkable here
  std::unique_ptr<rcPolyMesh, PolyMeshDel> pmesh(rcAllocPolyMesh());
  if (!pmesh || !rcBuildPolyMesh(ctx, *cset, cfg.maxVertsPerPoly, *pmesh))
    return fail("rcBuildPolyMesh failed");
  std::unique_ptr<rcPolyMeshDetail, DetailDel> dmesh(rcAllocPolyMeshDetail());
  if (!dmesh || !rcBuildPolyMeshDetail(ctx, *pmesh, *chf, cfg.detailSampleDist, cfg.detailSampleMaxError, *dmesh))
    return fail("rcBuildPolyMeshDetail failed");
  chf.reset();
  cset.reset();
  if (pmesh->npolys == 0) return true;
  if (pmesh->nverts >= 0xffff) return fail("too many vertices per tile for Detour");

  for (int i = 0; i < pmesh->npolys; ++i) {
    if (pmesh->areas[i] == RC_WALKABLE_AREA) pmesh->flags[i] = kWalkFlag;
  }

  dtNavMeshCreateParams p;
  std::memset(&p, 0, sizeof(p));
  p.verts = pmesh->verts;
  p.vertCount = pmesh->nverts;
  p.polys = pmesh->polys;
  p.polyAreas = pmesh->areas;
  p.polyFlags = pmesh->flags;
  p.polyCount = pmesh->npolys;
  p.nvp = pmesh->nvp;
  p.detailMeshes = dmesh->meshes;
  p.detailVerts = dmesh->verts;
  p.detailVertsCount = dmesh->nverts;
  p.detailTris = dmesh->tris;
  p.detailTriCount = dmesh->ntris;
  p.walkableHeight = nav.params.agent_height;
  p.walkableRadius = nav.params.agent_radius;
  p.walkableClimb = nav.params.agent_max_climb;
  p.tileX = tile_x;
  p.tileY = tile_y;
  p.tileLayer = 0;
  rcVcopy(p.bmin, pmesh->bmin);
  rcVcopy(p.bmax, pmesh->bmax);
  p.cs = cfg.cs;
  p.ch = cfg.ch;
  p.buildBvTree = true;
  if (!dtCreateNavMeshData(&p, data, data_size)) return fail("dtCreateNavMeshData failed");
  *polys = pmesh->npolys;
  return true;
}

// Tile (tx, ty): its config (bordered bounds) and the triangles overlapping it
// in x/z (gathered into nav.tile_tris), as Sample_TileMesh::buildTileMesh with
// a linear scan instead of the chunky triangle mesh.
rcConfig tile_config(DetourNav::Impl& nav, int tx, int ty) {
  rcConfig cfg = nav.cfg;
  const float tcs = static_cast<float>(cfg.tileSize) * cfg.cs;
  cfg.bmin[0] = nav.bmin[0] + static_cast<float>(tx) * tcs;
  cfg.bmin[1] = nav.bmin[1];
  cfg.bmin[2] = nav.bmin[2] + static_cast<float>(ty) * tcs;
  cfg.bmax[0] = nav.bmin[0] + static_cast<float>(tx + 1) * tcs;
  cfg.bmax[1] = nav.bmax[1];
  cfg.bmax[2] = nav.bmin[2] + static_cast<float>(ty + 1) * tcs;
  const float border = static_cast<float>(cfg.borderSize) * cfg.cs;
  cfg.bmin[0] -= border;
  cfg.bmin[2] -= border;
  cfg.bmax[0] += border;
  cfg.bmax[2] += border;

  nav.tile_tris.clear();
  const float* v = nav.verts.data();
  float ymin = cfg.bmin[1], ymax = cfg.bmax[1];
  const size_t nt = nav.tris.size() / 3;
  for (size_t t = 0; t < nt; ++t) {
    const int* tri = &nav.tris[3 * t];
    const float* a = v + 3 * tri[0];
    const float* b = v + 3 * tri[1];
    const float* c = v + 3 * tri[2];
    if (std::max({a[0], b[0], c[0]}) < cfg.bmin[0] || std::min({a[0], b[0], c[0]}) > cfg.bmax[0] ||
        std::max({a[2], b[2], c[2]}) < cfg.bmin[2] || std::min({a[2], b[2], c[2]}) > cfg.bmax[2])
      continue;
    nav.tile_tris.insert(nav.tile_tris.end(), tri, tri + 3);
    ymin = std::min({ymin, a[1], b[1], c[1]});
    ymax = std::max({ymax, a[1], b[1], c[1]});
  }
  // New geometry outside the first build's height range (a dig): widen by
  // whole cells so the span quantization stays that of the neighbour tiles.
  if (ymin < cfg.bmin[1]) cfg.bmin[1] -= std::ceil((cfg.bmin[1] - ymin) / cfg.ch) * cfg.ch;
  if (ymax > cfg.bmax[1]) cfg.bmax[1] += std::ceil((ymax - cfg.bmax[1]) / cfg.ch) * cfg.ch;
  return cfg;
}

}  // namespace

std::unique_ptr<DetourNav> detour_build(const std::vector<float>& verts, const std::vector<int>& tris,
                                        const DetourParams& params, DetourBuildStats* stats,
                                        std::string* error) {
  auto fail = [&](const std::string& what) -> std::unique_ptr<DetourNav> {
    if (error) *error = what;
    return nullptr;
  };
  if (verts.size() % 3 != 0 || tris.size() % 3 != 0 || tris.empty()) return fail("detour_build: bad input sizes");
  const int nverts = static_cast<int>(verts.size() / 3);
  for (int i : tris)
    if (i < 0 || i >= nverts) return fail("detour_build: triangle index out of range");
  if (params.verts_per_poly > DT_VERTS_PER_POLYGON) return fail("detour_build: verts_per_poly too large");

  auto impl = std::make_unique<DetourNav::Impl>();
  DetourNav::Impl& nav = *impl;
  nav.params = params;
  nav.verts = verts;  // copies outside the timing: the input is "in memory"
  nav.tris = tris;

  const auto t0 = Clock::now();
  rcCalcBounds(nav.verts.data(), nverts, nav.bmin, nav.bmax);

  // Sample_SoloMesh / Sample_TileMesh configuration.
  rcConfig& cfg = nav.cfg;
  std::memset(&cfg, 0, sizeof(cfg));
  cfg.cs = params.cell_size;
  cfg.ch = params.cell_height;
  cfg.walkableSlopeAngle = params.agent_max_slope;
  cfg.walkableHeight = static_cast<int>(std::ceil(params.agent_height / cfg.ch));
  cfg.walkableClimb = static_cast<int>(std::floor(params.agent_max_climb / cfg.ch));
  cfg.walkableRadius = static_cast<int>(std::ceil(params.agent_radius / cfg.cs));
  cfg.maxEdgeLen = static_cast<int>(params.edge_max_len / params.cell_size);
  cfg.maxSimplificationError = params.edge_max_error;
  cfg.minRegionArea = params.region_min_size * params.region_min_size;
  cfg.mergeRegionArea = params.region_merge_size * params.region_merge_size;
  cfg.maxVertsPerPoly = params.verts_per_poly;
  cfg.detailSampleDist = params.detail_sample_dist < 0.9f ? 0 : params.cell_size * params.detail_sample_dist;
  cfg.detailSampleMaxError = params.cell_height * params.detail_sample_max_error;
  rcVcopy(cfg.bmin, nav.bmin);
  rcVcopy(cfg.bmax, nav.bmax);
  rcCalcGridSize(cfg.bmin, cfg.bmax, cfg.cs, &nav.grid_w, &nav.grid_h);

  nav.mesh.reset(dtAllocNavMesh());
  nav.query.reset(dtAllocNavMeshQuery());
  if (!nav.mesh || !nav.query) return fail("detour_build: out of memory");
  int total_polys = 0, tiles = 0;
  std::string err;

  if (params.tile_size <= 0) {
    cfg.width = nav.grid_w;
    cfg.height = nav.grid_h;
    unsigned char* data = nullptr;
    int size = 0;
    if (!build_nav_data(nav, cfg, nav.tris.data(), static_cast<int>(nav.tris.size() / 3), 0, 0, &data, &size,
                        &total_polys, &err))
      return fail(err);
    if (!data) return fail("detour_build: no walkable polygons");
    if (dtStatusFailed(nav.mesh->init(data, size, DT_TILE_FREE_DATA))) {
      dtFree(data);
      return fail("dtNavMesh::init failed");
    }
    tiles = 1;
  } else {
    cfg.tileSize = params.tile_size;
    cfg.borderSize = cfg.walkableRadius + 3;
    cfg.width = cfg.tileSize + cfg.borderSize * 2;
    cfg.height = cfg.tileSize + cfg.borderSize * 2;
    nav.tiles_w = (nav.grid_w + cfg.tileSize - 1) / cfg.tileSize;
    nav.tiles_h = (nav.grid_h + cfg.tileSize - 1) / cfg.tileSize;
    const unsigned tile_bits =
        std::min(ilog2(next_pow2(static_cast<unsigned>(nav.tiles_w * nav.tiles_h))), 14u);
    const unsigned poly_bits = 22 - tile_bits;
    dtNavMeshParams mp;
    std::memset(&mp, 0, sizeof(mp));
    rcVcopy(mp.orig, nav.bmin);
    mp.tileWidth = static_cast<float>(cfg.tileSize) * cfg.cs;
    mp.tileHeight = static_cast<float>(cfg.tileSize) * cfg.cs;
    mp.maxTiles = 1 << tile_bits;
    mp.maxPolys = 1 << poly_bits;
    if (dtStatusFailed(nav.mesh->init(&mp))) return fail("dtNavMesh::init (tiled) failed");
    for (int y = 0; y < nav.tiles_h; ++y) {
      for (int x = 0; x < nav.tiles_w; ++x) {
        const rcConfig tcfg = tile_config(nav, x, y);
        if (nav.tile_tris.empty()) continue;
        unsigned char* data = nullptr;
        int size = 0, polys = 0;
        if (!build_nav_data(nav, tcfg, nav.tile_tris.data(), static_cast<int>(nav.tile_tris.size() / 3), x, y,
                            &data, &size, &polys, &err))
          return fail(err);
        if (!data) continue;
        if (dtStatusFailed(nav.mesh->addTile(data, size, DT_TILE_FREE_DATA, 0, nullptr))) {
          dtFree(data);
          return fail("dtNavMesh::addTile failed");
        }
        total_polys += polys;
        ++tiles;
      }
    }
  }
  if (dtStatusFailed(nav.query->init(nav.mesh.get(), params.max_nodes)))
    return fail("dtNavMeshQuery::init failed");
  const double build_ms = ms_since(t0);

  if (stats) {
    stats->build_ms = build_ms;
    stats->polys = total_polys;
    stats->grid_w = nav.grid_w;
    stats->grid_h = nav.grid_h;
    stats->tiles = tiles;
  }
  return std::make_unique<DetourNav>(std::move(impl));
}

namespace {
// findRandomPoint takes a plain function pointer: the generator lives here.
thread_local std::mt19937 g_rng;
float frand() {
  // [0, 1): 24 random mantissa bits.
  return static_cast<float>(g_rng() >> 8) * (1.0f / 16777216.0f);
}
}  // namespace

std::vector<DetourPair> detour_random_pairs(DetourNav& nav_, int count, uint32_t seed) {
  DetourNav::Impl& nav = nav_.impl();
  g_rng.seed(seed);
  std::vector<DetourPair> pairs;
  pairs.reserve(static_cast<size_t>(std::max(count, 0)));
  for (int i = 0; i < count; ++i) {
    DetourPair pair;
    dtPolyRef ref = 0;
    if (dtStatusFailed(nav.query->findRandomPoint(&nav.filter, frand, &ref, &pair.start.x))) break;
    if (dtStatusFailed(nav.query->findRandomPoint(&nav.filter, frand, &ref, &pair.goal.x))) break;
    pairs.push_back(pair);
  }
  return pairs;
}

DetourPath detour_find_path(DetourNav& nav_, const glm::vec3& start, const glm::vec3& goal) {
  DetourNav::Impl& nav = nav_.impl();
  DetourPath out;
  dtPolyRef start_ref = 0, goal_ref = 0;
  float spos[3], epos[3];
  nav.query->findNearestPoly(&start.x, kHalfExtents, &nav.filter, &start_ref, spos);
  nav.query->findNearestPoly(&goal.x, kHalfExtents, &nav.filter, &goal_ref, epos);
  if (!start_ref || !goal_ref) return out;

  dtPolyRef polys[kMaxPathPolys];
  int npolys = 0;
  const dtStatus st = nav.query->findPath(start_ref, goal_ref, spos, epos, &nav.filter, polys, &npolys, kMaxPathPolys);
  out.out_of_nodes = dtStatusDetail(st, DT_OUT_OF_NODES);
  if (dtStatusFailed(st) || npolys == 0) return out;
  out.found = polys[npolys - 1] == goal_ref;

  // A partial path ends at the point of its last poly nearest the goal.
  float end[3] = {epos[0], epos[1], epos[2]};
  if (!out.found) nav.query->closestPointOnPoly(polys[npolys - 1], epos, end, nullptr);

  float straight[kMaxPathPolys * 3];
  int nstraight = 0;
  nav.query->findStraightPath(spos, end, polys, npolys, straight, nullptr, nullptr, &nstraight, kMaxPathPolys);
  out.straight.resize(static_cast<size_t>(nstraight));
  for (int i = 0; i < nstraight; ++i) {
    out.straight[static_cast<size_t>(i)] = glm::vec3(straight[3 * i], straight[3 * i + 1], straight[3 * i + 2]);
    if (i > 0) out.length += glm::length(glm::dvec3(out.straight[i]) - glm::dvec3(out.straight[i - 1]));
  }
  return out;
}

double detour_rebuild_tile(DetourNav& nav_, const std::vector<float>& verts, const std::vector<int>& tris,
                           const glm::vec3& at, std::string* error) {
  DetourNav::Impl& nav = nav_.impl();
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return -1.0;
  };
  if (nav.params.tile_size <= 0) return fail("detour_rebuild_tile: not a tiled navmesh");
  if (verts.size() % 3 != 0 || tris.size() % 3 != 0) return fail("detour_rebuild_tile: bad input sizes");
  const int nverts = static_cast<int>(verts.size() / 3);
  for (int i : tris)
    if (i < 0 || i >= nverts) return fail("detour_rebuild_tile: triangle index out of range");
  nav.verts = verts;  // the new triangle list: not timed
  nav.tris = tris;

  const float tcs = static_cast<float>(nav.cfg.tileSize) * nav.cfg.cs;
  const int tx = std::clamp(static_cast<int>(std::floor((at.x - nav.bmin[0]) / tcs)), 0, nav.tiles_w - 1);
  const int ty = std::clamp(static_cast<int>(std::floor((at.z - nav.bmin[2]) / tcs)), 0, nav.tiles_h - 1);

  const auto t0 = Clock::now();
  const rcConfig tcfg = tile_config(nav, tx, ty);
  unsigned char* data = nullptr;
  int size = 0, polys = 0;
  std::string err;
  if (!nav.tile_tris.empty() &&
      !build_nav_data(nav, tcfg, nav.tile_tris.data(), static_cast<int>(nav.tile_tris.size() / 3), tx, ty, &data,
                      &size, &polys, &err))
    return fail(err);
  nav.mesh->removeTile(nav.mesh->getTileRefAt(tx, ty, 0), nullptr, nullptr);
  if (data && dtStatusFailed(nav.mesh->addTile(data, size, DT_TILE_FREE_DATA, 0, nullptr))) {
    dtFree(data);
    return fail("dtNavMesh::addTile failed");
  }
  return ms_since(t0);
}

}  // namespace ldc::bench

namespace ldc::bench {

// The nearest point of Detour's navmesh within half_extents of p, for
// comparing walkable areas (bench/nav_coverage.cpp).
bool detour_nearest_point(DetourNav& nav, const glm::vec3& p, const glm::vec3& half_extents,
                          glm::vec3* nearest) {
  DetourNav::Impl& impl = nav.impl();
  dtPolyRef ref = 0;
  float out[3];
  if (dtStatusFailed(impl.query->findNearestPoly(&p.x, &half_extents.x, &impl.filter, &ref, out)) || !ref) {
    return false;
  }
  *nearest = glm::vec3(out[0], out[1], out[2]);
  return true;
}

}  // namespace ldc::bench
