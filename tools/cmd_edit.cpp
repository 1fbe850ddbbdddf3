// ldc edit: a world plus a JSON script of brush edits -> the edited world.
#include <cstdio>
#include <memory>

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

void print_edit_report(const nlohmann::json& report) {
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
  if (report.contains("validation")) std::printf("%s", validation_text(report["validation"]).c_str());
  std::printf("wrote %s (version %llu)\n", report["output"].get<std::string>().c_str(),
              static_cast<unsigned long long>(report["version"].get<uint64_t>()));
  print_seconds(report["seconds"]);
}

int run_edit(const EditArgs& a, const CommonOptions& common) {
  set_thread_count(common.threads);
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
                                             "to a .ldc world");
  cmd->add_option("input", args->input, ".ldc file")->required();
  cmd->add_option("--script", args->script, "JSON edit script (format below)")->required();
  cmd->add_option("-o,--output", args->output, "Output .ldc file (written only if every edit succeeds)")->required();
  cmd->add_flag("--batch", args->batch, "Apply all edits in one apply_batch (one undo step; per-batch counts)");
  cmd->add_flag("--validate", args->validate, "Validate the result; exit 2 and write nothing if invalid");
  cmd->add_option("--mesh", args->mesh,
                  "Also contour the world before the edits, re-mesh only what each edit dirtied, and write the "
                  "mesh here (.obj .ply .stl .glb .drc) with its quality report");
  cmd->footer(kEditScriptHelp);
  cmd->callback([args, &common] {
    int code = run_edit(*args, common);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ldc::tool
