#include "app/terrain_scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "io/void_fill.h"

namespace terravol::app {

namespace {

int floor_log2(int v) {
  int k = 0;
  while ((2 << k) <= v) ++k;
  return k;
}

io::SceneFrame centre_frame(const io::Mosaic& mosaic, const WindowChoice& w) {
  const io::Georef& g = mosaic.georef();
  const double lat = g.y0 - (w.row0 + w.cells / 2) * g.dy;
  const double lon = g.x0 + (w.col0 + w.cells / 2) * g.dx;
  return io::SceneFrame(lat, std::remainder(lon, 360.0));
}

}  // namespace

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

int default_levels(int cells) { return std::max(1, floor_log2(cells) - 2); }

TerrainScene::TerrainScene(const io::Mosaic& mosaic, const WindowChoice& window, int levels)
    : window_(window), frame_(centre_frame(mosaic, window)), tree_(build(*this, mosaic, levels)) {}

mrbsp::TerrainTree TerrainScene::build(TerrainScene& s, const io::Mosaic& mosaic, int levels) {
  const int n = s.window_.cells, side = n + 1;
  const int k = floor_log2(n);
  if (levels < 1 || levels > k + 1) {
    throw std::invalid_argument("--levels " + std::to_string(levels) + ": a window of " + std::to_string(n) +
                                " cells has 1.." + std::to_string(k + 1) + " levels");
  }
  const io::Georef& g = mosaic.georef();
  s.lat_step_ = g.dy;
  s.lon_step_ = g.dx;
  s.bounds_.north = g.y0 - s.window_.row0 * g.dy;
  s.bounds_.south = s.bounds_.north - n * g.dy;
  s.bounds_.west = g.x0 + s.window_.col0 * g.dx;
  s.bounds_.east = s.bounds_.west + n * g.dx;

  io::Grid grid = mosaic.read_window(s.window_.row0, s.window_.col0, side, side);
  s.filled_ = io::fill_voids(grid);

  s.xs_.resize(side);
  s.ys_.resize(side);
  for (int i = 0; i < side; ++i) s.xs_[i] = s.frame_.x_of_lon(s.bounds_.west + i * g.dx);
  for (int j = 0; j < side; ++j) s.ys_[j] = s.frame_.y_of_lat(s.bounds_.south + j * g.dy);
  s.heights_.resize(static_cast<std::size_t>(side) * side);
  s.z_.resize(s.heights_.size());
  s.min_z_ = std::numeric_limits<float>::max();
  s.max_z_ = std::numeric_limits<float>::lowest();
  for (int j = 0; j < side; ++j) {
    const int grid_row = n - j;  // io grids have row 0 north; the tree wants row 0 south
    for (int i = 0; i < side; ++i) {
      const std::size_t t = static_cast<std::size_t>(j) * side + i;
      const float h = grid.heights[grid.index(grid_row, i)];
      s.heights_[t] = h;
      s.z_[t] = static_cast<float>(h - s.frame_.curvature_drop(s.xs_[i], s.ys_[j]));
      s.min_z_ = std::min(s.min_z_, s.z_[t]);
      s.max_z_ = std::max(s.max_z_, s.z_[t]);
    }
  }
  mrbsp::TerrainWindow tw;
  tw.cells = n;
  tw.xs = s.xs_;
  tw.ys = s.ys_;
  tw.z = s.z_;
  const auto t0 = std::chrono::steady_clock::now();
  mrbsp::TerrainTree tree(tw, levels);
  s.build_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return tree;
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

}  // namespace terravol::app
