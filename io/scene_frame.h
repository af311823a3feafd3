// The scene frame: a local equirectangular frame in which every line of constant latitude or
// longitude is an exact plane y = c or x = c (docs/architecture.md, "The scene frame").
#pragma once

namespace terravol::io {

struct ScenePoint {
  double x = 0.0;  // metres east of the origin along the frame's x axis
  double y = 0.0;  // metres north of the origin
  double z = 0.0;  // metres: height minus the Earth's curvature drop
};

struct Geodetic {
  double lat = 0.0;  // degrees
  double lon = 0.0;  // degrees, in [-180, 180)
  double h = 0.0;    // metres in the data's vertical datum
};

// Frame about the origin (lat0, lon0):
//   x = N(lat0) cos(lat0) * (lon - lon0),  y = M(lat0) * (lat - lat0)   (angles in radians)
//   z = h - (x^2 + y^2) / (2 R),           R = sqrt(M(lat0) N(lat0))
// with M and N the meridional and prime-vertical radii of curvature of the WGS84 ellipsoid
// at lat0 (GeographicLib). lon - lon0 is taken in [-180, 180), so a window may span the
// antimeridian. x depends on longitude only and y on latitude only: planes x = c and y = c are
// exactly the meridians and parallels. The drop moves points only vertically.
//
// Scale error: distances along a parallel at latitude lat are scaled by
// N(lat0) cos(lat0) / (N(lat) cos(lat)), along a meridian by M(lat0) / M(lat); see scale_error().
// At 45 degrees that is about 1.8% one degree north or south of the origin, 0.9% at half a
// degree; east-west offsets add no error. Heights are not scaled.
class SceneFrame {
 public:
  // Precondition: -85 <= lat0 <= 85 (the frame degenerates at the poles); throws
  // std::invalid_argument otherwise.
  SceneFrame(double lat0, double lon0);

  double lat0() const { return lat0_; }
  double lon0() const { return lon0_; }
  double metres_per_degree_lon() const { return ex_; }  // N(lat0) cos(lat0) * pi / 180
  double metres_per_degree_lat() const { return ey_; }  // M(lat0) * pi / 180
  double curvature_radius() const { return r_; }        // R, metres

  double x_of_lon(double lon) const;
  double y_of_lat(double lat) const;
  double lon_of_x(double x) const;  // in [-180, 180)
  double lat_of_y(double y) const;
  double curvature_drop(double x, double y) const { return (x * x + y * y) / (2.0 * r_); }

  ScenePoint to_scene(const Geodetic& g) const;
  Geodetic to_geodetic(const ScenePoint& p) const;  // exact inverse of to_scene

  // Largest relative error of the frame's horizontal scale at (lat, lon) against the true
  // ellipsoidal scale, over the east and north directions: max(|sx - 1|, |sy - 1|).
  double scale_error(double lat) const;

 private:
  double lat0_, lon0_, ex_, ey_, r_;
};

}  // namespace terravol::io
