// Ground truth for walkable floors on analytic terrains (issue 20 item 5):
// ldc::nav and Recast/Detour against the exact walkable set of the agent rules
// (bench/nav_truth.h). bench_nav prints the same section.
//
//   nav_truth [--quick] [--pairs N] [--grid M] [--seed S] [--only NAME ...] [--ppm DIR] [--detail]
//             [--no-landscape]
//
// --quick: 200 pairs. --only: terrains whose name starts with NAME (the
// landscape is "landscape"). --ppm: top-down disagreement images per terrain
// and peer. --detail: the largest disagreement clusters (coordinates, exact
// slopes). --no-landscape: the analytic terrains only.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "nav_truth.h"

int main(int argc, char** argv) {
  ldc::bench::NavTruthOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--quick") {
      options.pairs = 200;
    } else if (a == "--pairs" && has_value) {
      options.pairs = std::atoi(argv[++i]);
    } else if (a == "--grid" && has_value) {
      options.grid = std::atof(argv[++i]);
    } else if (a == "--seed" && has_value) {
      options.seed = uint32_t(std::strtoul(argv[++i], nullptr, 10));
    } else if (a == "--only" && has_value) {
      options.only.push_back(argv[++i]);
    } else if (a == "--ppm" && has_value) {
      options.ppm_dir = argv[++i];
    } else if (a == "--no-landscape") {
      options.landscape = false;
    } else if (a == "--detail") {
      options.detail = true;
    } else {
      std::fprintf(stderr,
                   "usage: %s [--quick] [--pairs N] [--grid M] [--seed S] [--only NAME ...] [--ppm DIR] [--detail] "
                   "[--no-landscape]\n",
                   argv[0]);
      return 2;
    }
  }
  if (options.pairs < 0 || !(options.grid > 0.0)) {
    std::fprintf(stderr, "--pairs must be >= 0 and --grid > 0\n");
    return 2;
  }
  ldc::bench::run_nav_truth(options);
  return 0;
}
