// ldc inside: which points are inside the solid (points from a file or stdin, JSON out).
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

#include "common.h"
#include "json_inputs.h"
#include "ldc/io.h"
#include "ldc/internal/vec_text.h"

namespace ldc::tool {
namespace {

struct InsideArgs {
  std::string world;
  std::string points;  // file; empty = stdin
};

int run_inside(const InsideArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  Result<World> w = load_world_file(a.world);
  if (!w.ok()) return fail("inside", w.status());
  Result<std::vector<glm::dvec3>> pts = [&]() -> Result<std::vector<glm::dvec3>> {
    if (a.points.empty()) return read_points(std::cin, "<stdin>");
    Result<std::string> text = read_file(a.points);  // refuses FIFOs and devices, which would block or never end
    if (!text.ok()) return text.status();
    std::istringstream f(text.value());
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
