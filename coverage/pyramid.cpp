// Hierarchical polygon tiling with coverage masks: N. Greene, "Hierarchical Polygon Tiling with
// Coverage Masks", SIGGRAPH 1996.
//  - Section 3 (triage coverage masks): a cell's 8x8 children classified per edge as covered
//    (C), vacant (V) or active; the polygon's mask Pc = AND of the edges' C masks, Pv = OR of
//    their V masks; against the pyramid cell (Cc, Cv): W = Cv & Pc (vacant children the polygon
//    covers wholly), A = ~(W | Pv | Cc) (children to subdivide), Cc |= W, Cv &= ~W.
//  - Section 3.1 / listing 1 (tile_poly): the recursion, with edges that do not cross a child
//    dropped on the way down and coverage propagated up after each child.
//  - Section 4.1 (the coverage pyramid) and 4.5 (point sampling): one-bit masks of 8x8 pixels at
//    the finest level, triage masks above, a single root mask.
//  - Section 4.3: a polygon is tiled from the smallest cells that enclose it (here up to 2x2
//    cells of one level, or up to 4x4 finest tiles directly) rather than from the root.
//  - Section 5.2 (test-only tiling): hidden() runs the same recursion without writing and
//    reports visible at the first vacant sample or vacant child the polygon covers.
//
// Where this departs from the paper, and why:
//  - Exact edge functions instead of mask tables. Greene looks edge masks up in tables indexed
//    by the edge's two intercepts on the cell border, quantized to 64 intervals per side
//    (section 4.2), and makes the triage masks conservative by marking active every child the
//    quantization quadrilateral touches. The issue asks that coverage never claim a pixel the
//    GPU may leave unfilled, so the finest masks must be exact; and on a current CPU a 1 MB
//    table does not stay in L1 while evaluating the edge on the 8x8 lattice is a handful of
//    SIMD adds and sign extractions (mask32/mask64 below). So every mask here, triage ones
//    included, comes from the exact integer edge function (1/256 px fixed point, as llvmpipe
//    snaps). Triage masks are conservative by construction: a child's C bit is set only when
//    the edge function is >= its threshold at the child's extreme pixel centre (the corner
//    where the edge function is least: min(0, a) and min(0, b) steps of s - 1 pixels from the
//    child's first centre), so at every pixel centre of the child; a V bit only when it is
//    below the threshold at the child's greatest corner, so at every centre. They classify
//    pixel centres, which is all the finest level can hold, so no quadrilateral widening is
//    needed and no child is active without reason.
//  - The finest level is always exact: when a triage W bit covers a vacant child wholly, the
//    child's subtree is filled as well (fill()). Each cell is filled at most once per frame
//    (it never becomes vacant again before clear()), so this costs at most one pass over the
//    finest level per frame, and it lets the small-polygon path read and write finest tiles
//    without looking at their ancestors.
//  - Pixels outside the viewport count as covered (border tiles have those bits set, missing
//    children of a triage mask are C), so clipping to the viewport is free: cover() never
//    claims them and hidden() never finds them vacant.
//  - The erosion margin and the dilation are exact: each edge's threshold is M |d| (M the
//    margin in 1/256 px, |d| the edge length) rounded to the integer that decides the same
//    centres, found with an exact integer square root.
#include "coverage/pyramid.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "coverage/fixed.h"

namespace terravol::coverage {

using detail::FixedPoint;
using detail::i128;
using detail::i64;
using detail::kHalfPixel;
using detail::kSubpixel;

namespace {

constexpr std::uint64_t kAll = ~std::uint64_t{0};
constexpr int kMaxEdges = kMaxVertices + 4;  // hidden() adds the box of a disc or capsule
constexpr int kDirectTiles = 4;              // polygons within 4x4 tiles skip the triage levels


// Rows j0..j1 (bytes j0..j1 of a mask) set.
constexpr std::uint64_t row_mask(int j0, int j1) {
  return (kAll << (8 * j0)) & (kAll >> (8 * (7 - j1)));
}
// The children (i, j) with i0 <= i <= i1 and j0 <= j <= j1, all in [0, 7].
constexpr std::uint64_t rect_mask(int i0, int i1, int j0, int j1) {
  const std::uint64_t cols = (0xFFull << i0) & (0xFFull >> (7 - i1));
  return (cols * 0x0101010101010101ull) & row_mask(j0, j1);
}

// The 8x8 lattice masks of an edge function: bit 8 j + i is set where v + i sa + j sb >= 0,
// i, j in [0, 8). Word-wide: one SIMD add per 2 or 4 lattice points, and the signs of two rows
// (16 points) packed to bytes and taken by one movemask.
// mask64: every value must fit in 63 bits (|v| + 7 |sa| + 7 |sb| < 2^62).
[[gnu::always_inline]] inline std::uint64_t mask64(i64 v, i64 sa, i64 sb) {
#if TERRAVOL_COVERAGE_SIMD
  // Two rows at a time: the high halves of each row's eight values (their signs) gathered into
  // 32-bit lanes, packed with saturation (which keeps signs) to sixteen bytes, and their signs
  // taken at once.
  __m128i r0 = _mm_set_epi64x(v + sa, v);
  __m128i r1 = _mm_add_epi64(r0, _mm_set1_epi64x(2 * sa));
  __m128i r2 = _mm_add_epi64(r0, _mm_set1_epi64x(4 * sa));
  __m128i r3 = _mm_add_epi64(r0, _mm_set1_epi64x(6 * sa));
  const __m128i step = _mm_set1_epi64x(sb);
  const auto row = [&] {
    const __m128i lo = _mm_castps_si128(_mm_shuffle_ps(_mm_castsi128_ps(r0), _mm_castsi128_ps(r1), _MM_SHUFFLE(3, 1, 3, 1)));
    const __m128i hi = _mm_castps_si128(_mm_shuffle_ps(_mm_castsi128_ps(r2), _mm_castsi128_ps(r3), _MM_SHUFFLE(3, 1, 3, 1)));
    r0 = _mm_add_epi64(r0, step);
    r1 = _mm_add_epi64(r1, step);
    r2 = _mm_add_epi64(r2, step);
    r3 = _mm_add_epi64(r3, step);
    return _mm_packs_epi32(lo, hi);
  };
  std::uint64_t neg = 0;
  for (int j = 0; j < 8; j += 2) {
    const __m128i a = row();
    const __m128i b = row();
    neg |= static_cast<std::uint64_t>(static_cast<std::uint32_t>(_mm_movemask_epi8(_mm_packs_epi16(a, b)))) << (8 * j);
  }
  return ~neg;
#else
  std::uint64_t m = 0;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i)
      if (v + i * sa + j * sb >= 0) m |= std::uint64_t{1} << (8 * j + i);
  return m;
#endif
}

// The same on rows j0..j1 only (the others zero), for values that fit in 32 bits
// (|v| + 7 |sa| + 7 |sb| < 2^31).
std::uint64_t mask32(i64 v, i64 sa, i64 sb, int j0, int j1) {
#if TERRAVOL_COVERAGE_SIMD
  // Two rows at a time from row j0 & ~1 (so also rows just outside j0..j1, whose values fit
  // as well: within the tile), packed with saturation to sixteen bytes whose signs are taken
  // at once.
  const int first = j0 & ~1;
  const auto v0 = static_cast<std::int32_t>(v + first * sb), a = static_cast<std::int32_t>(sa);
  __m128i lo = _mm_set_epi32(v0 + 3 * a, v0 + 2 * a, v0 + a, v0);
  __m128i hi = _mm_add_epi32(lo, _mm_set1_epi32(4 * a));
  const __m128i step = _mm_set1_epi32(static_cast<std::int32_t>(sb));
  std::uint64_t neg = 0;
  for (int j = first; j <= j1; j += 2) {
    const __m128i r0 = _mm_packs_epi32(lo, hi);
    lo = _mm_add_epi32(lo, step);
    hi = _mm_add_epi32(hi, step);
    const __m128i r1 = _mm_packs_epi32(lo, hi);
    lo = _mm_add_epi32(lo, step);
    hi = _mm_add_epi32(hi, step);
    neg |= static_cast<std::uint64_t>(static_cast<std::uint32_t>(_mm_movemask_epi8(_mm_packs_epi16(r0, r1)))) << (8 * j);
  }
  return ~neg & row_mask(j0, j1);
#else
  return mask64(v, sa, sb) & row_mask(j0, j1);
#endif
}

// An edge of a small polygon on the pixel lattice: inside where a x + b y + c >= 0.
struct SmallEdge {
  i64 a, b, c;
};

// The edge q0 -> q1 of a small polygon of orientation sign (+1 counterclockwise), eroded by
// margin (1/256 px); a repeated vertex gives an edge everything passes. With |a|, |b| < 2^15
// and margin <= 2^16, m^2 (a^2 + b^2) < 2^63, so the threshold's exact check fits 64 bits.
[[gnu::always_inline]] inline SmallEdge small_edge(FixedPoint q0, FixedPoint q1, i64 sign, i64 margin) {
  const i64 a = -(q1.y - q0.y) * sign, b = (q1.x - q0.x) * sign;
  if (a == 0 && b == 0) return {0, 0, 0};
  const bool owned = a > 0 || (a == 0 && b > 0);
  i64 t = owned ? 0 : 1;
  if (margin > 0) {
    // r = floor(m |d|), from an estimate off by less than one, then t as in inner_threshold.
    const auto n = static_cast<std::uint64_t>(margin * margin) * static_cast<std::uint64_t>(a * a + b * b);
    const double fa = static_cast<double>(a), fb = static_cast<double>(b);
    auto r = static_cast<std::uint64_t>(static_cast<i64>(static_cast<double>(margin) * std::sqrt(fa * fa + fb * fb)));
    if (r * r > n) --r;
    if ((r + 1) * (r + 1) <= n) ++r;
    t = static_cast<i64>(r) + (owned && r * r == n ? 0 : 1);
  }
  return {a, b, (a * (kHalfPixel - q0.x) + b * (kHalfPixel - q0.y) - t) >> detail::kSubpixelBits};  // floor
}

// The mask of pixels inside all N edges of a tile whose first pixel is (ox, oy), on rows
// j0..j1, for values that fit in 32 bits over the tile: one pass, the edges' values OR-ed so
// that one sign extraction tests them all.
#if TERRAVOL_COVERAGE_SIMD
// The edges prepared for SIMD: columns 0..3 of a row hold c + a x + b y + (0, a, 2a, 3a).
struct SmallLanes {
  __m128i lane, four_a, step;
};

template <int N>
[[gnu::always_inline]] inline std::uint64_t small_mask(const SmallEdge* e, const SmallLanes* l, i64 ox, i64 oy, int j0, int j1) {
  // Rows in pairs from j0 & ~1 (a row just outside j0..j1 lies in the tile, near the polygon,
  // so its values fit as well), each pair's sixteen values packed with saturation to bytes
  // whose signs are taken at once (as mask32).
  const int first = j0 & ~1;
  __m128i lo[N], hi[N];
  for (int k = 0; k < N; ++k) {
    lo[k] = _mm_add_epi32(_mm_set1_epi32(static_cast<std::int32_t>(e[k].c + e[k].a * ox + e[k].b * (oy + first))), l[k].lane);
    hi[k] = _mm_add_epi32(lo[k], l[k].four_a);
  }
  const auto row = [&] {
    __m128i lo_or = lo[0], hi_or = hi[0];
    for (int k = 1; k < N; ++k) {
      lo_or = _mm_or_si128(lo_or, lo[k]);
      hi_or = _mm_or_si128(hi_or, hi[k]);
    }
    for (int k = 0; k < N; ++k) {
      lo[k] = _mm_add_epi32(lo[k], l[k].step);
      hi[k] = _mm_add_epi32(hi[k], l[k].step);
    }
    return _mm_packs_epi32(lo_or, hi_or);
  };
  std::uint64_t neg = 0;
  for (int j = first; j <= j1; j += 2) {
    const __m128i a = row();
    const __m128i b = row();
    neg |= static_cast<std::uint64_t>(static_cast<std::uint32_t>(_mm_movemask_epi8(_mm_packs_epi16(a, b)))) << (8 * j);
  }
  return ~neg & row_mask(j0, j1);
}
#else
template <int N>
std::uint64_t small_mask(const SmallEdge* e, i64 ox, i64 oy, int j0, int j1) {
  std::uint64_t m = row_mask(j0, j1);
  for (int k = 0; k < N; ++k) m &= mask64(e[k].c + e[k].a * ox + e[k].b * oy, e[k].a, e[k].b);
  return m;
}
#endif

}  // namespace

// A rounded corner of hidden()'s dilated polygon: pixels of the offset polygon (every edge
// moved out by the dilation) that lie in the vertex's normal cone farther than the dilation
// from the vertex are outside the rounded region.
struct Corner {
  FixedPoint v;              // the vertex, 1/256 px
  i64 px, py;                // previous vertex - v
  i64 nx, ny;                // next vertex - v
  bool whole_plane;          // a single point: its cone is the whole plane
};

// The polygon as edge functions on the pixel lattice: pixel (x, y) is inside edge k when
// a[k] x + b[k] y + c[k] >= 0 (the threshold, fill rule and 1/256 px offset folded into c).
// Trivially constructible (arrays left uninitialized): one is made per call.
struct Pyramid::Edges {
  int n = 0;
  std::array<i64, kMaxEdges> a, b, c;
  std::array<std::uint8_t, kMaxEdges> all;  // 0, 1, ..., n - 1
  bool narrow = true;  // every |a|, |b| < 2^26, so values over a crossed tile fit 32 bits
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;  // pixel range that can be inside (clamped to the viewport)
  // hidden() only: the rounded corners, and the dilation (1/256 px).
  i64 dilation = 0;
  int corners = 0;
  std::array<Corner, kMaxVertices> corner;

  // Adds the edge whose pixel-lattice function is a x + b y + r / 256 (rounded down: the same
  // centres satisfy it, since a x + b y is an integer). Drops it when every centre of the
  // viewport satisfies it; returns false when none does (the polygon misses the viewport).
  bool add(i64 ea, i64 eb, i128 r, int width, int height) {
    const i128 ec = r >> detail::kSubpixelBits;  // floor(r / 256)
    const i128 lo = ec + static_cast<i128>(std::min<i64>(ea, 0)) * (width - 1) + static_cast<i128>(std::min<i64>(eb, 0)) * (height - 1);
    const i128 hi = ec + static_cast<i128>(std::max<i64>(ea, 0)) * (width - 1) + static_cast<i128>(std::max<i64>(eb, 0)) * (height - 1);
    if (lo >= 0) return true;
    if (hi < 0) return false;
    a[n] = ea;
    b[n] = eb;
    c[n] = static_cast<i64>(ec);  // |c| <= |a| (width - 1) + |b| (height - 1) here
    all[n] = static_cast<std::uint8_t>(n);
    narrow = narrow && std::abs(ea) < (i64{1} << 26) && std::abs(eb) < (i64{1} << 26);
    ++n;
    return true;
  }

  // Whether pixel (x, y) lies in a corner's cut: in a vertex's normal cone, farther than the
  // dilation from it (its nearest point of the polygon is the vertex, so it is outside the
  // rounded region). Exact.
  bool cut(int x, int y) const {
    for (int q = 0; q < corners; ++q) {
      const Corner& k = corner[static_cast<std::size_t>(q)];
      const i64 tx = static_cast<i64>(x) * kSubpixel + kHalfPixel - k.v.x;
      const i64 ty = static_cast<i64>(y) * kSubpixel + kHalfPixel - k.v.y;
      if (!k.whole_plane) {
        if (static_cast<i128>(tx) * k.px + static_cast<i128>(ty) * k.py > 0) continue;
        if (static_cast<i128>(tx) * k.nx + static_cast<i128>(ty) * k.ny > 0) continue;
      }
      return static_cast<i128>(tx) * tx + static_cast<i128>(ty) * ty > static_cast<i128>(dilation) * dilation;
    }
    return false;
  }
};

namespace {

// The start of a tiling (section 4.3): level 0 for up to kDirectTiles x kDirectTiles tiles, or
// the lowest triage level where the pixel range spans at most 2 x 2 cells.
int start_level(int x0, int x1, int y0, int y1, int top) {
  if ((x1 >> 3) - (x0 >> 3) < kDirectTiles && (y1 >> 3) - (y0 >> 3) < kDirectTiles) return 0;
  for (int k = 1; k < top; ++k) {
    const int sh = 3 * (k + 1);
    if ((x1 >> sh) - (x0 >> sh) <= 1 && (y1 >> sh) - (y0 >> sh) <= 1) return k;
  }
  return top;
}

// Values of edge e of a cell at level k (children s = 8^k px wide) whose first pixel is (ox, oy):
// the function at the first centre, and its least and greatest offset over s x s pixels.
struct EdgeAt {
  i64 f, lo, hi;
};
inline EdgeAt edge_at(const i64 a, const i64 b, const i64 c, i64 ox, i64 oy, i64 s) {
  return {c + a * ox + b * oy, (std::min<i64>(a, 0) + std::min<i64>(b, 0)) * (s - 1),
          (std::max<i64>(a, 0) + std::max<i64>(b, 0)) * (s - 1)};
}

}  // namespace

Pyramid::Pyramid(int width, int height) : width_(width), height_(height) {
  if (width < 1 || width > kMaxViewport || height < 1 || height > kMaxViewport) {
    throw std::invalid_argument("coverage::Pyramid: viewport " + std::to_string(width) + "x" +
                                std::to_string(height) + " outside 1.." + std::to_string(kMaxViewport));
  }
  Level tiles;
  tiles.w = (width + 7) / 8;
  tiles.h = (height + 7) / 8;
  levels_.push_back(tiles);
  do {
    Level l;
    l.w = (levels_.back().w + 7) / 8;
    l.h = (levels_.back().h + 7) / 8;
    l.cells.resize(static_cast<std::size_t>(l.w) * static_cast<std::size_t>(l.h));
    levels_.push_back(std::move(l));
  } while (levels_.back().w > 1 || levels_.back().h > 1);
  tiles_.resize(static_cast<std::size_t>(tiles.w) * static_cast<std::size_t>(tiles.h));
  clear();
}

// Whether the element (x, y) of a level (tiles at level 0) is wholly covered and whether it
// is wholly vacant; an element beyond the grid counts as covered.
std::pair<bool, bool> Pyramid::state(int level, int x, int y) const {
  const Level& l = levels_[static_cast<std::size_t>(level)];
  if (x >= l.w || y >= l.h) return {true, false};
  if (level == 0) return {tile(x, y) == kAll, tile(x, y) == 0};
  const Cell& m = l.cells[static_cast<std::size_t>(y) * static_cast<std::size_t>(l.w) + static_cast<std::size_t>(x)];
  return {m.c == kAll, m.v == kAll};
}

void Pyramid::clear() {
  std::fill(tiles_.begin(), tiles_.end(), 0);
  const int tw = levels_[0].w, th = levels_[0].h;
  // Pixels beyond the viewport's right and top edges are covered.
  if (width_ % 8) {
    const std::uint64_t cols = (0xFFull << (width_ % 8)) & 0xFF;
    for (int ty = 0; ty < th; ++ty) tile(tw - 1, ty) |= cols * 0x0101010101010101ull;
  }
  if (height_ % 8) {
    for (int tx = 0; tx < tw; ++tx) tile(tx, th - 1) |= row_mask(height_ % 8, 7);
  }
  // The triage masks of an empty pyramid, computed once from the levels below.
  if (cleared_.empty()) {
    for (std::size_t k = 1; k < levels_.size(); ++k) {
      for (int cy = 0; cy < levels_[k].h; ++cy) {
        for (int cx = 0; cx < levels_[k].w; ++cx) {
          Cell m{0, 0};
          for (int bit = 0; bit < 64; ++bit) {
            const auto [full, empty] = state(static_cast<int>(k) - 1, 8 * cx + (bit & 7), 8 * cy + (bit >> 3));
            m.c |= static_cast<std::uint64_t>(full) << bit;
            m.v |= static_cast<std::uint64_t>(empty) << bit;
          }
          cell(static_cast<int>(k), cx, cy) = m;
        }
      }
      cleared_.insert(cleared_.end(), levels_[k].cells.begin(), levels_[k].cells.end());
    }
  } else {
    auto from = cleared_.begin();
    for (std::size_t k = 1; k < levels_.size(); ++k) {
      std::copy_n(from, levels_[k].cells.size(), levels_[k].cells.begin());
      from += static_cast<std::ptrdiff_t>(levels_[k].cells.size());
    }
  }
  stats_ = Stats{};
}

bool Pyramid::is_full(int level, int cx, int cy) {
  return level == 0 ? tile(cx, cy) == kAll : cell(level, cx, cy).c == kAll;
}

bool Pyramid::all_full(int level, int cx0, int cx1, int cy0, int cy1) {
  for (int cy = cy0; cy <= cy1; ++cy)
    for (int cx = cx0; cx <= cx1; ++cx)
      if (!is_full(level, cx, cy)) return false;
  return true;
}

// Covers the pixels of mask in tile (tx, ty) and brings the triage masks up to date.
[[gnu::always_inline]] inline void Pyramid::claim(int tx, int ty, std::uint64_t mask) {
  std::uint64_t& t = tile(tx, ty);
  const std::uint64_t nw = mask & ~t;
  if (!nw) return;
  if (record_) report(tx, ty, nw);
  if (!claim_) return;
  const bool was_empty = t == 0;
  t |= nw;
  stats_.pixels_claimed += static_cast<std::uint64_t>(detail::popcount64(nw));
  if (was_empty || t == kAll) propagate(0, tx, ty);
}

// After the element (cx, cy) of a level changed, brings its ancestors' bits up to date, up to
// the first ancestor whose own state (wholly covered, wholly vacant) did not change.
void Pyramid::propagate(int level, int cx, int cy) {
  auto [full, empty] = state(level, cx, cy);
  for (int k = level + 1; k < static_cast<int>(levels_.size()); ++k) {
    Cell& p = cell(k, cx >> 3, cy >> 3);
    const std::uint64_t bit = std::uint64_t{1} << (8 * (cy & 7) + (cx & 7));
    const bool was_full = p.c == kAll, was_empty = p.v == kAll;
    if (full) p.c |= bit;
    if (!empty) p.v &= ~bit;
    full = p.c == kAll;
    empty = p.v == kAll;
    if (full == was_full && empty == was_empty) return;
    cx >>= 3;
    cy >>= 3;
  }
}

// Marks a vacant element and everything below it wholly covered (cover_cell reports it).
void Pyramid::fill(int level, int cx, int cy) {
  if (level == 0) {
    tile(cx, cy) = kAll;
    ++stats_.cells_filled;
    return;
  }
  Cell& m = cell(level, cx, cy);
  m.c = kAll;
  m.v = 0;
  ++stats_.cells_filled;
  if (level == 1) {
    for (int j = 0; j < 8; ++j) std::fill_n(&tile(8 * cx, 8 * cy + j), 8, kAll);
    stats_.cells_filled += 64;
    return;
  }
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) fill(level - 1, 8 * cx + i, 8 * cy + j);
}

// Reports every pixel of a (formerly) vacant element to record_: its tiles row by row, each row
// one run (a vacant element has every child, since missing children count as covered).
void Pyramid::report_subtree(int level, int cx, int cy) {
  const int side = 1 << (3 * level);  // tiles per side
  for (int j = 0; j < side; ++j) record_->push_back({cx * side, cy * side + j, kAll, side});
}

namespace {

// The exact mask of the polygon's pixels in the tile whose first pixel is (ox, oy), on rows
// j0..j1 (the others are outside the polygon's range).
}  // namespace

// The exact mask of the polygon's pixels in the tile whose first pixel is (ox, oy), on rows
// j0..j1 (the others are outside the polygon's range), from the edges act[0..n).
std::uint64_t Pyramid::tile_mask(const Edges& E, const std::uint8_t* act, int n, i64 ox, i64 oy, int j0, int j1) {
  std::uint64_t m = row_mask(j0, j1);
  for (int q = 0; q < n; ++q) {
    const int e = act[q];
    const EdgeAt v = edge_at(E.a[e], E.b[e], E.c[e], ox, oy, 8);
    if (v.f + v.lo >= 0) continue;  // the whole tile is inside this edge
    if (v.f + v.hi < 0) return 0;   // and here outside
    m &= E.narrow ? mask32(v.f, E.a[e], E.b[e], j0, j1) : mask64(v.f, E.a[e], E.b[e]);
    if (m == 0) return 0;
  }
  return m;
}

// Listing 1's tile_poly for a triage cell that is not wholly covered: act[0..n_in) are the
// edges that may cross it (the parent's active_edge_list).
void Pyramid::cover_cell(int level, int cx, int cy, const Edges& E, const std::uint8_t* act_in, int n_in) {
  ++stats_.cells_visited;
  std::array<std::uint8_t, kMaxEdges> act;  // the edges crossing this cell
  int n = 0;
  const int sh = 3 * level;  // children are s = 8^level px wide
  const i64 s = i64{1} << sh, ox = static_cast<i64>(cx) << (sh + 3), oy = static_cast<i64>(cy) << (sh + 3);
  std::uint64_t pc = kAll, pv = 0;
  for (int q = 0; q < n_in; ++q) {
    const int e = act_in[q];
    const i64 a = E.a[e], b = E.b[e];
    const EdgeAt v = edge_at(a, b, E.c[e], ox, oy, s);
    const i64 spread = 7 * s;  // from the first child's corner to the last child's
    if (v.f + v.lo + (std::min<i64>(a, 0) + std::min<i64>(b, 0)) * spread >= 0) continue;  // wholly inside
    if (v.f + v.hi + (std::max<i64>(a, 0) + std::max<i64>(b, 0)) * spread < 0) return;   // wholly outside
    pc &= mask64(v.f + v.lo, s * a, s * b);   // children whose every centre is inside
    pv |= ~mask64(v.f + v.hi, s * a, s * b);  // children whose every centre is outside
    act[static_cast<std::size_t>(n++)] = static_cast<std::uint8_t>(e);
  }
  Cell& m = cell(level, cx, cy);
  const std::uint64_t w = m.v & pc;
  if (w) {
    if (claim_) {
      m.c |= w;
      m.v &= ~w;
      stats_.pixels_claimed += static_cast<std::uint64_t>(detail::popcount64(w)) * static_cast<std::uint64_t>(s * s);
    }
    if (level == 1 && record_) {
      // Tiles: each row's runs of newly covered tiles reported as one record each.
      for (int j = 0; j < 8; ++j) {
        for (unsigned row = static_cast<unsigned>(w >> (8 * j)) & 0xFFu; row;) {
          const int i0 = std::countr_zero(row);
          const int len = std::countr_one(row >> i0);
          record_->push_back({8 * cx + i0, 8 * cy + j, kAll, len});
          row &= ~(((1u << len) - 1u) << i0);
        }
      }
      if (claim_) {
        for (std::uint64_t bits = w; bits; bits &= bits - 1) fill(0, 8 * cx + (std::countr_zero(bits) & 7), 8 * cy + (std::countr_zero(bits) >> 3));
      }
    } else {
      for (std::uint64_t bits = w; bits; bits &= bits - 1) {
        const int bit = std::countr_zero(bits);
        if (claim_) fill(level - 1, 8 * cx + (bit & 7), 8 * cy + (bit >> 3));
        if (record_) report_subtree(level - 1, 8 * cx + (bit & 7), 8 * cy + (bit >> 3));
      }
    }
  }
  for (std::uint64_t active = ~(w | pv | m.c); active; active &= active - 1) {
    const int bit = std::countr_zero(active);
    const int x = 8 * cx + (bit & 7), y = 8 * cy + (bit >> 3);
    const std::uint64_t b = std::uint64_t{1} << bit;
    if (level == 1) {
      ++stats_.cells_visited;
      std::uint64_t& t = tile(x, y);
      const std::uint64_t nw = tile_mask(E, act.data(), n, static_cast<i64>(x) * 8, static_cast<i64>(y) * 8, 0, 7) & ~t;
      if (!nw) continue;
      if (record_) report(x, y, nw);
      if (!claim_) continue;
      t |= nw;
      stats_.pixels_claimed += static_cast<std::uint64_t>(detail::popcount64(nw));
      m.v &= ~b;
      if (t == kAll) m.c |= b;
    } else {
      cover_cell(level - 1, x, y, E, act.data(), n);
      if (!claim_) continue;
      const Cell& ch = cell(level - 1, x, y);
      if (ch.c == kAll) m.c |= b;
      if (ch.v != kAll) m.v &= ~b;
    }
  }
}

// cover() for a triangle (N = 3) or a quad (N = 4) whose bounding box is under 128 px and
// whose pixel range spans at most 2 x 2 tiles: the same exact predicate, in 64-bit arithmetic
// (coordinates under 2^24 units, edge components under 2^15, so every product fits), all edges
// tested in one SIMD pass per row.
template <int N>
void Pyramid::cover_small(const detail::FixedPoint* p, i64 margin, int x0, int x1, int y0, int y1) {
  i64 area2 = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
  if constexpr (N == 4) area2 += (p[2].x - p[0].x) * (p[3].y - p[0].y) - (p[2].y - p[0].y) * (p[3].x - p[0].x);
  if (area2 == 0) return;
  const i64 sign = area2 > 0 ? 1 : -1;
  std::array<SmallEdge, N> e;
  e[0] = small_edge(p[0], p[1], sign, margin);
  e[1] = small_edge(p[1], p[2], sign, margin);
  if constexpr (N == 3) {
    e[2] = small_edge(p[2], p[0], sign, margin);
  } else {
    e[2] = small_edge(p[2], p[3], sign, margin);
    e[3] = small_edge(p[3], p[0], sign, margin);
  }
#if TERRAVOL_COVERAGE_SIMD
  std::array<SmallLanes, N> lanes;
  for (int k = 0; k < N; ++k) {
    const auto a = static_cast<std::int32_t>(e[k].a);
    lanes[k] = {_mm_set_epi32(3 * a, 2 * a, a, 0), _mm_set1_epi32(4 * a), _mm_set1_epi32(static_cast<std::int32_t>(e[k].b))};
  }
#endif
  const int tx0 = x0 >> 3, tx1 = x1 >> 3, ty0 = y0 >> 3, ty1 = y1 >> 3;
  for (int ty = ty0; ty <= ty1; ++ty) {
    const int j0 = std::max(0, y0 - 8 * ty), j1 = std::min(7, y1 - 8 * ty);
    for (int tx = tx0; tx <= tx1; ++tx) {
      if (tile(tx, ty) == kAll) continue;
      ++stats_.cells_visited;
#if TERRAVOL_COVERAGE_SIMD
      claim(tx, ty, small_mask<N>(e.data(), lanes.data(), static_cast<i64>(tx) * 8, static_cast<i64>(ty) * 8, j0, j1));
#else
      claim(tx, ty, small_mask<N>(e.data(), static_cast<i64>(tx) * 8, static_cast<i64>(ty) * 8, j0, j1));
#endif
    }
  }
}

// cover() for a triangle whose pixel range holds at most 2 x 2 pixels (most distant terrain
// triangles): each candidate centre tested against each edge directly, with the margin compared
// squared (E^2 against m^2 (a^2 + b^2)), so no square root. With the bounding box under 128 px,
// |E| < 2^31.2 and every square fits 64 bits unsigned.
void Pyramid::cover_tiny(const detail::FixedPoint* p, i64 margin, int x0, int x1, int y0, int y1) {
  const i64 area2 = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
  if (area2 == 0) return;
  const i64 sign = area2 > 0 ? 1 : -1;
  struct Edge {
    i64 a, b, x, y;        // inward normal, and a point on the edge
    std::uint64_t limit;   // m^2 (a^2 + b^2)
    bool owned;
  };
  std::array<Edge, 3> e;
  for (int i = 0; i < 3; ++i) {
    const FixedPoint q0 = p[i], q1 = p[i == 2 ? 0 : i + 1];
    const i64 a = -(q1.y - q0.y) * sign, b = (q1.x - q0.x) * sign;
    e[static_cast<std::size_t>(i)] = {a, b, q0.x, q0.y, static_cast<std::uint64_t>(margin * margin) * static_cast<std::uint64_t>(a * a + b * b),
                                      a > 0 || (a == 0 && b > 0)};
  }
  int last_tile = -1;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      std::uint64_t& t = tile(x >> 3, y >> 3);
      const std::uint64_t bit = std::uint64_t{1} << (8 * (y & 7) + (x & 7));
      if (t & bit) continue;
      const int tile_id = (y >> 3) * levels_[0].w + (x >> 3);
      stats_.cells_visited += tile_id != last_tile ? 1 : 0;  // tiles, as the other paths count
      last_tile = tile_id;
      const i64 px = static_cast<i64>(x) * kSubpixel + kHalfPixel, py = static_cast<i64>(y) * kSubpixel + kHalfPixel;
      bool inside = true;
      for (const Edge& k : e) {
        const i64 v = k.a * (px - k.x) + k.b * (py - k.y);  // |d| times the distance inside
        const std::uint64_t v2 = static_cast<std::uint64_t>(v) * static_cast<std::uint64_t>(v);
        inside = inside && v >= 0 && (v2 > k.limit || (v2 == k.limit && k.owned));
      }
      if (inside) claim(x >> 3, y >> 3, bit);
    }
  }
}

namespace {

// Snaps N vertices (N > 0 known at compile time, or n at run time) and bounds them; false if one
// is not finite or beyond kMaxCoordinate.
struct Bounds {
  i64 xmin, xmax, ymin, ymax;
};
template <int N>
bool snap_all(const glm::dvec2* v, int n, FixedPoint* p, Bounds& b) {
  const int count = N > 0 ? N : n;
  if (!detail::snap(v[0], p[0])) return false;
  b = {p[0].x, p[0].x, p[0].y, p[0].y};
  for (int i = 1; i < count; ++i) {
    if (!detail::snap(v[i], p[i])) return false;
    b.xmin = std::min(b.xmin, p[i].x);
    b.xmax = std::max(b.xmax, p[i].x);
    b.ymin = std::min(b.ymin, p[i].y);
    b.ymax = std::max(b.ymax, p[i].y);
  }
  return true;
}

// The contract's argument checks of cover() and hidden().
void check_arguments(const char* function, const char* distance, double px, std::size_t points) {
  if (!(px >= 0.0 && px <= kMaxMargin)) {
    throw std::invalid_argument(std::string("coverage::Pyramid::") + function + ": " + distance + " " + std::to_string(px) +
                                " px outside [0, " + std::to_string(kMaxMargin) + "]");
  }
  if (points > static_cast<std::size_t>(kMaxVertices)) {
    throw std::invalid_argument(std::string("coverage::Pyramid::") + function + ": " + std::to_string(points) +
                                " points, more than " + std::to_string(kMaxVertices));
  }
}

}  // namespace

void Pyramid::cover(std::span<const glm::dvec2> polygon, double margin_px) { cover_polygon(polygon, margin_px); }

void Pyramid::cover(std::span<const glm::dvec2> polygon, double margin_px, std::vector<TileMask>& claimed) {
  record(polygon, margin_px, claimed, true);
}

void Pyramid::vacant(std::span<const glm::dvec2> polygon, double margin_px, std::vector<TileMask>& out) {
  record(polygon, margin_px, out, false);
}

void Pyramid::record(std::span<const glm::dvec2> polygon, double margin_px, std::vector<TileMask>& to, bool claim) {
  record_ = &to;
  claim_ = claim;
  try {
    cover_polygon(polygon, margin_px);
  } catch (...) {
    record_ = nullptr;
    claim_ = true;
    throw;
  }
  record_ = nullptr;
  claim_ = true;
}

void Pyramid::cover_polygon(std::span<const glm::dvec2> polygon, double margin_px) {
  check_arguments("cover", "margin", margin_px, polygon.size());
  ++stats_.cover_calls;
  const int nv = static_cast<int>(polygon.size());
  if (nv < 3) return;
  std::array<FixedPoint, kMaxVertices> p;
  Bounds bb;
  if (!(nv == 3 ? snap_all<3>(polygon.data(), nv, p.data(), bb) : snap_all<0>(polygon.data(), nv, p.data(), bb))) return;
  const auto [xmin, xmax, ymin, ymax] = bb;
  // A centre inside by more than the margin lies at least the margin inside the bounding box
  // (pixel x has its centre at 256 x + 128 units).
  const i64 margin = detail::snap_distance_up(margin_px);
  const int x0 = static_cast<int>(std::max<i64>(0, (xmin + margin - kHalfPixel + kSubpixel - 1) >> detail::kSubpixelBits));
  const int x1 = static_cast<int>(std::min<i64>(width_ - 1, (xmax - margin - kHalfPixel) >> detail::kSubpixelBits));
  const int y0 = static_cast<int>(std::max<i64>(0, (ymin + margin - kHalfPixel + kSubpixel - 1) >> detail::kSubpixelBits));
  const int y1 = static_cast<int>(std::min<i64>(height_ - 1, (ymax - margin - kHalfPixel) >> detail::kSubpixelBits));
  if (x0 > x1 || y0 > y1) return;
  constexpr i64 kSmall = i64{1} << 15, kNear = i64{1} << 24;
  if (nv <= 4 && (x1 >> 3) - (x0 >> 3) < kDirectTiles && (y1 >> 3) - (y0 >> 3) < kDirectTiles && xmax - xmin < kSmall && ymax - ymin < kSmall &&
      xmin > -kNear && xmax < kNear && ymin > -kNear && ymax < kNear) {
    if (nv == 3 && x1 - x0 <= 1 && y1 - y0 <= 1) {
      cover_tiny(p.data(), margin, x0, x1, y0, y1);
    } else if (nv == 3) {
      cover_small<3>(p.data(), margin, x0, x1, y0, y1);
    } else {
      cover_small<4>(p.data(), margin, x0, x1, y0, y1);
    }
    return;
  }
  cover_general(p.data(), nv, margin, x0, x1, y0, y1);
}

// cover() for any other polygon: edge functions in 128-bit arithmetic where they must be, the
// triage recursion from the smallest enclosing cells (or straight to the tiles when it spans at
// most 4 x 4 of them).
void Pyramid::cover_general(const detail::FixedPoint* p, int nv, i64 margin, int x0, int x1, int y0, int y1) {
  Edges E;
  E.x0 = x0;
  E.x1 = x1;
  E.y0 = y0;
  E.y1 = y1;
  const int top = static_cast<int>(levels_.size()) - 1;
  const int k = start_level(x0, x1, y0, y1, top);
  const int sh = 3 * (k + 1);
  const int cx0 = x0 >> sh, cx1 = x1 >> sh, cy0 = y0 >> sh, cy1 = y1 >> sh;
  if (all_full(k, cx0, cx1, cy0, cy1)) return;  // everything the polygon could claim is covered already

  // Orientation from the sign of the area (twice the area, exactly).
  i128 area2 = 0;
  for (int i = 1; i + 1 < nv; ++i) area2 += detail::cross(p[0], p[i], p[i + 1]);
  if (area2 == 0) return;
  const i64 sign = area2 > 0 ? 1 : -1;
  for (int i = 0; i < nv; ++i) {
    const FixedPoint q0 = p[i], q1 = p[(i + 1) % nv];
    if (q0 == q1) continue;
    // Inward normal (a, b) of the edge q0 -> q1; the edge function E(P) = (a, b) . (P - q0) is
    // |d| times the distance of P inside the edge's line.
    const i64 a = -(q1.y - q0.y) * sign, b = (q1.x - q0.x) * sign;
    // Inside when E > M |d|, or E >= M |d| on an edge that owns its centres (the fill rule,
    // pyramid.h): E >= t.
    const i64 t = detail::inner_threshold(margin, a, b, a > 0 || (a == 0 && b > 0));
    // E(P) - t at the centre of pixel (x, y), P = 256 (x, y) + 128: 256 (a x + b y) + r.
    const i128 r = static_cast<i128>(a) * (kHalfPixel - q0.x) + static_cast<i128>(b) * (kHalfPixel - q0.y) - t;
    if (!E.add(a, b, r, width_, height_)) return;
  }

  if (k == 0) {
    for (int ty = cy0; ty <= cy1; ++ty) {
      const int j0 = std::max(0, E.y0 - 8 * ty), j1 = std::min(7, E.y1 - 8 * ty);
      for (int tx = cx0; tx <= cx1; ++tx) {
        if (tile(tx, ty) == kAll) continue;
        ++stats_.cells_visited;
        claim(tx, ty, tile_mask(E, E.all.data(), E.n, static_cast<i64>(tx) * 8, static_cast<i64>(ty) * 8, j0, j1));
      }
    }
    return;
  }
  for (int cy = cy0; cy <= cy1; ++cy) {
    for (int cx = cx0; cx <= cx1; ++cx) {
      if (is_full(k, cx, cy)) continue;
      cover_cell(k, cx, cy, E, E.all.data(), E.n);
      if (claim_) propagate(k, cx, cy);
    }
  }
}

namespace {

// The children of a cell (first pixel (ox, oy), children 2^sh px wide) that a pixel box
// [x0, x1] x [y0, y1] touches.
std::uint64_t touched(i64 ox, i64 oy, int sh, int x0, int x1, int y0, int y1) {
  const i64 size = i64{8} << sh;
  if (x1 < ox || y1 < oy || x0 >= ox + size || y0 >= oy + size) return 0;
  const int i0 = static_cast<int>(std::max<i64>(0, (x0 - ox) >> sh)), i1 = static_cast<int>(std::min<i64>(7, (x1 - ox) >> sh));
  const int j0 = static_cast<int>(std::max<i64>(0, (y0 - oy) >> sh)), j1 = static_cast<int>(std::min<i64>(7, (y1 - oy) >> sh));
  return rect_mask(i0, i1, j0, j1);
}

}  // namespace

// Whether every pixel of tile (tx, ty), rows j0..j1, that lies in the dilated polygon is
// covered.
bool Pyramid::hidden_tile(int tx, int ty, const Edges& E, const std::uint8_t* act, int n, int j0, int j1) {
  ++stats_.cells_visited;
  ++stats_.hidden_cells_visited;
  // The offset polygon's uncovered pixels, within the dilated bounding box (beyond it every
  // centre is farther than the dilation; the offset polygon's mitred corners may reach there).
  const i64 ox = static_cast<i64>(tx) * 8, oy = static_cast<i64>(ty) * 8;
  const std::uint64_t cand = tile_mask(E, act, n, ox, oy, j0, j1) & ~tile(tx, ty) & touched(ox, oy, 0, E.x0, E.x1, E.y0, E.y1);
  if (!cand || E.corners == 0) return !cand;
  // Visible unless a rounded corner cuts every one away. The normal cones of a convex polygon's
  // vertices are disjoint, so the first whose cone holds the pixel decides.
  for (std::uint64_t bits = cand; bits; bits &= bits - 1) {
    const int bit = std::countr_zero(bits);
    if (!E.cut(8 * tx + (bit & 7), 8 * ty + (bit >> 3))) return false;
  }
  return true;
}

// Section 5.2's test-only tile_poly for a triage cell that is not wholly covered.
bool Pyramid::hidden_cell(int level, int cx, int cy, const Edges& E, const std::uint8_t* act_in, int n_in) {
  ++stats_.cells_visited;
  ++stats_.hidden_cells_visited;
  std::array<std::uint8_t, kMaxEdges> act;
  int n = 0;
  const int sh = 3 * level;
  const i64 s = i64{1} << sh, ox = static_cast<i64>(cx) << (sh + 3), oy = static_cast<i64>(cy) << (sh + 3);
  std::uint64_t outside = 0;
  for (int q = 0; q < n_in; ++q) {
    const int e = act_in[q];
    const i64 a = E.a[e], b = E.b[e];
    const EdgeAt v = edge_at(a, b, E.c[e], ox, oy, s);
    const i64 spread = 7 * s;
    if (v.f + v.lo + (std::min<i64>(a, 0) + std::min<i64>(b, 0)) * spread >= 0) continue;
    if (v.f + v.hi + (std::max<i64>(a, 0) + std::max<i64>(b, 0)) * spread < 0) return true;  // misses the cell
    outside |= ~mask64(v.f + v.hi, s * a, s * b);
    act[static_cast<std::size_t>(n++)] = static_cast<std::uint8_t>(e);
  }
  // Children beyond the dilated bounding box hold no pixel of the dilated polygon. (Section 5.2
  // also stops at a vacant child the polygon covers wholly; here the first such child is
  // reached through its tiles instead, a few cells further, which spares classifying children
  // against the rounded corners.)
  outside |= ~touched(ox, oy, sh, E.x0, E.x1, E.y0, E.y1);
  const Cell& m = cell(level, cx, cy);
  for (std::uint64_t active = ~(outside | m.c); active; active &= active - 1) {
    const int bit = std::countr_zero(active);
    const int x = 8 * cx + (bit & 7), y = 8 * cy + (bit >> 3);
    if (level == 1 ? !hidden_tile(x, y, E, act.data(), n, 0, 7) : !hidden_cell(level - 1, x, y, E, act.data(), n)) {
      return false;
    }
  }
  return true;
}

bool Pyramid::hidden(std::span<const glm::dvec2> polygon, double dilation_px) {
  check_arguments("hidden", "dilation", dilation_px, polygon.size());
  ++stats_.hidden_calls;
  const auto answer = [this](bool h) {
    stats_.hidden_true += h ? 1 : 0;
    return h;
  };
  const int np = static_cast<int>(polygon.size());
  if (np == 0) return answer(true);
  std::array<FixedPoint, kMaxVertices> p;
  Bounds bb;
  if (!(np == 8 ? snap_all<8>(polygon.data(), np, p.data(), bb) : snap_all<0>(polygon.data(), np, p.data(), bb))) return answer(false);
  const auto [xmin, xmax, ymin, ymax] = bb;
  const i64 dilation = detail::snap_distance_up(dilation_px);
  Edges E;
  E.dilation = dilation;
  E.x0 = static_cast<int>(std::max<i64>(0, (xmin - dilation - kHalfPixel + kSubpixel - 1) >> detail::kSubpixelBits));
  E.x1 = static_cast<int>(std::min<i64>(width_ - 1, (xmax + dilation - kHalfPixel) >> detail::kSubpixelBits));
  E.y0 = static_cast<int>(std::max<i64>(0, (ymin - dilation - kHalfPixel + kSubpixel - 1) >> detail::kSubpixelBits));
  E.y1 = static_cast<int>(std::min<i64>(height_ - 1, (ymax + dilation - kHalfPixel) >> detail::kSubpixelBits));
  if (E.x0 > E.x1 || E.y0 > E.y1) return answer(true);  // no pixel of the viewport is that near
  const int top = static_cast<int>(levels_.size()) - 1;
  const int k = start_level(E.x0, E.x1, E.y0, E.y1, top);
  const int sh = 3 * (k + 1);
  const int cx0 = E.x0 >> sh, cx1 = E.x1 >> sh, cy0 = E.y0 >> sh, cy1 = E.y1 >> sh;
  if (all_full(k, cx0, cx1, cy0, cy1)) return answer(true);  // everything near the polygon is covered

  std::array<FixedPoint, kMaxVertices> h;
  const int nh = detail::convex_hull_fixed(std::span(p.data(), static_cast<std::size_t>(np)), h);
  // The offset polygon: every edge of the (counterclockwise) hull moved out by the dilation,
  // E(P) >= -D |d|, that is E(P) >= -floor(D |d|) for the integer E. Two points make a strip.
  for (int i = 0; nh >= 2 && i < nh; ++i) {
    const FixedPoint q0 = h[i], q1 = h[(i + 1) % nh];
    const i64 a = -(q1.y - q0.y), b = q1.x - q0.x;
    const i64 t = -detail::scaled_length_floor(dilation, a, b);
    const i128 r = static_cast<i128>(a) * (kHalfPixel - q0.x) + static_cast<i128>(b) * (kHalfPixel - q0.y) - t;
    if (!E.add(a, b, r, width_, height_)) return answer(true);
  }
  if (nh <= 2) {
    // A disc or a capsule: bound it by its box (x0 <= x <= x1, y0 <= y <= y1), so that the
    // corners' cuts are bounded too.
    constexpr i64 u = kSubpixel;
    if (!E.add(1, 0, -static_cast<i128>(E.x0) * u, width_, height_) || !E.add(-1, 0, static_cast<i128>(E.x1) * u, width_, height_) ||
        !E.add(0, 1, -static_cast<i128>(E.y0) * u, width_, height_) || !E.add(0, -1, static_cast<i128>(E.y1) * u, width_, height_)) {
      return answer(true);
    }
  }
  // The rounded corners. With no dilation the offset polygon is the polygon and there is
  // nothing to cut.
  for (int i = 0; dilation > 0 && i < nh; ++i) {
    Corner& c = E.corner[static_cast<std::size_t>(E.corners++)];
    const FixedPoint v = h[i], prev = h[(i + nh - 1) % nh], next = h[(i + 1) % nh];
    c.v = v;
    c.px = prev.x - v.x;
    c.py = prev.y - v.y;
    c.nx = next.x - v.x;
    c.ny = next.y - v.y;
    c.whole_plane = nh == 1;
  }

  if (k == 0) {
    for (int ty = cy0; ty <= cy1; ++ty) {
      const int j0 = std::max(0, E.y0 - 8 * ty), j1 = std::min(7, E.y1 - 8 * ty);
      for (int tx = cx0; tx <= cx1; ++tx) {
        if (tile(tx, ty) == kAll) continue;
        if (!hidden_tile(tx, ty, E, E.all.data(), E.n, j0, j1)) return answer(false);
      }
    }
    return answer(true);
  }
  for (int cy = cy0; cy <= cy1; ++cy) {
    for (int cx = cx0; cx <= cx1; ++cx) {
      if (is_full(k, cx, cy)) continue;
      if (!hidden_cell(k, cx, cy, E, E.all.data(), E.n)) return answer(false);
    }
  }
  return answer(true);
}

bool Pyramid::covered(int x, int y) const {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return false;
  return (tile(x >> 3, y >> 3) >> (8 * (y & 7) + (x & 7))) & 1;
}

std::uint64_t Pyramid::covered_count() const {
  std::uint64_t n = 0;
  for (std::uint64_t t : tiles_) n += static_cast<std::uint64_t>(detail::popcount64(t));
  return n - (static_cast<std::uint64_t>(tiles_.size()) * 64 - static_cast<std::uint64_t>(width_) * static_cast<std::uint64_t>(height_));
}

std::string Pyramid::check_invariants() const {
  const int tw = levels_[0].w, th = levels_[0].h;
  for (int ty = 0; ty < th; ++ty) {
    for (int tx = 0; tx < tw; ++tx) {
      for (int bit = 0; bit < 64; ++bit) {
        const int x = 8 * tx + (bit & 7), y = 8 * ty + (bit >> 3);
        if ((x >= width_ || y >= height_) && !((tile(tx, ty) >> bit) & 1)) {
          return "tile (" + std::to_string(tx) + ", " + std::to_string(ty) + "): pixel (" + std::to_string(x) +
                 ", " + std::to_string(y) + ") outside the viewport is not covered";
        }
      }
    }
  }
  for (std::size_t k = 1; k < levels_.size(); ++k) {
    const Level& l = levels_[k];
    for (int cy = 0; cy < l.h; ++cy) {
      for (int cx = 0; cx < l.w; ++cx) {
        const Cell& m = l.cells[static_cast<std::size_t>(cy) * static_cast<std::size_t>(l.w) + static_cast<std::size_t>(cx)];
        for (int bit = 0; bit < 64; ++bit) {
          const int x = 8 * cx + (bit & 7), y = 8 * cy + (bit >> 3);
          const auto [full, empty] = state(static_cast<int>(k) - 1, x, y);
          const bool c = (m.c >> bit) & 1, v = (m.v >> bit) & 1;
          if (c != full || v != empty) {
            return "level " + std::to_string(k) + " cell (" + std::to_string(cx) + ", " + std::to_string(cy) +
                   ") child (" + std::to_string(x) + ", " + std::to_string(y) + "): C=" + std::to_string(c) +
                   " V=" + std::to_string(v) + " but the child is " + (full ? "covered" : empty ? "vacant" : "partly covered");
          }
        }
      }
    }
  }
  return {};
}

}  // namespace terravol::coverage
