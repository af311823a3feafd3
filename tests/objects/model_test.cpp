#include "objects/model.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <glm/common.hpp>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "io/error.h"
#include "objects/test_models.h"
#include "temp_dir.h"

namespace terravol::objects {
namespace {

std::vector<char> bytes_of(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write(const std::filesystem::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

std::string error_of(const std::filesystem::path& p) {
  try {
    read_model(p);
  } catch (const io::FormatError& e) {
    return e.what();
  }
  return "(no error)";
}

// A binary STL read by hand: 80 header bytes, a uint32 count, 50 bytes per triangle (normal,
// three vertices, attribute).
std::vector<std::array<glm::vec3, 3>> stl_triangles(const std::vector<char>& b) {
  std::uint32_t n = 0;
  std::memcpy(&n, b.data() + 80, 4);
  std::vector<std::array<glm::vec3, 3>> out(n);
  for (std::uint32_t t = 0; t < n; ++t) {
    for (int v = 0; v < 3; ++v) std::memcpy(&out[t][static_cast<std::size_t>(v)], b.data() + 84 + 50 * t + 12 + 12 * v, 12);
  }
  return out;
}

TEST(Model, BinaryStlGivesTheFilesTrianglesInOrder) {
  REQUIRE_ASSIMP_MODEL("STL/Spider_binary.stl");
  const auto file = test::assimp_model("STL/Spider_binary.stl");
  const Model m = read_model(file);
  std::vector<std::array<glm::vec3, 3>> expected;
  for (const auto& t : stl_triangles(bytes_of(file))) {
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) expected.push_back(t);
  }
  ASSERT_EQ(m.mesh.triangle_count(), expected.size());
  for (std::size_t t = 0; t < expected.size(); ++t) {
    for (std::size_t v = 0; v < 3; ++v) {
      const glm::dvec3 got = m.mesh.vertices[m.mesh.triangles[3 * t + v]];
      ASSERT_EQ(glm::vec3(got), expected[t][v]) << "triangle " << t << " vertex " << v;
    }
  }
  EXPECT_LT(m.mesh.vertices.size(), 3 * expected.size()) << "shared vertices are joined";
}

TEST(Model, PlyQuadsBecomeTwoTrianglesEach) {
  REQUIRE_ASSIMP_MODEL("PLY/cube.ply");
  const Model m = read_model(test::assimp_model("PLY/cube.ply"));
  EXPECT_EQ(m.mesh.triangle_count(), 12u);  // six quad faces in the file
  glm::dvec3 lo(1e9), hi(-1e9);
  for (const auto& v : m.mesh.vertices) {
    lo = glm::min(lo, v);
    hi = glm::max(hi, v);
  }
  EXPECT_EQ(lo, glm::dvec3(0.0));
  EXPECT_EQ(hi, glm::dvec3(1.0));
}

TEST(Model, PerVertexColoursAreTheFiles) {
  REQUIRE_ASSIMP_MODEL("PLY/float-color.ply");
  const Model m = read_model(test::assimp_model("PLY/float-color.ply"));
  ASSERT_EQ(m.mesh.triangle_count(), 1u);
  EXPECT_TRUE(m.vertex_colors);
  for (const auto& c : m.mesh.colors) EXPECT_EQ(c, glm::u8vec4(0, 0, 255, 255));  // "0 0 1 1" per vertex
}

// The truck's triangles counted from its glTF file: each node's meshes' primitives' index
// counts over three, every node of the default scene's hierarchy counted.
std::size_t gltf_triangles(const nlohmann::json& d, const std::string& node) {
  std::size_t n = 0;
  const auto& nd = d["nodes"][node];
  if (nd.contains("meshes")) {
    for (const auto& mesh : nd["meshes"]) {
      for (const auto& p : d["meshes"][mesh.get<std::string>()]["primitives"]) {
        n += d["accessors"][p["indices"].get<std::string>()]["count"].get<std::size_t>() / 3;
      }
    }
  }
  for (const auto& c : nd["children"]) n += gltf_triangles(d, c.get<std::string>());
  return n;
}

TEST(Model, GltfMilkTruckHasEveryNodesTrianglesAndMaterialColours) {
  REQUIRE_ASSIMP_MODEL("glTF/CesiumMilkTruck/CesiumMilkTruck.gltf");
  const auto file = test::assimp_model("glTF/CesiumMilkTruck/CesiumMilkTruck.gltf");
  const nlohmann::json d = nlohmann::json::parse(std::ifstream(file));
  std::size_t expected = 0;
  for (const auto& n : d["scenes"][d["scene"].get<std::string>()]["nodes"]) expected += gltf_triangles(d, n.get<std::string>());
  const Model m = read_model(file);
  EXPECT_EQ(m.mesh.triangle_count(), expected);
  EXPECT_EQ(m.meshes, 5u);  // truck, glass, window trim, and the wheels mesh used by two nodes
  // The window trim's diffuse colour [0.064, 0.064, 0.064] is 16/255 on some vertices.
  bool trim = false;
  for (const auto& c : m.mesh.colors) trim = trim || c == glm::u8vec4(16, 16, 16, 255);
  EXPECT_TRUE(trim);
}

TEST(Model, ObjMaterialColourAndOpacity) {
  test::TempDir dir;
  write(dir.path() / "m.mtl", "newmtl red\nKd 1 0 0\nd 0.5\n");
  write(dir.path() / "m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl red\nf 1 2 3 4\n");
  const Model m = read_model(dir.path() / "m.obj");
  ASSERT_EQ(m.mesh.triangle_count(), 2u);
  for (const auto& c : m.mesh.colors) EXPECT_EQ(c, glm::u8vec4(255, 0, 0, 128));
}

// m.obj in `dir`: one triangle with texture coordinates, its material in m.mtl: `colour` (an
// MTL line, or empty) and the diffuse texture `texture`.
std::filesystem::path textured_triangle(const test::TempDir& dir, const std::string& colour, const std::string& texture) {
  write(dir.path() / "m.mtl", "newmtl textured\n" + colour + "map_Kd " + texture + "\n");
  write(dir.path() / "m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl textured\nf 1/1 2/2 3/3\n");
  return dir.path() / "m.obj";
}

// A 2 x 2 texture (a binary PPM beside the model: its first row is the image's top) on a
// quad whose texture coordinates lie on the texels' centres: each corner takes its texel's
// colour times the material's (v = 0 is the image's bottom row).
TEST(Model, TextureColoursAreSampledAtTheVerticesTextureCoordinates) {
  test::TempDir dir;
  const std::string ppm = std::string("P6\n2 2\n255\n") + std::string("\x00\x00\xff\xff\xff\xff", 6) +  // top: blue, white
                          std::string("\xff\x00\x00\x00\xff\x00", 6);                                       // bottom: red, green
  write(dir.path() / "t.ppm", ppm);
  write(dir.path() / "m.mtl", "newmtl textured\nKd 1 1 0.5\nmap_Kd t.ppm\n");
  write(dir.path() / "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "vt 0.25 0.25\nvt 0.75 0.25\nvt 0.75 0.75\nvt 0.25 0.75\nusemtl textured\nf 1/1 2/2 3/3 4/4\n");
  const Model m = read_model(dir.path() / "m.obj");
  ASSERT_EQ(m.mesh.triangle_count(), 2u);
  EXPECT_EQ(m.textured_meshes, 1u);
  EXPECT_TRUE(m.missing_textures.empty());
  const std::map<std::pair<double, double>, glm::u8vec4> expected = {
      {{0.0, 0.0}, {255, 0, 0, 255}}, {{1.0, 0.0}, {0, 255, 0, 255}}, {{1.0, 1.0}, {255, 255, 128, 255}}, {{0.0, 1.0}, {0, 0, 128, 255}}};
  ASSERT_EQ(m.mesh.vertices.size(), 4u);
  for (std::size_t v = 0; v < 4; ++v) {
    const auto it = expected.find({m.mesh.vertices[v].x, m.mesh.vertices[v].y});
    ASSERT_NE(it, expected.end());
    EXPECT_EQ(m.mesh.colors[v], it->second) << "vertex " << v;
  }
  // Half way between two texels' centres the colour is their mean.
  write(dir.path() / "h.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0.5 0.25\nvt 0.5 0.25\nvt 0.5 0.25\nusemtl textured\nf 1/1 2/2 3/3\n");
  for (const auto& c : read_model(dir.path() / "h.obj").mesh.colors) EXPECT_EQ(c, glm::u8vec4(128, 128, 0, 255));
}

// A texture the material names that cannot be read: absent, or a PNG cut short after its
// header (its checksum wrong too; VTK's PNG reader takes the process down on it, libpng's
// error jumping out of it, so textures are decoded in a child process). Either costs a
// warning, not the model: the material's colour, and the texture's name reported.
TEST(Model, ATextureThatCannotBeReadLeavesTheMaterialsColourAndIsReported) {
  const std::string cut = std::string("\x89PNG\r\n\x1a\n", 8) + std::string("\0\0\0\x0dIHDR", 8) +
                          std::string("\0\0\0\x02\0\0\0\x02\x08\x02\0\0\0", 13) + std::string("\x01\x02\x03\x04", 4) +
                          std::string("\0\0\0\x10IDAT", 8);
  for (const auto& [name, bytes] : {std::pair<std::string, std::string>{"gone.png", ""}, {"cut.png", cut}}) {
    test::TempDir dir;
    if (!bytes.empty()) write(dir.path() / name, bytes);
    const Model m = read_model(textured_triangle(dir, "Kd 0 1 0\n", name));
    EXPECT_EQ(m.textured_meshes, 0u) << name;
    ASSERT_EQ(m.missing_textures.size(), 1u) << name;
    EXPECT_EQ(m.missing_textures[0], name);
    for (const auto& c : m.mesh.colors) EXPECT_EQ(c, glm::u8vec4(0, 255, 0, 255)) << name;
  }
}

// A texture whose header claims 10^10 pixels is refused from its header, naming the model and
// the texture.
TEST(Model, AnAbsurdlyLargeTextureIsRefusedFromItsHeader) {
  test::TempDir dir;
  write(dir.path() / "big.ppm", "P6\n100000 100000\n255\n\x01\x02\x03");
  try {
    read_model(textured_triangle(dir, "", "big.ppm"));
    FAIL() << "an absurd texture was read";
  } catch (const io::FormatError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("m.obj"), std::string::npos) << what;
    EXPECT_NE(what.find("big.ppm"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(Model, BadInputIsOneLineNamingTheFile) {
  test::TempDir dir;
  const auto expect_error = [](const std::filesystem::path& p, const std::string& part) {
    const std::string e = error_of(p);
    EXPECT_EQ(e.rfind(p.string() + ": ", 0), 0u) << e;
    EXPECT_NE(e.find(part), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  };
  expect_error(dir.path() / "absent.glb", "no such file");
  write(dir.path() / "empty.obj", "");
  expect_error(dir.path() / "empty.obj", "empty file");
  write(dir.path() / "junk.stl", std::string("solid x\nthis is not an stl file at all\n"));
  expect_error(dir.path() / "junk.stl", "");
  write(dir.path() / "junk.gltf", "{ \"asset\": ");
  expect_error(dir.path() / "junk.gltf", "");
  write(dir.path() / "junk.xyzzy", "nothing assimp knows");
  expect_error(dir.path() / "junk.xyzzy", "");
  write(dir.path() / "lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n");
  expect_error(dir.path() / "lines.obj", "no triangles");
  expect_error(dir.path(), "not a regular file");
  if (std::filesystem::exists(test::assimp_model("PLY/points.ply"))) {
    expect_error(test::assimp_model("PLY/points.ply"), "no triangles");
  }
  if (std::filesystem::exists(test::assimp_model("PLY/pond.0.ply"))) {
    expect_error(test::assimp_model("PLY/pond.0.ply"), "no triangles");  // a coloured point cloud
  }
}

TEST(Model, TruncatedBinaryStlIsRefusedAtEveryLength) {
  REQUIRE_ASSIMP_MODEL("STL/Spider_binary.stl");
  const std::vector<char> b = bytes_of(test::assimp_model("STL/Spider_binary.stl"));
  test::TempDir dir;
  const auto p = dir.path() / "cut.stl";
  for (std::size_t n : {std::size_t{1}, std::size_t{80}, std::size_t{84}, std::size_t{100}, b.size() / 2, b.size() - 1}) {
    std::ofstream(p, std::ios::binary).write(b.data(), static_cast<std::streamsize>(n));
    const std::string e = error_of(p);
    EXPECT_EQ(e.rfind(p.string() + ": ", 0), 0u) << n << " bytes: " << e;
  }
}

TEST(Model, AbsurdlyLargeModelIsRefused) {
  // A binary STL claiming kMaxModelTriangles + 1 triangles, with the bytes to hold them.
  test::TempDir dir;
  const auto p = dir.path() / "huge.stl";
  const std::uint32_t n = static_cast<std::uint32_t>(kMaxModelTriangles + 1);
  std::vector<char> b(84 + 50 * static_cast<std::size_t>(n), 0);
  std::memcpy(b.data() + 80, &n, 4);
  for (std::uint32_t t = 0; t < n; ++t) {
    const float v[9] = {static_cast<float>(t), 0, 0, static_cast<float>(t) + 1, 0, 0, static_cast<float>(t), 1, 0};
    std::memcpy(b.data() + 84 + 50 * static_cast<std::size_t>(t) + 12, v, sizeof v);
  }
  std::ofstream(p, std::ios::binary).write(b.data(), static_cast<std::streamsize>(b.size()));
  EXPECT_NE(error_of(p).find("too large"), std::string::npos) << error_of(p);
}

}  // namespace
}  // namespace terravol::objects
