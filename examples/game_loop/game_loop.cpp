// A scripted play session on the default landscape: the "does it fit in a
// frame" proof for engine programmers.
//
// One LiveWorld (live/live.h) owns the world, its chunk meshes, nav mesh
// and query caches. Every frame, as a game would:
//   1. edit     the player digs a trench (1.2 m spheres) as it walks west
//               across the landscape (every fifth frame it builds a pillar
//               beside the trench instead): one LiveWorld::apply;
//   2. re-mesh  LiveWorld::update_meshes re-meshes what the edit dirtied and
//               names the chunk meshes that changed (an engine re-uploads those);
//   3. nav      LiveWorld::update_nav takes the same dirty chunks;
//   4. path     an agent walking north across the trench re-plans its path
//               from where it stands (the live world's NavQuery) and takes a step;
//   5. queries  ray casts find the ground under the player and the agent,
//               and a fan of 32 rays looks ahead of the player (Queries);
//               LiveWorld::update_queries then frees what edits replaced.
// It prints each frame's times as a markdown table, then the median, p95
// and max of each column. With --png DIR it renders a few frames in
// process (render/render.h, the renderer of `ldc render`) with the agent's
// path and the two characters drawn on top, and writes them as PNGs.
//
// Usage: game_loop [--frames N] [--png DIR] [--quiet]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "ldc/io.h"
#include "ldc/terrain.h"
#include "live/live.h"
#include "render/render.h"

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Options {
  int frames = 60;
  std::string png_dir;
  bool quiet = false;
};

bool parse_options(int argc, char** argv, Options* o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--frames" && has_value) {
      o->frames = std::atoi(argv[++i]);
      if (o->frames < 1 || o->frames > 100000) {
        std::fprintf(stderr, "--frames %s: must be in 1 .. 100000\n", argv[i]);
        return false;
      }
    } else if (a == "--png" && has_value) {
      o->png_dir = argv[++i];
    } else if (a == "--quiet") {
      o->quiet = true;
    } else {
      std::fprintf(stderr, "usage: game_loop [--frames N] [--png DIR] [--quiet]\n");
      return false;
    }
  }
  return true;
}

// One frame's measurements.
struct Frame {
  double edit_ms = 0, remesh_ms = 0, nav_ms = 0, path_ms = 0, query_ms = 0;
  size_t dirty = 0, remeshed = 0, changed_meshes = 0;
  ldc::PathStatus path_status = ldc::PathStatus::kComplete;
  double path_length = 0;
  bool path_found = false;
  double total_ms() const { return edit_ms + remesh_ms + nav_ms + path_ms + query_ms; }
};

// What the session keeps between frames.
struct Session {
  ldc::LiveWorld live;
  glm::dvec3 player{0.0};
  glm::dvec3 agent{0.0};
  glm::dvec3 goal{0.0};
  std::vector<glm::dvec3> agent_path;
  // Where the player stands each frame: on the landscape as it was before
  // the session (so the trench keeps its depth instead of deepening as each
  // dig starts from the bottom of the last one).
  std::vector<glm::dvec3> script;

  explicit Session(ldc::LiveWorld l) : live(std::move(l)) {}
};

// The ground under (x, y): a ray cast straight down from above the landscape.
std::optional<glm::dvec3> ground(const ldc::Queries& q, double x, double y) {
  ldc::Result<ldc::RayHit> hit = q.ray_cast({{x, y, 60.0}, {0.0, 0.0, -1.0}});
  if (!hit.ok() || !hit->hit) return std::nullopt;
  return hit->point;
}

// The player walks west along y = 24 from the east edge (x = 47.5) to x = 12
// over the session: its trench soon cuts the agent's route around the east
// side, and the agent has to re-plan (a detour, then no way across: its path
// then ends at the nearest point it can reach, status "unreachable").
glm::dvec2 player_xy(int frame, int frames) {
  const double t = frames > 1 ? double(frame) / double(frames - 1) : 0.0;
  return {47.5 - 35.5 * t, 24.0};
}

double apply_edit(Session& s, int frame) {
  const glm::dvec3 p = s.player;
  const ldc::Brush brush = frame % 5 == 4
                               ? ldc::Brush::box(p + glm::dvec3(0.0, 2.5, 0.8), {0.5, 0.5, 1.2}, ldc::kMaterialDirt)
                               : ldc::Brush::sphere(p, 1.2);
  const ldc::EditOp op = frame % 5 == 4 ? ldc::EditOp::kUnion : ldc::EditOp::kSubtract;
  const Clock::time_point start = Clock::now();
  ldc::Result<ldc::EditReceipt> r = s.live.apply(brush, op);
  const double ms = ms_since(start);
  if (!r.ok()) std::fprintf(stderr, "frame %d: edit: %s\n", frame, r.status().to_string().c_str());
  return ms;
}

// Moves the agent `step` metres along its path.
void walk(Session& s, double step) {
  for (size_t i = 1; i < s.agent_path.size() && step > 0.0; ++i) {
    const glm::dvec3 d = s.agent_path[i] - s.agent;
    const double len = glm::length(d);
    if (len <= step) {
      s.agent = s.agent_path[i];
      step -= len;
      continue;
    }
    s.agent += d * (step / len);
    return;
  }
}

Frame play_frame(Session& s, int frame) {
  Frame f;
  s.player = s.script[size_t(frame)];
  f.edit_ms = apply_edit(s, frame);

  // Every consumer up to date at once: re-mesh, nav, query caches.
  ldc::Result<ldc::LiveUpdate> u = s.live.update();
  if (u.ok()) {
    f.dirty = u->dirty_chunks;
    f.remesh_ms = 1000.0 * u->mesh_seconds;
    f.nav_ms = 1000.0 * u->nav_seconds;
    f.remeshed = u->chunks_remeshed;
    f.changed_meshes = u->meshes.size();  // what an engine re-uploads this frame
  } else {
    std::fprintf(stderr, "frame %d: update: %s\n", frame, u.status().to_string().c_str());
  }

  Clock::time_point t = Clock::now();
  ldc::Result<ldc::NavPath> path = ldc::Status(ldc::ErrorCode::kInternal, "no path query");
  if (ldc::Result<ldc::NavQuery*> query = s.live.path_query(); query.ok()) path = (*query)->find_path(s.agent, s.goal);
  f.path_ms = ms_since(t);
  if (path.ok()) {
    f.path_found = true;
    f.path_status = path->status;
    f.path_length = path->length;
    s.agent_path = path->corners;
    walk(s, 0.5);
  }

  t = Clock::now();
  const ldc::Queries& queries = s.live.queries();
  const std::optional<glm::dvec3> under_player = ground(queries, s.player.x, s.player.y);
  const std::optional<glm::dvec3> under_agent = ground(queries, s.agent.x, s.agent.y);
  std::vector<ldc::Ray> fan(32);
  for (size_t i = 0; i < fan.size(); ++i) {
    const double a = -0.8 + 1.6 * double(i) / double(fan.size() - 1);
    fan[i] = {s.player + glm::dvec3(0.0, 0.0, 1.7), {std::cos(a), std::sin(a), -0.3}, 30.0};
  }
  std::vector<ldc::RayHit> hits(fan.size());
  const ldc::Status fan_status = queries.ray_cast(fan, hits);
  f.query_ms = ms_since(t);
  if (!fan_status.ok()) std::fprintf(stderr, "frame %d: ray fan: %s\n", frame, fan_status.to_string().c_str());
  if (!under_player) std::fprintf(stderr, "frame %d: no ground under the player at (%.1f, %.1f) after digging at z = %.2f\n", frame, s.player.x, s.player.y, s.player.z);
  if (!under_agent) std::fprintf(stderr, "frame %d: no ground under the agent at (%.1f, %.1f)\n", frame, s.agent.x, s.agent.y);
  return f;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, size_t(std::ceil(p * double(v.size()))) - (p > 0 ? 1 : 0));
  return v[i];
}

void print_table(const std::vector<Frame>& frames, bool rows) {
  std::printf("| frame | dirty chunks | changed meshes | edit ms | re-mesh ms | nav update ms | path ms | path | "
              "queries ms | total ms |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|\n");
  if (rows) {
    for (size_t i = 0; i < frames.size(); ++i) {
      const Frame& f = frames[i];
      const std::string path = f.path_found ? std::string(ldc::path_status_name(f.path_status)) + " " +
                                                  std::to_string(int(std::lround(f.path_length))) + " m"
                                            : "no floor";
      std::printf("| %zu | %zu | %zu | %.2f | %.2f | %.2f | %.2f | %s | %.2f | %.2f |\n", i, f.dirty,
                  f.changed_meshes, f.edit_ms, f.remesh_ms, f.nav_ms, f.path_ms, path.c_str(), f.query_ms,
                  f.total_ms());
    }
  }
  auto column = [&](double (*get)(const Frame&)) {
    std::vector<double> v;
    for (const Frame& f : frames) v.push_back(get(f));
    return v;
  };
  const std::vector<double> cols[6] = {
      column([](const Frame& f) { return f.edit_ms; }),  column([](const Frame& f) { return f.remesh_ms; }),
      column([](const Frame& f) { return f.nav_ms; }),   column([](const Frame& f) { return f.path_ms; }),
      column([](const Frame& f) { return f.query_ms; }), column([](const Frame& f) { return f.total_ms(); })};
  const char* names[3] = {"median", "p95", "max"};
  const double ps[3] = {0.5, 0.95, 1.0};
  for (int r = 0; r < 3; ++r) {
    std::printf("| **%s** | | | %.2f | %.2f | %.2f | %.2f | | %.2f | %.2f |\n", names[r], percentile(cols[0], ps[r]),
                percentile(cols[1], ps[r]), percentile(cols[2], ps[r]), percentile(cols[3], ps[r]),
                percentile(cols[4], ps[r]), percentile(cols[5], ps[r]));
  }
}

// Renders the live world with an overlay (the agent's path; player and
// agent as points) and writes it to DIR/frame_NNN.png.
bool render_frame(const Session& s, const Options& o, int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%03d.png", frame);
  const std::string png_path = (std::filesystem::path(o.png_dir) / name).string();
  ldc::CameraConfig view;
  view.position = glm::dvec3(24, 6, 40);
  view.target = glm::dvec3(24, 26, 3);
  view.fov_degrees = 60.0;
  view.width = 640;
  view.height = 360;
  ldc::RenderOptions options;
  options.shadows = true;
  std::vector<glm::dvec3>& path = options.overlay.paths.emplace_back();
  for (const glm::dvec3& c : s.agent_path) path.push_back(c + glm::dvec3(0.0, 0.0, 0.2));
  options.overlay.points = {s.player + glm::dvec3(0.0, 0.0, 0.5), s.agent + glm::dvec3(0.0, 0.0, 0.5)};
  ldc::Result<ldc::Camera> camera = ldc::Camera::make(view);
  ldc::Result<ldc::Image> image = camera.ok() ? ldc::render(s.live.queries(), *camera, options) : camera.status();
  const ldc::Status st = image.ok() ? ldc::write_png(*image, png_path) : image.status();
  if (!st.ok()) {
    std::fprintf(stderr, "render failed: %s\n", st.to_string().c_str());
    return false;
  }
  std::printf("wrote %s\n", png_path.c_str());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse_options(argc, argv, &o)) return 2;
  if (!o.png_dir.empty()) std::filesystem::create_directories(o.png_dir);

  Clock::time_point t = Clock::now();
  ldc::Result<ldc::World> world = ldc::build_terrain({}, 0.2);
  if (!world.ok()) return std::fprintf(stderr, "%s\n", world.status().to_string().c_str()), 1;
  const double terrain_ms = ms_since(t);
  t = Clock::now();
  ldc::Result<ldc::LiveWorld> live = ldc::LiveWorld::create(std::move(world).value(), {.meshes = true, .nav = true});
  if (!live.ok()) return std::fprintf(stderr, "%s\n", live.status().to_string().c_str()), 1;
  const double live_ms = ms_since(t);
  Session s(std::move(live).value());
  const std::optional<glm::dvec3> start = ground(s.live.queries(), 24.0, 10.0);
  const std::optional<glm::dvec3> goal = ground(s.live.queries(), 40.5, 25.5);
  if (!start || !goal) return std::fprintf(stderr, "no ground under the agent's start or goal\n"), 1;
  s.agent = *start;
  s.goal = *goal;
  for (int i = 0; i < o.frames; ++i) {
    const glm::dvec2 xy = player_xy(i, o.frames);
    const std::optional<glm::dvec3> g = ground(s.live.queries(), xy.x, xy.y);
    if (!g) return std::fprintf(stderr, "no ground under the player at (%.1f, %.1f)\n", xy.x, xy.y), 1;
    s.script.push_back(*g);
  }
  std::printf("# game_loop: %d frames on the default landscape (48 x 48 m, h = 0.2 m)\n\n", o.frames);
  std::printf("setup: landscape %.0f ms, live world (chunk meshes and nav mesh) %.0f ms (%zu chunk meshes)\n\n",
              terrain_ms, live_ms, s.live.meshes()->chunks().size());

  std::vector<Frame> frames;
  const int render_every = std::max(1, o.frames / 3);
  for (int i = 0; i < o.frames; ++i) {
    frames.push_back(play_frame(s, i));
    if (!o.png_dir.empty() && (i % render_every == 0 || i == o.frames - 1)) {
      if (!render_frame(s, o, i)) return 1;
    }
  }
  print_table(frames, !o.quiet);
  const double agent_left = glm::length(glm::dvec2(s.goal - s.agent));
  std::printf("\nagent: %.1f m from its goal after %d frames; last path %s\n", agent_left, o.frames,
              frames.back().path_found ? ldc::path_status_name(frames.back().path_status) : "none");
  return 0;
}
