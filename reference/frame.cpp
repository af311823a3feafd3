#include "reference/frame.h"

#include <GeographicLib/Ellipsoid.hpp>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace terravol::reference {

namespace {
constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;
}  // namespace

Frame::Frame(double lat0, double lon0) : lat0_(lat0), lon0_(lon0) {
  if (!std::isfinite(lat0) || !std::isfinite(lon0) || lat0 < -85.0 || lat0 > 85.0) {
    throw std::invalid_argument("reference frame: origin " + std::to_string(lat0) + ", " +
                                std::to_string(lon0) + " is not a latitude in [-85, 85] and a longitude");
  }
  const GeographicLib::Ellipsoid& wgs84 = GeographicLib::Ellipsoid::WGS84();
  const double m = wgs84.MeridionalCurvatureRadius(lat0);
  const double n = wgs84.TransverseCurvatureRadius(lat0);
  east_per_radian_ = n * std::cos(lat0 * kRadiansPerDegree);
  north_per_radian_ = m;
  radius_ = std::sqrt(m * n);
}

glm::dvec3 Frame::to_scene(double lat, double lon, double h) const {
  double dlon = std::fmod(lon - lon0_, 360.0);  // into [-180, 180)
  if (dlon < -180.0) dlon += 360.0;
  if (dlon >= 180.0) dlon -= 360.0;
  const double x = east_per_radian_ * dlon * kRadiansPerDegree;
  const double y = north_per_radian_ * (lat - lat0_) * kRadiansPerDegree;
  return {x, y, h - (x * x + y * y) / (2.0 * radius_)};
}

double Frame::lat_of(double y) const { return lat0_ + y / north_per_radian_ / kRadiansPerDegree; }

double Frame::lon_of(double x) const {
  double lon = std::fmod(lon0_ + x / east_per_radian_ / kRadiansPerDegree, 360.0);
  if (lon < -180.0) lon += 360.0;
  if (lon >= 180.0) lon -= 360.0;
  return lon;
}

}  // namespace terravol::reference
