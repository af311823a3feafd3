#include "objects/lod.h"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <random>
#include <string>

#include "objects/model.h"
#include "objects/test_models.h"

namespace terravol::objects {
namespace {

// A unit square in the plane z = z0, two triangles.
volume::Mesh square(double z0, glm::u8vec4 c = {255, 255, 255, 255}) {
  volume::Mesh m;
  m.vertices = {{0, 0, z0}, {1, 0, z0}, {1, 1, z0}, {0, 1, z0}};
  m.colors.assign(4, c);
  m.triangles = {0, 1, 2, 0, 2, 3};
  return m;
}

TEST(Hausdorff, OfAShiftedParallelSquareIsTheShift) {
  EXPECT_NEAR(hausdorff_distance(square(0.0), square(0.25)), 0.25, 1e-9);
  EXPECT_NEAR(hausdorff_distance(square(0.0), square(0.0)), 0.0, 1e-12);
}

TEST(Hausdorff, SeesThePointFarthestFromTheOtherSurface) {
  // A square against its half: the far edge of the whole square is 0.5 from the half (x <= 0.5),
  // the half is on the square (distance 0): the Hausdorff distance is the larger, 0.5.
  volume::Mesh half = square(0.0);
  half.vertices[1].x = half.vertices[2].x = 0.5;
  EXPECT_NEAR(hausdorff_distance(square(0.0), half), 0.5, 1e-9);
}

// The closest point of triangle abc to p (C. Ericson, Real-Time Collision Detection, 5.1.5).
glm::dvec3 closest_on_triangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// The largest distance from a vertex of `from` to the triangles of `to`, by brute force.
double vertex_distance(const volume::Mesh& from, const volume::Mesh& to) {
  double worst = 0;
  for (const glm::dvec3& p : from.vertices) {
    double best = INFINITY;
    for (std::size_t t = 0; t < to.triangles.size(); t += 3) {
      const glm::dvec3 q = closest_on_triangle(p, to.vertices[to.triangles[t]], to.vertices[to.triangles[t + 1]],
                                               to.vertices[to.triangles[t + 2]]);
      best = std::min(best, glm::length(p - q));
    }
    worst = std::max(worst, best);
  }
  return worst;
}

struct Counts {
  const char* file;
  LodMethod method;
};

class LodLevels : public ::testing::TestWithParam<Counts> {};

TEST_P(LodLevels, EachAboutAQuarterOfThePreviousWithGrowingError) {
  REQUIRE_ASSIMP_MODEL(GetParam().file);
  const Model model = read_model(test::assimp_model(GetParam().file));
  LodOptions o;
  o.method = GetParam().method;
  const std::vector<Lod> lods = make_lods(model.mesh, o);
  // Levels until one would have fewer than 12 triangles: at least 4 of the 5 on these models
  // (1,312 to 3,624 triangles and more).
  ASSERT_GE(lods.size(), 4u) << "a model of " << model.mesh.triangle_count() << " triangles";
  EXPECT_EQ(lods[0].mesh.triangle_count(), model.mesh.triangle_count());
  EXPECT_EQ(lods[0].error, 0.0);
  const bool brute_force = model.mesh.triangle_count() <= 4000;
  const double n = static_cast<double>(model.mesh.triangle_count());
  for (std::size_t k = 1; k < lods.size(); ++k) {
    const double t = static_cast<double>(lods[k].mesh.triangle_count()), target = n * std::pow(0.25, static_cast<double>(k));
    EXPECT_LE(t, target * 1.5 + 2) << "level " << k;
    EXPECT_GE(t, target * 0.25) << "level " << k;
    EXPECT_LT(t, static_cast<double>(lods[k - 1].mesh.triangle_count())) << "level " << k;
    EXPECT_GT(lods[k].hausdorff, 0.0) << "level " << k;
    EXPECT_EQ(lods[k].error, std::max(lods[k].hausdorff, lods[k - 1].error)) << "level " << k;
    if (!brute_force) continue;
    // Independently, by brute force: every vertex of each mesh is among the samples, so its
    // distance to the other surface bounds the Hausdorff distance measured from below.
    const double vertices = std::max(vertex_distance(model.mesh, lods[k].mesh), vertex_distance(lods[k].mesh, model.mesh));
    EXPECT_LE(vertices, lods[k].hausdorff * (1 + 1e-9) + 1e-12) << "level " << k;
    EXPECT_GT(vertices, 0.2 * lods[k].hausdorff) << "level " << k;
    ASSERT_EQ(lods[k].mesh.colors.size(), lods[k].mesh.vertices.size());
  }
}

INSTANTIATE_TEST_SUITE_P(TestModels, LodLevels,
                         ::testing::Values(Counts{"glTF/CesiumMilkTruck/CesiumMilkTruck.gltf", LodMethod::kDecimation},
                                           Counts{"glTF/CesiumMilkTruck/CesiumMilkTruck.gltf", LodMethod::kClustering},
                                           Counts{"PLY/Wuson.ply", LodMethod::kDecimation},
                                           Counts{"STL/Spider_binary.stl", LodMethod::kDecimation}),
                         [](const auto& param_info) {
                           const std::string file = param_info.param.file;
                           std::string f = file.substr(file.rfind('/') + 1);
                           f = f.substr(0, f.find('.'));
                           return file.substr(0, file.find('/')) + "_" + f +
                                  (param_info.param.method == LodMethod::kClustering ? "_clustering" : "_decimation");
                         });

TEST(Lod, RefusesAnEmptyModelAndBadOptions) {
  EXPECT_THROW(make_lods(volume::Mesh{}), std::invalid_argument);
  LodOptions o;
  o.ratio = 1.0;
  EXPECT_THROW(make_lods(square(0.0), o), std::invalid_argument);
  o.ratio = 0.25;
  o.levels = 0;
  EXPECT_THROW(make_lods(square(0.0), o), std::invalid_argument);
}

TEST(Lod, TinyModelKeepsOnlyItsFullLevel) {
  EXPECT_EQ(make_lods(square(0.0)).size(), 1u);  // 2 triangles: no level of 12 or more below it
}

TEST(ColorCube, IsTheBoxWithEachFaceTheColourFacingThatWay) {
  // Two squares: one facing +z (red) at z = 1, one facing -z (blue, reversed winding) at z = 0.
  volume::Mesh m = square(1.0, {255, 0, 0, 255});
  volume::Mesh down = square(0.0, {0, 0, 255, 200});
  down.triangles = {0, 2, 1, 0, 3, 2};
  volume::append(m, down);
  const volume::Mesh cube = color_cube(m);
  ASSERT_EQ(cube.triangle_count(), 12u);
  for (std::size_t t = 0; t < cube.triangles.size(); t += 3) {
    const glm::dvec3 a = cube.vertices[cube.triangles[t]], b = cube.vertices[cube.triangles[t + 1]],
                     c = cube.vertices[cube.triangles[t + 2]];
    const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    const glm::dvec3 centre = (a + b + c) / 3.0;
    EXPECT_GT(glm::dot(n, centre - glm::dvec3(0.5)), 0.0) << "faces outward";
    const glm::u8vec4 col = cube.colors[cube.triangles[t]];
    // The sides face no triangle: the area-weighted mean of both.
    const glm::u8vec4 want = n.z > 0.5 ? glm::u8vec4(255, 0, 0, 255) : n.z < -0.5 ? glm::u8vec4(0, 0, 255, 200) : glm::u8vec4(128, 0, 128, 228);
    EXPECT_EQ(col, want);
    for (const glm::dvec3& p : {a, b, c}) {
      EXPECT_TRUE(p.x == 0.0 || p.x == 1.0);
      EXPECT_TRUE(p.z == 0.0 || p.z == 1.0);
    }
  }
}

}  // namespace
}  // namespace terravol::objects
