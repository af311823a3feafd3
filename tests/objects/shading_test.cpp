// objects::sunlit: the terrain's hillshade on a placed model, two-sided, flat across sharp
// edges and smooth across gentle ones.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/geometric.hpp>

#include "objects/shading.h"

namespace terravol::objects {
namespace {

// An axis-aligned cube of side 2 about the origin, 8 shared corners, outward winding, one
// colour.
volume::Mesh cube(glm::u8vec4 colour) {
  volume::Mesh m;
  for (int c = 0; c < 8; ++c) {
    m.vertices.emplace_back(c & 1 ? 1.0 : -1.0, c & 2 ? 1.0 : -1.0, c & 4 ? 1.0 : -1.0);
    m.colors.push_back(colour);
  }
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) m.triangles.insert(m.triangles.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  return m;
}

// The colour of the triangle whose first corner's face normal is `n` (all its corners share it).
glm::u8vec4 face_colour(const volume::Mesh& lit, const glm::dvec3& n) {
  for (std::size_t t = 0; t < lit.triangle_count(); ++t) {
    const glm::dvec3 a = lit.vertices[lit.triangles[3 * t]], b = lit.vertices[lit.triangles[3 * t + 1]],
                     c = lit.vertices[lit.triangles[3 * t + 2]];
    const glm::dvec3 f = glm::normalize(glm::cross(b - a, c - a));
    if (glm::dot(f, n) > 0.999) {
      const glm::u8vec4 first = lit.colors[lit.triangles[3 * t]];
      for (int k = 1; k < 3; ++k) EXPECT_EQ(lit.colors[lit.triangles[3 * t + static_cast<std::size_t>(k)]], first) << "a flat face";
      return first;
    }
  }
  ADD_FAILURE() << "no face with normal " << n.x << " " << n.y << " " << n.z;
  return {};
}

TEST(Sunlit, ACubeIsLitFaceByFaceAsTheTerrainIsByTheSameSun) {
  const volume::Mesh in = cube({200, 100, 50, 128});
  Sunlight sun;
  sun.azimuth_deg = 90.0;  // from the east
  sun.elevation_deg = 30.0;
  sun.ambient = 0.35;
  const volume::Mesh lit = sunlit(in, sun);
  EXPECT_EQ(lit.triangle_count(), in.triangle_count());
  EXPECT_EQ(lit.vertices.size(), 24u) << "each corner split between its three faces";
  // Up and down: |n . sun| = sin 30, shade 1: the colour as it was, the alpha kept.
  EXPECT_EQ(face_colour(lit, {0, 0, 1}), (glm::u8vec4{200, 100, 50, 128}));
  EXPECT_EQ(face_colour(lit, {0, 0, -1}), (glm::u8vec4{200, 100, 50, 128})) << "two-sided";
  // East and west: cos 30 / sin 30 = 1.732, shade min(0.35 + 0.65 * 1.732, 1.3) = 1.3.
  EXPECT_EQ(face_colour(lit, {1, 0, 0}), (glm::u8vec4{255, 130, 65, 128}));
  EXPECT_EQ(face_colour(lit, {-1, 0, 0}), (glm::u8vec4{255, 130, 65, 128}));
  // North and south: perpendicular to the light, the ambient share alone.
  EXPECT_EQ(face_colour(lit, {0, 1, 0}), (glm::u8vec4{70, 35, 18, 128}));
  EXPECT_EQ(face_colour(lit, {0, -1, 0}), (glm::u8vec4{70, 35, 18, 128}));
  for (std::size_t t = 0; t < lit.triangles.size(); ++t) {
    EXPECT_EQ(lit.vertices[lit.triangles[t]], in.vertices[in.triangles[t]]) << "the same corners, in the same order";
  }
}

// A finely tessellated sphere bends by a few degrees between neighbours: no vertex is split,
// and the shade is the hillshade of the sphere's own normal at each vertex (seeded sun).
TEST(Sunlit, ASmoothSurfaceKeepsItsVerticesAndIsShadedByItsNormal) {
  volume::Mesh sphere;
  constexpr int kRings = 40, kSegments = 80;
  for (int r = 0; r <= kRings; ++r) {
    for (int s = 0; s < kSegments; ++s) {
      const double theta = M_PI * r / kRings, phi = 2 * M_PI * s / kSegments;
      sphere.vertices.emplace_back(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      sphere.colors.emplace_back(100, 100, 100, 255);
    }
  }
  for (int r = 0; r < kRings; ++r) {
    for (int s = 0; s < kSegments; ++s) {
      const auto at = [&](int rr, int ss) { return static_cast<std::uint32_t>(rr * kSegments + (ss % kSegments)); };
      if (r > 0) sphere.triangles.insert(sphere.triangles.end(), {at(r, s), at(r + 1, s), at(r, s + 1)});
      if (r + 1 < kRings) sphere.triangles.insert(sphere.triangles.end(), {at(r, s + 1), at(r + 1, s), at(r + 1, s + 1)});
    }
  }
  std::mt19937 rng(20261206);
  for (int trial = 0; trial < 5; ++trial) {
    Sunlight sun;
    sun.azimuth_deg = std::uniform_real_distribution<double>(0.0, 360.0)(rng);
    sun.elevation_deg = std::uniform_real_distribution<double>(30.0, 80.0)(rng);
    const volume::Mesh lit = sunlit(sphere, sun);
    ASSERT_EQ(lit.vertices.size(), sphere.vertices.size()) << "no vertex split";
    const double az = sun.azimuth_deg * M_PI / 180, el = sun.elevation_deg * M_PI / 180;
    const glm::dvec3 towards(std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
    for (std::size_t v = 0; v < lit.vertices.size(); ++v) {
      if (std::abs(lit.vertices[v].z) > 0.99) continue;  // the poles' copies, each on one triangle
      const glm::dvec3 n = glm::normalize(lit.vertices[v]);
      const double s = std::min(0.35 + 0.65 * std::abs(glm::dot(n, towards)) / std::sin(el), 1.3);
      EXPECT_NEAR(lit.colors[v].r, 100 * s, 2.5) << "vertex " << v;
    }
  }
}

TEST(Sunlit, ASunBelowTheHorizonOrABadAmbientIsRefused) {
  Sunlight sun;
  sun.elevation_deg = 0.0;
  EXPECT_THROW(sunlit(cube({1, 2, 3, 4}), sun), std::invalid_argument);
  sun.elevation_deg = 30.0;
  sun.ambient = 1.5;
  EXPECT_THROW(sunlit(cube({1, 2, 3, 4}), sun), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::objects
