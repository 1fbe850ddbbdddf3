// ldc path: a walking path between two points of a world or a mesh level (JSON out).
#include <cstdio>
#include <map>
#include <memory>
#include <optional>

#include "common.h"
#include "ldc/internal/vec_text.h"
#include "ldc/io.h"
#include "meshio/meshio.h"
#include "nav/nav.h"
#include "nav_inputs.h"

namespace ldc::tool {
namespace {

const char* const kPathHelp = R"(The input is an .ldc world, or a mesh level (OBJ, PLY, STL, OFF) that is first
built into an LDC at the navigation cell size (--cell-size). The up axis (--up) defaults to z
for .ldc worlds (the built-in landscape is z up; a world records no up axis) and to y for
meshes (the Recast convention). A mesh level is read with --mode auto: closed, outward-facing
parts (props, boxes) as solids, and everything else (one-sided floors, single-quad walls, open
rooms) as thin shells below their triangles, so an export from a game needs no preparation.
Output (stdout, or -o FILE), drawable with `ldc render --overlay FILE`:
  {"status": "complete" | "unreachable" | "out_of_nodes", "length": metres,
   "path": [[x,y,z], ...], "start": [x,y,z] (the start snapped to its floor), "end": [x,y,z]
   (the goal's floor, or where a partial path stops), "points": [start, end],
   "regions", "nodes_searched",
   "nav": {"floors", "walkable", "regions", "components", "memory_bytes", "build_seconds"},
   "query_seconds", "start_inside_solid", "goal_inside_solid",
   "links_taken": [{"id", "corner"}, ...] (off-mesh links of --links taken: see below)}
A start or goal inside solid geometry (a wall, or deeper than --max-climb in the ground) is snapped to the nearest walkable floor
like any other point, with a warning on stderr and *_inside_solid true in the JSON.
"unreachable": the goal lies on another walkable island (or has no floor near it, or --filter
leaves no way to it); the path ends at the start island's point nearest the goal.
"out_of_nodes": the search spent --max-nodes
(default 2048, the library's budget) before reaching the goal; the path ends at the explored region
nearest the goal: raise --max-nodes for long paths. The exit status is 0 for every status.
)";

struct PathArgs {
  std::string input;
  std::string from, to;
  std::string output;
  std::string up = "auto";
  double cell_size = 0.3;
  MeshReadingArgs reading;
  int max_nodes = 2048;  // NavQuery's default budget (nav/nav.h)
  NavConfig agent;
  std::string filter_file;  // --filter (nav_inputs.h)
  std::string links_file;   // --links
};

Result<World> load_input(const PathArgs& a, Context* ctx) {
  if (has_ldc_extension(a.input) || is_store_file(a.input)) return load_world_file(a.input, {}, ctx);
  if (!(a.cell_size > 0.0) || !std::isfinite(a.cell_size)) {
    return Status(ErrorCode::kInvalidArgument,
                  "--cell-size " + std::to_string(a.cell_size) + ": must be a finite number > 0");
  }
  Result<BuildConfig> config = mesh_build_config(a.reading, a.agent.up_axis);
  if (!config.ok()) return config.status();
  Result<TriangleMesh> mesh = load_mesh(a.input);
  if (!mesh.ok()) return mesh.status();
  GridConfig grid;
  grid.cell_size = a.cell_size;
  return build_from_mesh(mesh.value(), grid, config.value(), ctx);
}

// link_index: the NavMesh's link ids -> their index in the --links file.
nlohmann::json path_json(const NavPath& path, const NavMesh& nav, const std::map<uint32_t, size_t>& link_index,
                         double build_seconds, double query_seconds) {
  nlohmann::json points = nlohmann::json::array();
  for (const glm::dvec3& p : path.corners) points.push_back(vec_json(p));
  nlohmann::json links = nlohmann::json::array();
  for (const NavPathLink& l : path.links) {
    auto it = link_index.find(l.id);
    links.push_back({{"id", it != link_index.end() ? it->second : size_t(l.id)}, {"corner", l.corner}});
  }
  const NavStats s = nav.stats();
  return {{"status", path_status_name(path.status)},
          {"length", path.length},
          {"path", points},
          {"start", vec_json(path.corners.front())},
          {"end", vec_json(path.corners.back())},
          {"points", {vec_json(path.corners.front()), vec_json(path.corners.back())}},
          {"regions", path.regions},
          {"nodes_searched", path.nodes_searched},
          {"nav", {{"floors", s.floors}, {"walkable", s.walkable}, {"regions", s.regions},
                   {"components", s.components}, {"memory_bytes", s.memory_bytes},
                   {"build_seconds", build_seconds}}},
          {"query_seconds", query_seconds},
          {"links_taken", links}};
}

void print_summary(std::FILE* f, const nlohmann::json& j) {
  std::fprintf(f, "path %s: %.3f m through %zu corners (%zu regions, %zu nodes searched, %.1f us)\n",
               j["status"].get<std::string>().c_str(), j["length"].get<double>(), j["path"].size(),
               j["regions"].get<size_t>(), j["nodes_searched"].get<size_t>(),
               j["query_seconds"].get<double>() * 1e6);
  std::fprintf(f, "nav: %zu walkable floors, %zu regions, %zu islands, built in %.1f ms\n",
               j["nav"]["walkable"].get<size_t>(), j["nav"]["regions"].get<size_t>(),
               j["nav"]["components"].get<size_t>(), j["nav"]["build_seconds"].get<double>() * 1e3);
  const nlohmann::json& links = j["links_taken"];
  if (links.empty()) return;
  std::string list;
  for (const nlohmann::json& l : links) {
    const size_t k = l["corner"].get<size_t>();
    list += (list.empty() ? "" : ", ") + std::string("link ") + std::to_string(l["id"].get<size_t>()) +
            " (corners " + std::to_string(k) + " to " + std::to_string(k + 1) + ")";
  }
  std::fprintf(f, "links: %zu taken: %s\n", links.size(), list.c_str());
}

// Adds the links of a --links file; warns about those with an end on no
// walkable floor (kept, unused). Returns the NavMesh id -> file index map.
Result<std::map<uint32_t, size_t>> add_links(NavMesh& nav, const LinksFile& file) {
  std::map<uint32_t, size_t> index;
  NavQuery probe(nav);
  for (size_t i = 0; i < file.links.size(); ++i) {
    const NavLink& link = file.links[i];
    Result<uint32_t> id = nav.add_link(link);
    if (!id.ok()) return Status(id.status().code(), link_context(file, i) + ": " + id.status().message());
    index[id.value()] = i;
    if (nav.link_attached(id.value())) continue;
    for (const auto& [name, end] : {std::pair{"a", link.a}, std::pair{"b", link.b}}) {
      if (probe.nearest_walkable(end, glm::dvec3(link.radius)).ok()) continue;
      char text[160];
      std::snprintf(text, sizeof(text), ": end %s (%g, %g, %g) has no walkable floor within %g m; unused", name,
                    end.x, end.y, end.z, link.radius);
      warn("path", link_context(file, i) + text);
    }
  }
  return index;
}

// A point asked for inside a wall or deep in the ground is snapped to the
// nearest floor like any other; say so, since the caller probably meant
// something else. A point on a floor, or less than a step (max_climb) below
// its top, is not inside.
void warn_if_inside_solid(const World& world, const NavConfig& agent, const char* which,
                          const glm::dvec3& asked, const glm::dvec3& used, nlohmann::json& out,
                          bool quiet) {
  glm::dvec3 step_up = asked;
  step_up[agent.up_axis] += agent.max_climb;
  const bool inside = world.inside(asked) && world.inside(step_up);
  out[std::string(which) + "_inside_solid"] = inside;
  if (!inside || quiet) return;
  char text[256];
  std::snprintf(text, sizeof(text), "the %s (%g, %g, %g) lies inside solid geometry; the path %s at the "
                "nearest walkable floor, (%g, %g, %g), %.2f m away", which, asked.x, asked.y, asked.z,
                std::string(which) == "start" ? "starts" : "ends", used.x, used.y, used.z,
                glm::length(used - asked));
  warn("path", text);
}

int run_path(PathArgs a, const CommonOptions& common) {
  set_thread_count(common.threads);
  glm::dvec3 from, to;
  if (a.max_nodes < 16 || a.max_nodes > (1 << 20))
    return fail("path", Status(ErrorCode::kInvalidArgument,
                               "--max-nodes " + std::to_string(a.max_nodes) + ": must be 16 .. 1048576"));
  if (!parse_vec3(a.from, &from)) return fail("path", "--from " + a.from + ": expected x,y,z");
  if (!parse_vec3(a.to, &to)) return fail("path", "--to " + a.to + ": expected x,y,z");
  // A mesh level follows the Recast convention (y up); an .ldc world records none (z).
  Result<int> up = parse_up_axis(a.up, has_ldc_extension(a.input) ? kLdcUpAxis : 1);
  if (!up.ok()) return fail("path", up.status());
  a.agent.up_axis = up.value();
  // The filter and links files are checked in full before the level is built.
  std::optional<FilterFile> filter_file;
  if (!a.filter_file.empty()) {
    Result<FilterFile> f = read_filter_file(a.filter_file);
    if (!f.ok()) return fail("path", f.status());
    filter_file = std::move(f).value();
  }
  LinksFile links;
  if (!a.links_file.empty()) {
    Result<LinksFile> l = read_links_file(a.links_file);
    if (!l.ok()) return fail("path", l.status());
    links = std::move(l).value();
    for (size_t i = 0; filter_file && filter_file->excludes() && i < links.links.size(); ++i) {
      if (links.links[i].flags & kExcludedAreaFlag) {
        return fail("path", Status(ErrorCode::kInvalidArgument,
                                   link_context(links, i) + ": field 'flags' is " + std::to_string(links.links[i].flags) +
                                       ": uses flag 32768, which \"exclude\": true in " + filter_file->path +
                                       " reserves for excluded materials"));
      }
    }
  }
  ProgressBar bar(!common.quiet);
  Result<World> world = load_input(a, bar.context());
  if (!world.ok()) return fail("path", world.status());
  PathQueryOptions options;
  if (filter_file) {
    Result<ResolvedFilter> resolved = resolve_filter(*filter_file, world.value());
    if (!resolved.ok()) return fail("path", resolved.status());
    a.agent.material_areas = resolved->material_areas;
    options.filter = resolved->filter;
  }
  ScopedTimer build_timer(nullptr, "");
  Result<NavMesh> nav = NavMesh::build(world.value(), a.agent, bar.context());
  const double build_seconds = build_timer.seconds();
  bar.finish();
  if (!nav.ok()) return fail("path", nav.status());
  Result<std::map<uint32_t, size_t>> link_index = add_links(nav.value(), links);
  if (!link_index.ok()) return fail("path", link_index.status());
  NavQuery query(nav.value(), a.max_nodes);
  options.search_half_extents = glm::dvec3(2.0);
  options.search_half_extents[a.agent.up_axis] = 4.0;
  ScopedTimer query_timer(nullptr, "");
  Result<NavPath> path = query.find_path(from, to, options);
  const double query_seconds = query_timer.seconds();
  if (!path.ok()) {
    // A start on floors the filter does not pass has "no walkable floor": say that there is one.
    Result<NavPoint> unfiltered = query.nearest_walkable(from, options.search_half_extents);
    if (filter_file && unfiltered.ok() && path.status().message().find("no walkable floor") != std::string::npos) {
      return fail("path", path.status().to_string() + " that " + filter_file->path + " allows (the floor at " +
                              detail::vec_text(unfiltered->position) + " is one it excludes)");
    }
    return fail("path", path.status());
  }
  nlohmann::json out = path_json(path.value(), nav.value(), link_index.value(), build_seconds, query_seconds);
  const bool quiet = common.quiet && !common.strict;  // --strict must see the warning it acts on
  warn_if_inside_solid(world.value(), a.agent, "start", from, path.value().corners.front(), out, quiet);
  warn_if_inside_solid(world.value(), a.agent, "goal", to, path.value().corners.back(), out, quiet);
  if (a.output.empty()) {
    std::printf("%s\n", json_text(out).c_str());
    if (!common.json) print_summary(stderr, out);
    return 0;
  }
  if (Status s = write_file_atomically(a.output, json_text(out) + "\n"); !s.ok()) return fail("path", s);
  if (common.json) {
    std::printf("%s\n", json_text(nlohmann::json{{"ok", true}, {"output", a.output}, {"status", out["status"]},
                                                 {"length", out["length"]}}).c_str());
  } else {
    print_summary(stdout, out);
    std::printf("wrote %s\n", a.output.c_str());
  }
  return 0;
}

}  // namespace

void add_path_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<PathArgs>();
  CLI::App* cmd = app.add_subcommand("path", "Walking path between two points of a world or mesh level (JSON out)");
  cmd->add_option("input", args->input, ".ldc world or mesh level")->required();
  cmd->add_option("--from", args->from, "Start x,y,z (m); snapped to the nearest walkable floor")->required();
  cmd->add_option("--to", args->to, "Goal x,y,z (m)")->required();
  add_up_option(cmd, args->up, "z for an .ldc world (it records no up axis), y for a mesh");
  cmd->add_option("--cell-size", args->cell_size, "Navigation cell for mesh input (m)")->capture_default_str();
  add_mesh_reading_options(cmd, args->reading, "auto");
  cmd->add_option("--agent-height", args->agent.agent_height, "Free height the agent needs (m)")->capture_default_str();
  cmd->add_option("--agent-radius", args->agent.agent_radius, "Agent radius: erosion from walls and drops (m)")->capture_default_str();
  cmd->add_option("--max-climb", args->agent.max_climb, "Highest step between neighbouring floors (m)")->capture_default_str();
  cmd->add_option("--max-slope", args->agent.max_slope_degrees, "Steepest walkable floor (degrees)")->capture_default_str();
  cmd->add_flag("!--no-filter-low-hanging", args->agent.filter_low_hanging_obstacles,
                "Do not lift steep floors just above walkable ones (Recast's low-hanging-obstacle filter)");
  cmd->add_flag("!--no-filter-ledges", args->agent.filter_ledge_spans,
                "Keep floors beside drops deeper than --max-climb (Recast's ledge filter)");
  cmd->add_flag("!--no-filter-low-height", args->agent.filter_low_height_spans,
                "Keep floors with less than --agent-height above them (Recast's low-height filter)");
  cmd->add_option("--max-nodes", args->max_nodes, "A* node budget in chains of rectangles (nav/nav.h), 16 .. 1048576 (default: NavQuery's, as in nav/nav.h)")
      ->capture_default_str();
  cmd->add_option("--filter", args->filter_file, "Query filter (JSON): per-material costs and exclusions (below)");
  cmd->add_option("--links", args->links_file, "Off-mesh links (JSON): jumps, ladders, teleporters (below)");
  output_file(cmd->add_option("-o,--output", args->output, "Write the path JSON here instead of stdout"));
  cmd->footer(std::string(kPathHelp) + kNavFilterHelp);
  cmd->callback([args, &common] {
    int code = run_path(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
