#include "bench_common.h"
#include "meshio/meshio.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

namespace ldc::bench {

Args parse_args(int argc, char** argv, std::vector<std::string> default_meshes) {
  Args a;
  a.data_dir = LDC_BENCH_DATA_DIR;
  a.meshes = std::move(default_meshes);
  for (int i = 1; i < argc; ++i) {
    std::string s = argv[i];
    if (s == "--quick") a.quick = true;
    else if (s == "--accuracy") a.accuracy_only = true;
    else if (s == "--data" && i + 1 < argc) a.data_dir = argv[++i];
    else if (s == "--meshes" && i + 1 < argc) {
      a.meshes.clear();
      std::stringstream in(argv[++i]);
      for (std::string m; std::getline(in, m, ',');) a.meshes.push_back(m);
    } else {
      std::fprintf(stderr, "usage: %s [--quick] [--accuracy] [--data DIR] [--meshes a.obj,b.obj]\n", argv[0]);
      std::exit(2);
    }
  }
  return a;
}

TriangleMesh load(const Args& args, const std::string& name) {
  Result<TriangleMesh> m = load_mesh(args.data_dir + "/" + name);
  if (!m.ok()) {
    std::fprintf(stderr, "%s\n", m.status().to_string().c_str());
    std::exit(1);
  }
  return std::move(m.value());
}

void print_machine() {
  std::string cpu = "unknown";
  std::ifstream info("/proc/cpuinfo");
  for (std::string line; std::getline(info, line);) {
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
  char date[64];
  std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::printf("- machine: %s, %u hardware threads\n- compiler: %s\n- date: %s\n", cpu.c_str(),
              std::thread::hardware_concurrency(), __VERSION__, date);
}

}  // namespace ldc::bench
