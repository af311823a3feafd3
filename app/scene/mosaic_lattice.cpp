#include "app/scene/mosaic_lattice.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
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

double km_beyond(const io::Mosaic& mosaic, double lat, double lon) {
  double clat = lat, clon = lon;
  clamp_to_mosaic(mosaic, clat, clon);
  constexpr double kKmPerDegree = 111.2;
  const double north = (lat - clat) * kKmPerDegree;
  const double east = std::remainder(lon - clon, 360.0) * kKmPerDegree * std::cos(lat * std::numbers::pi / 180.0);
  return std::hypot(north, east);
}

void require_near(const io::Mosaic& mosaic, double lat, double lon) {
  const double km = km_beyond(mosaic, lat, lon);
  if (km <= kMaxKmBeyond) return;
  const io::Georef& g = mosaic.georef();
  const double south = g.y0 - (mosaic.rows() - 1) * g.dy, east = g.x0 + (mosaic.cols() - 1) * g.dx;
  char b[64];
  std::snprintf(b, sizeof b, " is %.1f km beyond the DEM (", km);
  throw std::runtime_error("camera " + degrees(lat, 'N', 'S') + ", " + degrees(lon, 'E', 'W') + b + degrees(south, 'N', 'S') +
                           " .. " + degrees(g.y0, 'N', 'S') + ", " + degrees(g.x0, 'E', 'W') + " .. " + degrees(east, 'E', 'W') +
                           "; at most " + std::to_string(static_cast<int>(kMaxKmBeyond)) + " km)");
}

void clamp_to_mosaic(const io::Mosaic& mosaic, double& lat, double& lon) {
  const io::Georef& g = mosaic.georef();
  const double south = g.y0 - (mosaic.rows() - 1) * g.dy;
  lat = std::clamp(lat, south, g.y0);
  lon = std::remainder(g.x0 + std::clamp(east_of_west(g, lon), 0.0, (mosaic.cols() - 1) * g.dx), 360.0);
}

void clamp_near_mosaic(const io::Mosaic& mosaic, double& lat, double& lon) {
  const double km = km_beyond(mosaic, lat, lon);
  if (km <= kMaxKmBeyond) return;
  double clat = lat, clon = lon;
  clamp_to_mosaic(mosaic, clat, clon);
  // Back along the way to the nearest point, a little inside the limit (the longitude's scale
  // changes with the latitude, so the limit itself could round outside).
  const double t = 0.999 * kMaxKmBeyond / km;
  lat = clat + t * (lat - clat);
  lon = std::remainder(clon + t * std::remainder(lon - clon, 360.0), 360.0);
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
