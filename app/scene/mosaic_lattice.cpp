#include "app/scene/mosaic_lattice.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace terravol::app::scene {

namespace {

// Degrees east of the mosaic's west edge, in [0, 360).
double east_of_west(const io::Georef& g, double lon) { return std::remainder(lon - g.x0 - 180.0, 360.0) + 180.0; }

constexpr double kEdgeTolerance = 1e-9;  // samples

}  // namespace

LatticePoint lattice_point(const io::Mosaic& mosaic, double lat, double lon) {
  const io::Georef& g = mosaic.georef();
  return {(g.y0 - lat) / g.dy, east_of_west(g, lon) / g.dx};
}

bool inside(const io::Mosaic& mosaic, const LatticePoint& p) {
  return p.row >= -kEdgeTolerance && p.row <= mosaic.rows() - 1 + kEdgeTolerance && p.col >= -kEdgeTolerance &&
         p.col <= mosaic.cols() - 1 + kEdgeTolerance;
}

void require_inside(const io::Mosaic& mosaic, double lat, double lon) {
  if (inside(mosaic, lattice_point(mosaic, lat, lon))) return;
  const io::Georef& g = mosaic.georef();
  const double south = g.y0 - (mosaic.rows() - 1) * g.dy, east = g.x0 + (mosaic.cols() - 1) * g.dx;
  throw std::runtime_error("camera " + degrees(lat, 'N', 'S') + ", " + degrees(lon, 'E', 'W') +
                           " is outside the DEM (" + degrees(south, 'N', 'S') + " .. " + degrees(g.y0, 'N', 'S') +
                           ", " + degrees(g.x0, 'E', 'W') + " .. " + degrees(east, 'E', 'W') + ")");
}

void clamp_to_mosaic(const io::Mosaic& mosaic, double& lat, double& lon) {
  const io::Georef& g = mosaic.georef();
  const double south = g.y0 - (mosaic.rows() - 1) * g.dy;
  lat = std::clamp(lat, south, g.y0);
  lon = std::remainder(g.x0 + std::clamp(east_of_west(g, lon), 0.0, (mosaic.cols() - 1) * g.dx), 360.0);
}

CameraPose default_pose(const io::Mosaic& mosaic) {
  const io::Georef& g = mosaic.georef();
  CameraPose p;
  p.lat = g.y0 - (mosaic.rows() - 1) * g.dy / 2.0;
  p.lon = std::remainder(g.x0 + (mosaic.cols() - 1) * g.dx / 2.0, 360.0);
  p.alt = 1500.0;  // above the ground
  p.heading_deg = 0.0;
  p.pitch_deg = -15.0;
  return p;
}

std::string degrees(double v, char positive, char negative) {
  char b[32];
  std::snprintf(b, sizeof b, "%.5f %c", std::abs(v), v < 0 ? negative : positive);
  return b;
}

}  // namespace terravol::app::scene
