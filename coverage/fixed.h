// Internal to coverage/: the fixed-point window coordinates (1/256 px, llvmpipe's 8 sub-pixel
// bits) that every exact test of the pyramid works in, and the exact convex hull on them.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>

#include <glm/vec2.hpp>

#include "coverage/pyramid.h"

namespace terravol::coverage::detail {

using i64 = std::int64_t;
using i128 = __int128;

inline constexpr int kSubpixelBits = 8;
inline constexpr i64 kSubpixel = i64{1} << kSubpixelBits;  // units per pixel
inline constexpr i64 kHalfPixel = kSubpixel / 2;           // a pixel centre is at 256 px + 128

struct FixedPoint {
  i64 x, y;
  bool operator==(const FixedPoint&) const = default;
};

// Snaps window coordinates (pixels) to 1/256 px, nearest with ties to even (the default
// rounding mode, as llvmpipe's lrintf). False for a coordinate that is not finite or beyond
// kMaxCoordinate.
inline bool snap(glm::dvec2 p, FixedPoint& out) {
  if (!(std::abs(p.x) <= kMaxCoordinate) || !(std::abs(p.y) <= kMaxCoordinate)) return false;
  out.x = std::llrint(p.x * static_cast<double>(kSubpixel));
  out.y = std::llrint(p.y * static_cast<double>(kSubpixel));
  return true;
}

// A distance in pixels as a whole number of 1/256 px, rounded up.
inline i64 snap_distance_up(double px) { return static_cast<i64>(std::ceil(px * static_cast<double>(kSubpixel))); }

// floor(sqrt(n)) for 0 <= n < 2^120.
inline i64 isqrt_floor(i128 n) {
  if (n <= 0) return 0;
  auto r = static_cast<i64>(std::sqrt(static_cast<double>(n)));
  while (static_cast<i128>(r) * r > n) --r;
  while (static_cast<i128>(r + 1) * (r + 1) <= n) ++r;
  return r;
}

// (b - a) x (c - a): positive when a, b, c turn counterclockwise (y up).
inline i128 cross(FixedPoint a, FixedPoint b, FixedPoint c) {
  return static_cast<i128>(b.x - a.x) * (c.y - a.y) - static_cast<i128>(b.y - a.y) * (c.x - a.x);
}

// The convex hull of pts, counterclockwise from the lowest-leftmost point, without collinear or
// repeated vertices (Andrew's monotone chain; every turn test exact). Sorts pts in place. Writes
// at most pts.size() vertices to hull and returns their number (1 for coincident points, 2 for
// collinear ones, 0 for none).
int convex_hull_fixed(std::span<FixedPoint> pts, std::span<FixedPoint> hull);

}  // namespace terravol::coverage::detail
