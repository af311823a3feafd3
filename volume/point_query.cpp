// Point queries (point_query.h).
#include "volume/point_query.h"

#include <GeographicLib/LocalCartesian.hpp>

#include <limits>
#include <stdexcept>

#include "volume/compare.h"

namespace terravol::volume {

PointQuery::PointQuery(const Volume& volume) : volume_(volume) {
  if (volume.frame.kind == FrameKind::kNone) {
    throw std::invalid_argument(volume.name + ": the volume has no frame (give one, e.g. geographic or enu:LAT,LON,H)");
  }
  if (volume.frame.kind == FrameKind::kEnu) {
    enu_ = std::make_unique<GeographicLib::LocalCartesian>(volume.frame.origin_lat, volume.frame.origin_lon,
                                                           volume.frame.origin_h);
  }
}

PointQuery::~PointQuery() = default;
PointQuery::PointQuery(PointQuery&&) noexcept = default;

std::array<double, 3> PointQuery::world(double lat, double lon, double height_agl, double ground_m) const {
  if (enu_) {
    std::array<double, 3> w{};
    enu_->Forward(lat, lon, ground_m + height_agl, w[0], w[1], w[2]);
    return w;
  }
  return {lon, lat, volume_.frame.height == HeightRef::kGround ? height_agl : ground_m + height_agl};
}

double PointQuery::value(double lat, double lon, double height_agl, double ground_m) const {
  const auto w = world(lat, lon, height_agl, ground_m);
  const auto v = sample_trilinear(volume_, w[0], w[1], w[2]);
  return v ? *v : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace terravol::volume
