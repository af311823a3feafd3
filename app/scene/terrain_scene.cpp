#include "app/scene/terrain_scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "app/scene/timing.h"
#include "io/void_fill.h"

namespace terravol::app::scene {

namespace {

int floor_log2(int v) {
  int k = 0;
  while ((2 << k) <= v) ++k;
  return k;
}

}  // namespace

io::SceneFrame centre_frame(const io::Mosaic& mosaic, const WindowChoice& w) {
  const io::Georef& g = mosaic.georef();
  const double lat = g.y0 - (w.row0 + w.cells / 2) * g.dy;
  const double lon = g.x0 + (w.col0 + w.cells / 2) * g.dx;
  return io::SceneFrame(lat, std::remainder(lon, 360.0));
}

WindowChoice choose_window(int rows, int cols, double row, double col, int max_cells) {
  const int side = std::min(rows, cols);
  if (side < 3) {
    throw std::invalid_argument("the DEM is too small to render (" + std::to_string(rows) + " x " +
                                std::to_string(cols) + " samples; at least 3 x 3 needed)");
  }
  WindowChoice w;
  w.cells = std::min(1 << floor_log2(side - 1), max_cells);
  auto place = [&](double at, int n) {
    const int first = static_cast<int>(std::lround(at - w.cells / 2.0));
    return std::clamp(first, 0, n - 1 - w.cells);
  };
  w.row0 = place(row, rows);
  w.col0 = place(col, cols);
  return w;
}

WindowChoice plan_slide(const WindowChoice& current, int rows, int cols, double row, double col, int step,
                        double margin) {
  const int n = current.cells;
  // The new first line of one axis: `first` moved by whole steps toward `at`, kept in [0, last].
  auto move = [&](int first, double at, int samples) {
    const double offset = at - first;
    if (offset >= margin * n && offset <= (1.0 - margin) * n) return first;
    const int last = samples - 1 - n;
    int steps = static_cast<int>(std::lround((at - (first + n / 2.0)) / step));
    while (steps > 0 && first + steps * step > last) --steps;
    while (steps < 0 && first + steps * step < 0) ++steps;
    return first + steps * step;
  };
  WindowChoice w = current;
  w.row0 = move(current.row0, row, rows);
  w.col0 = move(current.col0, col, cols);
  return w;
}

int default_levels(int cells) { return std::max(1, floor_log2(cells) - 2); }

TerrainScene::TerrainScene(const io::Mosaic& mosaic, const WindowChoice& window, int levels)
    : window_(window), frame_(centre_frame(mosaic, window)), tree_(build(*this, mosaic, levels)) {}

mrbsp::TerrainTree TerrainScene::build(TerrainScene& s, const io::Mosaic& mosaic, int levels) {
  const int n = s.window_.cells;
  const int k = floor_log2(n);
  if (levels < 1 || levels > k + 1) {
    throw std::invalid_argument("--levels " + std::to_string(levels) + ": a window of " + std::to_string(n) +
                                " cells has 1.." + std::to_string(k + 1) + " levels");
  }
  const mrbsp::TerrainWindow tw = s.adopt(read_scene_window(mosaic, s.window_, s.frame_));
  const auto t0 = Clock::now();
  mrbsp::TerrainTree tree(tw, levels);
  s.build_ms_ = ms_since(t0);
  return tree;
}

void TerrainScene::slide(const io::Mosaic& mosaic, const WindowChoice& window) {
  if (window.cells != window_.cells) {
    throw std::invalid_argument("TerrainScene::slide: a window of " + std::to_string(window.cells) +
                                " cells for a scene of " + std::to_string(window_.cells));
  }
  slide(read_scene_window(mosaic, window, frame_));
}

void TerrainScene::slide(SceneWindow&& moved) {
  if (moved.window.cells != window_.cells || moved.xs.size() != xs_.size() || moved.z.size() != z_.size()) {
    throw std::invalid_argument("TerrainScene::slide: a window of " + std::to_string(moved.window.cells) +
                                " cells for a scene of " + std::to_string(window_.cells));
  }
  tree_.slide(adopt(std::move(moved)));
}

mrbsp::TerrainWindow TerrainScene::adopt(SceneWindow&& w) {
  window_ = w.window;
  bounds_ = w.bounds;
  lat_step_ = w.lat_step;
  lon_step_ = w.lon_step;
  filled_ = w.filled;
  xs_ = std::move(w.xs);
  ys_ = std::move(w.ys);
  heights_ = std::move(w.heights);
  z_ = std::move(w.z);
  min_z_ = w.min_z;
  max_z_ = w.max_z;
  mrbsp::TerrainWindow tw;
  tw.cells = window_.cells;
  tw.xs = xs_;
  tw.ys = ys_;
  tw.z = z_;
  return tw;
}

SceneWindow read_scene_window(const io::Mosaic& mosaic, const WindowChoice& window, const io::SceneFrame& frame) {
  const int n = window.cells, side = n + 1;
  SceneWindow w;
  w.window = window;
  io::Grid grid = mosaic.read_window(window.row0, window.col0, side, side);
  w.filled = io::fill_voids(grid);

  const io::Georef& g = mosaic.georef();
  w.lat_step = g.dy;
  w.lon_step = g.dx;
  w.bounds.north = g.y0 - window.row0 * g.dy;
  w.bounds.south = w.bounds.north - n * g.dy;
  w.bounds.west = g.x0 + window.col0 * g.dx;
  w.bounds.east = w.bounds.west + n * g.dx;

  w.xs.resize(side);
  w.ys.resize(side);
  // From the mosaic's own lattice (column col0 + i, row row0 + n - j from the north), not from
  // the window's corner: a sample's plane offset is then the same double in every window
  // holding it, so that a slide can find the samples two windows share and keep what lies on
  // them (mrbsp::TerrainTree::slide).
  for (int i = 0; i < side; ++i) w.xs[i] = frame.x_of_lon(g.x0 + (window.col0 + i) * g.dx);
  for (int j = 0; j < side; ++j) w.ys[j] = frame.y_of_lat(g.y0 - (window.row0 + n - j) * g.dy);
  w.heights.resize(static_cast<std::size_t>(side) * side);
  w.z.resize(w.heights.size());
  w.min_z = std::numeric_limits<float>::max();
  w.max_z = std::numeric_limits<float>::lowest();
  for (int j = 0; j < side; ++j) {
    const int grid_row = n - j;  // io grids have row 0 north; the tree wants row 0 south
    for (int i = 0; i < side; ++i) {
      const std::size_t t = static_cast<std::size_t>(j) * side + i;
      const float h = grid.heights[grid.index(grid_row, i)];
      w.heights[t] = h;
      w.z[t] = static_cast<float>(h - frame.curvature_drop(w.xs[i], w.ys[j]));
      w.min_z = std::min(w.min_z, w.z[t]);
      w.max_z = std::max(w.max_z, w.z[t]);
    }
  }
  return w;
}

double TerrainScene::ground_height(double lat, double lon) const {
  const int n = window_.cells, side = n + 1;
  const double lon_offset = std::remainder(lon - bounds_.west, 360.0);
  const double u = std::clamp(lon_offset / lon_step_, 0.0, static_cast<double>(n));
  const double v = std::clamp((lat - bounds_.south) / lat_step_, 0.0, static_cast<double>(n));
  const int i = std::min(static_cast<int>(u), n - 1), j = std::min(static_cast<int>(v), n - 1);
  const double fu = u - i, fv = v - j;
  auto h = [&](int jj, int ii) { return static_cast<double>(heights_[static_cast<std::size_t>(jj) * side + ii]); };
  return (1 - fv) * ((1 - fu) * h(j, i) + fu * h(j, i + 1)) + fv * ((1 - fu) * h(j + 1, i) + fu * h(j + 1, i + 1));
}

double TerrainScene::far_plane(const glm::dvec3& eye) const {
  glm::dvec3 lo(xs_.front(), ys_.front(), min_z_), hi(xs_.back(), ys_.back(), max_z_);
  const std::vector<glm::vec3>& positions = tree_.positions();
  const std::size_t base = tree_.merged_base();
  if (merged_box_.version != tree_.merged_version() || merged_box_.count != positions.size()) {
    merged_box_.version = tree_.merged_version();
    merged_box_.count = positions.size();
    merged_box_.lo = glm::dvec3(std::numeric_limits<double>::max());
    merged_box_.hi = glm::dvec3(std::numeric_limits<double>::lowest());
    for (std::size_t v = base; v < positions.size(); ++v) {
      merged_box_.lo = glm::min(merged_box_.lo, glm::dvec3(positions[v]));
      merged_box_.hi = glm::max(merged_box_.hi, glm::dvec3(positions[v]));
    }
  }
  if (positions.size() > base) {
    lo = glm::min(lo, merged_box_.lo);
    hi = glm::max(hi, merged_box_.hi);
  }
  double far = 0.0;
  for (double x : {lo.x, hi.x})
    for (double y : {lo.y, hi.y})
      for (double z : {lo.z, hi.z}) far = std::max(far, glm::length(glm::dvec3(x, y, z) - eye));
  return far * 1.05 + 100.0;
}

}  // namespace terravol::app::scene
