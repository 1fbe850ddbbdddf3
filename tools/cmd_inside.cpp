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

// {"inside_count", "points": [{"inside", "point"}...], "total"} as
// json_text(doc, indent) prints it (keys sorted), streamed a point at a time:
// the whole document for 5 M points took 4.3 GB (issue 24). Returns whether
// every write succeeded.
bool write_inside_report(std::FILE* f, const std::vector<glm::dvec3>& points, const std::vector<uint8_t>& inside,
                         size_t count, int indent) {
  const bool pretty = indent >= 0;
  const char* nl = pretty ? "\n" : "";
  const char* colon = pretty ? ": " : ":";
  std::fprintf(f, "{%s%s\"inside_count\"%s%zu,%s%s\"points\"%s[", nl, pretty ? "  " : "", colon, count, nl,
               pretty ? "  " : "", colon);
  for (size_t i = 0; i < points.size(); ++i) {
    const glm::dvec3& p = points[i];
    std::string item = json_text({{"inside", inside[i] != 0}, {"point", {p.x, p.y, p.z}}}, indent);
    if (pretty) {  // nested two levels deep: every line of the item indented by 4 more
      std::string shifted = "\n    ";
      for (char c : item) shifted += c == '\n' ? std::string("\n    ") : std::string(1, c);
      item = std::move(shifted);
    }
    std::fprintf(f, "%s%s", i ? "," : "", item.c_str());
  }
  std::fprintf(f, "%s%s],%s%s\"total\"%s%zu%s}\n", points.empty() || !pretty ? "" : "\n",
               points.empty() || !pretty ? "" : "  ", nl, pretty ? "  " : "", colon, points.size(), nl);
  return std::fflush(f) == 0 && !std::ferror(f);
}

int run_inside(const InsideArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  Result<World> w = load_world_file(a.world);
  if (!w.ok()) return fail("inside", w.status());
  Result<std::vector<glm::dvec3>> pts = [&]() -> Result<std::vector<glm::dvec3>> {
    if (a.points.empty()) return read_points(std::cin, "<stdin>");
    Result<std::string> text = read_file(a.points);  // refuses FIFOs and devices, which would block or never end
    if (!text.ok()) return text.status();
    std::istringstream f(std::move(text.value()));  // C++20: moved in, not copied
    return read_points(f, a.points);
  }();
  if (!pts.ok()) return fail("inside", pts.status());
  const std::vector<glm::dvec3>& points = pts.value();
  std::vector<uint8_t> inside(points.size());
  size_t count = 0;
  for (size_t i = 0; i < points.size(); ++i) count += inside[i] = w.value().inside(points[i]) ? 1 : 0;
  if (!write_inside_report(stdout, points, inside, count, common.json ? 2 : -1)) {
    return fail("inside", "cannot write to stdout");
  }
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
