// Per-pixel references for the coverage pyramid, written from the contract in
// coverage/pyramid.h and sharing no code with coverage/: each pixel centre is tested against
// each edge (or each hull segment) on its own, in exact integer arithmetic on the same 1/256 px
// snapping.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

namespace terravol::coverage::test {

using i128 = __int128;
using i64 = long long;

struct Fx {
  i64 x, y;
};

inline Fx snap_ref(glm::dvec2 p) { return {static_cast<i64>(std::nearbyint(p.x * 256.0)), static_cast<i64>(std::nearbyint(p.y * 256.0))}; }
inline i64 units_up(double px) { return static_cast<i64>(std::ceil(px * 256.0)); }
inline Fx centre(int x, int y) { return {256LL * x + 128, 256LL * y + 128}; }

// A width x height bitmap, row-major from the bottom-left.
struct Bitmap {
  int w = 0, h = 0;
  std::vector<char> bits;
  Bitmap(int width, int height) : w(width), h(height), bits(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0) {}
  char& at(int x, int y) { return bits[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)]; }
  char at(int x, int y) const { return bits[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)]; }
  std::size_t count() const {
    std::size_t n = 0;
    for (char b : bits) n += b ? 1 : 0;
    return n;
  }
};

// The pixels cover(polygon, margin) must claim: centres at a distance greater than the margin
// inside every edge's line (or equal to it on an edge whose interior is on its +x side, or on
// its +y side when horizontal), edges between consecutive distinct snapped vertices, inside
// meaning the side the polygon's signed area puts it on.
inline Bitmap claimed_ref(const std::vector<glm::dvec2>& polygon, double margin, int width, int height) {
  Bitmap out(width, height);
  std::vector<Fx> v;
  for (const glm::dvec2& p : polygon) v.push_back(snap_ref(p));
  const std::size_t n = v.size();
  if (n < 3) return out;
  i128 area2 = 0;  // shoelace
  for (std::size_t i = 0; i < n; ++i) {
    const Fx a = v[i], b = v[(i + 1) % n];
    area2 += static_cast<i128>(a.x) * b.y - static_cast<i128>(b.x) * a.y;
  }
  if (area2 == 0) return out;
  const i64 orient = area2 > 0 ? 1 : -1;
  const i128 m = units_up(margin);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Fx p = centre(x, y);
      bool inside = true;
      for (std::size_t i = 0; i < n && inside; ++i) {
        const Fx a = v[i], b = v[(i + 1) % n];
        if (a.x == b.x && a.y == b.y) continue;
        const i128 dx = b.x - a.x, dy = b.y - a.y;
        // Signed distance times |d|, positive on the interior side.
        const i128 s = orient * (dx * (p.y - a.y) - dy * (p.x - a.x));
        const i128 nx = -orient * dy, ny = orient * dx;  // inward normal
        const bool owns = nx > 0 || (nx == 0 && ny > 0);
        if (s < 0) {
          inside = false;
        } else {
          const i128 lhs = s * s, rhs = m * m * (dx * dx + dy * dy);
          inside = lhs > rhs || (lhs == rhs && owns);
        }
      }
      if (inside) out.at(x, y) = 1;
    }
  }
  return out;
}

inline i128 cross_ref(Fx o, Fx a, Fx b) { return static_cast<i128>(a.x - o.x) * (b.y - o.y) - static_cast<i128>(a.y - o.y) * (b.x - o.x); }

// The convex hull's vertices by gift wrapping (counterclockwise; farthest point on ties, so
// collinear points drop out).
inline std::vector<Fx> hull_ref(std::vector<Fx> pts) {
  std::vector<Fx> h;
  if (pts.empty()) return h;
  std::size_t start = 0;
  for (std::size_t i = 1; i < pts.size(); ++i)
    if (pts[i].x < pts[start].x || (pts[i].x == pts[start].x && pts[i].y < pts[start].y)) start = i;
  Fx cur = pts[start];
  for (;;) {
    h.push_back(cur);
    Fx best = cur;
    for (const Fx& q : pts) {
      if (q.x == cur.x && q.y == cur.y) continue;
      if (best.x == cur.x && best.y == cur.y) {
        best = q;
        continue;
      }
      const i128 c = cross_ref(cur, best, q);
      const i128 db = static_cast<i128>(best.x - cur.x) * (best.x - cur.x) + static_cast<i128>(best.y - cur.y) * (best.y - cur.y);
      const i128 dq = static_cast<i128>(q.x - cur.x) * (q.x - cur.x) + static_cast<i128>(q.y - cur.y) * (q.y - cur.y);
      if (c < 0 || (c == 0 && dq > db)) best = q;  // q is clockwise of best: wrap tighter
    }
    if ((best.x == cur.x && best.y == cur.y) || (best.x == h[0].x && best.y == h[0].y)) break;
    cur = best;
    if (h.size() > pts.size()) break;
  }
  return h;
}

// Whether the centre p is within distance d (1/256 px) of the convex polygon h (a point, a
// segment or a counterclockwise polygon), exactly.
inline bool within_ref(const std::vector<Fx>& h, Fx p, i64 d) {
  const i128 d2 = static_cast<i128>(d) * d;
  if (h.size() >= 3) {
    bool in = true;
    for (std::size_t i = 0; i < h.size() && in; ++i) in = cross_ref(h[i], h[(i + 1) % h.size()], p) >= 0;
    if (in) return true;
  }
  const auto dist2_le = [&](Fx a, Fx b) {
    const i128 px = p.x - a.x, py = p.y - a.y, bx = b.x - a.x, by = b.y - a.y;
    const i128 t = px * bx + py * by, len2 = bx * bx + by * by;
    if (len2 == 0 || t <= 0) return px * px + py * py <= d2;
    if (t >= len2) {
      const i128 qx = p.x - b.x, qy = p.y - b.y;
      return qx * qx + qy * qy <= d2;
    }
    const i128 c = px * by - py * bx;
    return c * c <= d2 * len2;
  };
  if (h.size() == 1) return dist2_le(h[0], h[0]);
  for (std::size_t i = 0; i < h.size(); ++i)
    if (dist2_le(h[i], h[(i + 1) % h.size()])) return true;
  return false;
}

// hidden(points, dilation) against a coverage bitmap: every viewport pixel whose centre is
// within the dilation of the points' convex hull is covered.
inline bool hidden_ref(const Bitmap& covered, const std::vector<glm::dvec2>& points, double dilation) {
  std::vector<Fx> pts;
  for (const glm::dvec2& p : points) pts.push_back(snap_ref(p));
  if (pts.empty()) return true;
  const std::vector<Fx> h = hull_ref(pts);
  const i64 d = units_up(dilation);
  for (int y = 0; y < covered.h; ++y)
    for (int x = 0; x < covered.w; ++x)
      if (!covered.at(x, y) && within_ref(h, centre(x, y), d)) return false;
  return true;
}

}  // namespace terravol::coverage::test
