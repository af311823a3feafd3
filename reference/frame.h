// The scene frame, written again from its definition in docs/architecture.md ("The scene
// frame"), for the independent reference (reference/check.h). Deliberately not io::SceneFrame:
// the check must not share the placement code of what it checks.
#pragma once

#include <glm/vec3.hpp>

namespace terravol::reference {

// A local equirectangular frame about (lat0, lon0), degrees:
//   x = N(lat0) cos(lat0) (lon - lon0),  y = M(lat0) (lat - lat0)   (angles in radians)
//   z = h - (x^2 + y^2) / (2 R),         R = sqrt(M(lat0) N(lat0))
// with M and N the meridional and prime-vertical radii of curvature of WGS84 at lat0
// (GeographicLib::Ellipsoid), lon - lon0 wrapped into [-180, 180). Metres.
class Frame {
 public:
  // Throws std::invalid_argument unless -85 <= lat0 <= 85 and both are finite.
  Frame(double lat0, double lon0);

  // lat, lon in degrees; h metres in the DEM's vertical datum. Returns scene metres.
  glm::dvec3 to_scene(double lat, double lon, double h) const;
  // The inverse for the horizontal axes: the latitude of y and the longitude (in [-180, 180)) of
  // x, degrees.
  double lat_of(double y) const;
  double lon_of(double x) const;

  double lat0() const { return lat0_; }
  double lon0() const { return lon0_; }

 private:
  double lat0_, lon0_;
  double east_per_radian_, north_per_radian_, radius_;
};

}  // namespace terravol::reference
