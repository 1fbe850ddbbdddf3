// The tool's input readers from text (tools/json_inputs.h, edit_script.h,
// nav_inputs.h): what each accepts, and that each refusal names the file and
// the field. The fuzzer fuzz/fuzz_json_inputs.cpp runs the same readers; its
// findings are pinned here by name, their inputs in fuzz/corpus/json_inputs/.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "edit_script.h"
#include "json_inputs.h"
#include "nav_inputs.h"

namespace ldc::tool {
namespace {

// The refusal's message, or a failure when the reader accepted.
template <class T>
std::string refusal(const Result<T>& r) {
  EXPECT_FALSE(r.ok());
  return r.ok() ? std::string() : r.status().message();
}

Result<TriangleMesh> no_mesh(const std::string& path) { return Status(ErrorCode::kIoError, path + ": cannot open"); }

Result<std::vector<ScriptEdit>> script(const std::string& text) {
  return read_edit_script_text(text, "dir/script.json", no_mesh);
}

Result<std::vector<glm::dvec3>> points(const std::string& text) {
  std::istringstream in(text);
  return read_points(in, "points.txt");
}

// `depth` arrays inside each other around `inner`.
std::string nested(int depth, const std::string& inner = "") {
  return std::string(size_t(depth), '[') + inner + std::string(size_t(depth), ']');
}

// ---- edit scripts ------------------------------------------------------------

TEST(JsonInputs, EditScriptSphereIsReadInOrder) {
  auto r = script(R"({"edits": [{"op": "subtract", "brush": "sphere", "centre": [1, 2, 3], "radius": 1.5},
                               {"op": "add", "brush": "box", "centre": [0, 0, 0], "half_extents": [1, 1, 1],
                                "material": 7}]})");
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r.value().size(), 2u);
  EXPECT_EQ(r.value()[0].brush_name, "sphere");
  EXPECT_EQ(r.value()[0].edit.op, EditOp::kSubtract);
  EXPECT_EQ(r.value()[1].edit.op, EditOp::kUnion);
  EXPECT_EQ(r.value()[1].edit.brush.material, 7);
}

TEST(JsonInputs, EditScriptMeshIsLoadedFromTheScriptsFolder) {
  std::string asked;
  auto load = [&](const std::string& path) { asked = path; return no_mesh(path); };
  auto r = read_edit_script_text(R"({"edits": [{"op": "union", "brush": "mesh", "mesh": "rock.obj"}]})",
                                 "dir/script.json", load);
  EXPECT_EQ(asked, "dir/rock.obj");
  EXPECT_NE(refusal(r).find("dir/script.json: edit 0: field 'mesh'"), std::string::npos) << refusal(r);
}

TEST(JsonInputs, EditScriptRadiusOfTheWrongTypeIsRefusedByName) {
  auto r = script(R"({"edits": [{"op": "union", "brush": "sphere", "centre": [0, 0, 0], "radius": "big"}]})");
  EXPECT_NE(refusal(r).find("dir/script.json: edit 0: field 'radius' must be a number, not string"), std::string::npos);
}

TEST(JsonInputs, EditScriptHugeMaterialIsRefusedByName) {
  auto r = script(R"({"edits": [{"op": "union", "brush": "sphere", "centre": [0, 0, 0], "radius": 1,
                                 "material": 1e300}]})");
  EXPECT_NE(refusal(r).find("edit 0: field 'material' is 1e+300: must be a whole number in 0 .. 65535"),
            std::string::npos) << refusal(r);
}

TEST(JsonInputs, EditScriptTruncatedIsRefusedAsMalformed) {
  auto r = script(R"({"edits": [{"op": "union", "brush": "sph)");
  EXPECT_NE(refusal(r).find("dir/script.json: malformed JSON"), std::string::npos) << refusal(r);
}

TEST(JsonInputs, EditScriptNaNIsRefusedAsNotJson) {
  auto r = script(R"({"edits": [{"op": "union", "brush": "sphere", "centre": [0, 0, 0], "radius": NaN}]})");
  EXPECT_NE(refusal(r).find("JSON has no NaN or Infinity"), std::string::npos) << refusal(r);
}

// ---- render overlays ---------------------------------------------------------

TEST(JsonInputs, OverlayPathAndPointsAreRead) {
  auto r = read_overlay_text(R"({"polyline": [[0, 0, 0], [1, 2, 3]], "points": [[4, 5, 6]]})", "o.json");
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r.value().paths.size(), 1u);
  EXPECT_EQ(r.value().paths[0][1], glm::dvec3(1, 2, 3));
  ASSERT_EQ(r.value().points.size(), 1u);
  EXPECT_EQ(r.value().points[0], glm::dvec3(4, 5, 6));
}

TEST(JsonInputs, OverlayPointOfTheWrongTypeIsRefusedByIndex) {
  auto r = read_overlay_text(R"({"points": [[1, 2, 3], [1, "x", 3]]})", "o.json");
  EXPECT_NE(refusal(r).find("--overlay o.json: points[1] must be [x, y, z]"), std::string::npos) << refusal(r);
}

TEST(JsonInputs, OverlayOverflowingNumberIsRefusedAsNotFinite) {
  auto r = read_overlay_text(R"({"path": [[1, 1e400, 3]]})", "o.json");
  EXPECT_NE(refusal(r).find("--overlay o.json: malformed JSON"), std::string::npos) << refusal(r);
}

TEST(JsonInputs, OverlayTruncatedIsRefusedAsMalformed) {
  EXPECT_NE(refusal(read_overlay_text(R"({"path": [[1, 1, )", "o.json")).find("o.json: malformed JSON"),
            std::string::npos);
}

// Found while writing the fuzzer: the message for a bad entry dump()ed it, recursing once per
// level. 10,000 nested brackets (fuzz/corpus/json_inputs/overlay_deep_nesting_stack_overflow)
// overflowed the fuzzer's stack; 300,000 (600 KB) made `ldc render --overlay` die of SIGSEGV.
// Issue 24 sweep: nlohmann's parser stopped at a zero byte, so a document
// followed by "\0" and anything was read as the document.
TEST(JsonInputs, ZeroByteAfterTheDocumentIsRefused) {
  const std::string overlay = std::string(R"({"path": [[0, 0, 0]]})") + std::string(2, '\0') + "garbage";
  EXPECT_NE(refusal(read_overlay_text(overlay, "o.json")).find("o.json: not a JSON text file (a zero byte at offset 21)"),
            std::string::npos);
  const std::string rays = std::string(R"([{"origin": [0, 0, 0], "direction": [0, 0, 1]}])") + '\0';
  EXPECT_NE(refusal(read_rays_text(rays, "r.json")).find("r.json: not a JSON text file (a zero byte at offset"),
            std::string::npos);
}

// Other fields are allowed: the overlay is often `ldc path`'s whole report.
TEST(JsonInputs, OverlayTakesAPathReportWithItsOtherFields) {
  auto r = read_overlay_text(R"({"status": "complete", "path": [[0, 0, 0], [1, 0, 0]], "length": 1.0})", "o.json");
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_EQ(r.value().paths.size(), 1u);
  EXPECT_EQ(r.value().paths[0].size(), 2u);
}

TEST(JsonInputs, OverlayDeeplyNestedEntryIsRefusedWithoutOverflowingTheStack) {
  auto r = read_overlay_text("{\"points\": [" + nested(300000) + "]}", "o.json");
  EXPECT_NE(refusal(r).find("o.json: arrays and objects nested deeper than 64 levels"), std::string::npos);
}

TEST(JsonInputs, NestingUpToTheLimitIsParsed) {
  EXPECT_TRUE(parse_json_text(nested(kMaxJsonDepth), "n.json").ok());
  EXPECT_FALSE(parse_json_text(nested(kMaxJsonDepth + 1), "n.json").ok());
  // Brackets inside strings, escaped quotes included, are not nesting.
  EXPECT_TRUE(parse_json_text("[\"\\\"" + nested(100) + "\"]", "n.json").ok());
}

// ---- raycast rays ------------------------------------------------------------

TEST(JsonInputs, RaysAreReadFromAListOrAnObject) {
  auto r = read_rays_text(R"({"rays": [{"origin": [0, 0, 5], "direction": [0, 0, -2], "max_distance": 3},
                                       {"origin": [1, 1, 1], "direction": [1, 0, 0]}]})", "rays.json");
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r.value().size(), 2u);
  EXPECT_EQ(r.value()[0].direction, glm::dvec3(0, 0, -2));
  EXPECT_EQ(r.value()[0].max_distance, 3.0);
  EXPECT_TRUE(std::isinf(r.value()[1].max_distance));
}

TEST(JsonInputs, RayDirectionOfTheWrongTypeIsRefusedByName) {
  auto r = read_rays_text(R"([{"origin": [0, 0, 0], "direction": [1, "x", 0]}])", "rays.json");
  EXPECT_NE(refusal(r).find("rays.json: ray 0: field 'direction' must be an array of three numbers"),
            std::string::npos) << refusal(r);
}

TEST(JsonInputs, RayDirectionThatOverflowsIsRefusedByName) {
  auto r = read_rays_text(R"([{"origin": [0, 0, 0], "direction": [1e308, 1e308, 0]}])", "rays.json");
  EXPECT_NE(refusal(r).find("ray 0: field 'direction'"), std::string::npos) << refusal(r);
  EXPECT_NE(refusal(r).find("no usable length"), std::string::npos) << refusal(r);
}

TEST(JsonInputs, RayNegativeMaxDistanceIsRefusedByName) {
  auto r = read_rays_text(R"([{"origin": [0, 0, 0], "direction": [1, 0, 0], "max_distance": -1}])", "rays.json");
  EXPECT_NE(refusal(r).find("ray 0: field 'max_distance' -1 must be a number >= 0"), std::string::npos) << refusal(r);
}

TEST(JsonInputs, RaysTruncatedAreRefusedAsMalformed) {
  EXPECT_NE(refusal(read_rays_text(R"([{"origin": [0, )", "rays.json")).find("rays.json: malformed JSON"),
            std::string::npos);
}

// ---- inside points -----------------------------------------------------------

TEST(JsonInputs, PointsAreReadSkippingCommentsAndBlankLines) {
  auto r = points("# header\n0 0 0\n\n100, 100, 100 # far\n");
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r.value().size(), 2u);
  EXPECT_EQ(r.value()[1], glm::dvec3(100, 100, 100));
}

// The stream reads neither "nan" nor an overflowing 1e400 as a number.
TEST(JsonInputs, PointWithNaNOrOverflowIsRefusedByLine) {
  EXPECT_EQ(refusal(points("0 0 0\n1 2 nan\n")), "points.txt:2: expected three numbers");
  EXPECT_EQ(refusal(points("1e400 2 3\n")), "points.txt:1: expected 'x y z'");
}

TEST(JsonInputs, PointWithTwoNumbersIsRefusedByLine) {
  EXPECT_EQ(refusal(points("1 2\n")), "points.txt:1: expected three numbers");
}

// ---- path filters ------------------------------------------------------------

TEST(JsonInputs, FilterMaterialsAreReadInTheFilesOrder) {
  auto r = read_filter_text(R"({"materials": {"mud": {"cost": 5}, "3": {"flags": 4, "exclude": true}},
                                 "include_flags": 7})", "filter.json");
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r.value().materials.size(), 2u);
  EXPECT_EQ(r.value().materials[0].key, "mud");
  EXPECT_EQ(r.value().materials[0].cost, 5.0);
  EXPECT_TRUE(r.value().materials[1].exclude);
  EXPECT_EQ(r.value().include_flags, 7);
}

TEST(JsonInputs, FilterCostOfTheWrongTypeIsRefusedByName) {
  auto r = read_filter_text(R"({"materials": {"mud": {"cost": "high"}}})", "filter.json");
  EXPECT_NE(refusal(r).find("filter.json: material 'mud': field 'cost' must be a number, not string"),
            std::string::npos) << refusal(r);
}

TEST(JsonInputs, FilterHugeFlagsAreRefusedByName) {
  auto r = read_filter_text(R"({"include_flags": 1e300})", "filter.json");
  EXPECT_NE(refusal(r).find("filter.json: field 'include_flags' is 1e+300"), std::string::npos) << refusal(r);
}

TEST(JsonInputs, FilterOverOneMebibyteIsRefusedBeforeParsing) {
  auto r = read_filter_text(std::string(kNavInputMaxBytes + 1, ' '), "filter.json");
  EXPECT_EQ(r.status().code(), ErrorCode::kTooLarge);
  EXPECT_NE(refusal(r).find("filter.json: over the limit"), std::string::npos);
}

TEST(JsonInputs, FilterTruncatedIsRefusedAsMalformed) {
  EXPECT_NE(refusal(read_filter_text(R"({"materials": {"mud": )", "filter.json")).find("filter.json: malformed JSON"),
            std::string::npos);
}

// ---- path links --------------------------------------------------------------

TEST(JsonInputs, LinksAreReadWithTheirDefaults) {
  auto r = read_links_text(R"({"links": [{"a": [0, 0, 0], "b": [1, 2, 3], "cost": 4}]})", "links.json");
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r.value().links.size(), 1u);
  EXPECT_EQ(r.value().links[0].b, glm::dvec3(1, 2, 3));
  EXPECT_EQ(r.value().links[0].cost, 4.0);
  EXPECT_TRUE(r.value().links[0].bidirectional);
  EXPECT_EQ(r.value().links[0].radius, 1.0);
}

TEST(JsonInputs, LinkRadiusOfTheWrongTypeIsRefusedByName) {
  auto r = read_links_text(R"({"links": [{"a": [0, 0, 0], "b": [1, 1, 1], "radius": [1]}]})", "links.json");
  EXPECT_NE(refusal(r).find("links.json: link 0: field 'radius' must be a number, not array"), std::string::npos)
      << refusal(r);
}

TEST(JsonInputs, LinksOverTheCountLimitAreRefused) {
  std::string list;
  for (size_t i = 0; i <= kMaxLinks; ++i) list += std::string(i ? "," : "") + "{}";
  auto r = read_links_text("{\"links\": [" + list + "]}", "links.json");
  EXPECT_NE(refusal(r).find("links.json: 10001 links: at most 10000"), std::string::npos) << refusal(r);
}

TEST(JsonInputs, LinksTruncatedAreRefusedAsMalformed) {
  EXPECT_NE(refusal(read_links_text(R"({"links": [{"a": )", "links.json")).find("links.json: malformed JSON"),
            std::string::npos);
}

}  // namespace
}  // namespace ldc::tool
