// ldc edit: a world plus a JSON script of brush edits -> the edited world; a .ldcs store is edited in place.
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <variant>

#include "cmd_store.h"
#include "common.h"
#include "contour/contour.h"
#include "meshio/meshio.h"
#include "edit_script.h"
#include "ldc/io.h"
#include "live/live.h"
#include "mesh_output.h"

namespace ldc::tool {
namespace {

struct EditArgs {
  std::string input;
  std::string script;
  std::string output;
  bool batch = false;
  bool validate = false;
  std::string mesh;  // --mesh: contour before the edits, re-mesh after each, write here
};

// With --mesh the live world keeps chunk meshes, as a game would: built
// once, then only what each edit dirtied is re-meshed.
Status update_meshes(LiveWorld& live, nlohmann::json& entry) {
  if (!live.meshes()) return {};
  Result<LiveUpdate> u = live.update();
  if (!u.ok()) return u.status();
  entry["remesh_ms"] = 1000.0 * u->mesh_seconds;
  entry["chunk_meshes_updated"] = u->chunks_remeshed;
  entry["chunk_meshes_changed"] = u->meshes.size();
  return {};
}


nlohmann::json edit_json(size_t index, const ScriptEdit& e) {
  return {{"index", index}, {"op", edit_op_name(e.edit.op)}, {"brush", e.brush_name}};
}

// Progress of a script's edits as one stage: each apply reports its own
// "rasterize" and "edit" stages from 0 to 100%, which showed '100%' after the
// first of 1e5 edits (issue 24). Stage timers are passed on to `ctx`.
class ScriptProgress {
 public:
  ScriptProgress(Context* ctx, size_t edits) : ctx_(ctx), edits_(edits ? edits : 1) {
    each_.set_progress([this](std::string_view stage, double fraction) {
      // Rasterizing is the first half of an edit, merging the second.
      double within = stage == "rasterize" ? 0.5 * fraction : stage == "edit" ? 0.5 + 0.5 * fraction : 0.0;
      if (ctx_) ctx_->report_progress("edits", (double(index_) + within) / double(edits_));
    });
  }
  ~ScriptProgress() {
    if (!ctx_) return;
    for (const auto& [stage, seconds] : each_.timers()) ctx_->add_time(stage, seconds);
  }
  ScriptProgress(const ScriptProgress&) = delete;
  ScriptProgress& operator=(const ScriptProgress&) = delete;
  Context* at(size_t index) {
    index_ = index;
    return &each_;
  }

 private:
  Context* ctx_;
  size_t edits_;
  size_t index_ = 0;
  Context each_;
};

// One apply per edit, so that each edit's chunks and time are its own.
Status apply_each(LiveWorld& live, const std::vector<ScriptEdit>& edits, Context* ctx, nlohmann::json& report) {
  ScriptProgress progress(ctx, edits.size());
  for (size_t i = 0; i < edits.size(); ++i) {
    ScopedTimer t(nullptr, "");
    Result<EditReceipt> r = live.apply(edits[i].edit.brush, edits[i].edit.op, progress.at(i));
    if (!r.ok()) {
      return Status(r.status().code(), "edit " + std::to_string(i) + " (" + edit_op_name(edits[i].edit.op) + " " +
                                           edits[i].brush_name + ") failed: " + r.status().message());
    }
    nlohmann::json e = edit_json(i, edits[i]);
    e["chunks_changed"] = r.value().changed_chunks.size();
    e["ms"] = 1000.0 * t.seconds();
    Status s = update_meshes(live, e);
    if (!s.ok()) return s;
    report["edits"].push_back(std::move(e));
  }
  return {};
}

// One apply_batch: one undo step that visits each chunk once, so chunks and
// time are known for the batch only. The library's errors name the edit index.
Status apply_as_batch(LiveWorld& live, const std::vector<ScriptEdit>& edits, Context* ctx, nlohmann::json& report) {
  std::vector<WorldEditor::Edit> batch;
  for (const ScriptEdit& e : edits) batch.push_back(e.edit);
  ScopedTimer t(nullptr, "");
  Result<EditReceipt> r = live.apply_batch(batch, ctx);
  if (!r.ok()) return r.status();
  for (size_t i = 0; i < edits.size(); ++i) report["edits"].push_back(edit_json(i, edits[i]));
  report["batch"] = {{"chunks_changed", r.value().changed_chunks.size()}, {"ms", 1000.0 * t.seconds()}};
  return update_meshes(live, report["batch"]);
}

// --validate: an invalid result is an error, and nothing is written.
Status validate_result(const World& world, nlohmann::json& report, Context* ctx) {
  report["validation"] = validation_json(world, ctx);
  const nlohmann::json& v = report["validation"];
  if (v["ok"].get<bool>()) return {};
  std::string first = v["messages"].empty() ? "" : ": " + v["messages"][0].get<std::string>();
  return {ErrorCode::kInternal, "the edited world is not valid (" + std::to_string(v["errors"].get<size_t>()) +
                                    " errors" + first + "); nothing written"};
}

void print_edit_lines(const nlohmann::json& report) {
  for (const auto& e : report["edits"]) {
    std::printf("edit %zu: %s %s", e["index"].get<size_t>(), e["op"].get<std::string>().c_str(),
                e["brush"].get<std::string>().c_str());
    if (e.contains("chunks_changed")) {
      std::printf(": %zu chunks changed, %.2f ms", e["chunks_changed"].get<size_t>(), e["ms"].get<double>());
    }
    if (e.contains("remesh_ms")) std::printf(", re-mesh %.2f ms", e["remesh_ms"].get<double>());
    std::printf("\n");
  }
  if (report.contains("batch")) {
    const auto& b = report["batch"];
    std::printf("batch of %zu edits: %zu chunks changed, %.2f ms", report["edits"].size(),
                b["chunks_changed"].get<size_t>(), b["ms"].get<double>());
    if (b.contains("remesh_ms")) std::printf(", re-mesh %.2f ms", b["remesh_ms"].get<double>());
    std::printf("\n");
  }
}

void print_edit_report(const nlohmann::json& report) {
  print_edit_lines(report);
  if (report.contains("validation")) std::printf("%s", validation_text(report["validation"]).c_str());
  std::printf("wrote %s (version %llu)\n", report["output"].get<std::string>().c_str(),
              static_cast<unsigned long long>(report["version"].get<uint64_t>()));
  print_seconds(report["seconds"]);
}

// The box of a brush in world space (m), from its shape alone (nothing is
// rasterized, so a huge brush is bounded before it costs memory): a
// primitive's own bounds, a noise sphere's largest radius, a mesh's
// transformed vertices.
WorldBox brush_box(const Brush& brush) {
  struct Visitor {
    WorldBox operator()(const Primitive& p) const { return make_primitive_solid(p)->bounds(); }
    WorldBox operator()(const NoiseShape& n) const {
      return corners(glm::dvec3(n.noise.radius * (1.0 + n.noise.amplitude)), n.transform);
    }
    WorldBox operator()(const MeshShape& m) const {
      WorldBox b{glm::dvec3(std::numeric_limits<double>::infinity()), glm::dvec3(-std::numeric_limits<double>::infinity())};
      if (!m.mesh) return b;
      for (const glm::dvec3& p : m.mesh->positions) {
        const glm::dvec3 w = glm::dvec3(m.transform * glm::dvec4(p, 1.0));
        b.min = glm::min(b.min, w);
        b.max = glm::max(b.max, w);
      }
      return b;
    }
    // The local box [-half, half] under an affine transform.
    static WorldBox corners(const glm::dvec3& half, const glm::dmat4& transform) {
      WorldBox b{glm::dvec3(std::numeric_limits<double>::infinity()), glm::dvec3(-std::numeric_limits<double>::infinity())};
      for (int i = 0; i < 8; ++i) {
        const glm::dvec3 local((i & 1) ? half.x : -half.x, (i & 2) ? half.y : -half.y, (i & 4) ? half.z : -half.z);
        const glm::dvec3 w = glm::dvec3(transform * glm::dvec4(local, 1.0));
        b.min = glm::min(b.min, w);
        b.max = glm::max(b.max, w);
      }
      return b;
    }
  };
  return std::visit(Visitor{}, brush.shape);
}

// Options that a .ldcs store refuses: it is edited in place, in one commit,
// and neither meshed nor validated as a whole. Messages are printed as they are.
Status check_store_edit_options(const EditArgs& a) {
  if (!a.output.empty()) {
    return Status(ErrorCode::kInvalidArgument, "-o " + a.output + ": a .ldcs store (" + a.input +
                                                   ") is edited in place, in one atomic commit; copy it first to "
                                                   "keep the original");
  }
  if (!a.mesh.empty()) {
    return Status(ErrorCode::kInvalidArgument, "--mesh is for .ldc worlds; contour the edited part of the store " +
                                                   a.input + " with ldc contour --region");
  }
  if (a.validate) return Status(ErrorCode::kInvalidArgument, "--validate is for .ldc worlds, not the store " + a.input);
  return {};
}

// An intersect would page (and empty) every chunk of the store, so a script
// with one is refused before the store opens. The message is printed as it is.
Status check_store_edit_ops(const EditArgs& a, const std::vector<ScriptEdit>& list) {
  for (size_t i = 0; i < list.size(); ++i) {
    if (list[i].edit.op == EditOp::kIntersect) {
      return Status(ErrorCode::kInvalidArgument,
                    a.script + ": edit " + std::to_string(i) + " (intersect " + list[i].brush_name +
                        ") would remove everything outside its brush across the whole store " + a.input +
                        "; stores take union, subtract and paint");
    }
  }
  return {};
}

// Groups of edits that share a window: each edit alone, or all with --batch.
std::vector<std::vector<size_t>> store_edit_groups(size_t edits, bool batch) {
  std::vector<std::vector<size_t>> groups;
  for (size_t i = 0; i < edits; ++i) {
    if (!batch || groups.empty()) groups.emplace_back();
    groups.back().push_back(i);
  }
  return groups;
}

// The chunks one edit's brush meets. Returns kExitSuccess, or fail()'s code
// once the error is printed (a brush without finite bounds, a box outside the
// store's or over the limit).
int brush_chunks(const SourceLayout& layout, size_t index, const ScriptEdit& e, ChunkRange* chunks) {
  const std::string what = "edit " + std::to_string(index) + " (" + edit_op_name(e.edit.op) + " " + e.brush_name + ")";
  // The brush's box grown by two cells (its rasterization covers it plus a cell).
  const WorldBox box = brush_box(e.edit.brush);
  const glm::dvec3 grow(2.0 * layout.lattice.cell_size);
  if (!std::isfinite(box.min.x + box.min.y + box.min.z + box.max.x + box.max.y + box.max.z)) {
    return fail("edit", what + ": the brush has no finite bounds");
  }
  Result<ChunkRange> r = chunks_of_box(layout, box.min - grow, box.max + grow, 0, what);
  if (!r.ok()) return fail("edit", r.status());
  *chunks = r.value();
  return kExitSuccess;
}

// Every group's window (its brushes' chunks plus one chunk of margin), all
// bounded before anything is paged. Returns kExitSuccess, or fail()'s code
// once the error is printed.
int store_edit_windows(const EditArgs& a, const SourceLayout& layout, const std::vector<ScriptEdit>& list,
                       const std::vector<std::vector<size_t>>& groups, std::vector<ChunkRange>* windows) {
  for (const std::vector<size_t>& group : groups) {
    ChunkRange wanted;
    for (size_t k = 0; k < group.size(); ++k) {
      ChunkRange r;
      if (int code = brush_chunks(layout, group[k], list[group[k]], &r); code != kExitSuccess) return code;
      wanted = k == 0 ? r : ChunkRange{glm::min(wanted.lo, r.lo), glm::max(wanted.hi, r.hi)};
    }
    const std::string what = a.batch ? "the batch's window" : "edit " + std::to_string(group[0]) + "'s window";
    Result<ChunkRange> window = clip_chunks(layout, wanted, 1, what);
    if (!window.ok()) return fail("edit", window.status());
    windows->push_back(window.value());
  }
  return kExitSuccess;
}

// --batch: all edits in one apply_batch on the one window. The message is printed as it is.
Status apply_store_batch(WorldEditor& editor, const std::vector<ScriptEdit>& list, Context* ctx,
                         nlohmann::json& report) {
  std::vector<WorldEditor::Edit> batch;
  for (const ScriptEdit& e : list) batch.push_back(e.edit);
  ScopedTimer t(nullptr, "");
  Result<EditReceipt> r = editor.apply_batch(batch, ctx);
  if (!r.ok()) {
    return Status(r.status().code(), "the batch failed: " + r.status().message() + "; nothing committed");
  }
  for (size_t i = 0; i < list.size(); ++i) report["edits"].push_back(edit_json(i, list[i]));
  report["batch"] = {{"chunks_changed", r.value().changed_chunks.size()}, {"ms", 1000.0 * t.seconds()}};
  return {};
}

// Edit `i` alone on its window. The message is printed as it is.
Status apply_store_edit(WorldEditor& editor, const std::vector<ScriptEdit>& list, size_t i,
                        ScriptProgress& progress, nlohmann::json& report) {
  ScopedTimer t(nullptr, "");
  Result<EditReceipt> r = editor.apply(list[i].edit.brush, list[i].edit.op, progress.at(i));
  if (!r.ok()) {
    return Status(r.status().code(), "edit " + std::to_string(i) + " (" + edit_op_name(list[i].edit.op) + " " +
                                         list[i].brush_name + ") failed: " + r.status().message() +
                                         "; nothing committed");
  }
  nlohmann::json entry = edit_json(i, list[i]);
  entry["chunks_changed"] = r.value().changed_chunks.size();
  entry["ms"] = 1000.0 * t.seconds();
  report["edits"].push_back(entry);
  return {};
}

// One group: its window paged in, its edits applied, the chunks they changed
// put back to the pager (later windows see them). Page and edit times add up
// in report["seconds"]. Returns kExitSuccess, or fail()'s code once the error is printed.
int edit_store_window(const EditArgs& a, const std::vector<ScriptEdit>& list, const std::vector<size_t>& group,
                      const ChunkRange& range, PagedWorld& paged, ProgressBar& bar, ScriptProgress& progress,
                      nlohmann::json& report) {
  ScopedTimer page(nullptr, "");
  Result<World> window = paged.window(range.lo, range.hi, bar.context());
  report["seconds"]["page"] = report["seconds"]["page"].get<double>() + page.seconds();
  if (!window.ok()) return fail("edit", window.status());
  ScopedTimer apply(nullptr, "");
  WorldEditor editor(std::move(window).value());
  Status applied = a.batch ? apply_store_batch(editor, list, bar.context(), report)
                           : apply_store_edit(editor, list, group[0], progress, report);
  if (!applied.ok()) return fail("edit", applied.message());
  std::vector<glm::ivec3> changed;
  for (const DirtyChunk& d : editor.take_dirty()) changed.push_back(d.chunk);
  if (Status s = paged.put(editor.world(), changed); !s.ok()) return fail("edit", s);
  report["seconds"]["edits"] = report["seconds"]["edits"].get<double>() + apply.seconds();
  return kExitSuccess;
}

// The commit's counts and the log after it.
void add_commit_report(nlohmann::json& report, size_t dirty, const PagedWorld& paged, size_t paged_slots,
                       const ChunkLogStats& st) {
  report["chunks_committed"] = dirty;
  report["chunks_paged"] = paged.stats().page_ins;
  report["window_slots"] = paged_slots;
  report["log"] = {{"commits", st.commits}, {"sequence", st.sequence}, {"live_chunks", st.live_chunks},
                   {"file_bytes", st.file_bytes}, {"dead_fraction", st.dead_fraction()}};
  report["ok"] = true;
}

void print_store_edit_report(const nlohmann::json& report, const std::string& input, size_t dirty,
                             const ChunkLogStats& st) {
  print_edit_lines(report);
  if (dirty == 0) {
    std::printf("no chunk changed: nothing committed to %s\n", input.c_str());
  } else {
    std::printf("committed %zu chunks to %s (commit %llu; %llu live chunks, %llu bytes)\n", dirty, input.c_str(),
                static_cast<unsigned long long>(st.sequence), static_cast<unsigned long long>(st.live_chunks),
                static_cast<unsigned long long>(st.file_bytes));
  }
  print_seconds(report["seconds"]);
}

// A store is edited in place: each edit (all of them with --batch) runs on a
// window of the chunks its brush meets plus one chunk of margin, the chunks
// it changed go back to the pager (later windows see them), and the end
// commits them all to the log as one commit (atomic: all or none).
int run_store_edit(const EditArgs& a, const CommonOptions& common) {
  if (Status s = check_store_edit_options(a); !s.ok()) return fail("edit", s.message());
  Result<std::vector<ScriptEdit>> edits = read_edit_script(a.script);  // a bad script fails before the store opens
  if (!edits.ok()) return fail("edit", edits.status());
  const std::vector<ScriptEdit>& list = edits.value();
  if (Status s = check_store_edit_ops(a, list); !s.ok()) return fail("edit", s.message());
  Result<Store> store = open_store(a.input);
  if (!store.ok()) return fail("edit", store.status());
  const std::vector<std::vector<size_t>> groups = store_edit_groups(list.size(), a.batch);
  std::vector<ChunkRange> windows;
  if (int code = store_edit_windows(a, store->source->layout(), list, groups, &windows); code != kExitSuccess) {
    return code;
  }
  ProgressBar bar(!common.quiet);
  nlohmann::json report = {{"input", a.input}, {"script", a.script}, {"output", a.input},
                           {"edits", nlohmann::json::array()}, {"seconds", {{"page", 0.0}, {"edits", 0.0}}}};
  PagedWorld paged(store->source);
  ScriptProgress progress(bar.context(), list.size());
  size_t paged_slots = 0;
  for (size_t g = 0; g < groups.size(); ++g) {
    if (int code = edit_store_window(a, list, groups[g], windows[g], paged, bar, progress, report);
        code != kExitSuccess) {
      return code;
    }
    paged_slots += size_t(windows[g].slots());
  }
  const size_t dirty = paged.stats().dirty;
  ScopedTimer save(nullptr, "");
  Status s = store->save(paged);
  report["seconds"]["commit"] = save.seconds();
  bar.finish();
  if (!s.ok()) return fail("edit", s);  // the log keeps its previous commit
  const ChunkLogStats st = store->log->stats();
  add_commit_report(report, dirty, paged, paged_slots, st);
  if (common.json) {
    std::printf("%s\n", json_text(report).c_str());
  } else {
    print_store_edit_report(report, a.input, dirty, st);
  }
  return kExitSuccess;
}

int run_edit(const EditArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
  if (is_store_file(a.input)) return run_store_edit(a, common);
  if (a.output.empty()) return fail("edit", "-o is required for a .ldc world (" + a.input + ")");
  if (!has_ldc_extension(a.output)) return fail("edit", "-o " + a.output + ": the output must be a .ldc file");
  if (!a.mesh.empty()) {
    Result<MeshFormat> format = mesh_format_from_path(a.mesh);
    if (!format.ok()) return fail("edit", "--mesh: " + format.status().message());
  }
  Result<std::vector<ScriptEdit>> edits = read_edit_script(a.script);  // a bad script fails before the world loads
  if (!edits.ok()) return fail("edit", edits.status());
  ProgressBar bar(!common.quiet);
  ScopedTimer load(nullptr, "");
  Result<World> w = load_world(a.input, {}, bar.context());
  if (!w.ok()) return fail("edit", w.status());
  nlohmann::json report = {{"input", a.input}, {"script", a.script}, {"output", a.output},
                           {"edits", nlohmann::json::array()}, {"seconds", {{"load", load.seconds()}}}};
  ScopedTimer contour(nullptr, "");
  // The chunk meshes as a game keeps them (LiveConfig's default: no local
  // untangling); the assembled mesh goes through untangle_mesh before it is written.
  Result<LiveWorld> created =
      LiveWorld::create(std::move(w).value(), {.meshes = !a.mesh.empty()}, bar.context());
  if (!created.ok()) return fail("edit", created.status());
  LiveWorld& live = created.value();
  if (live.meshes()) report["seconds"]["contour_before_edits"] = contour.seconds();
  ScopedTimer apply(nullptr, "");
  Status s = a.batch ? apply_as_batch(live, edits.value(), bar.context(), report)
                     : apply_each(live, edits.value(), bar.context(), report);
  report["seconds"]["edits"] = apply.seconds();
  if (!s.ok()) return fail("edit", s);
  if (a.validate && !(s = validate_result(live.world(), report, bar.context())).ok()) {
    fail("edit", s);
    return kExitInvalid;  // as `ldc build --validate`
  }
  ScopedTimer save(nullptr, "");
  s = save_world(live.world(), a.output, {}, bar.context());
  report["seconds"]["save"] = save.seconds();
  report["seconds"]["stages"] = stage_seconds(*bar.context());
  bar.finish();
  if (!s.ok()) return fail("edit", s);
  report["version"] = live.version();
  if (live.meshes()) {
    report["world_output"] = a.output;
    ContourMesh mesh = live.meshes()->assemble();
    if (Status u = untangle_output(bar.context(), mesh, report); !u.ok()) return fail("edit", u);
    return write_and_report("edit", live.world(), mesh, live.meshes()->stats(), a.mesh, bar,
                            std::move(report), common, [](const nlohmann::json& r) {
                              nlohmann::json edits_only = r;
                              edits_only["output"] = r["world_output"];
                              edits_only["seconds"] = nlohmann::json::object();
                              print_edit_report(edits_only);
                            });
  }
  report["ok"] = true;
  if (common.json) std::printf("%s\n", json_text(report).c_str());
  else print_edit_report(report);
  return 0;
}

}  // namespace

void add_edit_command(CLI::App& app, CommonOptions& common) {
  auto args = std::make_shared<EditArgs>();
  CLI::App* cmd = app.add_subcommand("edit", "Apply a JSON script of brush edits (add, subtract, intersect, paint) "
                                             "to a .ldc world or a .ldcs store");
  cmd->add_option("input", args->input, ".ldc file, or a .ldcs store (edited in place, one atomic commit)")->required();
  cmd->add_option("--script", args->script, "JSON edit script (format below)")->required();
  output_file(cmd->add_option("-o,--output", args->output,
                              "Output .ldc file (written only if every edit succeeds); required for a .ldc input, "
                              "refused for a store"));
  cmd->add_flag("--batch", args->batch, "Apply all edits in one apply_batch (one undo step; per-batch counts)");
  cmd->add_flag("--validate", args->validate, "Validate the result; exit 2 and write nothing if invalid");
  output_file(cmd->add_option("--mesh", args->mesh,
                              "Also contour the world before the edits, re-mesh only what each edit dirtied, and "
                              "write the mesh here (.obj .ply .stl .glb .drc) with its quality report"));
  cmd->footer(kEditScriptHelp);
  cmd->callback([args, &common] {
    int code = run_edit(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
