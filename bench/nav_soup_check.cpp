// ldc::nav against Recast/Detour on the soup levels of tests/data/levels
// (issue 20), as a pass/fail check (ctest recast.soup_levels_match_detour,
// label recast): each level built with build_from_mesh(BuildConfig kAuto, y
// up) at h = 0.3 and by Recast with RecastDemo's settings; seeded start/goal
// pairs from Detour's findRandomPoint. Fails (exit 1, naming the level and
// the figure) when ldc finds a walkable floor within Detour's query box
// (2, 4, 2) m at fewer than 95% of Detour's start points, or agrees with
// Detour on which pairs are reachable for fewer than 90% of them. Also prints,
// without failing: the length ratio, how many complete paths walk through a
// wall on either side, and the first pairs where the two differ, with their
// coordinates (y up).
//
//   nav_soup_check [--pairs N] [--mode auto|solid|surface] [--show-paths] [--probe x,y,z ...]
//                  [--data DIR] [level.obj ...]
//
// Default: the three soup levels, 200 pairs each, read with kAuto (--mode:
// another BuildMode, to compare; the thresholds are the same). --show-paths adds both
// paths' corners (and ldc's grid A* length) where the lengths differ by more
// than 10% / 30%; --probe prints each side's walkable point nearest x,y,z
// (within 0.3 m across and 1 m up or down) on every level.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "detour_peer.h"
#include "ldc/build.h"
#include "meshio/meshio.h"
#include "nav/nav.h"

namespace {

constexpr double kMinFloorShare = 0.95;
constexpr double kMinAgreement = 0.90;
constexpr int kShown = 5;  // disagreeing pairs printed per kind

std::string xyz(const glm::dvec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.2f, %.2f, %.2f)", p.x, p.y, p.z);
  return buf;
}

// Where a path walks through a wall: its corner-to-corner segments, followed
// in 0.15 m steps at 0.95 m and 1.7 m over the floor under each step (over any
// step the agent may climb, under its head; the floor is ldc's walkable floor
// nearest the segment there, within 2.5 m up or down, or the segment where
// there is none), against the level's steep triangles (|normal.y| < 0.7:
// walls, railings, fences, the sides of props). through_wall gives the first
// hit point, if any.
struct WallHits {
  std::vector<std::array<glm::dvec3, 3>> walls;

  explicit WallHits(const ldc::TriangleMesh& mesh) {
    for (const glm::uvec3& t : mesh.triangles) {
      const glm::dvec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
      const glm::dvec3 n = glm::cross(b - a, c - a);
      const double len = glm::length(n);
      if (len > 0.0 && std::abs(n.y) < 0.7 * len) walls.push_back({a, b, c});
    }
  }

  // Möller-Trumbore on the segment p -> q.
  static bool hit(const glm::dvec3& p, const glm::dvec3& q, const std::array<glm::dvec3, 3>& t, glm::dvec3* at) {
    const glm::dvec3 d = q - p, e1 = t[1] - t[0], e2 = t[2] - t[0];
    const glm::dvec3 h = glm::cross(d, e2);
    const double det = glm::dot(e1, h);
    if (std::abs(det) < 1e-12) return false;
    const glm::dvec3 s = p - t[0];
    const double u = glm::dot(s, h) / det;
    if (u < 0.0 || u > 1.0) return false;
    const glm::dvec3 qv = glm::cross(s, e1);
    const double v = glm::dot(d, qv) / det;
    if (v < 0.0 || u + v > 1.0) return false;
    const double k = glm::dot(e2, qv) / det;
    if (k < 0.0 || k > 1.0) return false;
    *at = p + k * d;
    return true;
  }

  template <class Vec>
  bool through_wall(const std::vector<Vec>& corners, const ldc::NavQuery& query, glm::dvec3* at) const {
    for (size_t i = 1; i < corners.size(); ++i) {
      const glm::dvec3 a(corners[i - 1]), b(corners[i]);
      const int steps = std::max(1, int(std::ceil(glm::length(glm::dvec2(b.x - a.x, b.z - a.z)) / 0.15)));
      std::vector<glm::dvec3> floor(size_t(steps) + 1);
      for (int k = 0; k <= steps; ++k) {
        const glm::dvec3 p = a + (b - a) * (double(k) / steps);
        ldc::Result<ldc::NavPoint> f = query.nearest_walkable(p, {0.3, 2.5, 0.3});
        floor[size_t(k)] = f.ok() ? glm::dvec3(p.x, f->position.y, p.z) : p;
      }
      // The walls near this segment.
      const glm::dvec3 lo = glm::min(a, b) - 0.5, hi = glm::max(a, b) + glm::dvec3(0.5, 2.5, 0.5);
      for (const auto& t : walls) {
        const glm::dvec3 tlo = glm::min(glm::min(t[0], t[1]), t[2]), thi = glm::max(glm::max(t[0], t[1]), t[2]);
        if (glm::any(glm::lessThan(thi, lo)) || glm::any(glm::greaterThan(tlo, hi))) continue;
        for (double lift : {0.95, 1.7}) {
          const glm::dvec3 up(0.0, lift, 0.0);
          for (int k = 0; k < steps; ++k)
            if (hit(floor[size_t(k)] + up, floor[size_t(k) + 1] + up, t, at)) return true;
        }
      }
    }
    return false;
  }
};

// Returns false when a threshold is missed (or the level cannot be built).
bool check_level(const std::string& path, int pair_count, ldc::BuildMode mode, bool show_paths,
                 const std::vector<glm::dvec3>& probes) {
  const std::string name = path.substr(path.find_last_of('/') + 1);
  ldc::Result<ldc::TriangleMesh> mesh = ldc::load_mesh(path);
  if (!mesh.ok()) {
    std::printf("FAIL %s: %s\n", name.c_str(), mesh.status().to_string().c_str());
    return false;
  }
  std::vector<float> verts;
  std::vector<int> tris;
  for (const glm::dvec3& p : mesh->positions) verts.insert(verts.end(), {float(p.x), float(p.y), float(p.z)});
  for (const glm::uvec3& t : mesh->triangles) tris.insert(tris.end(), {int(t.x), int(t.y), int(t.z)});
  std::string error;
  std::unique_ptr<ldc::bench::DetourNav> detour = ldc::bench::detour_build(verts, tris, {}, nullptr, &error);
  if (!detour) {
    std::printf("FAIL %s: Detour build failed: %s\n", name.c_str(), error.c_str());
    return false;
  }

  ldc::GridConfig grid;
  grid.cell_size = 0.3;
  ldc::BuildConfig build;
  build.mode = mode;
  build.up_axis = 1;
  ldc::BuildReport report;
  ldc::Result<ldc::World> world = ldc::build_from_mesh(mesh.value(), grid, build, nullptr, &report);
  if (!world.ok()) {
    std::printf("FAIL %s: build_from_mesh: %s\n", name.c_str(), world.status().to_string().c_str());
    return false;
  }
  ldc::NavConfig config;
  config.up_axis = 1;
  ldc::Result<ldc::NavMesh> nav = ldc::NavMesh::build(world.value(), config);
  if (!nav.ok()) {
    std::printf("FAIL %s: NavMesh::build: %s\n", name.c_str(), nav.status().to_string().c_str());
    return false;
  }
  ldc::NavQuery query(nav.value());
  ldc::NavQuery grid_query(nav.value(), 1 << 20);  // --show-paths: the grid A* reference, unbounded
  ldc::PathQueryOptions options;
  options.search_half_extents = glm::dvec3(2.0, 4.0, 2.0);  // Detour's

  // --probe: what each side has under the given points (0.3 x 0.3 m across, 1 m up and down).
  for (const glm::dvec3& p : probes) {
    const glm::dvec3 box(0.3, 1.0, 0.3);
    ldc::Result<ldc::NavPoint> ours = query.nearest_walkable(p, box);
    glm::vec3 theirs;
    const bool found = ldc::bench::detour_nearest_point(*detour, glm::vec3(p), glm::vec3(box), &theirs);
    std::printf("  probe %s: ldc %s, Detour %s\n", xyz(p).c_str(),
                ours.ok() ? xyz(ours->position).c_str() : "no floor",
                found ? xyz(glm::dvec3(theirs)).c_str() : "no polygon");
  }

  const std::vector<ldc::bench::DetourPair> pairs = ldc::bench::detour_random_pairs(*detour, pair_count, 1);
  const WallHits walls(mesh.value());
  int floors = 0, agree = 0, both = 0, ours_only = 0, theirs_only = 0, ours_through = 0, theirs_through = 0;
  std::vector<double> ratios;
  std::vector<std::string> no_floor, differ, odd_length, through;  // the first few of each, printed
  for (const ldc::bench::DetourPair& pair : pairs) {
    const glm::dvec3 a(pair.start), b(pair.goal);
    const bool floor = query.nearest_walkable(a, options.search_half_extents).ok();
    floors += floor;
    if (!floor && int(no_floor.size()) < kShown) no_floor.push_back("start " + xyz(a));
    const ldc::bench::DetourPath dp = ldc::bench::detour_find_path(*detour, pair.start, pair.goal);
    ldc::Result<ldc::NavPath> lp = query.find_path(a, b, options);
    const bool ours = lp.ok() && lp->status == ldc::PathStatus::kComplete;
    agree += ours == dp.found;
    glm::dvec3 at;
    if (ours && walls.through_wall(lp->corners, query, &at)) {
      ++ours_through;
      if (int(through.size()) < kShown) {
        std::string line = "ldc " + xyz(a) + " -> " + xyz(b) + " at " + xyz(at);
        if (show_paths) {
          line += "\n    ldc corners:";
          for (const glm::dvec3& c : lp->corners) line += " " + xyz(c);
        }
        through.push_back(line);
      }
    }
    if (dp.found && walls.through_wall(dp.straight, query, &at)) {
      ++theirs_through;
      if (int(through.size()) < kShown) through.push_back("Detour " + xyz(a) + " -> " + xyz(b) + " at " + xyz(at));
    }
    if (ours && dp.found) {
      ++both;
      if (dp.length > 0.0) {
        const double r = lp->length / dp.length;
        ratios.push_back(r);
        // Much shorter than Detour: a shortcut (through a wall?); much longer: a detour.
        if ((r < 0.9 || r > 1.3) && int(odd_length.size()) < kShown) {
          char buf[96];
          std::snprintf(buf, sizeof buf, ": ldc %.2f m, Detour %.2f m", lp->length, dp.length);
          std::string line = xyz(a) + " -> " + xyz(b) + buf;
          if (show_paths) {
            ldc::Result<ldc::NavPath> gp = grid_query.find_grid_path(a, b, options);
            if (gp.ok()) {
              char grid_buf[96];
              std::snprintf(grid_buf, sizeof grid_buf, " (ldc grid A*: %s, %.2f m)", ldc::path_status_name(gp->status),
                            gp->length);
              line += grid_buf;
            }
            line += "\n    ldc corners:";
            for (const glm::dvec3& c : lp->corners) line += " " + xyz(c);
            line += "\n    Detour corners:";
            for (const glm::vec3& c : dp.straight) line += " " + xyz(glm::dvec3(c));
          }
          odd_length.push_back(line);
        }
      }
    } else if (ours != dp.found) {
      (ours ? ours_only : theirs_only) += 1;
      if (int(differ.size()) < 2 * kShown) {
        const std::string why = lp.ok() ? ldc::path_status_name(lp->status) : lp.status().to_string();
        differ.push_back(xyz(a) + " -> " + xyz(b) + (ours ? ": ldc complete, Detour not" : ": Detour complete, ldc " + why));
      }
    }
  }
  const double n = std::max<double>(1.0, double(pairs.size()));
  const double floor_share = floors / n, agreement = agree / n;
  std::sort(ratios.begin(), ratios.end());
  double mean = 0.0;
  for (double r : ratios) mean += r;
  mean /= std::max<size_t>(1, ratios.size());
  const ldc::NavStats stats = nav->stats();
  std::printf(
      "%s (%s): %zu triangles (%zu solid, %zu surface components); ldc %zu walkable floors, %zu islands; "
      "%zu pairs: ldc floor at %.1f%% of Detour's start points, reachability agreement %.1f%% "
      "(both complete %d, ldc only %d, Detour only %d), length ratio ldc/Detour mean %.3f, min %.3f, max %.3f; "
      "complete paths through a wall (0.95 or 1.7 m up): ldc %d, Detour %d\n",
      name.c_str(), ldc::build_mode_name(mode), mesh->triangles.size(), report.solid_components, report.surface_components, stats.walkable,
      stats.components, pairs.size(), 100.0 * floor_share, 100.0 * agreement, both, ours_only, theirs_only, mean,
      ratios.empty() ? 0.0 : ratios.front(), ratios.empty() ? 0.0 : ratios.back(), ours_through, theirs_through);
  for (const std::string& s : through) std::printf("  through a wall: %s\n", s.c_str());
  for (const std::string& s : no_floor) std::printf("  no ldc floor near Detour's %s\n", s.c_str());
  for (const std::string& s : differ) std::printf("  differ: %s\n", s.c_str());
  for (const std::string& s : odd_length) std::printf("  length: %s\n", s.c_str());
  bool ok = true;
  if (pairs.empty()) {
    std::printf("FAIL %s: Detour gave no start/goal pairs\n", name.c_str());
    ok = false;
  }
  if (floor_share < kMinFloorShare) {
    std::printf("FAIL %s: ldc finds a floor at %.1f%% of Detour's start points (want >= %.0f%%)\n", name.c_str(),
                100.0 * floor_share, 100.0 * kMinFloorShare);
    ok = false;
  }
  if (agreement < kMinAgreement) {
    std::printf("FAIL %s: reachability agreement %.1f%% (want >= %.0f%%)\n", name.c_str(), 100.0 * agreement,
                100.0 * kMinAgreement);
    ok = false;
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  int pairs = 200;
  bool show_paths = false;
  ldc::BuildMode mode = ldc::BuildMode::kAuto;
  std::vector<glm::dvec3> probes;
  std::string data = LDC_TEST_DATA_DIR;
  std::vector<std::string> levels;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--pairs" && i + 1 < argc) {
      pairs = std::atoi(argv[++i]);
    } else if (a == "--probe" && i + 1 < argc) {
      glm::dvec3 p;
      if (std::sscanf(argv[++i], "%lf,%lf,%lf", &p.x, &p.y, &p.z) != 3) {
        std::fprintf(stderr, "--probe %s: want x,y,z\n", argv[i]);
        return 2;
      }
      probes.push_back(p);
    } else if (a == "--mode" && i + 1 < argc) {
      const std::string m = argv[++i];
      if (m == "auto") mode = ldc::BuildMode::kAuto;
      else if (m == "solid") mode = ldc::BuildMode::kSolid;
      else if (m == "surface") mode = ldc::BuildMode::kSurface;
      else {
        std::fprintf(stderr, "--mode %s: use auto, solid or surface\n", m.c_str());
        return 2;
      }
    } else if (a == "--show-paths") {
      show_paths = true;
    } else if (a == "--data" && i + 1 < argc) {
      data = argv[++i];
    } else if (!a.empty() && a[0] != '-') {
      levels.push_back(a);
    } else {
      std::fprintf(stderr, "usage: %s [--pairs N] [--mode auto|solid|surface] [--show-paths] [--probe x,y,z ...] [--data DIR] "
                   "[level.obj ...]\n",
                   argv[0]);
      return 2;
    }
  }
  if (pairs < 1) {
    std::fprintf(stderr, "--pairs must be >= 1\n");
    return 2;
  }
  if (levels.empty()) {
    for (const char* l : {"soup_rooms", "soup_storeys", "soup_yard"}) levels.push_back(data + "/levels/" + l + ".obj");
  }
  bool ok = true;
  for (const std::string& level : levels) ok = check_level(level, pairs, mode, show_paths, probes) && ok;
  std::printf(ok ? "ok: all levels within the thresholds\n" : "FAILED\n");
  return ok ? 0 : 1;
}
