// Tests of the mesh loaders (OBJ, PLY, STL, OFF), save_obj, check_mesh and
// mesh_topology: the real meshes in tests/data, files written in memory for
// every format variant, every error path, and a seeded mutation fuzz.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ldc/io.h"
#include "ldc/mesh.h"
#include "meshio/meshio.h"

namespace ldc {
namespace {

// ------------------------------------------------------------------ helpers

std::string data_file(const std::string& name) {
  return std::string(LDC_TEST_DATA_DIR) + "/" + name;
}

std::string temp_file(const std::string& name) {
  return ::testing::TempDir() + "ldc_mesh_io_" + name;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

::testing::AssertionResult fails_with(const Result<TriangleMesh>& result, ErrorCode code,
                                      const std::string& text) {
  if (result.ok())
    return ::testing::AssertionFailure() << "parsed, expected an error with '" << text << "'";
  const Status& status = result.status();
  if (status.code() != code)
    return ::testing::AssertionFailure() << "wrong code: " << status.to_string();
  if (status.message().find(text) == std::string::npos) {
    return ::testing::AssertionFailure()
           << "'" << status.message() << "' does not contain '" << text << "'";
  }
  return ::testing::AssertionSuccess();
}

// Unwraps a result that must be ok; fails the test with the message otherwise.
TriangleMesh parsed(Result<TriangleMesh> result) {
  EXPECT_TRUE(result.ok()) << result.status().to_string();
  if (!result.ok()) return {};
  EXPECT_TRUE(check_mesh(result.value()).ok()) << check_mesh(result.value()).to_string();
  return std::move(result).value();
}

glm::dvec3 triangle_normal(const TriangleMesh& mesh, size_t t) {
  const glm::uvec3& tri = mesh.triangles[t];
  const glm::dvec3& a = mesh.positions[tri.x];
  return glm::cross(mesh.positions[tri.y] - a, mesh.positions[tri.z] - a);
}

double total_area(const TriangleMesh& mesh) {
  double area = 0.0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    area += 0.5 * glm::length(triangle_normal(mesh, t));
  return area;
}

// Unit cube [0,1]^3: vertex i = (i & 1, i >> 1 & 1, i >> 2 & 1), six
// outward counter-clockwise quads.
const std::array<std::array<uint32_t, 4>, 6> kCubeQuads = {
    {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}}};

glm::dvec3 cube_corner(uint32_t i) { return glm::dvec3(i & 1, (i >> 1) & 1, (i >> 2) & 1); }

TriangleMesh cube_mesh() {
  TriangleMesh mesh;
  for (uint32_t i = 0; i < 8; ++i) mesh.positions.push_back(cube_corner(i));
  for (const auto& q : kCubeQuads) {
    mesh.triangles.emplace_back(q[0], q[1], q[2]);
    mesh.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return mesh;
}

std::string cube_obj() {
  std::string text;
  for (uint32_t i = 0; i < 8; ++i) {
    const glm::dvec3 p = cube_corner(i);
    text +=
        "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
  }
  for (const auto& q : kCubeQuads) {
    text += "f " + std::to_string(q[0] + 1) + " " + std::to_string(q[1] + 1) + " " +
            std::to_string(q[2] + 1) + " " + std::to_string(q[3] + 1) + "\n";
  }
  return text;
}

void expect_closed_unit_cube(const TriangleMesh& mesh) {
  EXPECT_EQ(mesh.triangle_count(), 12u);
  EXPECT_TRUE(mesh_topology(mesh).closed());
  EXPECT_EQ(mesh_topology(mesh).boundary_edges, 0u);
  EXPECT_NEAR(mesh_signed_volume(mesh), 1.0, 1e-12);
}

// Appends `value` in the given byte order.
template <class T>
void put(std::string& out, T value, bool big_endian) {
  auto raw = std::bit_cast<std::array<char, sizeof(T)>>(value);
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(raw.begin(), raw.end());
  out.append(raw.data(), raw.size());
}

enum class Encoding { kAscii, kLittle, kBig };

const char* format_line(Encoding encoding) {
  switch (encoding) {
    case Encoding::kAscii: return "format ascii 1.0\n";
    case Encoding::kLittle: return "format binary_little_endian 1.0\n";
    case Encoding::kBig: return "format binary_big_endian 1.0\n";
  }
  return "";
}

// A PLY of the cube that exercises the awkward parts: x y z of three
// different types, a colour and a list property on vertices, a property
// before the face list, and an extra element with a list in the middle.
std::string cube_ply(Encoding encoding) {
  std::string out = std::string("ply\n") + format_line(encoding) +
                    "comment written by test_mesh_io\nelement vertex 8\nproperty float x\n"
                    "property double y\nproperty short z\nproperty uchar red\n"
                    "property list uchar float extra\nelement face 6\nproperty uchar flags\n"
                    "property list uchar int vertex_indices\nelement edge 2\nproperty int vertex1\n"
                    "property list ushort uchar tags\nproperty int vertex2\nend_header\n";
  const bool big = encoding == Encoding::kBig;
  const bool ascii = encoding == Encoding::kAscii;
  for (uint32_t i = 0; i < 8; ++i) {
    const glm::dvec3 p = cube_corner(i);
    const uint8_t extras = static_cast<uint8_t>(i % 3);
    if (ascii) {
      out += std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(int(p.z)) +
             " 200 " + std::to_string(extras);
      for (int e = 0; e < extras; ++e) out += " 0.5";
      out += "\n";
      continue;
    }
    put(out, float(p.x), big);
    put(out, double(p.y), big);
    put(out, int16_t(p.z), big);
    put(out, uint8_t{200}, big);
    put(out, extras, big);
    for (int e = 0; e < extras; ++e) put(out, 0.5f, big);
  }
  for (const auto& q : kCubeQuads) {
    if (ascii) {
      out += "7 4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " +
             std::to_string(q[2]) + " " + std::to_string(q[3]) + "\n";
      continue;
    }
    put(out, uint8_t{7}, big);
    put(out, uint8_t{4}, big);
    for (uint32_t v : q) put(out, int32_t(v), big);
  }
  for (int edge = 0; edge < 2; ++edge) {
    if (ascii) {
      out += "0 2 9 9 1\n";
      continue;
    }
    put(out, int32_t{0}, big);
    put(out, uint16_t{2}, big);
    put(out, uint8_t{9}, big);
    put(out, uint8_t{9}, big);
    put(out, int32_t{1}, big);
  }
  return out;
}

// A plain PLY: float x y z, faces as uchar count + int indices.
std::string simple_ply(Encoding encoding, const std::vector<glm::dvec3>& positions,
                       const std::vector<std::vector<int>>& faces) {
  std::string out = std::string("ply\n") + format_line(encoding) + "element vertex " +
                    std::to_string(positions.size()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string(faces.size()) +
                    "\nproperty list uchar int vertex_indices\nend_header\n";
  const bool big = encoding == Encoding::kBig;
  for (const glm::dvec3& p : positions) {
    if (encoding == Encoding::kAscii) {
      out += std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
    } else {
      for (int axis = 0; axis < 3; ++axis) put(out, float(p[axis]), big);
    }
  }
  for (const auto& face : faces) {
    if (encoding == Encoding::kAscii) {
      out += std::to_string(face.size());
      for (int v : face) out += " " + std::to_string(v);
      out += "\n";
    } else {
      put(out, uint8_t(face.size()), big);
      for (int v : face) put(out, int32_t(v), big);
    }
  }
  return out;
}

// Tetrahedron with outward triangles as STL would store it: corners repeated.
const std::vector<glm::dvec3> kTetraCorners = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
const std::vector<glm::uvec3> kTetraTriangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

std::string tetra_text_stl() {
  std::string out = "solid tetra\n";
  for (const glm::uvec3& tri : kTetraTriangles) {
    out += "  facet normal 0 0 0\n    outer loop\n";
    for (int corner = 0; corner < 3; ++corner) {
      const glm::dvec3& p = kTetraCorners[tri[corner]];
      out += "      vertex " + std::to_string(p.x) + " " + std::to_string(p.y) + " " +
             std::to_string(p.z) + "\n";
    }
    out += "    endloop\n  endfacet\n";
  }
  return out + "endsolid tetra\n";
}

std::string tetra_binary_stl(const std::string& header_text) {
  std::string out = header_text;
  out.resize(80, ' ');
  put(out, uint32_t(kTetraTriangles.size()), false);
  for (const glm::uvec3& tri : kTetraTriangles) {
    for (int k = 0; k < 3; ++k) put(out, 0.0f, false);  // normal, ignored
    for (int corner = 0; corner < 3; ++corner) {
      for (int axis = 0; axis < 3; ++axis) put(out, float(kTetraCorners[tri[corner]][axis]), false);
    }
    put(out, uint16_t{0}, false);
  }
  return out;
}

std::string cube_off() {
  std::string out = "OFF\n# a cube\n8 6 12\n";
  for (uint32_t i = 0; i < 8; ++i) {
    const glm::dvec3 p = cube_corner(i);
    out += std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
  }
  for (const auto& q : kCubeQuads) {
    out += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
           " " + std::to_string(q[3]) + "\n";
  }
  return out;
}

// ------------------------------------------------------------- real meshes

struct RealMesh {
  const char* file;
  size_t triangles;
  size_t vertices;
};

TEST(RealMeshes, LoadWithExactTriangleCounts) {
  const RealMesh meshes[] = {{"stanford-bunny.obj", 69451, 35947}, {"fandisk.obj", 12946, 6475},
                             {"rocker-arm.obj", 20088, 10044},     {"spot.obj", 5856, 2930},
                             {"teapot.obj", 6320, 3644},           {"suzanne.obj", 968, 507},
                             {"nav_test.obj", 1612, 884}};
  for (const RealMesh& expected : meshes) {
    SCOPED_TRACE(expected.file);
    const TriangleMesh mesh = parsed(load_mesh(data_file(expected.file)));
    EXPECT_EQ(mesh.triangle_count(), expected.triangles);
    EXPECT_EQ(mesh.positions.size(), expected.vertices);
  }
}

TEST(RealMeshes, ClosedPartsAreClosedAndTheBunnyIsNot) {
  for (const char* file : {"spot.obj", "fandisk.obj", "rocker-arm.obj"}) {
    SCOPED_TRACE(file);
    const TriangleMesh mesh = parsed(load_mesh(data_file(file)));
    const MeshTopology topology = mesh_topology(mesh);
    EXPECT_TRUE(topology.closed());
    EXPECT_EQ(topology.boundary_edges, 0u);
    EXPECT_EQ(topology.nonmanifold_edges, 0u);
    EXPECT_GT(mesh_signed_volume(mesh), 0.0);
  }
  const MeshTopology bunny = mesh_topology(parsed(load_mesh(data_file("stanford-bunny.obj"))));
  EXPECT_FALSE(bunny.closed());
  EXPECT_GT(bunny.boundary_edges, 0u);
}

TEST(RealMeshes, NavTestKeepsItsUsemtlGroupsAndIgnoresTheMissingMtllib) {
  // 30 `usemtl` lines, all naming "Default": one material, used by every face.
  const TriangleMesh mesh = parsed(load_mesh(data_file("nav_test.obj")));
  ASSERT_EQ(mesh.material_names, std::vector<std::string>{"Default"});
  ASSERT_EQ(mesh.triangle_material.size(), mesh.triangle_count());
  for (uint16_t id : mesh.triangle_material) EXPECT_EQ(id, 0);
}

struct PolygonFace {
  size_t corners;
  glm::dvec3 normal;  // Newell normal: length = twice the projected area
};

// Each face's corner count and Newell normal, read independently of the loader.
std::vector<PolygonFace> faces_of_obj(const std::string& text) {
  std::istringstream in(text);
  std::vector<glm::dvec3> positions;
  std::vector<PolygonFace> faces;
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string keyword;
    fields >> keyword;
    if (keyword == "v") {
      glm::dvec3 p;
      fields >> p.x >> p.y >> p.z;
      positions.push_back(p);
    }
    if (keyword != "f") continue;
    std::vector<glm::dvec3> corners;
    for (std::string token; fields >> token;) corners.push_back(positions[std::stoi(token) - 1]);
    glm::dvec3 normal(0.0);
    for (size_t i = 0; i < corners.size(); ++i)
      normal += glm::cross(corners[i], corners[(i + 1) % corners.size()]);
    faces.push_back({corners.size(), normal});
  }
  return faces;
}

TEST(RealMeshes, NavTestPolygonsTriangulateWithoutOverlap) {
  // Projected onto its polygon's best-fit plane, every triangle must face the
  // polygon's way and together they must cover its area exactly once. A fan
  // over the four non-convex 8-gons would overlap (66 to 104 instead of 56).
  const std::string text = read_bytes(data_file("nav_test.obj"));
  const TriangleMesh mesh = parsed(parse_obj(text, "nav_test.obj"));
  size_t t = 0;
  for (const PolygonFace& face : faces_of_obj(text)) {
    const glm::dvec3 unit = glm::normalize(face.normal);
    double twice_area = 0.0;
    for (size_t k = 0; k + 2 < face.corners; ++k, ++t) {
      ASSERT_LT(t, mesh.triangle_count());
      const double projected = glm::dot(triangle_normal(mesh, t), unit);
      EXPECT_GT(projected, 0.0) << "triangle " << t << " is flipped";
      twice_area += projected;
    }
    EXPECT_NEAR(twice_area, glm::length(face.normal), 1e-9 * glm::length(face.normal))
        << "before triangle " << t;
  }
  EXPECT_EQ(t, mesh.triangle_count());
}

TEST(RealMeshes, BunnySaveObjRoundTripsExactly) {
  const TriangleMesh bunny = parsed(load_mesh(data_file("stanford-bunny.obj")));
  const std::string path = temp_file("bunny.obj");
  ASSERT_TRUE(save_mesh(bunny, path).ok());
  const TriangleMesh again = parsed(load_mesh(path));
  EXPECT_EQ(again.positions, bunny.positions);
  EXPECT_EQ(again.triangles, bunny.triangles);
  std::remove(path.c_str());
}

TEST(RealMeshes, NavTestSaveObjKeepsMaterials) {
  const TriangleMesh nav = parsed(load_mesh(data_file("nav_test.obj")));
  const std::string path = temp_file("nav.obj");
  ASSERT_TRUE(save_mesh(nav, path).ok());
  const TriangleMesh again = parsed(load_mesh(path));
  EXPECT_EQ(again.triangles, nav.triangles);
  EXPECT_EQ(again.material_names, nav.material_names);
  EXPECT_EQ(again.triangle_material, nav.triangle_material);
  std::remove(path.c_str());
}

// ---------------------------------------------------------------------- OBJ

TEST(ObjLoader, AllFaceVertexFormsParse) {
  const TriangleMesh mesh =
      parsed(parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                       "f 1 2 3\nf 1/1 2/1 3/1\nf 1//1 2//1 3//1\nf 1/1/1 2/1/1 3/1/1\n",
                       "forms.obj"));
  ASSERT_EQ(mesh.triangle_count(), 4u);
  for (const glm::uvec3& tri : mesh.triangles) EXPECT_EQ(tri, glm::uvec3(0, 1, 2));
}

TEST(ObjLoader, NegativeIndicesCountBackFromTheLastVertex) {
  const TriangleMesh mesh =
      parsed(parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 0 0 1\nf -4 -1 -3\n", "rel.obj"));
  ASSERT_EQ(mesh.triangle_count(), 2u);
  EXPECT_EQ(mesh.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], glm::uvec3(0, 3, 1));
}

TEST(ObjLoader, CrLfTabsTrailingSpaceAndCommentsAreTolerated) {
  const TriangleMesh mesh = parsed(parse_obj(
      "# header\r\nv\t0 0 0  \r\nv 1 0 0 # end comment\r\n\tv 0 1 0\r\n\r\nf 1 2 3\t \r\n",
      "crlf.obj"));
  EXPECT_EQ(mesh.triangle_count(), 1u);
  EXPECT_EQ(mesh.positions[1], glm::dvec3(1, 0, 0));
}

TEST(ObjLoader, WeightsColoursAndIgnoredKeywordsAreSkipped) {
  const TriangleMesh mesh = parsed(parse_obj(
      "mtllib missing.mtl\no thing\ng group\ns 1\nv 0 0 0 1 0.5 0.5 0.5\nv 1 0 0 1\nv 0 1 0\n"
      "vp 0.5\nl 1 2\nfrobnicate 7\nf 1 2 3\n",
      "skip.obj"));
  EXPECT_EQ(mesh.triangle_count(), 1u);
  EXPECT_EQ(mesh.positions[0], glm::dvec3(0, 0, 0));
  EXPECT_TRUE(mesh.material_names.empty());
  EXPECT_TRUE(mesh.triangle_material.empty());
}

TEST(ObjLoader, QuadsTriangulateAndCubeIsClosed) {
  expect_closed_unit_cube(parsed(parse_obj(cube_obj(), "cube.obj")));
}

TEST(ObjLoader, UsemtlIdsFollowFirstSeenOrder) {
  const TriangleMesh mesh =
      parsed(parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl stone\nf 1 2 3\nusemtl wood\nf 1 2 "
                       "3\nusemtl stone\nf 1 2 3\n",
                       "m.obj"));
  EXPECT_EQ(mesh.material_names, (std::vector<std::string>{"stone", "wood"}));
  EXPECT_EQ(mesh.triangle_material, (std::vector<uint16_t>{0, 1, 0}));
}

TEST(ObjLoader, FacesBeforeTheFirstUsemtlGetDefault) {
  const TriangleMesh mesh =
      parsed(parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\nusemtl brick\nf 1 2 "
                       "3\nusemtl default\nf 1 2 3\n",
                       "d.obj"));
  EXPECT_EQ(mesh.material_names, (std::vector<std::string>{"default", "brick"}));
  EXPECT_EQ(mesh.triangle_material, (std::vector<uint16_t>{0, 0, 1, 0}));
}

TEST(ObjLoader, MaterialNamesKeepInnerSpaces) {
  const TriangleMesh mesh =
      parsed(parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl  old  brick \r\nf 1 2 3\n", "s.obj"));
  EXPECT_EQ(mesh.material_names, std::vector<std::string>{"old  brick"});
}

TEST(ObjLoader, FaceIndexOutOfRangeNamesTheLine) {
  EXPECT_TRUE(fails_with(parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 5\n", "x.obj"),
                         ErrorCode::kParseError,
                         "x.obj:4: face index 5 out of range (3 vertices so far)"));
  EXPECT_TRUE(fails_with(parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", "x.obj"),
                         ErrorCode::kParseError,
                         "x.obj:4: face index -4 out of range (3 vertices so far)"));
}

TEST(ObjLoader, FaceBeforeItsVerticesIsOutOfRange) {
  EXPECT_TRUE(fails_with(parse_obj("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "x.obj"),
                         ErrorCode::kParseError,
                         "x.obj:1: face index 1 out of range (0 vertices so far)"));
}

TEST(ObjLoader, FaceIndexZeroIsAnError) {
  EXPECT_TRUE(fails_with(parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "x.obj"),
                         ErrorCode::kParseError, "x.obj:4: face index 0 is invalid"));
}

TEST(ObjLoader, NonIntegerFaceIndexNamesTheToken) {
  EXPECT_TRUE(fails_with(parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x3\n", "x.obj"),
                         ErrorCode::kParseError, "x.obj:4: face index 'x3' is not an integer"));
  EXPECT_TRUE(fails_with(parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 /3\n", "x.obj"),
                         ErrorCode::kParseError, "'/3' is not an integer"));
}

TEST(ObjLoader, NanCoordinateNamesVertexAndLine) {
  EXPECT_TRUE(fails_with(parse_obj("v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n", "x.obj"),
                         ErrorCode::kParseError,
                         "x.obj:3: vertex 3 coordinate 'nan' is not a finite number"));
}

TEST(ObjLoader, InfiniteCoordinatesAreErrors) {
  EXPECT_TRUE(fails_with(parse_obj("v inf 0 0\n", "x.obj"), ErrorCode::kParseError,
                         "'inf' is not a finite number"));
  EXPECT_TRUE(fails_with(parse_obj("v 0 -infinity 0\n", "x.obj"), ErrorCode::kParseError,
                         "is not a finite number"));
  EXPECT_TRUE(fails_with(parse_obj("v 0 0 1e999\n", "x.obj"), ErrorCode::kParseError,
                         "'1e999' is not a finite"));
}

TEST(ObjLoader, UnderflowingCoordinatesReadAsZero) {
  const TriangleMesh mesh =
      parsed(parse_obj("v 1e-999 -0.0 1e-400\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "u.obj"));
  EXPECT_EQ(mesh.positions[0], glm::dvec3(0.0));
}

TEST(ObjLoader, LeadingPlusSignIsAccepted) {
  const TriangleMesh mesh = parsed(parse_obj("v +1.5 0 0\nv 1 0 0\nv 0 1 0\nf +1 2 3\n", "p.obj"));
  EXPECT_EQ(mesh.positions[0].x, 1.5);
}

TEST(ObjLoader, MalformedCoordinateNamesTheToken) {
  EXPECT_TRUE(fails_with(parse_obj("v 0 1.0.0 0\n", "x.obj"), ErrorCode::kParseError,
                         "x.obj:1: vertex 1 coordinate '1.0.0' is not a number"));
  EXPECT_TRUE(fails_with(parse_obj("v 0 1\n", "x.obj"), ErrorCode::kParseError,
                         "x.obj:1: vertex 1 has 2 coordinates"));
}

TEST(ObjLoader, FaceWithTwoVerticesIsAnError) {
  EXPECT_TRUE(fails_with(parse_obj("v 0 0 0\nv 1 0 0\nf 1 2\n", "x.obj"), ErrorCode::kParseError,
                         "x.obj:3: face has 2 vertices (needs at least 3)"));
}

TEST(ObjLoader, EmptyFileHasNoTriangles) {
  EXPECT_TRUE(fails_with(parse_obj("", "e.obj"), ErrorCode::kParseError, "e.obj: no triangles"));
  EXPECT_TRUE(
      fails_with(parse_obj(" \n\r\n", "e.obj"), ErrorCode::kParseError, "e.obj: no triangles"));
  EXPECT_TRUE(fails_with(parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "e.obj"), ErrorCode::kParseError,
                         "no triangles"));
}

TEST(ObjLoader, MaxTrianglesIsEnforced) {
  LoadOptions options;
  options.max_triangles = 11;
  EXPECT_TRUE(fails_with(parse_obj(cube_obj(), "c.obj", options), ErrorCode::kTooLarge,
                         "more than 11 triangles"));
  options.max_triangles = 12;
  EXPECT_TRUE(parse_obj(cube_obj(), "c.obj", options).ok());
  options.max_triangles = 0;
  EXPECT_TRUE(fails_with(parse_obj(cube_obj(), "c.obj", options), ErrorCode::kInvalidArgument,
                         "max_triangles"));
}

// ------------------------------------------------------------ triangulation

// Loads one polygon given by 2D points placed in 3D by `place`.
TriangleMesh polygon_mesh(const std::vector<glm::dvec2>& points,
                          const std::function<glm::dvec3(glm::dvec2)>& place) {
  std::string text;
  char line[128];
  for (const glm::dvec2& p : points) {
    const glm::dvec3 q = place(p);
    std::snprintf(line, sizeof(line), "v %.17g %.17g %.17g\n", q.x, q.y, q.z);
    text += line;
  }
  text += "f";
  for (size_t i = 1; i <= points.size(); ++i) text += " " + std::to_string(i);
  return parsed(parse_obj(text + "\n", "polygon.obj"));
}

double shoelace_area(const std::vector<glm::dvec2>& points) {
  double twice = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const glm::dvec2& a = points[i];
    const glm::dvec2& b = points[(i + 1) % points.size()];
    twice += a.x * b.y - a.y * b.x;
  }
  return 0.5 * twice;
}

// An L whose first corner sees only part of the polygon, so a fan from it
// would produce a clockwise, overlapping triangle.
const std::vector<glm::dvec2> kLShape = {{2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 0}, {2, 0}};

void expect_exact_cover(const TriangleMesh& mesh, const std::vector<glm::dvec2>& points,
                        const glm::dvec3& normal) {
  ASSERT_EQ(mesh.triangle_count(), points.size() - 2);
  const double area = std::abs(shoelace_area(points));
  EXPECT_NEAR(total_area(mesh), area, 1e-9 * area);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    EXPECT_GT(glm::dot(triangle_normal(mesh, t), normal), 0.0) << "triangle " << t << " is flipped";
  }
}

TEST(Triangulation, NonConvexLShapeCoversItsAreaExactly) {
  const TriangleMesh mesh = polygon_mesh(kLShape, [](glm::dvec2 p) { return glm::dvec3(p, 0.0); });
  expect_exact_cover(mesh, kLShape, glm::dvec3(0, 0, 1));
}

TEST(Triangulation, TiltedFarAwayLShapeUsesItsBestFitPlane) {
  const glm::dvec3 u = glm::normalize(glm::dvec3(1, 2, 3));
  const glm::dvec3 v = glm::normalize(glm::cross(glm::dvec3(0, 0, 1), u));
  const glm::dvec3 offset(1000.0, -2000.0, 500.0);
  const TriangleMesh mesh =
      polygon_mesh(kLShape, [&](glm::dvec2 p) { return offset + p.x * u + p.y * v; });
  expect_exact_cover(mesh, kLShape, glm::cross(u, v));
}

TEST(Triangulation, ClockwisePolygonKeepsItsWinding) {
  std::vector<glm::dvec2> clockwise(kLShape.rbegin(), kLShape.rend());
  const TriangleMesh mesh =
      polygon_mesh(clockwise, [](glm::dvec2 p) { return glm::dvec3(p, 0.0); });
  expect_exact_cover(mesh, clockwise, glm::dvec3(0, 0, -1));
}

TEST(Triangulation, CombWithManyReflexCornersCoversItsArea) {
  std::vector<glm::dvec2> comb = {{0, 0}, {10, 0}, {10, 3}};
  for (int tooth = 4; tooth >= 0; --tooth) {
    comb.push_back({2.0 * tooth + 1.0, 3});
    comb.push_back({2.0 * tooth + 0.5, 1});
    comb.push_back({2.0 * tooth, 3});
  }
  const TriangleMesh mesh =
      polygon_mesh(comb, [](glm::dvec2 p) { return glm::dvec3(p.x, 0.0, p.y); });
  expect_exact_cover(mesh, comb, glm::dvec3(0, -1, 0));
}

TEST(Triangulation, CollinearCornerOnAnEdgeIsKept) {
  const std::vector<glm::dvec2> square = {{0, 0}, {0.5, 0}, {1, 0}, {1, 1}, {0, 1}};
  const TriangleMesh mesh = polygon_mesh(square, [](glm::dvec2 p) { return glm::dvec3(p, 0.0); });
  expect_exact_cover(mesh, square, glm::dvec3(0, 0, 1));
}

TEST(Triangulation, DegeneratePolygonFallsBackToAFan) {
  const std::vector<glm::dvec2> line = {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}};
  const TriangleMesh mesh = polygon_mesh(line, [](glm::dvec2 p) { return glm::dvec3(p, 0.0); });
  EXPECT_EQ(mesh.triangle_count(), 3u);
  EXPECT_EQ(total_area(mesh), 0.0);
}

TEST(Triangulation, RepeatedCornerStillGivesKMinusTwoTriangles) {
  const TriangleMesh mesh = parsed(
      parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 3 4\nf 1 2 1 2 3 4\n", "rep.obj"));
  EXPECT_EQ(mesh.triangle_count(), 3u + 4u);
}

// ---------------------------------------------------------------------- PLY

TEST(PlyLoader, AsciiCubeWithExtraPropertiesAndElements) {
  expect_closed_unit_cube(parsed(parse_ply(cube_ply(Encoding::kAscii), "cube.ply")));
}

TEST(PlyLoader, BinaryLittleEndianCube) {
  expect_closed_unit_cube(parsed(parse_ply(cube_ply(Encoding::kLittle), "cube.ply")));
}

TEST(PlyLoader, BinaryBigEndianCube) {
  const TriangleMesh mesh = parsed(parse_ply(cube_ply(Encoding::kBig), "cube.ply"));
  expect_closed_unit_cube(mesh);
  for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(mesh.positions[i], cube_corner(i));
}

TEST(PlyLoader, AllThreeEncodingsGiveTheSameMesh) {
  const TriangleMesh ascii = parsed(parse_ply(cube_ply(Encoding::kAscii), "a.ply"));
  const TriangleMesh little = parsed(parse_ply(cube_ply(Encoding::kLittle), "l.ply"));
  const TriangleMesh big = parsed(parse_ply(cube_ply(Encoding::kBig), "b.ply"));
  EXPECT_EQ(ascii.positions, little.positions);
  EXPECT_EQ(ascii.triangles, little.triangles);
  EXPECT_EQ(big.positions, little.positions);
  EXPECT_EQ(big.triangles, little.triangles);
}

TEST(PlyLoader, CrLfHeaderAndVertexIndexNameAreAccepted) {
  const std::string text =
      "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty double x\r\nproperty double y\r\n"
      "property double z\r\nelement face 1\r\nproperty list uint8 uint32 "
      "vertex_index\r\nend_header\r\n"
      "0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n";
  EXPECT_EQ(parsed(parse_ply(text, "crlf.ply")).triangle_count(), 1u);
}

TEST(PlyLoader, FaceElementBeforeVertexElement) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
      "4 0 1 2 3\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
  const TriangleMesh mesh = parsed(parse_ply(text, "order.ply"));
  EXPECT_EQ(mesh.triangle_count(), 2u);
  EXPECT_DOUBLE_EQ(total_area(mesh), 1.0);
}

TEST(PlyLoader, TruncatedBinaryNamesTheByteOffset) {
  const std::vector<glm::dvec3> corners = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  std::string bytes = simple_ply(Encoding::kLittle, corners, {{0, 1, 2}, {0, 2, 1}});
  bytes.resize(bytes.size() - 3);
  const size_t face_1 = bytes.find("end_header\n") + 11 + 3 * 12 + 13;
  EXPECT_TRUE(fails_with(
      parse_ply(bytes, "t.ply"), ErrorCode::kParseError,
      "t.ply: byte " + std::to_string(face_1) + ": face 1: list of 3 entries runs past the end"));
}

TEST(PlyLoader, HugeVertexCountOnATinyFileFailsBeforeAllocating) {
  for (const char* format : {"binary_little_endian", "ascii"}) {
    const std::string text =
        std::string("ply\nformat ") + format +
        " 1.0\nelement vertex 1099511627776\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n0 0 0 0 0 0 0 0 0 0 0 0";
    EXPECT_TRUE(fails_with(parse_ply(text, "huge.ply"), ErrorCode::kCorruptData,
                           "huge.ply:3: element 'vertex' declares 1099511627776 items"));
  }
}

TEST(PlyLoader, HugeFaceListLengthFailsBeforeAllocating) {
  std::string bytes = simple_ply(Encoding::kLittle, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {});
  bytes.replace(bytes.find("element face 0"), 14, "element face 1");
  bytes += '\xff';  // 255 indices announced, none present
  EXPECT_TRUE(fails_with(parse_ply(bytes, "l.ply"), ErrorCode::kParseError,
                         "list of 255 entries runs past the end"));
}

TEST(PlyLoader, FaceIndexOutOfRangeIsAnError) {
  const std::string bytes =
      simple_ply(Encoding::kAscii, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 3}});
  EXPECT_TRUE(fails_with(parse_ply(bytes, "i.ply"), ErrorCode::kParseError,
                         "i.ply:13: face 0 vertex index '3' out of range (3 vertices)"));
  const std::string binary =
      simple_ply(Encoding::kBig, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, -1, 2}});
  EXPECT_TRUE(fails_with(parse_ply(binary, "i.ply"), ErrorCode::kParseError,
                         "vertex index -1 out of range"));
}

TEST(PlyLoader, NanCoordinatesNameTheVertex) {
  const double nan = std::nan("");
  const std::string ascii =
      simple_ply(Encoding::kAscii, {{0, 0, 0}, {1, nan, 0}, {0, 1, 0}}, {{0, 1, 2}});
  EXPECT_TRUE(fails_with(parse_ply(ascii, "n.ply"), ErrorCode::kParseError,
                         "n.ply:11: vertex 1 coordinate 'nan' is not a finite number"));
  const std::string binary =
      simple_ply(Encoding::kLittle, {{0, 0, 0}, {1, 0, 0}, {0, 1, HUGE_VAL}}, {{0, 1, 2}});
  EXPECT_TRUE(fails_with(parse_ply(binary, "n.ply"), ErrorCode::kParseError,
                         "vertex 2 coordinate inf is not a finite"));
}

TEST(PlyLoader, MalformedHeadersNameTheLine) {
  EXPECT_TRUE(fails_with(parse_ply("solid x\n", "h.ply"), ErrorCode::kParseError,
                         "h.ply:1: not a PLY file"));
  EXPECT_TRUE(fails_with(parse_ply("ply\nformat ascii 1.0\nelement vertex 1\n", "h.ply"),
                         ErrorCode::kParseError, "no end_header"));
  EXPECT_TRUE(fails_with(parse_ply("ply\nformat binary_middle_endian 1.0\nend_header\n", "h.ply"),
                         ErrorCode::kParseError, "h.ply:2: unknown format 'binary_middle_endian'"));
  EXPECT_TRUE(fails_with(
      parse_ply("ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n",
                "h.ply"),
      ErrorCode::kParseError, "h.ply:4: unknown property type 'float128'"));
  EXPECT_TRUE(
      fails_with(parse_ply("ply\nformat ascii 1.0\nelement vertex -1\nend_header\n", "h.ply"),
                 ErrorCode::kParseError, "h.ply:3: element count '-1'"));
  EXPECT_TRUE(fails_with(
      parse_ply("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n",
                "h.ply"),
      ErrorCode::kParseError, "h.ply:3: element 'vertex' has no scalar property 'y'"));
}

TEST(PlyLoader, PointCloudHasNoTriangles) {
  const std::string bytes = simple_ply(Encoding::kLittle, {{0, 0, 0}}, {});
  EXPECT_TRUE(fails_with(parse_ply(bytes, "p.ply"), ErrorCode::kParseError, "p.ply: no triangles"));
}

TEST(PlyLoader, MaxTrianglesIsCheckedAgainstTheHeader) {
  LoadOptions options;
  options.max_triangles = 5;
  EXPECT_TRUE(fails_with(parse_ply(cube_ply(Encoding::kLittle), "c.ply", options),
                         ErrorCode::kTooLarge, "more than 5 triangles"));
  options.max_triangles = 11;  // 6 faces pass the header check, 12 triangles do not
  EXPECT_TRUE(fails_with(parse_ply(cube_ply(Encoding::kLittle), "c.ply", options),
                         ErrorCode::kTooLarge, "more than 11 triangles"));
}

// ---------------------------------------------------------------------- STL

void expect_welded_tetra(const TriangleMesh& mesh) {
  ASSERT_EQ(mesh.triangle_count(), 4u);
  EXPECT_EQ(mesh.positions.size(), 4u);  // 12 corners welded into 4 vertices
  EXPECT_TRUE(mesh_topology(mesh).closed());
  EXPECT_NEAR(mesh_signed_volume(mesh), 1.0 / 6.0, 1e-12);
}

TEST(StlLoader, TextStlWeldsCorners) {
  expect_welded_tetra(parsed(parse_stl(tetra_text_stl(), "t.stl")));
}

TEST(StlLoader, BinaryStlWeldsCorners) {
  expect_welded_tetra(parsed(parse_stl(tetra_binary_stl("binary tetra"), "t.stl")));
}

TEST(StlLoader, BinaryHeaderStartingWithSolidIsDetectedBySize) {
  expect_welded_tetra(
      parsed(parse_stl(tetra_binary_stl("solid tetra exported by a careless tool"), "t.stl")));
}

TEST(StlLoader, TruncatedBinaryIsAnError) {
  for (const char* header : {"binary tetra", "solid but binary"}) {
    std::string bytes = tetra_binary_stl(header);
    bytes.resize(bytes.size() - 10);
    EXPECT_TRUE(fails_with(parse_stl(bytes, "t.stl"), ErrorCode::kParseError,
                           "t.stl: binary STL header declares 4 triangles, which take 284 bytes, "
                           "but the file has 274"));
  }
  EXPECT_TRUE(fails_with(parse_stl("tiny", "t.stl"), ErrorCode::kParseError, "too short"));
}

TEST(StlLoader, NegativeZeroWeldsWithZero) {
  const std::string text =
      "solid z\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 "
      "0\nendloop\nendfacet\n"
      "facet normal 0 0 1\nouter loop\nvertex -0.0 -0 0\nvertex 0 1 0\nvertex -1 0 "
      "0\nendloop\nendfacet\nendsolid z\n";
  EXPECT_EQ(parsed(parse_stl(text, "z.stl")).positions.size(), 4u);
}

TEST(StlLoader, TextErrorsNameTheLine) {
  std::string nan_text = tetra_text_stl();
  nan_text.replace(nan_text.find("vertex 1.000000"), 15, "vertex nan");
  EXPECT_TRUE(fails_with(parse_stl(nan_text, "n.stl"), ErrorCode::kParseError,
                         "'nan' is not a finite number"));
  EXPECT_TRUE(fails_with(
      parse_stl("solid s\nfacet\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n", "s.stl"),
      ErrorCode::kParseError, "s.stl:6: facet has 2 vertices"));
  EXPECT_TRUE(fails_with(
      parse_stl("solid s\nfacet\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\n",
                "s.stl"),
      ErrorCode::kParseError, "s.stl:6: facet has more than 3 vertices"));
  EXPECT_TRUE(fails_with(parse_stl("solid s\nfacet\nvertex 0 0 0\n", "s.stl"),
                         ErrorCode::kParseError, "file ends inside a facet"));
  EXPECT_TRUE(fails_with(parse_stl("solid empty\nendsolid empty\n", "s.stl"),
                         ErrorCode::kParseError, "no triangles"));
}

TEST(StlLoader, BinaryNanNamesTheByteOffset) {
  std::string bytes = tetra_binary_stl("binary");
  const float nan = std::nanf("");
  std::memcpy(bytes.data() + 84 + 50 + 12 + 4, &nan, 4);  // triangle 1, corner 0, y
  EXPECT_TRUE(
      fails_with(parse_stl(bytes, "b.stl"), ErrorCode::kParseError,
                 "b.stl: byte 150: triangle 1 corner 0 coordinate nan is not a finite number"));
}

TEST(StlLoader, MaxTrianglesIsEnforced) {
  LoadOptions options;
  options.max_triangles = 3;
  EXPECT_TRUE(fails_with(parse_stl(tetra_binary_stl("b"), "b.stl", options), ErrorCode::kTooLarge,
                         "more than 3"));
  EXPECT_TRUE(fails_with(parse_stl(tetra_text_stl(), "t.stl", options), ErrorCode::kTooLarge,
                         "more than 3"));
}

// ---------------------------------------------------------------------- OFF

TEST(OffLoader, CubeOfQuadsIsClosed) {
  expect_closed_unit_cube(parsed(parse_off(cube_off(), "cube.off")));
}

TEST(OffLoader, ColoursNormalsCommentsAndCountsOnTheHeaderLineAreHandled) {
  const std::string text =
      "COFF 3 1 0   # counts on the header line\n\n"
      "0 0 0 255 0 0 255\n1 0 0 0 255 0 255  # coloured\n0 1 0 0 0 255 255\n"
      "3 0 1 2 0.5 0.5 0.5\n";
  const TriangleMesh mesh = parsed(parse_off(text, "c.off"));
  EXPECT_EQ(mesh.triangle_count(), 1u);
  EXPECT_EQ(mesh.positions[1], glm::dvec3(1, 0, 0));
  EXPECT_EQ(
      parsed(parse_off("NOFF\n3 1\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n", "n.off"))
          .triangle_count(),
      1u);
}

TEST(OffLoader, ErrorsNameTheLine) {
  EXPECT_TRUE(fails_with(parse_off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "o.off"),
                         ErrorCode::kParseError,
                         "o.off:6: face 0 vertex index '3' out of range (3 vertices)"));
  EXPECT_TRUE(fails_with(parse_off("OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n", "o.off"),
                         ErrorCode::kParseError,
                         "o.off:4: vertex 1 coordinate 'inf' is not a finite number"));
  EXPECT_TRUE(fails_with(parse_off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1  \n", "o.off"),
                         ErrorCode::kParseError, "o.off:6: face 0 has 2 vertices"));
  EXPECT_TRUE(
      fails_with(parse_off("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n# padding\n", "o.off"),
                 ErrorCode::kParseError, "o.off: file ends after 1 of 2 faces"));
  EXPECT_TRUE(fails_with(parse_off("PLY\n", "o.off"), ErrorCode::kParseError,
                         "o.off:1: expected an 'OFF' header"));
  EXPECT_TRUE(
      fails_with(parse_off("4OFF\n", "o.off"), ErrorCode::kUnsupported, "OFF variant '4OFF'"));
  EXPECT_TRUE(
      fails_with(parse_off("OFF BINARY\n", "o.off"), ErrorCode::kUnsupported, "binary OFF"));
}

TEST(OffLoader, HugeCountsOnATinyFileFailBeforeAllocating) {
  EXPECT_TRUE(fails_with(parse_off("OFF\n1000000000000 1 0\n0 0 0\n", "h.off"),
                         ErrorCode::kCorruptData,
                         "h.off:2: header declares 1000000000000 vertices"));
  EXPECT_TRUE(fails_with(parse_off("OFF\n3 18446744073709551615 0\n0 0 0\n", "h.off"),
                         ErrorCode::kCorruptData, "18446744073709551615 faces"));
}

// ---------------------------------------------------------------- load_mesh

TEST(LoadMesh, ExtensionIsCaseInsensitive) {
  const std::string path = temp_file("cube.OfF");
  std::ofstream(path, std::ios::binary) << cube_off();
  expect_closed_unit_cube(parsed(load_mesh(path)));
  std::remove(path.c_str());
}

TEST(LoadMesh, EveryFormatLoadsFromDisk) {
  const std::pair<std::string, std::string> files[] = {{"cube.ply", cube_ply(Encoding::kBig)},
                                                       {"cube.STL", tetra_binary_stl("solid")},
                                                       {"cube.obj", cube_obj()}};
  for (const auto& [name, bytes] : files) {
    const std::string path = temp_file(name);
    std::ofstream(path, std::ios::binary) << bytes;
    EXPECT_TRUE(parsed(load_mesh(path)).triangle_count() > 0) << name;
    std::remove(path.c_str());
  }
}

TEST(LoadMesh, UnknownExtensionIsUnsupported) {
  EXPECT_TRUE(fails_with(load_mesh("model.3ds"), ErrorCode::kUnsupported,
                         "model.3ds: unsupported mesh file type ('.3ds'"));
  EXPECT_TRUE(fails_with(load_mesh("dir.obj/model"), ErrorCode::kUnsupported, "no extension"));
}

TEST(LoadMesh, MissingFileNamesThePath) {
  EXPECT_TRUE(fails_with(load_mesh("/nonexistent/ldc/bunny.obj"), ErrorCode::kIoError,
                         "/nonexistent/ldc/bunny.obj: cannot open"));
}

TEST(LoadMesh, DirectoryIsAnIoError) {
  const std::string path = temp_file("directory.obj");
  std::filesystem::create_directories(path);
  EXPECT_TRUE(fails_with(load_mesh(path), ErrorCode::kIoError, path + ": cannot read"));
  std::filesystem::remove(path);
}

TEST(LoadMesh, ErrorsNameThePath) {
  const std::string path = temp_file("bad.obj");
  std::ofstream(path, std::ios::binary) << "v 0 0 0\nf 1 1 2\n";
  EXPECT_TRUE(
      fails_with(load_mesh(path), ErrorCode::kParseError, path + ":2: face index 2 out of range"));
  std::remove(path.c_str());
}

// ----------------------------------------------------------------- save_obj

TEST(SaveObj, AwkwardDoublesRoundTripBitForBit) {
  TriangleMesh mesh;
  mesh.positions = {{0.1, 1.0 / 3.0, -0.0},
                    {1e-300, 4.9e-324, 1.7976931348623157e308},
                    {-123456.789012345678, 2.2250738585072014e-308, 6.02214076e23}};
  mesh.triangles = {{0, 1, 2}};
  const std::string path = temp_file("awkward.obj");
  ASSERT_TRUE(save_mesh(mesh, path).ok());
  const TriangleMesh again = parsed(load_mesh(path));
  ASSERT_EQ(again.positions.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_EQ(std::bit_cast<uint64_t>(again.positions[i][axis]),
                std::bit_cast<uint64_t>(mesh.positions[i][axis]));
    }
  }
  std::remove(path.c_str());
}

TEST(SaveObj, MaterialsWithoutNamesAreWrittenAsMaterialId) {
  TriangleMesh mesh = cube_mesh();
  mesh.triangle_material.assign(12, 3);
  mesh.triangle_material[5] = 7;
  const std::string path = temp_file("mat.obj");
  ASSERT_TRUE(save_mesh(mesh, path).ok());
  const TriangleMesh again = parsed(load_mesh(path));
  EXPECT_EQ(again.material_names, (std::vector<std::string>{"material_3", "material_7"}));
  EXPECT_EQ(again.material_of(5), 1);
  EXPECT_EQ(again.material_of(6), 0);
  std::remove(path.c_str());
}

TEST(SaveObj, RefusesAnInvalidMeshAndAnUnwritablePath) {
  TriangleMesh mesh = cube_mesh();
  EXPECT_EQ(save_mesh(mesh, "/nonexistent/dir/x.obj").code(), ErrorCode::kIoError);
  mesh.triangles[0].y = 99;
  EXPECT_EQ(save_mesh(mesh, temp_file("never.obj")).code(), ErrorCode::kInvalidArgument);
}

// --------------------------------------------------- check_mesh and measures

TEST(CheckMesh, IndexOutOfRangeIsNamed) {
  TriangleMesh mesh = cube_mesh();
  mesh.triangles[4].z = 8;
  const Status status = check_mesh(mesh, "cube");
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(status.message().find("cube: triangle 4 vertex index 8 out of range (8 positions)"),
            std::string::npos)
      << status.message();
}

TEST(CheckMesh, OnlyReferencedPositionsMustBeFinite) {
  TriangleMesh mesh = cube_mesh();
  mesh.positions.push_back(glm::dvec3(std::nan(""), 0, 0));  // unreferenced: fine
  EXPECT_TRUE(check_mesh(mesh).ok());
  mesh.positions[3].y = HUGE_VAL;
  const Status status = check_mesh(mesh);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("vertex 3"), std::string::npos) << status.message();
}

TEST(CheckMesh, MaterialsMustMatchTriangles) {
  TriangleMesh mesh = cube_mesh();
  mesh.triangle_material.assign(11, 0);
  EXPECT_NE(check_mesh(mesh).message().find("triangle_material has 11 entries for 12 triangles"),
            std::string::npos);
  mesh.triangle_material.assign(12, 1);
  EXPECT_TRUE(check_mesh(mesh).ok());  // ids without names are allowed
  mesh.material_names = {"only"};
  EXPECT_NE(check_mesh(mesh).message().find("material id 1"), std::string::npos);
}

TEST(MeshMeasures, BoundsDiagonalAndVolumeOfAMovedCube) {
  TriangleMesh mesh = cube_mesh();
  for (glm::dvec3& p : mesh.positions) p = p * 2.0 + glm::dvec3(1e6, -5, 3);
  mesh.positions.push_back(glm::dvec3(1e9));  // unreferenced: outside the bounds
  const MeshBounds bounds = mesh_bounds(mesh);
  EXPECT_EQ(bounds.min, glm::dvec3(1e6, -5, 3));
  EXPECT_EQ(bounds.max, glm::dvec3(1e6 + 2, -3, 5));
  EXPECT_DOUBLE_EQ(bounds.diagonal(), std::sqrt(12.0));
  EXPECT_NEAR(mesh_signed_volume(mesh), 8.0, 1e-9);
  for (glm::uvec3& tri : mesh.triangles) std::swap(tri.y, tri.z);
  EXPECT_NEAR(mesh_signed_volume(mesh), -8.0, 1e-9);
}

// ------------------------------------------------------------ mesh_topology

TEST(MeshTopology, SingleTriangleHasThreeBoundaryEdges) {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  const MeshTopology topology = mesh_topology(mesh);
  EXPECT_EQ(topology.boundary_edges, 3u);
  EXPECT_EQ(topology.unbalanced_edges, 3u);
  EXPECT_FALSE(topology.closed());
}

TEST(MeshTopology, CubeWithSeparateFaceVerticesIsClosedByPosition) {
  const TriangleMesh shared = cube_mesh();
  TriangleMesh split;
  for (const glm::uvec3& tri : shared.triangles) {
    const uint32_t base = static_cast<uint32_t>(split.positions.size());
    for (int corner = 0; corner < 3; ++corner)
      split.positions.push_back(shared.positions[tri[corner]]);
    split.triangles.emplace_back(base, base + 1, base + 2);
  }
  const MeshTopology topology = mesh_topology(split);
  EXPECT_TRUE(topology.closed());
  EXPECT_EQ(topology.boundary_edges, 0u);
  EXPECT_EQ(topology.nonmanifold_edges, 0u);
}

TEST(MeshTopology, FlippedTriangleUnbalancesItsEdges) {
  TriangleMesh mesh = cube_mesh();
  std::swap(mesh.triangles[0].y, mesh.triangles[0].z);
  const MeshTopology topology = mesh_topology(mesh);
  EXPECT_EQ(topology.boundary_edges, 0u);
  EXPECT_EQ(topology.unbalanced_edges, 3u);
  EXPECT_FALSE(topology.closed());
}

TEST(MeshTopology, ThreeTrianglesOnOneEdgeAreNonManifold) {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  mesh.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const MeshTopology topology = mesh_topology(mesh);
  EXPECT_EQ(topology.nonmanifold_edges, 1u);
  EXPECT_EQ(topology.boundary_edges, 6u);
}

TEST(MeshTopology, DegenerateTrianglesAreCounted) {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 0, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 1, 3}, {1, 1, 2}};
  EXPECT_EQ(mesh_topology(mesh).degenerate_triangles, 3u);
}

// ------------------------------------------------------------ mutation fuzz

using Parser = Result<TriangleMesh> (*)(std::string_view, std::string_view, const LoadOptions&);

// One random edit of the kinds that break parsers: a flipped byte, a cut,
// an inserted number fragment, a removed or repeated span.
void mutate(std::string& bytes, std::mt19937& rng) {
  static const char* const kInserts[] = {"0",           "7",     "-", "nan", "-1",
                                         "99999999999", "1e999", " ", "\n",  "4294967296"};
  auto position = [&](size_t extra) {
    return std::uniform_int_distribution<size_t>(0, bytes.size() + extra)(rng);
  };
  switch (std::uniform_int_distribution<int>(0, 4)(rng)) {
    case 0:
      if (!bytes.empty()) bytes[position(0) % bytes.size()] = static_cast<char>(rng());
      break;
    case 1: bytes.resize(position(0)); break;
    case 2: bytes.insert(position(0), kInserts[rng() % std::size(kInserts)]); break;
    case 3: {
      const size_t at = position(0);
      bytes.erase(at, rng() % 16);
      break;
    }
    default: {
      const size_t at = position(0);
      bytes.insert(at, bytes.substr(at, rng() % 64));
      break;
    }
  }
}

TEST(MutationFuzz, ParsersEitherSucceedWithAValidMeshOrExplain) {
  const std::vector<glm::dvec3> square = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const std::pair<Parser, std::string> seeds[] = {
      {parse_obj,
       "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl a\nf 1/1 2/2 3/3 4/4\nusemtl b\nf -4 -2 -1\n"},
      {parse_ply, simple_ply(Encoding::kAscii, square, {{0, 1, 2, 3}})},
      {parse_ply, simple_ply(Encoding::kLittle, square, {{0, 1, 2, 3}, {0, 2, 1}})},
      {parse_ply, cube_ply(Encoding::kBig)},
      {parse_stl, tetra_text_stl()},
      {parse_stl, tetra_binary_stl("solid")},
      {parse_off, "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"}};
  LoadOptions options;
  options.max_triangles = 1000;
  for (const auto& [parse, seed] : seeds) {
    std::mt19937 rng(12345);
    int accepted = 0;
    for (int round = 0; round < 2000; ++round) {
      std::string bytes = seed;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int e = 0; e < edits; ++e) mutate(bytes, rng);
      const Result<TriangleMesh> result = parse(bytes, "fuzz", options);
      if (result.ok()) {
        ASSERT_TRUE(check_mesh(result.value()).ok()) << check_mesh(result.value()).message();
        ++accepted;
      } else {
        ASSERT_FALSE(result.status().message().empty());
      }
    }
    // Both outcomes occur, so the mutations neither leave the files intact nor always wreck them.
    EXPECT_GT(accepted, 0) << seed;
    EXPECT_LT(accepted, 2000) << seed;
  }
}

// ------------------------------------------------------------------ meshio

TEST(MeshIo, EveryFormatRoundTripsATriangleMesh) {
  TriangleMesh cube = cube_mesh();
  cube.triangle_material.assign(12, 2);
  cube.triangle_material[0] = 5;
  const double volume = mesh_signed_volume(cube);
  for (const char* ext : {"obj", "ply", "stl", "off", "glb", "drc"}) {
    const std::string path = temp_file(std::string("roundtrip.") + ext);
    ASSERT_TRUE(save_mesh(cube, path).ok()) << ext;
    const TriangleMesh again = parsed(load_mesh(path));
    EXPECT_EQ(again.triangle_count(), 12u) << ext;
    EXPECT_NEAR(mesh_signed_volume(again), volume, 1e-3 * volume) << ext;
    EXPECT_EQ(mesh_topology(again).closed(), true) << ext;
    std::remove(path.c_str());
  }
}

TEST(MeshIo, FormatsWithMaterialsKeepTheIds) {
  TriangleMesh cube = cube_mesh();
  cube.triangle_material.assign(12, 2);
  cube.triangle_material[7] = 9;
  for (const char* ext : {"obj", "ply", "glb", "drc"}) {
    const std::string path = temp_file(std::string("materials.") + ext);
    ASSERT_TRUE(save_mesh(cube, path).ok()) << ext;
    Result<ContourMesh> again = load_contour_mesh(path);
    ASSERT_TRUE(again.ok()) << ext << ": " << again.status().message();
    std::vector<int> counts(16, 0);
    for (uint16_t m : again->triangle_material) ++counts[m];
    EXPECT_EQ(counts[2], 11) << ext;
    EXPECT_EQ(counts[9], 1) << ext;
    std::remove(path.c_str());
  }
}

TEST(MeshIo, OffIsWrittenAndReadBackExactly) {
  const TriangleMesh cube = cube_mesh();
  const std::string path = temp_file("cube.off");
  ASSERT_TRUE(save_mesh(cube, path).ok());
  const TriangleMesh again = parsed(load_mesh(path));
  EXPECT_EQ(again.positions, cube.positions);
  EXPECT_EQ(again.triangles, cube.triangles);
  std::remove(path.c_str());
}

TEST(MeshIo, OffExtensionIsAcceptedAndUnknownOnesListTheFormats) {
  EXPECT_EQ(mesh_format_from_path("a/b.OFF").value(), MeshFormat::kOff);
  Result<MeshFormat> bad = mesh_format_from_path("a/b.3mf");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find(".obj, .ply, .stl, .off, .glb or .drc"), std::string::npos);
}

TEST(MeshIo, TriangleLimitHoldsForBinaryContainers) {
  const std::string path = temp_file("limit.glb");
  ASSERT_TRUE(save_mesh(cube_mesh(), path).ok());
  Result<TriangleMesh> r = load_mesh(path, {.max_triangles = 11});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kTooLarge);
  EXPECT_NE(r.status().message().find("12 triangles exceed the limit of 11"), std::string::npos);
  std::remove(path.c_str());
}

TEST(MeshIo, ARefusedSaveLeavesThePreviousFileIntact) {
  const std::string path = temp_file("keep.ply");
  ASSERT_TRUE(save_mesh(cube_mesh(), path).ok());
  const std::string before = read_file(path).value();
  TriangleMesh broken = cube_mesh();
  broken.triangles[3].y = 99;  // out of range
  Status s = save_mesh(broken, path);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find(path), std::string::npos);
  EXPECT_EQ(read_file(path).value(), before);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  std::remove(path.c_str());
}

}  // namespace
}  // namespace ldc
