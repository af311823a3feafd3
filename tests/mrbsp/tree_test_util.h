// Helpers of the mrbsp tests: small windows and the brute-force order check.
#pragma once

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mrbsp/terrain_tree.h"

namespace terravol::mrbsp::test {

// A window of n x n cells, 100 m spacing, heights from `height(i, j)`.
struct TestWindow {
  std::vector<double> xs, ys;
  std::vector<float> z;
  int n;
  template <class F>
  TestWindow(int cells, F height, double x0 = 0.0, double y0 = 0.0) : n(cells) {
    for (int i = 0; i <= n; ++i) {
      xs.push_back(x0 + 100.0 * i);
      ys.push_back(y0 + 100.0 * i);
    }
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) z.push_back(height(i, j));
  }
  TerrainWindow view() const { return {n, xs, ys, z}; }
};

// A 64 x 64-sample random terrain (heights uniform in [0, 300) m, fixed seed) to slide 16-cell
// windows over: window_at(ox, oy) starts at sample (ox, oy), at (100 ox, 100 oy) metres.
struct SlidingTerrain {
  std::vector<float> big;
  explicit SlidingTerrain(unsigned seed) : big(64 * 64) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> h(0.0f, 300.0f);
    for (float& v : big) v = h(rng);
  }
  TestWindow window_at(int ox, int oy) const {
    return TestWindow(16, [&](int i, int j) { return big[static_cast<std::size_t>((oy + j) * 64 + ox + i)]; },
                      100.0 * ox, 100.0 * oy);
  }
};

// Distance along the ray to the triangle, or a negative value when it misses (Moller-Trumbore).
inline double ray_triangle(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a, const glm::dvec3& b,
                    const glm::dvec3& c) {
  const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::abs(det) < 1e-12) return -1.0;
  const glm::dvec3 s = o - a;
  const double u = glm::dot(s, p) / det;
  if (u < 0.0 || u > 1.0) return -1.0;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(d, q) / det;
  if (v < 0.0 || u + v > 1.0) return -1.0;
  return glm::dot(e2, q) / det;
}

// For rays from the eye in many directions: along each ray, hits must be drawn from the
// farthest to the nearest (back-to-front) or the reverse. Hits at the same distance (shared
// edges, coplanar skirts) are not ordered against each other. Returns the violations.
inline int order_violations(const TerrainTree& tree, const Frame& f, const glm::dvec3& eye, int rays, std::mt19937& rng,
                     bool back_to_front) {
  const auto& p = tree.positions();
  std::normal_distribution<double> g;
  int violations = 0;
  std::vector<std::pair<double, std::size_t>> hits;
  for (int r = 0; r < rays; ++r) {
    glm::dvec3 d(g(rng), g(rng), g(rng));
    d = glm::normalize(d);
    hits.clear();
    for (std::size_t t = 0; t < f.indices.size() / 3; ++t) {
      const double dist = ray_triangle(eye, d, p[f.indices[3 * t]], p[f.indices[3 * t + 1]], p[f.indices[3 * t + 2]]);
      if (dist > 0) hits.emplace_back(dist, t);
    }
    std::sort(hits.begin(), hits.end());
    for (std::size_t a = 0; a < hits.size(); ++a)
      for (std::size_t b = a + 1; b < hits.size(); ++b) {
        if (hits[b].first - hits[a].first < 1e-6 * hits[b].first) continue;
        // hits[a] is nearer: back-to-front draws it later.
        if (back_to_front ? hits[a].second < hits[b].second : hits[a].second > hits[b].second) ++violations;
      }
  }
  return violations;
}

}  // namespace terravol::mrbsp::test
