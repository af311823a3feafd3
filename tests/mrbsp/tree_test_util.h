// Helpers of the mrbsp tests: small windows and the brute-force order check.
#pragma once

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
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
// A camera at `eye` looking along `forward` (not vertical), level, fov_y degrees high.
inline Camera looking(const glm::dvec3& eye, const glm::dvec3& forward, double fov_y, int width, int height,
                      double near_plane) {
  Camera c;
  c.eye = eye;
  c.forward = glm::normalize(forward);
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
  c.fov_y_deg = fov_y;
  c.width = width;
  c.height = height;
  c.near_plane = near_plane;
  return c;
}

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

// Vertex k of a frame: the tree's, or one of the frame's own (colour boxes' faces).
inline glm::dvec3 frame_vertex(const TerrainTree& tree, const Frame& f, std::uint32_t k) {
  if (k >= f.transient_base) return glm::dvec3(f.transient_positions[k - f.transient_base]);
  return glm::dvec3(tree.positions()[k]);
}

// For rays from the eye in many directions: along each ray, hits must be drawn from the
// farthest to the nearest (back-to-front) or the reverse. Hits at the same distance (shared
// edges, coplanar crack fills) are not ordered against each other. Returns the violations.
inline int order_violations(const TerrainTree& tree, const Frame& f, const glm::dvec3& eye, int rays, std::mt19937& rng,
                     bool back_to_front) {
  const auto p = [&](std::uint32_t k) { return frame_vertex(tree, f, k); };
  std::normal_distribution<double> g;
  int violations = 0;
  std::vector<std::pair<double, std::size_t>> hits;
  for (int r = 0; r < rays; ++r) {
    glm::dvec3 d(g(rng), g(rng), g(rng));
    d = glm::normalize(d);
    hits.clear();
    for (std::size_t t = 0; t < f.indices.size() / 3; ++t) {
      const double dist = ray_triangle(eye, d, p(f.indices[3 * t]), p(f.indices[3 * t + 1]), p(f.indices[3 * t + 2]));
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

// A 4-level tree over `w` with rolling hills (50-390 m) and random noise.
inline TerrainTree hilly_tree(std::mt19937& rng, TestWindow& w) {
  std::uniform_real_distribution<float> h(0.0f, 40.0f);
  for (std::size_t k = 0; k < w.z.size(); ++k)
    w.z[k] = 200.0f + 150.0f * std::sin(0.4f * static_cast<float>(k % 17)) * std::cos(0.3f * static_cast<float>(k / 17)) + h(rng);
  return TerrainTree(w.view(), 4);
}

}  // namespace terravol::mrbsp::test

namespace terravol::mrbsp::test {

// --- An independent reference for merged areas: brute-force convex clipping -----------------

using Poly3 = std::vector<glm::dvec3>;

// The part of a convex polygon where dot(n, p) + d >= 0 (Sutherland-Hodgman, one plane).
inline Poly3 clip_polygon(const Poly3& in, const glm::dvec3& n, double d) {
  Poly3 out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const glm::dvec3 &a = in[i], &b = in[(i + 1) % in.size()];
    const double sa = glm::dot(n, a) + d, sb = glm::dot(n, b) + d;
    if (sa >= 0) out.push_back(a);
    if ((sa >= 0) != (sb >= 0)) out.push_back(a + (b - a) * (sa / (sa - sb)));
  }
  return out;
}

inline double polygon_area(const Poly3& p) {
  glm::dvec3 n(0.0);
  for (std::size_t i = 1; i + 1 < p.size(); ++i) n += glm::cross(p[i] - p[0], p[i + 1] - p[0]);
  return 0.5 * glm::length(n);
}

struct ClipPlane {
  glm::dvec3 n;
  double d;
};

inline Poly3 clip_all(Poly3 p, const std::vector<ClipPlane>& planes) {
  for (const ClipPlane& c : planes) {
    if (p.size() < 3) break;
    p = clip_polygon(p, c.n, c.d);
  }
  return p;
}

// The view frustum of a camera (side planes and near plane, inside >= 0), derived here from
// the camera's definition, independently of the traversal's own.
inline std::vector<ClipPlane> frustum_of(const Camera& c) {
  const glm::dvec3 f = glm::normalize(c.forward), r = glm::normalize(glm::cross(f, c.up)), u = glm::cross(r, f);
  const double ty = std::tan(c.fov_y_deg * 3.14159265358979323846 / 360.0), tx = ty * c.width / c.height;
  std::vector<ClipPlane> planes;
  // Each side plane contains the eye and two corner rays; its normal points inwards.
  const glm::dvec3 corners[4] = {f + r * tx + u * ty, f - r * tx + u * ty, f - r * tx - u * ty, f + r * tx - u * ty};
  for (int k = 0; k < 4; ++k) {
    glm::dvec3 n = glm::normalize(glm::cross(corners[k], corners[(k + 1) % 4]));
    if (glm::dot(n, f) < 0) n = -n;
    planes.push_back({n, -glm::dot(n, c.eye)});
  }
  planes.push_back({f, -glm::dot(f, c.eye) - c.near_plane});
  return planes;
}

// A set of triangles (vertex positions and index triples).
struct TriangleSoup {
  std::vector<glm::dvec3> v;
  std::vector<glm::u8vec4> c;
  std::vector<std::uint32_t> t;
  Poly3 triangle(std::size_t k) const { return {v[t[3 * k]], v[t[3 * k + 1]], v[t[3 * k + 2]]}; }
  std::size_t size() const { return t.size() / 3; }
};

// The area of the frame's merged triangles within `planes`.
inline double drawn_merged_area(const TerrainTree& tree, const Frame& f, const std::vector<ClipPlane>& planes = {}) {
  double area = 0.0;
  const auto& p = tree.positions();
  for (std::size_t t = 0; t < f.level.size(); ++t) {
    if (f.level[t] != kMergedLevel) continue;
    area += polygon_area(clip_all({glm::dvec3(p[f.indices[3 * t]]), glm::dvec3(p[f.indices[3 * t + 1]]),
                                   glm::dvec3(p[f.indices[3 * t + 2]])},
                                  planes));
  }
  return area;
}

// What of `soup` an eye above the ground can see drawn with the frame's terrain, within
// `planes`: inside the window, the parts above the terrain triangles the frame draws (each
// clipped to its triangle's vertical prism and above its plane); outside the window's
// footprint [x0, x1] x [y0, y1], everything.
inline double area_above_drawn_terrain(const TerrainTree& tree, const Frame& f, const TriangleSoup& soup, double x0,
                                       double x1, double y0, double y1, const std::vector<ClipPlane>& planes = {}) {
  const auto& p = tree.positions();
  double area = 0.0;
  std::vector<ClipPlane> window = planes;
  window.push_back({{1, 0, 0}, -x0});
  window.push_back({{-1, 0, 0}, x1});
  window.push_back({{0, 1, 0}, -y0});
  window.push_back({{0, -1, 0}, y1});
  for (std::size_t k = 0; k < soup.size(); ++k) {
    area += polygon_area(clip_all(soup.triangle(k), planes)) - polygon_area(clip_all(soup.triangle(k), window));
  }
  for (std::size_t t = 0; t < f.level.size(); ++t) {
    if (f.level[t] < 0) continue;  // terrain triangles only
    const glm::dvec3 a(p[f.indices[3 * t]]), b(p[f.indices[3 * t + 1]]), c(p[f.indices[3 * t + 2]]);
    glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    if (n.z < 0) n = -n;
    std::vector<ClipPlane> prism = planes;
    prism.push_back({n, -glm::dot(n, a)});
    const glm::dvec3 centre = (a + b + c) / 3.0;
    for (const auto& [e0, e1] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      glm::dvec3 en = glm::normalize(glm::dvec3(-(e1.y - e0.y), e1.x - e0.x, 0.0));
      if (glm::dot(en, centre - e0) < 0) en = -en;
      prism.push_back({en, -glm::dot(en, e0)});
    }
    for (std::size_t k = 0; k < soup.size(); ++k) area += polygon_area(clip_all(soup.triangle(k), prism));
  }
  return area;
}

}  // namespace terravol::mrbsp::test
