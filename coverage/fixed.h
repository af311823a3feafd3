// Internal to coverage/: the fixed-point window coordinates (1/256 px, llvmpipe's 8 sub-pixel
// bits) that every exact test of the pyramid works in, and the exact convex hull on them.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>

#include <glm/vec2.hpp>

// SSE2 (every x86-64) for the word-wide mask operations; a portable scalar version otherwise,
// or when TERRAVOL_COVERAGE_SCALAR is defined (the scalar test build checks it on x86 too).
#if defined(__SSE2__) && !defined(TERRAVOL_COVERAGE_SCALAR)
#define TERRAVOL_COVERAGE_SIMD 1
#include <emmintrin.h>
#else
#define TERRAVOL_COVERAGE_SIMD 0
#endif

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

// Nearest integer, ties to even (the default rounding mode), for |x| < 2^62: one instruction
// where SSE2 has it (llrint is a library call without -fno-math-errno).
inline i64 round_even(double x) {
#if TERRAVOL_COVERAGE_SIMD
  return _mm_cvtsd_si64(_mm_set_sd(x));
#else
  return std::llrint(x);
#endif
}

// Snaps window coordinates (pixels) to 1/256 px, nearest with ties to even (as llvmpipe's
// lrintf). False for a coordinate that is not finite or beyond kMaxCoordinate.
inline bool snap(glm::dvec2 p, FixedPoint& out) {
  if (!(std::abs(p.x) <= kMaxCoordinate) || !(std::abs(p.y) <= kMaxCoordinate)) return false;
  out.x = round_even(p.x * static_cast<double>(kSubpixel));
  out.y = round_even(p.y * static_cast<double>(kSubpixel));
  return true;
}

// A distance in pixels (0 <= px <= kMaxMargin) as a whole number of 1/256 px, rounded up.
inline i64 snap_distance_up(double px) {
  const double u = px * static_cast<double>(kSubpixel);
  const auto t = static_cast<i64>(u);
  return t + (static_cast<double>(t) < u ? 1 : 0);
}

// floor(m sqrt(a^2 + b^2)) for 0 <= m <= 2^16 and |a|, |b| <= 2^34, exactly: an estimate in
// double, then corrected against m^2 (a^2 + b^2) in 128 bits.
inline i64 scaled_length_floor(i64 m, i64 a, i64 b) {
  if (m == 0) return 0;
  const double fa = static_cast<double>(a), fb = static_cast<double>(b);
  auto r = static_cast<i64>(static_cast<double>(m) * std::sqrt(fa * fa + fb * fb));
  const i128 n = static_cast<i128>(m * m) * (static_cast<i128>(a) * a + static_cast<i128>(b) * b);
  while (r > 0 && static_cast<i128>(r) * r > n) --r;
  while (static_cast<i128>(r + 1) * (r + 1) <= n) ++r;
  return r;
}
// Whether r is exactly m sqrt(a^2 + b^2).
inline bool is_scaled_length(i64 r, i64 m, i64 a, i64 b) {
  return static_cast<i128>(r) * r == static_cast<i128>(m * m) * (static_cast<i128>(a) * a + static_cast<i128>(b) * b);
}

// The edge threshold of cover(): the least integer t such that an edge function value E
// (|d| times the distance into the edge, 1/256 px units) passes the test E > m |d|, or
// E >= m |d| when the edge owns its centres (the fill rule), |d| = sqrt(a^2 + b^2). Estimated
// in double; when the estimate lies too near an integer for its rounding error, decided in
// 128-bit integers.
inline i64 inner_threshold(i64 m, i64 a, i64 b, bool owned) {
  if (m == 0) return owned ? 0 : 1;
  const double fa = static_cast<double>(a), fb = static_cast<double>(b);
  const double x = static_cast<double>(m) * std::sqrt(fa * fa + fb * fb);  // relative error < 5e-16
  const auto r = static_cast<i64>(x);
  const double frac = x - static_cast<double>(r), tol = 1e-15 * x + 1e-12;
  if (frac > tol && frac < 1.0 - tol) return r + 1;  // m |d| is not an integer: ceil = floor + 1
  const i64 f = scaled_length_floor(m, a, b);
  return owned && is_scaled_length(f, m, a, b) ? f : f + 1;
}

inline int popcount64(std::uint64_t x) {
  // Without -mpopcnt std::popcount is a library call; this is the usual SWAR count.
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return static_cast<int>((x * 0x0101010101010101ull) >> 56);
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
