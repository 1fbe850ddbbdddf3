// Ground truth for walkable floors (issue 20 item 5): analytic terrains whose
// walkable set follows exactly from the agent rules of nav/nav.h, and ldc::nav
// and Recast/Detour measured against it (walkable-area IoU, false and missed
// walkable area, reachability agreement on seeded pairs). Used by bench_nav
// (section "Ground truth on analytic terrains") and the standalone nav_truth.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace ldc::bench {

struct NavTruthOptions {
  int pairs = 1000;          // seeded start/goal pairs per terrain, drawn on the truth's walkable set
  uint32_t seed = 1;
  double grid = 0.05;        // truth and rasterization grid spacing [m]
  std::vector<std::string> only;  // terrain names (prefix match); empty: all
  std::string ppm_dir;       // when set: one top-down disagreement image per terrain and peer
  bool detail = false;       // print the largest disagreement clusters per terrain and peer
  // Also the default landscape (bench_nav's scene), its truth sampled from
  // the exact solid on a grid of max(grid, 0.1) m (several seconds).
  bool landscape = true;
};

struct NavTruthRow {
  std::string terrain, peer;
  double truth_m2 = 0;       // the truth's walkable area
  double peer_m2 = 0;        // the peer's walkable area on the truth's floors
  double iou = 0;            // |peer ∩ truth| / |peer ∪ truth| by area
  double false_m2 = 0;       // walkable for the peer, not in truth
  double missed_m2 = 0;      // walkable in truth, not for the peer
  double agreement = 0;      // fraction of pairs whose reachability (complete path) matches the truth's
  int pairs = 0;
  int truth_reachable = 0;   // pairs the truth connects
};

// Builds every terrain, its truth and both peers; prints the section (a
// markdown heading, the table and notes) to stdout and returns the rows.
std::vector<NavTruthRow> run_nav_truth(const NavTruthOptions& options);

}  // namespace ldc::bench
