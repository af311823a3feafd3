#include "io/scene_frame.h"

#include <GeographicLib/Ellipsoid.hpp>
#include <GeographicLib/Math.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace terravol::io {

namespace {
constexpr double kDeg = 3.14159265358979323846 / 180.0;

double east_radius(double lat) {  // N(lat) cos(lat)
  const auto& e = GeographicLib::Ellipsoid::WGS84();
  return e.TransverseCurvatureRadius(lat) * std::cos(lat * kDeg);
}
}  // namespace

SceneFrame::SceneFrame(double lat0, double lon0) : lat0_(lat0), lon0_(GeographicLib::Math::AngNormalize(lon0)) {
  if (!(lat0 >= -85.0 && lat0 <= 85.0)) {
    throw std::invalid_argument("SceneFrame: origin latitude " + std::to_string(lat0) + " outside [-85, 85]");
  }
  const auto& e = GeographicLib::Ellipsoid::WGS84();
  const double m = e.MeridionalCurvatureRadius(lat0);
  const double n = e.TransverseCurvatureRadius(lat0);
  ex_ = n * std::cos(lat0 * kDeg) * kDeg;
  ey_ = m * kDeg;
  r_ = std::sqrt(m * n);
}

double SceneFrame::x_of_lon(double lon) const { return ex_ * GeographicLib::Math::AngDiff(lon0_, lon); }
double SceneFrame::y_of_lat(double lat) const { return ey_ * (lat - lat0_); }
double SceneFrame::lon_of_x(double x) const {
  double lon = GeographicLib::Math::AngNormalize(lon0_ + x / ex_);
  return lon >= 180.0 ? lon - 360.0 : lon;
}
double SceneFrame::lat_of_y(double y) const { return lat0_ + y / ey_; }

ScenePoint SceneFrame::to_scene(const Geodetic& g) const {
  ScenePoint p;
  p.x = x_of_lon(g.lon);
  p.y = y_of_lat(g.lat);
  p.z = g.h - curvature_drop(p.x, p.y);
  return p;
}

Geodetic SceneFrame::to_geodetic(const ScenePoint& p) const {
  return {lat_of_y(p.y), lon_of_x(p.x), p.z + curvature_drop(p.x, p.y)};
}

double SceneFrame::scale_error(double lat) const {
  const auto& e = GeographicLib::Ellipsoid::WGS84();
  const double sx = ex_ / (east_radius(lat) * kDeg);
  const double sy = ey_ / (e.MeridionalCurvatureRadius(lat) * kDeg);
  return std::max(std::abs(sx - 1.0), std::abs(sy - 1.0));
}

}  // namespace terravol::io
