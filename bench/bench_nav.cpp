// Pathfinding: ldc::nav against Recast/Detour on the same 1,000 start/goal
// pairs (issue 6). Prints markdown tables: build time, query time (median and
// p99), agreement on which pairs are reachable, path length ratio, rebuild
// after a 2 m dig, and the grid A* baseline the region search replaces; then
// both against the exact walkable set of analytic terrains (bench/nav_truth.h).
// Scenes: RecastDemo's nav_test.obj, the landscape, the soup levels of
// tests/data/levels (issue 20: one-sided floors, single-quad walls, read with
// BuildConfig kAuto) and any --level FILE.obj (y up) given.
//
//   bench_nav [--quick] [--data DIR] [--level FILE.obj ...] [--scene NAME ...]
//
// --scene NAME (repeatable; nav_test, landscape, soup_rooms, ... or a --level
// file's name) runs only those scenes and skips the analytic terrains.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "bench_common.h"
#include "contour/contour.h"
#include "csg/csg.h"
#include "detour_peer.h"
#include "ldc/build.h"
#include "ldc/terrain.h"
#include "meshio/meshio.h"
#include "nav/nav.h"
#include "nav_truth.h"

namespace {

using Clock = std::chrono::steady_clock;

double us_since(Clock::time_point t) {
  return std::chrono::duration<double, std::micro>(Clock::now() - t).count();
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(q * double(v.size())))];
}

// Detour works y up; the scene's up axis maps onto it by a rotation.
struct Frame {
  int up = 1;
  glm::vec3 to_detour(const glm::dvec3& p) const {
    return up == 1 ? glm::vec3(p) : glm::vec3(float(p.x), float(p.z), float(-p.y));
  }
  glm::dvec3 from_detour(const glm::vec3& p) const {
    return up == 1 ? glm::dvec3(p) : glm::dvec3(p.x, -double(p.z), p.y);
  }
};

struct Triangles {
  std::vector<float> verts;
  std::vector<int> tris;
};

Triangles detour_triangles(const std::vector<glm::dvec3>& positions,
                           const std::vector<glm::uvec3>& triangles, const Frame& frame) {
  Triangles t;
  for (const glm::dvec3& p : positions) {
    const glm::vec3 q = frame.to_detour(p);
    t.verts.insert(t.verts.end(), {q.x, q.y, q.z});
  }
  for (const glm::uvec3& tri : triangles) t.tris.insert(t.tris.end(), {int(tri.x), int(tri.y), int(tri.z)});
  return t;
}

// The triangles whose ground-plane box meets [lo, hi] (Detour frame): what
// RecastDemo's chunky triangle index hands a tile build.
Triangles near(const Triangles& all, const glm::vec2& lo, const glm::vec2& hi) {
  Triangles out;
  out.verts = all.verts;
  for (size_t i = 0; i + 2 < all.tris.size(); i += 3) {
    glm::vec2 mn(1e30f), mx(-1e30f);
    for (int k = 0; k < 3; ++k) {
      const float* v = &all.verts[size_t(all.tris[i + size_t(k)]) * 3];
      mn = glm::min(mn, glm::vec2(v[0], v[2]));
      mx = glm::max(mx, glm::vec2(v[0], v[2]));
    }
    if (mx.x < lo.x || mn.x > hi.x || mx.y < lo.y || mn.y > hi.y) continue;
    out.tris.insert(out.tris.end(), {all.tris[i], all.tris[i + 1], all.tris[i + 2]});
  }
  return out;
}

struct Scene {
  std::string name;
  ldc::World world;
  Frame frame;
  Triangles triangles;  // what Detour builds from
  double world_build_ms = 0.0;
  std::string world_source;
};

struct QueryStats {
  std::vector<double> us;
  int complete = 0;
};

struct Row {
  std::string scene, peer, build, size, query_median, query_p99, complete, agree, length, rebuild;
};

void print_rows(const std::vector<Row>& rows) {
  std::printf("| scene | peer | build ms | regions / polys | query µs median | query µs p99 | complete | reachability agreement | length ratio ldc/Detour mean · p95 · max | rebuild after 2 m dig ms median · max |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    std::printf("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", r.scene.c_str(), r.peer.c_str(),
                r.build.c_str(), r.size.c_str(), r.query_median.c_str(), r.query_p99.c_str(),
                r.complete.c_str(), r.agree.c_str(), r.length.c_str(), r.rebuild.c_str());
  }
}

std::string fmt(const char* f, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, a);
  return buf;
}
std::string fmt3(const char* f, double a, double b, double c) {
  char buf[96];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

Scene nav_test_scene(const ldc::bench::Args& args) {
  Scene s;
  s.name = "nav_test";
  s.frame.up = 1;
  const ldc::TriangleMesh mesh = ldc::bench::load(args, "nav_test.obj");
  s.triangles = detour_triangles(mesh.positions, mesh.triangles, s.frame);
  ldc::GridConfig grid;
  grid.cell_size = 0.3;  // Recast's cell size
  s.world_build_ms = ldc::bench::median_ms(3, [&] { s.world = ldc::build_from_mesh(mesh, grid).value(); });
  s.world_source = "build_from_mesh at h = 0.3";
  return s;
}

// A game level from an OBJ (y up) read as a soup: closed outward-facing parts
// as solids, everything else (one-sided floors, single-quad walls) as thin
// shells under the triangles (BuildConfig kAuto, issue 20).
Scene soup_scene(const std::string& name, const ldc::TriangleMesh& mesh, const std::string& source) {
  Scene s;
  s.name = name;
  s.frame.up = 1;
  s.triangles = detour_triangles(mesh.positions, mesh.triangles, s.frame);
  ldc::GridConfig grid;
  grid.cell_size = 0.3;  // Recast's cell size
  ldc::BuildConfig build;
  build.mode = ldc::BuildMode::kAuto;
  build.up_axis = 1;
  ldc::BuildReport report;
  s.world_build_ms = ldc::bench::median_ms(3, [&] {
    s.world = ldc::build_from_mesh(mesh, grid, build, nullptr, &report).value();
  });
  s.world_source = "build_from_mesh (" + source + ", kAuto: " + std::to_string(report.solid_components) +
                   " solid, " + std::to_string(report.surface_components) + " surface components) at h = 0.3";
  return s;
}

Scene landscape_scene() {
  Scene s;
  s.name = "landscape";
  s.frame.up = 2;
  s.world_build_ms = ldc::bench::median_ms(1, [&] {
    s.world = ldc::build_terrain(ldc::TerrainConfig{}, 0.2).value();
  });
  s.world_source = "build_terrain at h = 0.2";
  const ldc::ContourMesh mesh = ldc::contour_world(s.world).value();
  s.triangles = detour_triangles(mesh.positions, mesh.triangles, s.frame);
  return s;
}

void run_scene(Scene& scene, bool quick, std::vector<Row>& rows, std::vector<std::string>& notes) {
  const int pairs_count = quick ? 200 : 1000;
  const int reps = quick ? 3 : 5;
  ldc::bench::DetourParams params;
  ldc::bench::DetourBuildStats dstats;
  std::string error;
  std::unique_ptr<ldc::bench::DetourNav> detour;
  const double detour_build = ldc::bench::median_ms(3, [&] {
    detour = ldc::bench::detour_build(scene.triangles.verts, scene.triangles.tris, params, &dstats, &error);
  });
  if (!detour) {
    std::printf("Detour build failed on %s: %s\n", scene.name.c_str(), error.c_str());
    return;
  }
  ldc::NavConfig config;
  config.up_axis = scene.frame.up;
  std::optional<ldc::NavMesh> nav;
  double build_1t = 0.0;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    build_1t = ldc::bench::median_ms(3, [&] { nav.emplace(ldc::NavMesh::build(scene.world, config).value()); });
  }
  const double build_2t = ldc::bench::median_ms(3, [&] { nav.emplace(ldc::NavMesh::build(scene.world, config).value()); });
  const ldc::NavStats nstats = nav->stats();

  const std::vector<ldc::bench::DetourPair> pairs = ldc::bench::detour_random_pairs(*detour, pairs_count, 1);
  ldc::NavQuery query(*nav);
  ldc::NavQuery grid_query(*nav, 1 << 20);
  ldc::PathQueryOptions options;
  options.search_half_extents = glm::dvec3(2.0);
  options.search_half_extents[scene.frame.up] = 4.0;  // Detour's (2, 4, 2)
  QueryStats ours, theirs, grid;
  int agree = 0, no_floor = 0, start_floor = 0;
  std::vector<double> ratios;
  std::vector<double> ours_both, theirs_both;  // query times on pairs both complete
  for (const ldc::bench::DetourPair& pair : pairs) {
    const glm::dvec3 a = scene.frame.from_detour(pair.start), b = scene.frame.from_detour(pair.goal);
    start_floor += query.nearest_walkable(a, options.search_half_extents).ok();
    ldc::bench::DetourPath dp;
    std::vector<double> t;
    for (int r = 0; r < reps; ++r) {
      const auto s = Clock::now();
      dp = ldc::bench::detour_find_path(*detour, pair.start, pair.goal);
      t.push_back(us_since(s));
    }
    theirs.us.push_back(percentile(t, 0.5));
    theirs.complete += dp.found;
    t.clear();
    ldc::Result<ldc::NavPath> lp = ldc::Status(ldc::ErrorCode::kInternal, "not run");
    for (int r = 0; r < reps; ++r) {
      const auto s = Clock::now();
      lp = query.find_path(a, b, options);
      t.push_back(us_since(s));
    }
    ours.us.push_back(percentile(t, 0.5));
    const bool our_complete = lp.ok() && lp->status == ldc::PathStatus::kComplete;
    no_floor += !lp.ok();
    ours.complete += our_complete;
    agree += our_complete == dp.found;
    if (our_complete && dp.found && dp.length > 0.0) ratios.push_back(lp->length / dp.length);
    if (our_complete && dp.found) {
      ours_both.push_back(ours.us.back());
      theirs_both.push_back(theirs.us.back());
    }
    const auto s = Clock::now();
    ldc::Result<ldc::NavPath> gp = grid_query.find_grid_path(a, b, options);
    grid.us.push_back(us_since(s));
    grid.complete += gp.ok() && gp->status == ldc::PathStatus::kComplete;
  }
  double ratio_mean = 0.0;
  for (double r : ratios) ratio_mean += r;
  ratio_mean /= std::max<size_t>(1, ratios.size());
  const double n = double(pairs.size());

  // Rebuild after a 2 m dig (a sphere of radius 1 m) at walkable points.
  std::vector<double> ours_rebuild, theirs_rebuild;
  {
    ldc::bench::DetourParams tiled = params;
    tiled.tile_size = 32;
    auto detour_tiled = ldc::bench::detour_build(scene.triangles.verts, scene.triangles.tris, tiled, nullptr, &error);
    glm::vec2 bmin(1e30f);
    for (size_t i = 0; i < scene.triangles.verts.size(); i += 3) {
      bmin = glm::min(bmin, glm::vec2(scene.triangles.verts[i], scene.triangles.verts[i + 2]));
    }
    const float tile_w = tiled.tile_size * tiled.cell_size;
    const float border = (std::ceil(tiled.agent_radius / tiled.cell_size) + 3) * tiled.cell_size;
    ldc::WorldEditor editor(scene.world);
    ldc::NavMesh edited = ldc::NavMesh::build(scene.world, config).value();
    const int digs = quick ? 3 : 10;
    for (int d = 0; d < digs; ++d) {
      const glm::dvec3 at = scene.frame.from_detour(pairs[size_t(d) * 7 % pairs.size()].start);
      if (!editor.apply(ldc::Brush::sphere(at, 1.0), ldc::EditOp::kSubtract).ok()) continue;
      const std::vector<ldc::DirtyChunk> dirty = editor.take_dirty();
      const auto s = Clock::now();
      (void)edited.update(editor.world(), dirty).value();
      ours_rebuild.push_back(us_since(s) / 1000.0);
      if (!detour_tiled) continue;
      const ldc::ContourMesh mesh = ldc::contour_world(editor.world()).value();
      const Triangles all = detour_triangles(mesh.positions, mesh.triangles, scene.frame);
      const glm::vec3 dat = scene.frame.to_detour(at);
      const glm::vec2 tile = glm::floor((glm::vec2(dat.x, dat.z) - bmin) / tile_w);
      const glm::vec2 lo = bmin + tile * tile_w - border, hi = bmin + (tile + 1.0f) * tile_w + border;
      const Triangles local = near(all, lo, hi);
      const double ms = ldc::bench::detour_rebuild_tile(*detour_tiled, local.verts, local.tris, dat, &error);
      if (ms >= 0.0) theirs_rebuild.push_back(ms);
    }
  }

  Row mine;
  mine.scene = scene.name;
  mine.peer = "**ldc** (regions + funnel)";
  mine.build = fmt("%.1f", build_2t) + " (1T " + fmt("%.1f", build_1t) + ")";
  mine.size = std::to_string(nstats.regions) + " regions (" + std::to_string(nstats.chains) + " chains)";
  mine.query_median = fmt("%.2f", percentile(ours.us, 0.5));
  mine.query_p99 = fmt("%.2f", percentile(ours.us, 0.99));
  mine.complete = fmt("%.1f%%", 100.0 * ours.complete / n);
  mine.agree = fmt("%.1f%%", 100.0 * agree / n);
  mine.length = fmt3("%.3f · %.3f · %.3f", ratio_mean, percentile(ratios, 0.95), percentile(ratios, 1.0)) +
                " (" + std::to_string(ratios.size()) + " pairs)";
  mine.rebuild = fmt("%.3f", percentile(ours_rebuild, 0.5)) + " · " + fmt("%.3f", percentile(ours_rebuild, 1.0));
  rows.push_back(mine);
  Row peer;
  peer.scene = scene.name;
  peer.peer = "Detour (solo; tile 32 for rebuilds)";
  peer.build = fmt("%.1f", detour_build) + " (1T)";
  peer.size = std::to_string(dstats.polys) + " polys";
  peer.query_median = fmt("%.2f", percentile(theirs.us, 0.5));
  peer.query_p99 = fmt("%.2f", percentile(theirs.us, 0.99));
  peer.complete = fmt("%.1f%%", 100.0 * theirs.complete / n);
  peer.agree = "—";
  peer.length = "1";
  peer.rebuild = theirs_rebuild.empty() ? "failed: " + error
                                        : fmt("%.3f", percentile(theirs_rebuild, 0.5)) + " · " +
                                              fmt("%.3f", percentile(theirs_rebuild, 1.0));
  rows.push_back(peer);
  Row base;
  base.scene = scene.name;
  base.peer = "ldc grid A* (baseline)";
  base.build = "same";
  base.size = std::to_string(nstats.walkable) + " floors";
  base.query_median = fmt("%.2f", percentile(grid.us, 0.5));
  base.query_p99 = fmt("%.2f", percentile(grid.us, 0.99));
  base.complete = fmt("%.1f%%", 100.0 * grid.complete / n);
  base.agree = base.length = base.rebuild = "—";
  rows.push_back(base);
  notes.push_back(scene.name + ": on the " + std::to_string(ours_both.size()) +
                  " pairs both complete, query µs median / p99: ldc " + fmt("%.2f", percentile(ours_both, 0.5)) +
                  " / " + fmt("%.2f", percentile(ours_both, 0.99)) + ", Detour " +
                  fmt("%.2f", percentile(theirs_both, 0.5)) + " / " + fmt("%.2f", percentile(theirs_both, 0.99)));
  notes.push_back(scene.name + ": world " + scene.world_source + " in " + fmt("%.0f", scene.world_build_ms) +
                  " ms (not in the build column); " + std::to_string(scene.triangles.tris.size() / 3) +
                  " triangles for Detour; ldc nav " + std::to_string(nstats.floors) + " floors, " +
                  std::to_string(nstats.walkable) + " walkable after erosion, " +
                  std::to_string(nstats.components) + " islands, " + fmt("%.1f", nstats.bytes_per_floor()) +
                  " bytes per floor (" + fmt("%.2f", nstats.memory_bytes / 1048576.0) + " MiB); " +
                  std::to_string(no_floor) + " pairs without an ldc floor within Detour's search box");
  notes.push_back(scene.name + ": **ldc finds a walkable floor within (2, 4, 2) m of " +
                  fmt("%.1f%%", 100.0 * start_floor / n) + " of Detour's " + std::to_string(pairs.size()) +
                  " start points**");
}

}  // namespace

int main(int argc, char** argv) {
  // --level FILE.obj (repeatable): that level (y up) as one more soup scene.
  std::vector<std::string> levels, scenes;
  std::vector<char*> rest{argv[0]};
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--level" || arg == "--scene") {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "usage: %s [--quick] [--data DIR] [--level FILE.obj ...] [--scene NAME ...]\n",
                     argv[0]);
        return 2;
      }
      (arg == "--level" ? levels : scenes).push_back(argv[++i]);
    } else {
      rest.push_back(argv[i]);
    }
  }
  const ldc::bench::Args args = ldc::bench::parse_args(int(rest.size()), rest.data(), {"nav_test.obj"});
  std::vector<ldc::TriangleMesh> level_meshes;  // read first: a bad file stops before the long runs
  for (const std::string& path : levels) {
    ldc::Result<ldc::TriangleMesh> mesh = ldc::load_mesh(path);
    if (!mesh.ok()) {
      std::fprintf(stderr, "%s\n", mesh.status().to_string().c_str());
      return 1;
    }
    level_meshes.push_back(std::move(mesh.value()));
  }
  auto wanted = [&](const std::string& name) {
    return scenes.empty() || std::find(scenes.begin(), scenes.end(), name) != scenes.end();
  };
  ldc::bench::print_machine();
  std::vector<Row> rows;
  std::vector<std::string> notes;
  if (wanted("nav_test")) {
    Scene nav_test = nav_test_scene(args);
    run_scene(nav_test, args.quick, rows, notes);
  }
  if (wanted("landscape")) {
    Scene landscape = landscape_scene();
    run_scene(landscape, args.quick, rows, notes);
  }
  // The soup levels of tests/data/levels (tests/levels/make_levels.cpp), then --level files.
  for (const char* level : {"soup_rooms", "soup_storeys", "soup_yard"}) {
    if (!wanted(level)) continue;
    const std::string file = std::string("levels/") + level + ".obj";
    Scene scene = soup_scene(level, ldc::bench::load(args, file), file);
    run_scene(scene, args.quick, rows, notes);
  }
  for (size_t i = 0; i < levels.size(); ++i) {
    const std::string& path = levels[i];
    const std::string name = path.substr(path.find_last_of('/') + 1);
    if (!wanted(name)) continue;
    Scene scene = soup_scene(name, level_meshes[i], path);
    run_scene(scene, args.quick, rows, notes);
  }
  std::printf("\n");
  print_rows(rows);
  std::printf("\n");
  for (const std::string& n : notes) std::printf("- %s\n", n.c_str());
  std::printf(
      "- Pairs: %s seeded random start/goal pairs from Detour's findRandomPoint; both libraries get "
      "the same points. Query time = median of the repetitions of one query (nearest-floor lookups "
      "included on both sides), then median and 99th percentile over the pairs; 1 thread. "
      "Complete = the path reaches the goal (Detour: ends in the goal's polygon). Length ratio over "
      "pairs both complete, 3D corner-to-corner lengths on both sides. Rebuild: ldc NavMesh::update "
      "after a WorldEditor dig of a sphere of radius 1 m at a pair's start; Detour removeTile + "
      "Recast build + addTile of the tile holding the dig (tile 32 cells = 9.6 m), from the "
      "re-contoured edited world's triangles near that tile.\n",
      args.quick ? "200" : "1,000");
  if (!scenes.empty()) return 0;  // a chosen few: no analytic terrains
  // Who is right: both against the exact walkable set of analytic terrains (issue 20 item 5).
  ldc::bench::NavTruthOptions truth;
  truth.pairs = args.quick ? 200 : 1000;
  ldc::bench::run_nav_truth(truth);
  return 0;
}
