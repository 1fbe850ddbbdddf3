// ldc contour (world or a region of a .ldcs store -> mesh) and ldc remesh (mesh -> LDC -> mesh).
#include <memory>
#include <string>
#include <vector>

#include "cmd_store.h"
#include "common.h"
#include "csg/csg.h"
#include "ldc/io.h"
#include "ldc/lod.h"
#include "mesh_output.h"
#include "meshio/meshio.h"

namespace ldc::tool {
namespace {

struct ContourArgs {
  std::string input;
  MeshOutputArgs mesh;
  GridConfig grid;  // remesh only
  std::string region;  // contour of a .ldcs store only: X0,Y0,Z0,X1,Y1,Z1 (m)
  int lod = 0;         // contour only: every 2^lod-th ray (ldc/lod.h)
  std::string lod_from;                 // contour only: X,Y,Z (m), with lod_bands
  std::vector<double> lod_bands;        // contour only: level k from lod_bands[k - 1] m on
};

// --lod-from and --lod-bands: each chunk's level by its distance from a
// point (lod_level, no hysteresis), set into args.level_of_chunk; the
// chunks per level go to report["lod"].
Status set_levels_by_distance(const ContourArgs& a, const World& w, MeshOutputArgs& mesh, nlohmann::json& report) {
  if (a.lod_bands.empty() != a.lod_from.empty())
    return Status(ErrorCode::kInvalidArgument, "--lod-from and --lod-bands go together: give both or neither");
  if (a.lod_bands.empty()) return {};
  if (a.lod > 0) return Status(ErrorCode::kInvalidArgument, "--lod and --lod-bands: give one or the other");
  glm::dvec3 from;
  if (!parse_vec3(a.lod_from, &from))
    return Status(ErrorCode::kInvalidArgument, "--lod-from '" + a.lod_from + "': expected X,Y,Z (m), finite");
  const LodBands bands{.start = a.lod_bands, .hysteresis = 0.0};
  if (Status s = check_lod_bands(bands); !s.ok()) return Status(s.code(), "--lod-bands: " + s.message());
  const int max_level = max_lod_level(w.chunk_size());
  if (int(a.lod_bands.size()) > max_level) {
    return Status(ErrorCode::kInvalidArgument, "--lod-bands: " + std::to_string(a.lod_bands.size()) +
                                                   " bands ask for levels up to " + std::to_string(a.lod_bands.size()) +
                                                   "; chunks of " + std::to_string(w.chunk_size()) +
                                                   " cells allow up to " + std::to_string(max_level));
  }
  const Lattice lattice = w.lattice();
  const int c = w.chunk_size();
  mesh.level_of_chunk = [bands, lattice, c, from](const glm::ivec3& chunk) {
    return lod_level(bands, chunk_distance(lattice, c, chunk, from), 0);
  };
  std::vector<size_t> per_level(a.lod_bands.size() + 1, 0);
  w.for_each_chunk([&](const glm::ivec3& chunk, ChunkKind, const Chunk*) { ++per_level[size_t(mesh.level_of_chunk(chunk))]; });
  report["lod"] = {{"from", {from.x, from.y, from.z}}, {"bands", a.lod_bands}, {"chunks_per_level", per_level}};
  return {};
}

// The world at level `lod` (itself at 0); the seconds coarsening took go to
// report["seconds"]["coarsen"].
Result<World> at_level(World world, int lod, nlohmann::json& report) {
  if (lod == 0) return world;
  ScopedTimer t(nullptr, "");
  Result<World> coarse = coarsen(world, lod);
  report["seconds"]["coarsen"] = t.seconds();
  report["lod"] = lod;
  return coarse;
}

// Cuts the window's solid down to the region's box (an intersect edit), so
// that it no longer reaches the window's faces, where contouring needs
// nothing solid (a window cut through the ground has rays inside at its
// sides): the mesh is then closed by caps on the region's faces. The cap
// sits half a cell inside the region's chunks (off the lattice's nodes); a
// face of the region on the store's own face needs no cap.
Result<World> cut_to_region(World window, const SourceLayout& layout, const ChunkRange& region, Context* ctx) {
  const double cs = layout.lattice.cell_size * layout.chunk_size, h = layout.lattice.cell_size;
  const glm::ivec3 box_lo = layout.box.chunk_origin, box_hi = layout.box.chunk_origin + layout.box.chunk_dims;
  glm::dvec3 min, max;
  bool cut = false;
  for (int a = 0; a < 3; ++a) {
    const double lo = layout.lattice.origin[a] + region.lo[a] * cs, hi = layout.lattice.origin[a] + region.hi[a] * cs;
    const bool cut_lo = region.lo[a] > box_lo[a], cut_hi = region.hi[a] < box_hi[a];
    min[a] = cut_lo ? lo + 0.5 * h : lo - cs;  // no cap: beyond the store's face
    max[a] = cut_hi ? hi - 0.5 * h : hi + cs;
    cut = cut || cut_lo || cut_hi;
  }
  if (!cut) return window;  // the whole store: its faces hold no solid
  WorldEditor editor(std::move(window));
  Result<EditReceipt> r = editor.apply(Brush::box(0.5 * (min + max), 0.5 * (max - min)), EditOp::kIntersect, ctx);
  if (!r.ok()) return Status(r.status().code(), "cutting the window to the region: " + r.status().message());
  return editor.world();
}

// A region of a store: the chunks it meets and one chunk of margin are
// paged in (the base generates those no commit holds), the solid is cut to
// the region's chunks (cut_to_region) and contoured.
int run_store_contour(const ContourArgs& a, const CommonOptions& common) {
  if (a.region.empty()) {
    return fail("contour", a.input + " is a .ldcs store: give --region X0,Y0,Z0,X1,Y1,Z1 (m), the part to contour");
  }
  Result<Store> store = open_store(a.input);
  if (!store.ok()) return fail("contour", store.status());
  const SourceLayout& layout = store->source->layout();
  Result<ChunkRange> range = parse_region(layout, a.region);
  if (!range.ok()) return fail("contour", range.status());
  // Bounded, margin included, before anything is paged.
  Result<ChunkRange> window = clip_chunks(layout, range.value(), 1, "--region '" + a.region + "' with its margin");
  if (!window.ok()) return fail("contour", window.status());
  ProgressBar bar(!common.quiet);
  ScopedTimer t(nullptr, "");
  PagedWorld paged(store->source);
  Result<World> w = paged.window(window->lo, window->hi, bar.context());
  if (!w.ok()) return fail("contour", w.status());
  const double page = t.seconds();
  ScopedTimer c(nullptr, "");
  w = cut_to_region(std::move(w).value(), layout, range.value(), bar.context());
  if (!w.ok()) return fail("contour", w.status());
  bar.finish();
  nlohmann::json report = {{"seconds", {{"page", page}, {"cut", c.seconds()}}},
                           {"region", range_json(layout, range.value())},
                           {"chunks_paged", paged.stats().page_ins}};
  MeshOutputArgs mesh = a.mesh;
  if (Status s = set_levels_by_distance(a, w.value(), mesh, report); !s.ok()) return fail("contour", s);
  w = at_level(std::move(w).value(), a.lod, report);
  if (!w.ok()) return fail("contour", w.status());
  return contour_and_report("contour", w.value(), mesh, bar, std::move(report), common,
                            [](const nlohmann::json& r) {
                              std::printf("  region %s, %zu chunks paged\n", range_text(r["region"]).c_str(),
                                          r["chunks_paged"].get<size_t>());
                            });
}

int run_contour(const ContourArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  Status out = check_mesh_output(a.mesh);
  if (!out.ok()) return fail("contour", out);
  if (is_store_file(a.input)) return run_store_contour(a, common);
  if (!a.region.empty()) return fail("contour", "--region is for .ldcs stores; " + a.input + " is not one");
  ProgressBar bar(!common.quiet);
  ScopedTimer t(nullptr, "");
  Result<World> w = load_world(a.input, {}, bar.context());
  if (!w.ok()) return fail("contour", w.status());
  nlohmann::json report = {{"seconds", {{"load", t.seconds()}}}};
  MeshOutputArgs mesh = a.mesh;
  if (Status s = set_levels_by_distance(a, w.value(), mesh, report); !s.ok()) return fail("contour", s);
  w = at_level(std::move(w).value(), a.lod, report);
  if (!w.ok()) return fail("contour", w.status());
  return contour_and_report("contour", w.value(), mesh, bar, std::move(report), common,
                            [](const nlohmann::json& r) {
                              if (!r.contains("lod") || !r["lod"].contains("chunks_per_level")) return;
                              std::string per;
                              for (const auto& n : r["lod"]["chunks_per_level"]) per += (per.empty() ? "" : " / ") + n.dump();
                              std::printf("  levels of detail by distance: chunks at level 0 / 1 / ... = %s\n", per.c_str());
                            });
}

int run_remesh(const ContourArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  Status out = check_mesh_output(a.mesh);
  if (!out.ok()) return fail("remesh", out);
  ProgressBar bar(!common.quiet);
  ScopedTimer t(nullptr, "");
  Result<TriangleMesh> m = load_mesh(a.input);
  if (!m.ok()) return fail("remesh", m.status());
  double load = t.seconds();
  ScopedTimer b(nullptr, "");
  Result<World> w = build_from_mesh(m.value(), a.grid, bar.context());
  if (!w.ok()) return fail("remesh", w.status());
  bar.finish();
  nlohmann::json report = {{"seconds", {{"load", load}, {"build", b.seconds()}}}};
  if (warn_if_rasterized_empty("remesh", w.value(), a.input, BuildMode::kSolid)) report["empty"] = true;
  return contour_and_report("remesh", w.value(), a.mesh, bar, std::move(report), common);
}

}  // namespace

void add_contour_commands(CLI::App& app, CommonOptions& common) {
  auto c = std::make_shared<ContourArgs>();
  CLI::App* contour = app.add_subcommand("contour", "Dual-contour a .ldc world into a mesh, with the quality report");
  contour->add_option("input", c->input, ".ldc file or .ldcs store (with --region)")->required();
  add_mesh_output_options(contour, c->mesh);
  contour->add_option("--region", c->region,
                      "A .ldcs store's box X0,Y0,Z0,X1,Y1,Z1 (m): the chunks it meets are paged in and contoured "
                      "as a world of their own (closed at the box's faces)");
  contour->add_option("--lod", c->lod,
                      "Level of detail K: contour every 2^K-th ray (cells 2^K h; 0 = full detail, at most 1, 2, 3 "
                      "for chunks of 16, 32, 64 cells)")
      ->check(CLI::Range(0, 3))
      ->capture_default_str();
  contour->add_option("--lod-from", c->lod_from,
                      "X,Y,Z (m): mesh each chunk at a level by its distance from this point (with --lod-bands); "
                      "the seams between levels are closed");
  contour->add_option("--lod-bands", c->lod_bands,
                      "D1[,D2[,D3]] (m, increasing): chunks from D1 on at level 1, from D2 on at level 2, ... "
                      "(with --lod-from)")
      ->delimiter(',');
  contour->callback([c, &common] {
    int code = run_contour(*c, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
  auto r = std::make_shared<ContourArgs>();
  r->mesh.max_error_cells = kAdaptiveMaxErrorCells;  // adaptive by default; contour stays uniform (engine-like)
  CLI::App* remesh = app.add_subcommand("remesh", "Mesh -> LDC -> mesh: a watertight remesh, with the quality report");
  remesh->add_option("input", r->input, "Mesh file (.obj .ply .stl .off)")->required();
  add_mesh_output_options(remesh, r->mesh);
  add_grid_options(remesh, r->grid, "the input");
  remesh->callback([r, &common] {
    int code = run_remesh(*r, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
