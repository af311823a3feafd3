// Box silhouettes for the test-only tiling of Greene 1996, section 5.2, and the exact convex
// hull (A. M. Andrew, "Another efficient algorithm for convex hulls in two dimensions", 1979)
// that Pyramid::hidden() takes of its points.
#include "coverage/silhouette.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "coverage/fixed.h"
#include "coverage/pyramid.h"

namespace terravol::coverage {

namespace detail {

int convex_hull_fixed(std::span<FixedPoint> pts, std::span<FixedPoint> hull) {
  const int n = static_cast<int>(pts.size());
  if (n == 0) return 0;
  std::sort(pts.begin(), pts.end(), [](FixedPoint a, FixedPoint b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  // Lower chain left to right, then upper chain right to left; a vertex stays only on a strict
  // left turn, so repeated and collinear points drop out.
  std::array<FixedPoint, 2 * kMaxVertices + 1> h;
  int k = 0;
  for (int i = 0; i < n; ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    if (k >= 1 && h[k - 1] == pts[i]) continue;
    h[k++] = pts[i];
  }
  for (int i = n - 2, lower = k + 1; i >= 0; --i) {
    while (k >= lower && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    if (h[k - 1] == pts[i]) continue;
    h[k++] = pts[i];
  }
  if (k > 1 && h[k - 1] == h[0]) --k;  // the upper chain ends where the lower began
  std::copy_n(h.begin(), k, hull.begin());
  return k;
}

}  // namespace detail

bool project_to_window(std::span<const glm::dvec4> clip, int width, int height,
                       std::span<glm::dvec2> window) {
  for (const glm::dvec4& p : clip) {
    if (!(p.w > 0.0) || !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.w)) return false;
  }
  for (std::size_t i = 0; i < clip.size(); ++i) {
    const glm::dvec4& p = clip[i];
    window[i] = {(p.x / p.w + 1.0) * 0.5 * width, (p.y / p.w + 1.0) * 0.5 * height};
  }
  return true;
}

int convex_hull(std::span<const glm::dvec2> points, std::span<glm::dvec2> hull) {
  if (points.size() > static_cast<std::size_t>(kMaxVertices)) {
    throw std::invalid_argument("coverage::convex_hull: " + std::to_string(points.size()) +
                                " points, more than " + std::to_string(kMaxVertices));
  }
  std::array<detail::FixedPoint, kMaxVertices> fixed;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!detail::snap(points[i], fixed[i])) {
      throw std::invalid_argument("coverage::convex_hull: point " + std::to_string(i) +
                                  " is not finite or beyond kMaxCoordinate");
    }
  }
  std::array<detail::FixedPoint, kMaxVertices> h;
  const int n = detail::convex_hull_fixed(std::span(fixed.data(), points.size()), h);
  constexpr double kInv = 1.0 / static_cast<double>(detail::kSubpixel);
  for (int i = 0; i < n; ++i) hull[static_cast<std::size_t>(i)] = {static_cast<double>(h[i].x) * kInv, static_cast<double>(h[i].y) * kInv};
  return n;
}

}  // namespace terravol::coverage
