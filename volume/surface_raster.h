// A volume's values on a surface of constant height (above the ground or above the datum),
// on a north-up geographic raster: the coverage map `terravol export-map` writes as GeoTIFF
// and KMZ.
#pragma once

#include <cstddef>
#include <vector>

#include "io/geo_raster.h"
#include "volume/volume.h"

namespace terravol::volume {

// The surface: `metres` above the ground (kGround) or above the DEM's vertical datum (kDatum).
struct SurfaceHeight {
  HeightRef ref = HeightRef::kGround;
  double metres = 0.0;
};

// The raster that covers a volume at its own resolution, values NaN until sampled:
// - a geographic frame: one pixel centred on each of the lattice's (longitude, latitude)
//   columns, so pixel (r, c) is column (i = c, j = dims[1] - 1 - r) and dlon, dlat are the
//   lattice spacings;
// - an ENU frame: the geographic bounding box of the lattice's eight corners, pixel centres
//   from its north-west corner at the lattice's east and north spacings in degrees at the
//   origin (GeographicLib LocalCartesian, at the origin's height), as many as it takes to
//   reach the box's south and east edges.
// Throws std::invalid_argument for a volume without a frame, or a raster of more than
// kMaxPoints pixels.
io::GeoRaster footprint_raster(const Volume& volume);

// Whether sampling `surface` needs the ground: a height above the ground in a volume whose
// heights are above the datum (geographic-datum or ENU), or a height above the datum in a
// terrain-following volume (geographic, heights above ground).
bool needs_ground(const Volume& volume, const SurfaceHeight& surface);

// Fills raster.values with the volume's value on `surface` at each pixel centre: the centre
// (latitude, longitude) at the surface's height (ground(lat, lon) converts between heights
// above the ground and above the datum where needs_ground) is turned into the volume's world
// coordinates (ENU: GeographicLib LocalCartesian::Forward, the inverse of LatticeMapper) and
// interpolated trilinearly between lattice points (sample_trilinear, compare.h); NaN where
// that lies outside the lattice or a point with a weight > 0 is not finite.
// Returns how many pixels got a value. Throws std::invalid_argument when the ground is needed
// and `ground` is empty, or the height is not finite.
std::size_t sample_surface(const Volume& volume, const SurfaceHeight& surface, const GroundFunction& ground,
                           io::GeoRaster& raster);

}  // namespace terravol::volume
