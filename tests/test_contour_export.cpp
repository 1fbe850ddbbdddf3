// Tests of contour/export.h (every format written and read back, errors,
// atomic writes), mesh_quality and to_openmesh, on small meshes built here.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "meshio/detail/tiny_gltf.h"  // ldc's private copy (libdraco exports another)
#include "meshio/meshio.h"
#include "contour/openmesh.h"

namespace ldc {
namespace {

namespace fs = std::filesystem;

// ------------------------------------------------------------------ fixtures

// Unit cube [0,1]^3, 12 outward triangles; the two top (z = 1) triangles
// have material 3, the others material 1; unit normals from the centre.
ContourMesh unit_cube(const glm::dvec3& lo = glm::dvec3(0.0)) {
  ContourMesh m;
  for (unsigned i = 0; i < 8; ++i) {
    const glm::dvec3 corner((i & 1) ? 1.0 : 0.0, (i & 2) ? 1.0 : 0.0, (i & 4) ? 1.0 : 0.0);
    m.positions.push_back(lo + corner);
    m.normals.push_back(glm::normalize(glm::vec3(corner) - glm::vec3(0.5f)));
  }
  const unsigned faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (int f = 0; f < 6; ++f) {
    const uint16_t material = f == 5 ? 3 : 1;  // face 5 is z = 1
    m.triangles.push_back({faces[f][0], faces[f][1], faces[f][2]});
    m.triangles.push_back({faces[f][0], faces[f][2], faces[f][3]});
    m.triangle_material.insert(m.triangle_material.end(), 2, material);
  }
  for (unsigned v = 0; v < 8; ++v) m.vertex_material.push_back((v & 4) ? 3 : 1);
  return m;
}

// A tetrahedron with coordinates that only a shortest round-trip format keeps.
ContourMesh tetrahedron() {
  ContourMesh m;
  m.positions = {{1.0 / 3.0, -0.0, 1e-17},
                 {12345.678901234567, 0.1, 0.2},
                 {0.3, 98765.4321, -7.000000000000001},
                 {0.5, 0.6, 4321.0000001}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  m.triangle_material = {0, 7, 7, 65535};
  return m;
}

// Two unit cubes sharing the edge x = y = 1 (vertices welded): 14 vertices.
ContourMesh cubes_sharing_an_edge() {
  ContourMesh a = unit_cube();
  const ContourMesh b = unit_cube(glm::dvec3(1.0, 1.0, 0.0));
  std::vector<uint32_t> remap(8);
  for (uint32_t v = 0; v < 8; ++v) {
    auto same = std::find(a.positions.begin(), a.positions.begin() + 8, b.positions[v]);
    remap[v] = same != a.positions.begin() + 8 ? static_cast<uint32_t>(same - a.positions.begin())
                                               : static_cast<uint32_t>(a.positions.size());
    if (remap[v] == a.positions.size()) {
      a.positions.push_back(b.positions[v]);
      a.normals.push_back(b.normals[v]);
      a.vertex_material.push_back(b.vertex_material[v]);
    }
  }
  for (size_t t = 0; t < b.triangles.size(); ++t) {
    const glm::uvec3& tri = b.triangles[t];
    a.triangles.push_back({remap[tri.x], remap[tri.y], remap[tri.z]});
    a.triangle_material.push_back(9);
  }
  return a;
}

// A directory of the running test's own (so that tests may run in
// parallel), removed by the ContourExport fixture after the test.
fs::path test_dir() {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return fs::path(::testing::TempDir()) /
         ("ldc_contour_export_" + std::to_string(::getpid()) + "_" + info->name());
}

std::string temp_path(const std::string& name) {
  fs::create_directories(test_dir());
  return (test_dir() / name).string();
}

class ContourExport : public ::testing::Test {
 protected:
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(test_dir(), ignored);
  }
};

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

using Corner = std::tuple<uint32_t, uint32_t, uint32_t, uint16_t>;

// Triangles with materials, each rotated to start at its smallest index
// (keeping its orientation), sorted: equal for the same faces in any order.
std::vector<Corner> canonical(const ContourMesh& m, const std::vector<uint32_t>* remap = nullptr) {
  std::vector<Corner> out;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    glm::uvec3 tri = m.triangles[t];
    if (remap) tri = {(*remap)[tri.x], (*remap)[tri.y], (*remap)[tri.z]};
    while (tri.x > tri.y || tri.x > tri.z) tri = {tri.y, tri.z, tri.x};
    out.emplace_back(tri.x, tri.y, tri.z, m.triangle_material.empty() ? 0 : m.triangle_material[t]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// For formats that renumber vertices: each loaded vertex's original index
// (the nearest original position, which must lie within `tolerance`).
std::vector<uint32_t> match_vertices(const ContourMesh& original, const ContourMesh& loaded,
                                     double tolerance) {
  std::vector<uint32_t> remap;
  for (const glm::dvec3& p : loaded.positions) {
    uint32_t best = 0;
    for (uint32_t v = 1; v < original.vertex_count(); ++v) {
      if (glm::length(original.positions[v] - p) < glm::length(original.positions[best] - p))
        best = v;
    }
    EXPECT_LE(glm::length(original.positions[best] - p), tolerance)
        << "no original vertex near a loaded one";
    remap.push_back(best);
  }
  return remap;
}

// The position as a float file stores it. Through a volatile: GCC 12.2 at
// -O2/-O3 folds a vectorised double -> float -> double pair (as in
// glm::dvec3(glm::vec3(p))) into a plain copy of x and y.
glm::dvec3 as_float(const glm::dvec3& p) {
  glm::dvec3 out;
  for (int axis = 0; axis < 3; ++axis) {
    const volatile float rounded = static_cast<float>(p[axis]);
    out[axis] = rounded;
  }
  return out;
}

Result<ContourMesh> save_and_load(const ContourMesh& mesh, const std::string& name,
                                  const ExportOptions& options = {}) {
  const std::string path = temp_path(name);
  Status saved = save_mesh(mesh, path, options);
  if (!saved.ok()) return saved;
  return load_contour_mesh(path);
}

// ------------------------------------------------------------------- formats

TEST_F(ContourExport, FormatComesFromTheExtensionInAnyCase) {
  EXPECT_EQ(mesh_format_from_path("a/b.OBJ").value(), MeshFormat::kObj);
  EXPECT_EQ(mesh_format_from_path("x.Ply").value(), MeshFormat::kPly);
  EXPECT_EQ(mesh_format_from_path("x.stl").value(), MeshFormat::kStl);
  EXPECT_EQ(mesh_format_from_path("x.GLB").value(), MeshFormat::kGlb);
  EXPECT_EQ(mesh_format_from_path("x.drc").value(), MeshFormat::kDraco);
}

TEST_F(ContourExport, UnknownExtensionIsRefusedByName) {
  const Result<MeshFormat> format = mesh_format_from_path("out/mesh.fbx");
  ASSERT_FALSE(format.ok());
  EXPECT_NE(format.status().message().find(".fbx"), std::string::npos) << format.status().message();
  const Status saved = save_mesh(unit_cube(), temp_path("mesh.fbx"));
  EXPECT_FALSE(saved.ok());
  EXPECT_NE(saved.message().find(".fbx"), std::string::npos);
  EXPECT_FALSE(mesh_format_from_path("dir.obj/noextension").ok());
}

TEST_F(ContourExport, ObjRoundTripsPositionsAndMaterialsExactly) {
  for (const ContourMesh& mesh : {unit_cube(), tetrahedron()}) {
    Result<ContourMesh> loaded = save_and_load(mesh, "round.obj");
    ASSERT_TRUE(loaded.ok()) << loaded.status().to_string();
    EXPECT_EQ(loaded->positions, mesh.positions);
    EXPECT_EQ(canonical(loaded.value()), canonical(mesh));
    EXPECT_EQ(loaded->normals.size(), mesh.vertex_count());
  }
  Result<ContourMesh> cube = save_and_load(unit_cube(), "cube.obj");
  EXPECT_EQ(cube->normals, unit_cube().normals);
  // Derived: the most common material around each vertex. Every top corner
  // has at least as many side triangles (1) as top ones (3); vertex 4 ties
  // 2 to 2 and takes the smaller id.
  EXPECT_EQ(cube->vertex_material, std::vector<uint16_t>(8, 1));
}

TEST_F(ContourExport, ObjIsReadByParseObjWithOneUsemtlPerMaterial) {
  const ContourMesh mesh = tetrahedron();
  ExportOptions options;
  options.material_names = {"grass", "", "", "", "", "", "", "stone wall"};
  const std::string path = temp_path("parse.obj");
  ASSERT_TRUE(save_mesh(mesh, path, options).ok());
  const std::string text = read_bytes(path);
  Result<TriangleMesh> parsed = parse_obj(text, path);
  ASSERT_TRUE(parsed.ok()) << parsed.status().to_string();
  EXPECT_EQ(parsed->positions, mesh.positions);
  EXPECT_EQ(parsed->material_names,
            (std::vector<std::string>{"grass", "stone wall", "material_65535"}));
  size_t usemtl = 0;
  for (size_t at = text.find("usemtl"); at != std::string::npos; at = text.find("usemtl", at + 1))
    ++usemtl;
  EXPECT_EQ(usemtl, 3u);
  Result<ContourMesh> loaded = load_contour_mesh(path);  // custom names map back to their ids
  ASSERT_TRUE(loaded.ok());
  EXPECT_EQ(canonical(loaded.value()), canonical(mesh));
}

TEST_F(ContourExport, ObjRefusesMaterialNamesItCannotKeep) {
  ExportOptions options;
  options.material_names = {"a#b"};
  const Status hash = save_mesh(tetrahedron(), temp_path("names.obj"), options);
  EXPECT_EQ(hash.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(hash.message().find("a#b"), std::string::npos);
  options.material_names = {"same", "", "", "", "", "", "", "same"};
  EXPECT_EQ(save_mesh(tetrahedron(), temp_path("names.obj"), options).code(),
            ErrorCode::kInvalidArgument);
}

TEST_F(ContourExport, PlyRoundTripsEverythingExactlyAndInOrder) {
  for (const ContourMesh& mesh : {unit_cube(), tetrahedron()}) {
    Result<ContourMesh> loaded = save_and_load(mesh, "round.ply");
    ASSERT_TRUE(loaded.ok()) << loaded.status().to_string();
    EXPECT_EQ(loaded->positions, mesh.positions);
    EXPECT_EQ(loaded->triangles, mesh.triangles);
    EXPECT_EQ(loaded->triangle_material, mesh.triangle_material);
    if (!mesh.normals.empty()) {
      EXPECT_EQ(loaded->normals, mesh.normals);
    }
  }
}

TEST_F(ContourExport, PlyIsReadByParsePlyDespiteTheMaterialProperty) {
  const ContourMesh mesh = tetrahedron();
  const std::string path = temp_path("parse.ply");
  ASSERT_TRUE(save_mesh(mesh, path).ok());
  Result<TriangleMesh> parsed = parse_ply(read_bytes(path), path);
  ASSERT_TRUE(parsed.ok()) << parsed.status().to_string();
  EXPECT_EQ(parsed->positions, mesh.positions);
  EXPECT_EQ(parsed->triangles, mesh.triangles);
}

TEST_F(ContourExport, StlLosesMaterialsButKeepsTriangles) {
  const ContourMesh mesh = unit_cube(glm::dvec3(0.1, 0.2, 0.3));
  const std::string path = temp_path("cube.stl");
  ASSERT_TRUE(save_mesh(mesh, path).ok());
  EXPECT_EQ(read_bytes(path).size(), 84u + 50u * 12u);
  Result<ContourMesh> loaded = load_contour_mesh(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().to_string();
  ASSERT_EQ(loaded->vertex_count(), 8u);  // corners welded back
  const std::vector<uint32_t> remap = match_vertices(mesh, loaded.value(), 1e-6);
  for (size_t v = 0; v < 8; ++v) {
    EXPECT_EQ(loaded->positions[v], as_float(mesh.positions[remap[v]]));
  }
  ContourMesh no_materials = mesh;
  no_materials.triangle_material.assign(12, 0);
  EXPECT_EQ(canonical(loaded.value(), &remap), canonical(no_materials));
  EXPECT_EQ(loaded->triangle_material, std::vector<uint16_t>(12, 0));
}

TEST_F(ContourExport, GlbRoundTripsWithinFloatPrecision) {
  for (const ContourMesh& mesh : {unit_cube(glm::dvec3(0.1, 0.2, 0.3)), tetrahedron()}) {
    Result<ContourMesh> loaded = save_and_load(mesh, "round.glb");
    ASSERT_TRUE(loaded.ok()) << loaded.status().to_string();
    ASSERT_EQ(loaded->vertex_count(), mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
      EXPECT_EQ(loaded->positions[v], as_float(mesh.positions[v]));
    }
    EXPECT_EQ(canonical(loaded.value()), canonical(mesh));
  }
  Result<ContourMesh> cube = save_and_load(unit_cube(), "cube.glb");
  EXPECT_EQ(cube->normals, unit_cube().normals);
  EXPECT_EQ(cube->vertex_material, unit_cube().vertex_material);  // the _MATERIAL attribute
}

TEST_F(ContourExport, GlbPassesTinygltfStructuralCheck) {
  const std::string path = temp_path("check.glb");
  ExportOptions options;
  options.material_names = {"", "dirt"};
  ASSERT_TRUE(save_mesh(unit_cube(), path, options).ok());
  ldc_tinygltf::Model model;
  ldc_tinygltf::TinyGLTF loader;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, path)) << err;
  EXPECT_EQ(err, "");
  EXPECT_EQ(warn, "");
  ASSERT_EQ(model.meshes.size(), 1u);
  ASSERT_EQ(model.meshes[0].primitives.size(), 2u);  // materials 1 and 3
  ASSERT_EQ(model.materials.size(), 2u);
  EXPECT_EQ(model.materials[0].name, "dirt");
  EXPECT_EQ(model.materials[1].name, "material_3");
  EXPECT_NE(model.materials[0].pbrMetallicRoughness.baseColorFactor,
            model.materials[1].pbrMetallicRoughness.baseColorFactor);
  for (const ldc_tinygltf::Primitive& primitive : model.meshes[0].primitives) {
    const ldc_tinygltf::Accessor& position = model.accessors[primitive.attributes.at("POSITION")];
    EXPECT_EQ(position.minValues, (std::vector<double>{0, 0, 0}));
    EXPECT_EQ(position.maxValues, (std::vector<double>{1, 1, 1}));
    const ldc_tinygltf::Accessor& material = model.accessors[primitive.attributes.at("_MATERIAL")];
    EXPECT_EQ(material.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    EXPECT_EQ(model.bufferViews[material.bufferView].byteStride % 4, 0u);  // 4-byte aligned
    EXPECT_EQ(model.accessors[primitive.attributes.at("NORMAL")].componentType,
              TINYGLTF_COMPONENT_TYPE_FLOAT);
    EXPECT_EQ(model.accessors[primitive.indices].componentType,
              TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  }
}

TEST_F(ContourExport, DracoRoundTripsWithinQuantizationAndKeepsMaterials) {
  for (int speed : {0, 5, 10}) {
    for (const ContourMesh& mesh : {unit_cube(glm::dvec3(0.1, 0.2, 0.3)), tetrahedron()}) {
      ExportOptions options;
      options.draco_speed = speed;
      Result<ContourMesh> loaded = save_and_load(mesh, "round.drc", options);
      ASSERT_TRUE(loaded.ok()) << loaded.status().to_string();
      ASSERT_EQ(loaded->vertex_count(), mesh.vertex_count());  // border points welded back
      double extent = 0.0;
      for (const glm::dvec3& p : mesh.positions)
        extent = std::max(extent, glm::length(p - mesh.positions[0]));
      const double step = 2.0 * extent / ((1 << options.draco_position_bits) - 1);
      const std::vector<uint32_t> remap = match_vertices(mesh, loaded.value(), 2.0 * step);
      EXPECT_EQ(canonical(loaded.value(), &remap), canonical(mesh)) << "speed " << speed;
    }
  }
}

TEST_F(ContourExport, EmptyMeshWritesAValidFileForEveryFormat) {
  const ContourMesh empty;
  for (const char* name : {"empty.obj", "empty.ply", "empty.stl", "empty.glb"}) {
    Result<ContourMesh> loaded = save_and_load(empty, name);
    ASSERT_TRUE(loaded.ok()) << name << ": " << loaded.status().to_string();
    EXPECT_EQ(loaded->triangle_count(), 0u) << name;
  }
  ldc_tinygltf::Model model;
  ldc_tinygltf::TinyGLTF loader;
  std::string err, warn;
  EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, temp_path("empty.glb"))) << err;
  EXPECT_EQ(err + warn, "");
  EXPECT_TRUE(model.meshes.empty());
  // Draco's encoders refuse (or crash on) a mesh without faces.
  const Status draco = save_mesh(empty, temp_path("empty.drc"));
  EXPECT_EQ(draco.code(), ErrorCode::kUnsupported);
  EXPECT_NE(draco.message().find("draco: cannot encode an empty mesh"), std::string::npos)
      << draco.message();
  EXPECT_FALSE(fs::exists(temp_path("empty.drc")));
  EXPECT_FALSE(fs::exists(temp_path("empty.drc.tmp")));
}

TEST_F(ContourExport, DracoKeepsTrianglesWithARepeatedIndex) {
  ContourMesh mesh = tetrahedron();
  mesh.triangles.push_back({0, 0, 1});  // edgebreaker alone would drop it
  mesh.triangle_material.push_back(5);
  Result<ContourMesh> loaded = save_and_load(mesh, "repeated.drc");
  ASSERT_TRUE(loaded.ok()) << loaded.status().to_string();
  ASSERT_EQ(loaded->triangle_count(), 5u);
  EXPECT_EQ(loaded->triangles.back().x, loaded->triangles.back().y);  // sequential: order kept
  EXPECT_EQ(loaded->triangle_material.back(), 5);
}

TEST_F(ContourExport, SameMeshGivesTheSameBytes) {
  for (const char* name : {"same.obj", "same.ply", "same.stl", "same.glb", "same.drc"}) {
    ASSERT_TRUE(save_mesh(unit_cube(), temp_path(std::string("a_") + name)).ok());
    ASSERT_TRUE(save_mesh(unit_cube(), temp_path(std::string("b_") + name)).ok());
    EXPECT_EQ(read_bytes(temp_path(std::string("a_") + name)),
              read_bytes(temp_path(std::string("b_") + name)))
        << name;
  }
}

// -------------------------------------------------------------------- errors

TEST_F(ContourExport, UnwritablePathGivesIoErrorAndLeavesNoFile) {
  const std::string missing_dir = temp_path("no-such-dir/mesh.obj");
  const Status status = save_mesh(unit_cube(), missing_dir);
  EXPECT_EQ(status.code(), ErrorCode::kIoError);
  EXPECT_NE(status.message().find(missing_dir), std::string::npos) << status.message();
  // The rename fails when the target is a directory: the tmp file must go.
  const std::string directory = temp_path("is-a-directory.ply");
  fs::create_directories(directory);
  const Status rename = save_mesh(unit_cube(), directory);
  EXPECT_EQ(rename.code(), ErrorCode::kIoError);
  EXPECT_NE(rename.message().find(directory), std::string::npos);
  EXPECT_FALSE(fs::exists(directory + ".tmp"));
}

TEST_F(ContourExport, IndexOutOfRangeIsNamed) {
  ContourMesh mesh = unit_cube();
  mesh.triangles[5].y = 8;
  const Status status = save_mesh(mesh, temp_path("bad_index.obj"));
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(status.message().find("triangle 5"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("index 8"), std::string::npos) << status.message();
  EXPECT_FALSE(fs::exists(temp_path("bad_index.obj")));
}

TEST_F(ContourExport, NanPositionIsNamed) {
  ContourMesh mesh = unit_cube();
  mesh.positions[6].z = std::numeric_limits<double>::quiet_NaN();
  const Status status = save_mesh(mesh, temp_path("bad_position.glb"));
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(status.message().find("vertex 6"), std::string::npos) << status.message();
}

TEST_F(ContourExport, WrongArraySizesAndOptionsAreNamed) {
  ContourMesh mesh = unit_cube();
  mesh.normals.pop_back();
  const Status normals = save_mesh(mesh, temp_path("bad_normals.ply"));
  EXPECT_EQ(normals.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(normals.message().find("normals"), std::string::npos) << normals.message();
  mesh = unit_cube();
  mesh.triangle_material.push_back(0);
  EXPECT_NE(save_mesh(mesh, temp_path("bad.ply")).message().find("triangle_material"),
            std::string::npos);
  ExportOptions options;
  options.draco_position_bits = 40;
  const Status bits = save_mesh(unit_cube(), temp_path("bad.drc"), options);
  EXPECT_EQ(bits.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(bits.message().find("draco_position_bits"), std::string::npos);
}

TEST_F(ContourExport, MissingFileIsNamed) {
  const std::string path = temp_path("never-written.ply");
  const Result<ContourMesh> loaded = load_contour_mesh(path);
  EXPECT_EQ(loaded.status().code(), ErrorCode::kIoError);
  EXPECT_NE(loaded.status().message().find(path), std::string::npos);
}

TEST_F(ContourExport, ToTriangleMeshKeepsPositionsTrianglesAndMaterials) {
  const ContourMesh mesh = unit_cube();
  const TriangleMesh out = to_triangle_mesh(mesh);
  EXPECT_EQ(out.positions, mesh.positions);
  EXPECT_EQ(out.triangles, mesh.triangles);
  EXPECT_EQ(out.triangle_material, mesh.triangle_material);
  EXPECT_TRUE(check_mesh(out).ok());
}

// ------------------------------------------------------------------- quality

TEST(ContourQuality, CubeIsClosedWithVolumeOneAndMinAngle45) {
  const MeshQuality q = mesh_quality(unit_cube(glm::dvec3(1000.0, -2000.0, 3000.0)));
  EXPECT_TRUE(q.closed());
  EXPECT_EQ(q.triangles, 12u);
  EXPECT_EQ(q.vertices, 8u);
  EXPECT_EQ(q.boundary_edges, 0u);
  EXPECT_EQ(q.nonmanifold_edges, 0u);
  EXPECT_EQ(q.unpaired_edges, 0u);
  EXPECT_EQ(q.nonmanifold_vertices, 0u);
  EXPECT_EQ(q.degenerate_triangles, 0u);
  EXPECT_EQ(q.unused_vertices, 0u);
  EXPECT_NEAR(q.volume, 1.0, 1e-12);
  EXPECT_NEAR(q.area, 6.0, 1e-12);
  EXPECT_NEAR(q.min_angle_deg, 45.0, 1e-9);
  EXPECT_EQ(q.min_angle_histogram[4], 12u);
}

TEST(ContourQuality, InsideOutCubeHasNegativeVolume) {
  ContourMesh mesh = unit_cube();
  for (glm::uvec3& tri : mesh.triangles) std::swap(tri.y, tri.z);
  const MeshQuality q = mesh_quality(mesh);
  EXPECT_TRUE(q.closed());
  EXPECT_NEAR(q.volume, -1.0, 1e-12);
}

TEST(ContourQuality, CubeWithOneTriangleRemovedHasThreeBoundaryEdges) {
  ContourMesh mesh = unit_cube();
  mesh.triangles.pop_back();
  const MeshQuality q = mesh_quality(mesh);
  EXPECT_EQ(q.boundary_edges, 3u);
  EXPECT_EQ(q.unpaired_edges, 3u);
  EXPECT_EQ(q.nonmanifold_vertices, 0u);  // an open fan is still one disc
  EXPECT_FALSE(q.closed());
}

TEST(ContourQuality, OneFlippedTriangleLeavesThreeUnpairedEdgesAndNoBoundary) {
  ContourMesh mesh = unit_cube();
  std::swap(mesh.triangles[0].y, mesh.triangles[0].z);
  const MeshQuality q = mesh_quality(mesh);
  EXPECT_EQ(q.boundary_edges, 0u);
  EXPECT_EQ(q.unpaired_edges, 3u);
  EXPECT_FALSE(q.closed());
}

TEST(ContourQuality, TwoCubesSharingOnlyAnEdge) {
  const ContourMesh mesh = cubes_sharing_an_edge();
  ASSERT_EQ(mesh.vertex_count(), 14u);
  const MeshQuality q = mesh_quality(mesh);
  EXPECT_EQ(q.nonmanifold_edges, 1u);
  EXPECT_EQ(q.nonmanifold_vertices, 2u);
  EXPECT_EQ(q.boundary_edges, 0u);
  EXPECT_EQ(q.unpaired_edges, 0u);  // each cube uses the shared edge once each way
  EXPECT_NEAR(q.volume, 2.0, 1e-12);
}

TEST(ContourQuality, TwoCubesSharingOnlyAVertexMakeItNonManifold) {
  ContourMesh mesh = unit_cube();
  const ContourMesh b = unit_cube(glm::dvec3(1.0));  // touches the first at (1, 1, 1) only
  for (uint32_t v = 1; v < 8; ++v) mesh.positions.push_back(b.positions[v]);  // b's 0 is a's 7
  for (const glm::uvec3& tri : b.triangles) {
    glm::uvec3 moved;
    for (int k = 0; k < 3; ++k) moved[k] = tri[k] == 0 ? 7 : tri[k] + 7;
    mesh.triangles.push_back(moved);
  }
  mesh.normals.clear();
  mesh.vertex_material.clear();
  mesh.triangle_material.clear();
  const MeshQuality q = mesh_quality(mesh);
  EXPECT_EQ(q.nonmanifold_vertices, 1u);
  EXPECT_EQ(q.nonmanifold_edges, 0u);
  EXPECT_TRUE(q.watertight());
  EXPECT_FALSE(q.closed());  // not a 2-manifold at the shared corner
}

TEST(ContourQuality, DegenerateTrianglesAndUnusedVerticesAreCounted) {
  ContourMesh mesh = unit_cube();
  mesh.positions.push_back({0.5, 0.0, 0.0});  // on the edge from vertex 0 to vertex 1
  mesh.positions.push_back({7.0, 7.0, 7.0});  // used by nothing
  mesh.triangles.push_back({0, 1, 8});        // collinear: zero area
  mesh.triangles.push_back({2, 2, 3});        // repeated index
  const MeshQuality q = mesh_quality(mesh);
  EXPECT_EQ(q.degenerate_triangles, 2u);
  EXPECT_EQ(q.unused_vertices, 1u);
  EXPECT_EQ(q.min_angle_deg, 0.0);
  EXPECT_EQ(q.min_angle_histogram[0], 2u);
  EXPECT_NEAR(q.area, 6.0, 1e-12);
}

TEST(ContourQuality, EmptyMeshIsClosedAndEmpty) {
  const MeshQuality q = mesh_quality(ContourMesh{});
  EXPECT_TRUE(q.closed());
  EXPECT_EQ(q.triangles, 0u);
  EXPECT_EQ(q.volume, 0.0);
}

// ------------------------------------------------------------------ OpenMesh

TEST(ContourOpenMesh, CubeHasEightVerticesTwelveFacesAndMaterials) {
  const ContourMesh cube = unit_cube();
  size_t duplicated = 99;
  const OpenTriMesh mesh = to_openmesh(cube, &duplicated);
  EXPECT_EQ(mesh.n_vertices(), 8u);
  EXPECT_EQ(mesh.n_faces(), 12u);
  EXPECT_EQ(duplicated, 0u);
  OpenMesh::FPropHandleT<unsigned short> material;
  ASSERT_TRUE(mesh.get_property_handle(material, kOpenMeshMaterialProperty));
  for (size_t f = 0; f < 12; ++f) {
    EXPECT_EQ(mesh.property(material, OpenTriMesh::FaceHandle(static_cast<int>(f))),
              cube.triangle_material[f]);
  }
  for (size_t v = 0; v < 8; ++v) {
    const OpenTriMesh::Normal n = mesh.normal(OpenTriMesh::VertexHandle(static_cast<int>(v)));
    EXPECT_EQ(glm::vec3(n[0], n[1], n[2]), cube.normals[v]);
  }
  const OpenTriMesh::Normal top = mesh.normal(OpenTriMesh::FaceHandle(10));  // a z = 1 face
  EXPECT_NEAR(top[2], 1.0f, 1e-6f);
}

TEST(ContourOpenMesh, NonManifoldInputKeepsEveryFaceOnDuplicatedVertices) {
  const ContourMesh mesh = cubes_sharing_an_edge();
  size_t duplicated = 0;
  const OpenTriMesh out = to_openmesh(mesh, &duplicated);
  EXPECT_EQ(out.n_faces(), 24u);
  EXPECT_GT(duplicated, 0u);
  EXPECT_EQ(duplicated % 3, 0u);
  EXPECT_EQ(out.n_vertices(), 14u + duplicated);
  OpenMesh::FPropHandleT<unsigned short> material;
  ASSERT_TRUE(out.get_property_handle(material, kOpenMeshMaterialProperty));
  size_t second_cube = 0;
  for (const auto face : out.faces()) second_cube += out.property(material, face) == 9 ? 1 : 0;
  EXPECT_EQ(second_cube, 12u);
}

TEST(ContourOpenMesh, MissingNormalsAreComputed) {
  ContourMesh cube = unit_cube();
  cube.normals.clear();
  const OpenTriMesh mesh = to_openmesh(cube);
  const OpenTriMesh::Normal n = mesh.normal(OpenTriMesh::VertexHandle(7));  // corner (1, 1, 1)
  EXPECT_GT(n[0], 0.3f);
  EXPECT_GT(n[1], 0.3f);
  EXPECT_GT(n[2], 0.3f);
}

}  // namespace
}  // namespace ldc
