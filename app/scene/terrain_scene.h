// The terrain a render draws: a square window of the mosaic's lattice around the camera, its
// voids filled, placed in a scene frame about the window's centre, and its MRBSP tree.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "io/grid.h"
#include "io/mosaic.h"
#include "io/scene_frame.h"
#include "mrbsp/terrain_tree.h"

namespace terravol::app::scene {

// A window of the mosaic lattice: rows [row0, row0 + cells] and columns [col0, col0 + cells]
// (cells + 1 samples per side; row 0 north, as in io::Grid).
struct WindowChoice {
  int row0 = 0, col0 = 0;
  int cells = 0;  // a power of two, >= 2
};

// The window for a camera at the fractional lattice position (row, col): side 2^k cells with
// k the largest such that 2^k + 1 samples fit in the mosaic (rows x cols) and 2^k <= max_cells,
// centred on (row, col) as nearly as whole samples allow and moved inward to lie inside the
// mosaic. Preconditions: max_cells a power of two >= 2. Throws std::invalid_argument when the
// mosaic is smaller than 3 x 3 samples.
WindowChoice choose_window(int rows, int cols, double row, double col, int max_cells);

// Sliding (Wiley et al. 1997, section 4.3): the window to move to when the camera, at the
// fractional lattice position (row, col), is within `margin` (a share of the side) of an edge of
// `current`. Each axis on which the camera is that near an edge moves by the whole number of
// `step` cells (the coarsest level's cell, so that every level's lattice stays on the same
// mosaic samples) that brings the camera nearest the window's centre, less whole steps where the
// mosaic (rows x cols samples) ends. Returns `current` when no move is needed or possible.
// Preconditions: step >= 1, 0 < margin < 0.5.
WindowChoice plan_slide(const WindowChoice& current, int rows, int cols, double row, double col, int step,
                        double margin = 0.25);

// The default level count for a window of `cells` = 2^k cells: k - 2, so that the coarsest
// level is 8 x 8 cells; at least 1.
int default_levels(int cells);

// Geographic extent of a window's samples, degrees.
struct WindowBounds {
  double south = 0, north = 0, west = 0, east = 0;
};

// The lattice of one window placed in a scene frame: what a TerrainScene holds (see its
// accessors for the conventions), and what a slide reads ahead, possibly on another thread.
struct SceneWindow {
  WindowChoice window;
  WindowBounds bounds;
  double lat_step = 0, lon_step = 0;  // degrees per row and column
  std::size_t filled = 0;             // samples filled by fill_voids
  std::vector<double> xs, ys;
  std::vector<float> heights, z;
  float min_z = 0, max_z = 0;
};

// The scene frame a TerrainScene of `window` is placed in: about the window's centre sample.
io::SceneFrame centre_frame(const io::Mosaic& mosaic, const WindowChoice& window);

// Reads `window` from the mosaic (read_window), fills its voids and the samples no tile covers
// (fill_voids) and places it in `frame`. Touches nothing but the mosaic (whose tile cache is
// not thread-safe: one reader at a time). Throws io::FormatError from the mosaic.
SceneWindow read_scene_window(const io::Mosaic& mosaic, const WindowChoice& window, const io::SceneFrame& frame);

class TerrainScene {
 public:
  // Reads the window from the mosaic (read_window), fills its voids and the samples no tile
  // covers (fill_voids), places it in a SceneFrame about the window's centre sample and builds
  // the tree with `levels` LOD levels (1 <= levels <= k + 1). Throws io::FormatError from the
  // mosaic and std::invalid_argument for a bad level count.
  TerrainScene(const io::Mosaic& mosaic, const WindowChoice& window, int levels);

  // Sliding (section 4.3): reads `window` (same cells as before) from the mosaic, recomputes
  // xs, ys, heights and z in the SAME scene frame (its origin does not move, so neither does
  // anything already placed in it, the camera included) and slides the tree. Throws
  // std::invalid_argument when the size differs, and io::FormatError from the mosaic, in which
  // case the scene keeps its old window.
  void slide(const io::Mosaic& mosaic, const WindowChoice& window);
  // The same with the window read ahead: `moved` from read_scene_window(mosaic, window,
  // frame()). Throws std::invalid_argument when its size differs.
  void slide(SceneWindow&& moved);

  const io::SceneFrame& frame() const { return frame_; }
  const WindowChoice& window() const { return window_; }
  WindowBounds bounds() const { return bounds_; }
  int cells() const { return window_.cells; }
  std::size_t filled_samples() const { return filled_; }

  // The lattice in the tree's convention (mrbsp::TerrainWindow): row 0 SOUTH, column 0 west;
  // xs[i] = x_of_lon(lon of column i), ys[j] = y_of_lat(lat of row j), heights[j * (n+1) + i]
  // in metres of the DEM's datum (voids filled), z = height - curvature drop.
  std::span<const double> xs() const { return xs_; }
  std::span<const double> ys() const { return ys_; }
  std::span<const float> heights() const { return heights_; }
  std::span<const float> z() const { return z_; }
  float min_z() const { return min_z_; }
  float max_z() const { return max_z_; }

  const mrbsp::TerrainTree& tree() const { return tree_; }
  // Merges surfaces into the tree by id (TerrainTree::set_surfaces: each replaces what its id
  // held, an empty one removes it; slide() merges them all again into the moved window).
  mrbsp::MergeStats set_surfaces(std::span<const std::uint32_t> ids, std::span<const mrbsp::SurfaceInput> surfaces) {
    return tree_.set_surfaces(ids, surfaces);
  }
  // Builds anew the small BSPs edits wore (TerrainTree::tidy).
  mrbsp::MergeStats tidy() { return tree_.tidy(); }
  double build_ms() const { return build_ms_; }  // the tree's constructor alone, wall clock

  // Bilinear height (metres, datum) at a geographic point; points outside the window are
  // clamped to its edge.
  double ground_height(double lat, double lon) const;

  // A far clipping distance for an eye (scene frame): the farthest any window sample or merged
  // vertex (volumes, objects and paths may reach beyond the window and above its highest
  // sample) can be, plus 5% and 100 m.
  double far_plane(const glm::dvec3& eye) const;

 private:
  static mrbsp::TerrainTree build(TerrainScene& self, const io::Mosaic& mosaic, int levels);
  mrbsp::TerrainWindow adopt(SceneWindow&& w);  // takes w's lattice; returns views of it for the tree
  WindowChoice window_;
  WindowBounds bounds_;
  double lat_step_ = 0, lon_step_ = 0;  // degrees per row and column
  io::SceneFrame frame_;
  std::size_t filled_ = 0;
  std::vector<double> xs_, ys_;
  std::vector<float> heights_, z_;
  float min_z_ = 0, max_z_ = 0;
  double build_ms_ = 0;
  mrbsp::TerrainTree tree_;
  // The merged vertices' box, for far_plane(): recomputed when the tree's merged_version() or
  // vertex count changed.
  struct MergedBox {
    std::uint64_t version = ~std::uint64_t{0};
    std::size_t count = 0;
    glm::dvec3 lo{0.0}, hi{0.0};
  };
  mutable MergedBox merged_box_;
};

}  // namespace terravol::app::scene
