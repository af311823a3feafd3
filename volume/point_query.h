// The value of a volume at a point given by latitude, longitude and height above the ground:
// what `terravol query` prints (and what a pick in the viewer shows).
#pragma once

#include <array>
#include <memory>

#include "volume/volume.h"

namespace GeographicLib {
class LocalCartesian;
}

namespace terravol::volume {

class PointQuery {
 public:
  // Keeps a reference to `volume`, which must outlive the query. Throws std::invalid_argument
  // ("NAME: the volume has no frame ...") for a volume without a frame.
  explicit PointQuery(const Volume& volume);
  ~PointQuery();
  PointQuery(PointQuery&&) noexcept;
  PointQuery& operator=(PointQuery&&) = delete;

  // The point's world coordinates in the volume's frame: geographic with heights above ground
  // (lon, lat, height_agl); geographic above the datum (lon, lat, ground_m + height_agl); ENU
  // (east, north, up) of (lat, lon, ground_m + height_agl) about the frame's origin
  // (GeographicLib LocalCartesian, heights taken as the frame's: volume.h). ground_m is the
  // DEM's height there (metres above its datum); unused for heights above ground.
  std::array<double, 3> world(double lat, double lon, double height_agl, double ground_m) const;

  // The volume's value there by trilinear interpolation between its lattice points
  // (sample_trilinear, compare.h): exact at a lattice point (to 1e-6 of a spacing); NaN outside
  // the lattice or where a lattice point with a non-zero weight is not finite.
  double value(double lat, double lon, double height_agl, double ground_m) const;

 private:
  const Volume& volume_;
  std::unique_ptr<GeographicLib::LocalCartesian> enu_;
};

}  // namespace terravol::volume
