// ldc inside: which points are inside the solid (points from a file or stdin, JSON out).
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "common.h"
#include "ldc/io.h"
#include "ldc/internal/vec_text.h"

namespace ldc::tool {
namespace {

struct InsideArgs {
  std::string world;
  std::string points;  // file; empty = stdin
};

// One point per line: "x y z" or "x,y,z"; blank lines and # comments skipped.
Result<std::vector<glm::dvec3>> read_points(std::istream& in, const std::string& name) {
  std::vector<glm::dvec3> out;
  std::string line;
  for (size_t n = 1; std::getline(in, line); ++n) {
    size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    for (char& c : line) if (c == ',') c = ' ';
    std::istringstream s(line);
    glm::dvec3 p;
    std::string rest;
    if (!(s >> p.x)) {
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      return Status(ErrorCode::kParseError, name + ":" + std::to_string(n) + ": expected 'x y z'");
    }
    if (!(s >> p.y >> p.z) || (s >> rest)) {
      return Status(ErrorCode::kParseError, name + ":" + std::to_string(n) + ": expected three numbers");
    }
    if (!detail::is_finite(p)) {
      return Status(ErrorCode::kParseError, name + ":" + std::to_string(n) + ": coordinate is not finite");
    }
    out.push_back(p);
  }
  return out;
}

int run_inside(const InsideArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  Result<World> w = load_world(a.world);
  if (!w.ok()) return fail("inside", w.status());
  Result<std::vector<glm::dvec3>> pts = [&]() -> Result<std::vector<glm::dvec3>> {
    if (a.points.empty()) return read_points(std::cin, "<stdin>");
    std::ifstream f(a.points);
    if (!f) return Status(ErrorCode::kIoError, a.points + ": cannot open");
    return read_points(f, a.points);
  }();
  if (!pts.ok()) return fail("inside", pts.status());
  nlohmann::json out = nlohmann::json::array();
  size_t count = 0;
  for (const glm::dvec3& p : pts.value()) {
    bool in = w.value().inside(p);
    count += in;
    out.push_back({{"point", {p.x, p.y, p.z}}, {"inside", in}});
  }
  nlohmann::json doc = {{"points", out}, {"inside_count", count}, {"total", pts.value().size()}};
  std::printf("%s\n", json_text(doc, common.json ? 2 : -1).c_str());
  return 0;
}

}  // namespace

void add_inside_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<InsideArgs>();
  CLI::App* cmd = app.add_subcommand("inside", "Test points against the solid (JSON on stdout)");
  cmd->add_option("world", args->world, ".ldc file")->required();
  cmd->add_option("--points", args->points, "File with one 'x y z' per line (default: stdin)");
  cmd->callback([args, &common] {
    int code = run_inside(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
