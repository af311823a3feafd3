// A float raster on WGS84 latitude and longitude (EPSG:4326): a coverage map on its way out
// to GIS tools (io/geotiff_write.h).
#pragma once

#include <cstddef>
#include <vector>

namespace terravol::io {

// North-up, pixel-is-area: pixel (r, c) covers longitudes [west + c dlon, west + (c + 1) dlon)
// and latitudes (north - (r + 1) dlat, north - r dlat], degrees; its value is the one at its
// centre. Invariant: values.size() == rows * cols.
struct GeoRaster {
  int rows = 0, cols = 0;
  double west = 0.0, north = 0.0;  // degrees, the outer edges
  double dlon = 0.0, dlat = 0.0;   // degrees per pixel, > 0
  std::vector<float> values;       // row 0 north, each row west to east; NaN: no value

  double centre_lon(int c) const { return west + (c + 0.5) * dlon; }
  double centre_lat(int r) const { return north - (r + 0.5) * dlat; }
  double east() const { return west + cols * dlon; }
  double south() const { return north - rows * dlat; }
  float at(int r, int c) const { return values[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + c]; }
};

}  // namespace terravol::io
