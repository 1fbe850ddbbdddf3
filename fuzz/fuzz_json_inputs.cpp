// libFuzzer target for the tool's small input files (tools/json_inputs.h,
// tools/edit_script.h, tools/nav_inputs.h).
//
// The first byte picks the reader (edit script, render overlay, raycast rays,
// inside points, path filter, path links), the rest is the file's text. A
// reader must refuse the text with a message or return values the tool can
// use as they are: finite numbers, counts within the readers' limits, brushes
// that check_brush accepts, a filter that resolves or is refused with a
// message. An exception escaping a reader aborts the run (a crash).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

#include "edit_script.h"
#include "json_inputs.h"
#include "ldc/internal/vec_text.h"
#include "nav_inputs.h"

namespace {

using ldc::detail::is_finite;

[[noreturn]] void fail(const char* what, const std::string& detail = "") {
  std::fprintf(stderr, "fuzz_json_inputs: %s%s%s\n", what, detail.empty() ? "" : ": ", detail.c_str());
  std::abort();
}

void expect(bool ok, const char* what) {
  if (!ok) fail(what);
}

// A refusal must say why.
template <class T>
bool accepted(const ldc::Result<T>& r) {
  if (!r.ok() && r.status().message().empty()) fail("error without a message", r.status().to_string());
  return r.ok();
}

// Mesh brushes get a tetrahedron for a .obj name and a refusal otherwise: no
// file is touched, and both the load and its failure are reached.
ldc::Result<ldc::TriangleMesh> fake_mesh(const std::string& path) {
  if (!path.ends_with(".obj")) return ldc::Status(ldc::ErrorCode::kIoError, path + ": cannot open");
  ldc::TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

bool finite_matrix(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(m[c][r])) return false;
    }
  }
  return true;
}

void edit_script(std::string_view text) {
  auto r = ldc::tool::read_edit_script_text(text, "fuzz/script.json", fake_mesh);
  if (!accepted(r)) return;
  expect(r.value().size() <= text.size(), "more edits than bytes");
  for (const ldc::tool::ScriptEdit& e : r.value()) {
    expect(!e.brush_name.empty(), "an edit without a brush name");
    expect(finite_matrix(e.edit.brush.transform()), "a brush with a non-finite transform");
    const ldc::Status s = ldc::check_brush(e.edit.brush);
    if (!s.ok()) fail("check_brush refuses an accepted brush", s.message());
  }
}

void overlay(std::string_view text) {
  auto r = ldc::tool::read_overlay_text(text, "fuzz/overlay.json");
  if (!accepted(r)) return;
  const ldc::Overlay& o = r.value();
  expect(o.paths.size() <= 2, "more than two paths (\"path\" and \"polyline\")");
  expect(o.points.size() <= ldc::kMaxOverlayVertices, "too many overlay points");
  for (const glm::dvec3& p : o.points) expect(is_finite(p), "a non-finite overlay point");
  for (const auto& path : o.paths) {
    expect(path.size() <= ldc::kMaxOverlayVertices, "too many path vertices");
    for (const glm::dvec3& p : path) expect(is_finite(p), "a non-finite path vertex");
  }
}

void rays(std::string_view text) {
  auto r = ldc::tool::read_rays_text(text, "fuzz/rays.json");
  if (!accepted(r)) return;
  expect(r.value().size() <= text.size(), "more rays than bytes");
  for (const ldc::Ray& ray : r.value()) {
    expect(is_finite(ray.origin) && is_finite(ray.direction), "a ray with a non-finite origin or direction");
    const double len = glm::length(ray.direction);
    expect(len > 0.0 && std::isfinite(len), "a ray direction without a usable length");
    expect(ray.max_distance >= 0.0, "a negative or NaN max_distance");
  }
}

void points(std::string_view text) {
  std::istringstream in{std::string(text)};
  auto r = ldc::tool::read_points(in, "fuzz/points.txt");
  if (!accepted(r)) return;
  expect(r.value().size() <= text.size(), "more points than bytes");
  for (const glm::dvec3& p : r.value()) expect(is_finite(p), "a non-finite point");
}

void filter(std::string_view text) {
  auto r = ldc::tool::read_filter_text(text, "fuzz/filter.json");
  if (!accepted(r)) return;
  expect(r.value().materials.size() <= 63, "more than 63 materials");
  for (const ldc::tool::MaterialRule& m : r.value().materials) {
    expect(std::isfinite(m.cost) && m.cost >= 0.01, "a material cost that is not finite and >= 0.01");
  }
  // Names are refused against a world without material names; ids resolve.
  static const ldc::World world;
  auto resolved = ldc::tool::resolve_filter(r.value(), world);
  if (!accepted(resolved)) return;
  const ldc::Status s = ldc::check_nav_filter(resolved.value().filter);
  if (!s.ok()) fail("check_nav_filter refuses a resolved filter", s.message());
}

void links(std::string_view text) {
  auto r = ldc::tool::read_links_text(text, "fuzz/links.json");
  if (!accepted(r)) return;
  expect(r.value().links.size() <= ldc::tool::kMaxLinks, "more links than kMaxLinks");
  for (const ldc::NavLink& l : r.value().links) {
    expect(is_finite(l.a) && is_finite(l.b), "a link with a non-finite end");
    expect(std::isfinite(l.cost) && std::isfinite(l.radius), "a link with a non-finite cost or radius");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  switch (data[0] % 6) {
    case 0: edit_script(text); break;
    case 1: overlay(text); break;
    case 2: rays(text); break;
    case 3: points(text); break;
    case 4: filter(text); break;
    default: links(text); break;
  }
  return 0;
}
