#include "app/scene/ground_grid.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "io/void_fill.h"

namespace terravol::app::scene {

GroundGrid::Span GroundGrid::span(const io::Mosaic& mosaic, double south, double north, double west,
                                  double east) {
  const io::Georef& g = mosaic.georef();
  const int r0 = static_cast<int>(std::floor((g.y0 - north) / g.dy)) - 2;
  const int r1 = static_cast<int>(std::ceil((g.y0 - south) / g.dy)) + 2;
  const int c0 = static_cast<int>(std::floor((west - g.x0) / g.dx)) - 2;
  const int c1 = static_cast<int>(std::ceil((east - g.x0) / g.dx)) + 2;
  return {r0, c0, std::clamp(r1 - r0 + 1, 2, 20000), std::clamp(c1 - c0 + 1, 2, 20000)};
}

GroundGrid::GroundGrid(const io::Mosaic& mosaic, const Span& s, io::Grid grid)
    : grid_(std::move(grid)) {
  const io::Georef& g = mosaic.georef();
  io::fill_voids(grid_);
  lat0_ = g.y0 - s.r0 * g.dy;
  lon0_ = g.x0 + s.c0 * g.dx;
  dlat_ = g.dy;
  dlon_ = g.dx;
}

GroundGrid::GroundGrid(const io::Mosaic& mosaic, double south, double north, double west,
                       double east) {
  const Span s = span(mosaic, south, north, west, east);
  *this = GroundGrid(mosaic, s, mosaic.read_window(s.r0, s.c0, s.rows, s.cols));
}

std::optional<GroundGrid> GroundGrid::cached(const io::Mosaic& mosaic, double south, double north,
                                             double west, double east) {
  const Span s = span(mosaic, south, north, west, east);
  std::optional<io::Grid> grid = mosaic.read_cached_window(s.r0, s.c0, s.rows, s.cols);
  if (!grid) return std::nullopt;
  return GroundGrid(mosaic, s, std::move(*grid));
}

double GroundGrid::operator()(double lat, double lon) const {
  const double r = std::clamp((lat0_ - lat) / dlat_, 0.0, grid_.rows - 1.0);
  const double c = std::clamp((lon - lon0_) / dlon_, 0.0, grid_.cols - 1.0);
  const int r0 = std::min(static_cast<int>(r), grid_.rows - 2), c0 = std::min(static_cast<int>(c), grid_.cols - 2);
  const double fr = r - r0, fc = c - c0;
  auto h = [&](int rr, int cc) { return static_cast<double>(grid_.heights[grid_.index(rr, cc)]); };
  return (1 - fr) * ((1 - fc) * h(r0, c0) + fc * h(r0, c0 + 1)) + fr * ((1 - fc) * h(r0 + 1, c0) + fc * h(r0 + 1, c0 + 1));
}

}  // namespace terravol::app::scene
