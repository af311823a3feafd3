// Geographic points on a DEM mosaic's sample lattice: the one place for the arithmetic that
// turns a longitude into a column (longitudes taken modulo 360 east of the mosaic's west edge,
// so a mosaic may cross the antimeridian), the check that a camera lies near enough to the
// mosaic, the default camera over it, and degrees as text for messages.
#pragma once

#include <string>

#include "app/scene/camera.h"
#include "io/mosaic.h"

namespace terravol::app::scene {

// A fractional lattice position: row 0 is the mosaic's north edge, column 0 its west edge.
struct LatticePoint {
  double row = 0.0, col = 0.0;
};

// The lattice position of (lat, lon) degrees: row = (y0 - lat) / dy, col = (lon - x0, taken in
// [0, 360)) / dx, with the mosaic's georef (y0, x0: the north-west sample).
LatticePoint lattice_point(const io::Mosaic& mosaic, double lat, double lon);

// Whether p lies within [0, rows - 1] x [0, cols - 1], allowing 1e-9 of a sample for rounding
// (a point clamped to the mosaic's edge in degrees is inside).
bool inside(const io::Mosaic& mosaic, const LatticePoint& p);

// How far (lat, lon) lies beyond the mosaic's edges, in kilometres (0 inside): the degrees
// beyond its latitude and longitude ranges at 111.2 km per degree (longitude's times
// cos(lat)), combined as a hypotenuse. Accurate to a percent or so: it bounds cameras.
double km_beyond(const io::Mosaic& mosaic, double lat, double lon);

// Cameras may lie beyond the DEM (an overview from outside a tile), up to this far: farther, a
// tile of a degree is a few pixels across, and the position is taken for a typing mistake.
inline constexpr double kMaxKmBeyond = 200.0;

// Throws std::runtime_error("camera 47.50000 N, 6.50000 E is 250.1 km beyond the DEM (45.00000 N
// .. 46.00000 N, 6.00000 E .. 7.00000 E; at most 200 km)") when (lat, lon) lies more than
// kMaxKmBeyond beyond the mosaic.
void require_near(const io::Mosaic& mosaic, double lat, double lon);

// The nearest point of the mosaic to (lat, lon), in place; longitude in [-180, 180].
void clamp_to_mosaic(const io::Mosaic& mosaic, double& lat, double& lon);
// (lat, lon) moved toward the mosaic's nearest point until it lies 0.999 kMaxKmBeyond beyond
// the mosaic, in place, when it lies farther (the viewer's flight stops there).
void clamp_near_mosaic(const io::Mosaic& mosaic, double& lat, double& lon);

// The camera `terravol view` starts from without --camera: 1500 m above the ground (alt is
// above the ground) over the mosaic's centre sample, heading north, pitch -15 degrees.
CameraPose default_pose(const io::Mosaic& mosaic);

// "45.50000 N": |v| with five decimals and the hemisphere letter (negative: `negative`).
std::string degrees(double v, char positive, char negative);

}  // namespace terravol::app::scene
