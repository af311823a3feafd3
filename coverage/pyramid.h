// The coverage pyramid of Greene, "Hierarchical Polygon Tiling with Coverage Masks", SIGGRAPH
// 1996 (sections 3, 3.1, 4.1, 4.5, 5.2), in its point-sampled form (section 4.5): the finest
// level holds one 64-bit mask per 8x8-pixel tile (one bit per pixel); above it, triage masks
// (a C "covered" and a V "vacant" bit per child, 8x8 children per cell) up to a single root.
// Polygons are tiled front to back; a tiled pixel is never tiled again.
//
// Conventions (the integration checks these against llvmpipe, see docs/architecture.md):
// - Window coordinates in pixels, GL convention: origin at the bottom-left corner of the
//   viewport, y up; pixel (x, y) is the unit square [x, x+1) x [y, y+1), its centre
//   (x + 0.5, y + 0.5). The viewport is glViewport(0, 0, width, height).
// - Vertices are first snapped to the nearest multiple of 1/256 pixel (ties to even), as
//   llvmpipe does (8 sub-pixel bits); everything below is then exact, in integers, on the
//   snapped polygon. Snapping moves an edge by at most sqrt(2)/512 = 0.0028 px: a caller that
//   wants guarantees about its unsnapped polygon adds that to its margin.
// - Fill rule (the ownership of a pixel centre lying exactly on an edge): a centre on an edge
//   is inside when the polygon's interior lies on the edge's +x side (a "left" edge) or, for
//   a horizontal edge, on its +y side (a "bottom" edge, in GL's y-up window coordinates).
//   This is Mesa's rule for GL: gallium sets bottom_edge_rule for window-system framebuffers,
//   whose rows run top-down, which makes it the same rule in GL coordinates for windows and
//   FBOs alike (llvmpipe's lp_setup_tri.c: "GL (normally) ends up needing a bottom-left fill
//   convention"). It decides only centres lying exactly at the margin's distance from an
//   edge, which in practice means margin 0.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>

namespace terravol::coverage {

namespace detail {
struct FixedPoint;
}

// Work counters since the last clear() (Greene, section 9: "cells visited" counts every pyramid
// cell, triage cell or finest tile, whose masks a tiling or a test composited).
struct Stats {
  std::uint64_t cover_calls = 0;
  std::uint64_t hidden_calls = 0;
  std::uint64_t hidden_true = 0;      // hidden() calls that answered true
  std::uint64_t cells_visited = 0;    // by cover() and hidden() together
  std::uint64_t hidden_cells_visited = 0;  // the part of cells_visited spent in hidden()
  std::uint64_t cells_filled = 0;     // cells and tiles set wholly covered below a triage W bit
  std::uint64_t pixels_claimed = 0;   // pixels newly covered by cover()
};

inline constexpr int kMaxViewport = 16384;     // width and height are in [1, kMaxViewport]
inline constexpr double kMaxCoordinate = 16777216.0;  // 2^24 px: |x| and |y| of any vertex
inline constexpr double kMaxMargin = 256.0;    // px: margin and dilation are in [0, kMaxMargin]
inline constexpr int kMaxVertices = 64;        // vertices of one polygon

// Pixels of `run` finest tiles in a row, (tx, ty) to (tx + run - 1, ty), each with the same
// mask: bit (y % 8) * 8 + x % 8 of tile (x / 8, y / 8). Runs longer than 1 have every pixel
// (a whole cell the polygon covers, reported row by row).
struct TileMask {
  int tx = 0, ty = 0;
  std::uint64_t mask = 0;
  int run = 1;
};

// Not thread-safe (hidden() counts into the stats too): one pyramid per thread.
class Pyramid {
 public:
  // An empty pyramid over a width x height viewport. Throws std::invalid_argument unless both
  // are in [1, kMaxViewport].
  Pyramid(int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }

  // Every pixel vacant again; the counters reset. Costs one pass over the finest masks (115 KB
  // at 1280x720).
  void clear();

  // True when every pixel of the viewport is covered.
  bool full() const { return root().c == ~std::uint64_t{0}; }

  // Tiles a convex polygon (vertices in order, either orientation) into the pyramid: a pixel
  // becomes covered when its centre lies inside the polygon eroded by margin_px, that is, for
  // every edge of the snapped polygon, the centre's distance from the edge's line, measured
  // into the polygon, is greater than margin_px, or equal to it on an edge that owns its
  // centres by the fill rule above. Only pixels inside the viewport are claimed: the polygon
  // may reach outside it or lie entirely outside. A polygon whose snapped form has no area, or
  // fewer than 3 vertices, claims nothing. A non-convex polygon claims the intersection of its
  // edges' inner half-planes (orientation from the sign of its area), which for a simple
  // polygon lies inside it. margin_px is rounded up to a multiple of 1/256 px.
  // Conservative by construction: never claims a centre within margin_px of an edge or
  // outside. A vertex with |x| or |y| above kMaxCoordinate, or not finite, makes the call claim
  // nothing (the caller clips to a guard band if it needs such polygons tiled).
  // Throws std::invalid_argument when margin_px is not in [0, kMaxMargin] or the polygon has
  // more than kMaxVertices vertices.
  void cover(std::span<const glm::dvec2> polygon, double margin_px);

  // cover(), and every pixel it newly covers appended to `claimed` (not cleared first), tile by
  // tile or in runs of whole tiles: for the renderer that shades what each polygon claims
  // (Greene, section 3.1: the W masks, down to the finest level; a triage W bit, a whole cell,
  // comes as one run per row of its tiles). A tile may appear more than once with disjoint
  // masks; every mask is non-zero; no pixel is reported twice between two clear()s, and the
  // union of the masks is exactly the set of pixels the call covered. Same contract and throws
  // as cover().
  void cover(std::span<const glm::dvec2> polygon, double margin_px, std::vector<TileMask>& claimed);

  // The pixels cover(polygon, margin_px) would claim now (those of the polygon still vacant),
  // appended to `out` tile by tile as cover() above reports them, without covering them: a
  // translucent polygon shows over exactly these. The pyramid is not changed (its stats count
  // the call as a cover call and its cells as visited). Same contract and throws as cover().
  void vacant(std::span<const glm::dvec2> polygon, double margin_px, std::vector<TileMask>& out);

  // Test-only tiling (section 5.2): true only when every pixel of the viewport whose centre
  // lies within dilation_px of the polygon (inside it, or outside at a Euclidean distance
  // <= dilation_px, so the corners are rounded) is covered. The polygon taken is the convex
  // hull of the snapped points (any order; 1 or 2 points make a disc or a capsule). Pixels
  // outside the viewport are not considered: a polygon reaching outside it is tested on the
  // pixels inside only, and one entirely outside is hidden. Never updates the pyramid; stops at
  // the first uncovered pixel. dilation_px is rounded up to a multiple of 1/256 px.
  // A point with |x| or |y| above kMaxCoordinate, or not finite, makes the answer false
  // (visible). An empty span is hidden. Throws std::invalid_argument when dilation_px is not in
  // [0, kMaxMargin] or there are more than kMaxVertices points.
  bool hidden(std::span<const glm::dvec2> polygon, double dilation_px);

  // Whether pixel (x, y) is covered (0 <= x < width, 0 <= y < height; false outside).
  bool covered(int x, int y) const;
  // The covered pixels of finest tile (tx, ty), 0 <= tx < grid_width(0), 0 <= ty <
  // grid_height(0) (unchecked): bit (y % 8) * 8 + x % 8; pixels beyond the viewport are set.
  std::uint64_t tile_bits(int tx, int ty) const { return tile(tx, ty); }
  // The number of covered pixels in the viewport.
  std::uint64_t covered_count() const;

  const Stats& stats() const { return stats_; }

  // The pyramid's shape: number of triage levels above the finest (the last is the 1x1 root
  // level) and each level's grid (level 0 is the finest, in 8x8-pixel tiles).
  int triage_levels() const { return static_cast<int>(levels_.size()) - 1; }
  int grid_width(int level) const { return levels_.at(static_cast<std::size_t>(level)).w; }
  int grid_height(int level) const { return levels_.at(static_cast<std::size_t>(level)).h; }

  // Checks that every triage mask agrees with the finest level below it (C bit exactly when
  // the child is wholly covered, V bit exactly when wholly vacant, missing children covered,
  // pixels outside the viewport covered). Returns an empty string when it holds, else a
  // description of the first disagreement. Costs a pass over the whole pyramid: for tests.
  std::string check_invariants() const;

 private:
  struct Cell {
    std::uint64_t c = 0;  // child wholly covered
    std::uint64_t v = 0;  // child wholly vacant
  };
  struct Level {
    int w = 0, h = 0;           // grid size, in cells (tiles at level 0)
    std::vector<Cell> cells;    // row-major from the bottom-left; empty at level 0
  };
  struct Edges;

  const Cell& root() const { return levels_.back().cells.front(); }
  Cell& cell(int level, int cx, int cy) {
    Level& l = levels_[static_cast<std::size_t>(level)];
    return l.cells[static_cast<std::size_t>(cy) * static_cast<std::size_t>(l.w) + static_cast<std::size_t>(cx)];
  }
  std::uint64_t& tile(int tx, int ty) {
    return tiles_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(levels_[0].w) + static_cast<std::size_t>(tx)];
  }
  std::uint64_t tile(int tx, int ty) const {
    return tiles_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(levels_[0].w) + static_cast<std::size_t>(tx)];
  }
  bool is_full(int level, int cx, int cy);
  bool all_full(int level, int cx0, int cx1, int cy0, int cy1);
  void claim(int tx, int ty, std::uint64_t mask);
  std::pair<bool, bool> state(int level, int x, int y) const;
  void propagate(int level, int cx, int cy);
  void fill(int level, int cx, int cy);
  static std::uint64_t tile_mask(const Edges& edges, const std::uint8_t* act, int n, std::int64_t ox,
                                 std::int64_t oy, int j0, int j1);
  [[gnu::noinline]] void cover_general(const detail::FixedPoint* p, int n, std::int64_t margin, int x0, int x1, int y0, int y1);
  void cover_tiny(const detail::FixedPoint* p, std::int64_t margin, int x0, int x1, int y0, int y1);
  template <int N>
  void cover_small(const detail::FixedPoint* p, std::int64_t margin, int x0, int x1, int y0, int y1);
  void cover_cell(int level, int cx, int cy, const Edges& edges, const std::uint8_t* act, int n);
  void cover_polygon(std::span<const glm::dvec2> polygon, double margin_px);
  void record(std::span<const glm::dvec2> polygon, double margin_px, std::vector<TileMask>& to, bool claim);
  void report(int tx, int ty, std::uint64_t mask) { record_->push_back({tx, ty, mask, 1}); }
  void report_subtree(int level, int cx, int cy);
  bool hidden_cell(int level, int cx, int cy, const Edges& edges, const std::uint8_t* act, int n);
  bool hidden_tile(int tx, int ty, const Edges& edges, const std::uint8_t* act, int n, int j0, int j1);

  int width_, height_;
  std::vector<std::uint64_t> tiles_;  // the finest level: bit (y % 8) * 8 + (x % 8) of tile (x / 8, y / 8)
  std::vector<Level> levels_;         // [0] the tile grid (no cells), then the triage levels
  std::vector<Cell> cleared_;         // every triage level's cells when empty, in order
  Stats stats_;
  // While cover(..., claimed) or vacant() runs: where the pixels go, and whether they are
  // covered (false: vacant(), which only reports them).
  std::vector<TileMask>* record_ = nullptr;
  bool claim_ = true;
};

}  // namespace terravol::coverage
