// Helpers of the volume geometry tests (geometry_test.cpp, textured_slice_test.cpp,
// reduction_test.cpp): small volumes in each frame, the Mesh invariants, and brute-force
// distances.
#pragma once

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "io/scene_frame.h"
#include "volume/geometry.h"

namespace terravol::volume::test {

inline constexpr double kLat0 = 45.5, kLon0 = 6.5;

// A volume with the given frame whose lattice starts at the south-west-bottom corner `origin`.
inline Volume make_volume(std::array<int, 3> dims, FrameKind kind, HeightRef height, std::array<double, 3> origin,
                          std::array<double, 3> spacing) {
  Volume v;
  v.name = "test_field";
  v.frame.kind = kind;
  v.frame.height = height;
  if (kind == FrameKind::kEnu) {
    v.frame.origin_lat = kLat0;
    v.frame.origin_lon = kLon0;
    v.frame.origin_h = 500.0;
  }
  v.lattice.dims = dims;
  v.lattice.origin = origin;
  v.lattice.spacing = spacing;
  v.values.assign(v.lattice.size(), 0.0f);
  v.active_points = v.values.size();
  return v;
}

// Geographic, heights above the datum: about 65 m (lon) x 62 m (lat) x 50 m cells.
inline Volume geographic_volume(std::array<int, 3> dims, HeightRef height = HeightRef::kDatum) {
  return make_volume(dims, FrameKind::kGeographic, height, {kLon0 - 0.01, kLat0 - 0.01, 100.0},
                     {1.0 / 1200.0, 1.0 / 1800.0, 50.0});
}

// Sets every point to f(scene position of the point).
template <class F>
void fill(Volume& v, const LatticeMapper& m, F f) {
  for (int k = 0; k < v.lattice.dims[2]; ++k)
    for (int j = 0; j < v.lattice.dims[1]; ++j)
      for (int i = 0; i < v.lattice.dims[0]; ++i) {
        const io::ScenePoint p = m.scene(i, j, k);
        v.values[v.lattice.index(i, j, k)] = static_cast<float>(f(glm::dvec3(p.x, p.y, p.z)));
      }
}

// Lattice coordinates of a scene point, for geographic volumes with heights above the datum.
inline glm::dvec3 lattice_of(const Volume& v, const io::SceneFrame& frame, const glm::dvec3& p) {
  const io::Geodetic g = frame.to_geodetic({p.x, p.y, p.z});
  const auto& l = v.lattice;
  return {(g.lon - l.origin[0]) / l.spacing[0], (g.lat - l.origin[1]) / l.spacing[1], (g.h - l.origin[2]) / l.spacing[2]};
}

inline double triangle_area(const Mesh& m, std::size_t t) {
  const glm::dvec3 a = m.vertices[m.triangles[3 * t]], b = m.vertices[m.triangles[3 * t + 1]],
                   c = m.vertices[m.triangles[3 * t + 2]];
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

inline glm::dvec3 centroid(const Mesh& m, std::size_t t) {
  return (m.vertices[m.triangles[3 * t]] + m.vertices[m.triangles[3 * t + 1]] + m.vertices[m.triangles[3 * t + 2]]) /
         3.0;
}

// The Mesh invariants of geometry.h.
inline void expect_valid(const Mesh& m) {
  ASSERT_EQ(m.colors.size(), m.vertices.size());
  ASSERT_EQ(m.triangles.size() % 3, 0u);
  std::vector<bool> used(m.vertices.size(), false);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t a = m.triangles[3 * t], b = m.triangles[3 * t + 1], c = m.triangles[3 * t + 2];
    ASSERT_LT(a, m.vertices.size());
    ASSERT_LT(b, m.vertices.size());
    ASSERT_LT(c, m.vertices.size());
    EXPECT_TRUE(a != b && b != c && a != c) << "triangle " << t;
    EXPECT_GT(triangle_area(m, t), 0.0) << "triangle " << t;
    used[a] = used[b] = used[c] = true;
  }
  EXPECT_EQ(std::count(used.begin(), used.end(), false), 0) << "unused vertices";
  for (const glm::dvec3& p : m.vertices) EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
}

// How many triangles use each directed edge.
inline std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed_edges(const Mesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    for (int e = 0; e < 3; ++e) ++edges[{m.triangles[3 * t + e], m.triangles[3 * t + (e + 1) % 3]}];
  return edges;
}

// The distance from p to triangle (a, b, c), by the closest point on the plane when it falls
// inside the triangle, else on the nearest edge (brute force, no acceleration).
inline double point_triangle_distance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  auto segment = [&](const glm::dvec3& s, const glm::dvec3& e) {
    const glm::dvec3 d = e - s;
    const double t = std::clamp(glm::dot(p - s, d) / glm::dot(d, d), 0.0, 1.0);
    return glm::length(p - (s + t * d));
  };
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double n2 = glm::dot(n, n);
  if (n2 > 0.0) {
    const glm::dvec3 q = p - glm::dot(p - a, n) / n2 * n;  // projection onto the plane
    const double wa = glm::dot(glm::cross(c - b, q - b), n), wb = glm::dot(glm::cross(a - c, q - c), n),
                 wc = glm::dot(glm::cross(b - a, q - a), n);
    if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0) return glm::length(p - q);
  }
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

// The distance from p to the nearest triangle of m.
inline double distance_to_mesh(const glm::dvec3& p, const Mesh& m) {
  double best = INFINITY;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    best = std::min(best, point_triangle_distance(p, m.vertices[m.triangles[3 * t]], m.vertices[m.triangles[3 * t + 1]],
                                                  m.vertices[m.triangles[3 * t + 2]]));
  }
  return best;
}

// ---- Slices

inline SliceSpec at(SliceKind kind, double value) {
  SliceSpec s;
  s.kind = kind;
  s.value = value;
  return s;
}

struct Scene {
  Volume volume;
  io::SceneFrame frame{kLat0, kLon0};
  GroundFunction ground;
  LatticeMapper mapper;

  Scene(Volume v, GroundFunction g = {}) : volume(std::move(v)), ground(std::move(g)), mapper(volume, frame, ground) {}
};

// A smooth terrain of 300 .. 900 m under the test volumes.
inline double hills(double lat, double lon) {
  return 600.0 + 200.0 * std::sin((lat - kLat0) * 300.0) + 100.0 * std::cos((lon - kLon0) * 250.0);
}

}  // namespace terravol::volume::test
