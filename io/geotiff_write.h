// Writing a geographic raster as a GeoTIFF with libtiff and libgeotiff (GeoTIFF 1.0, rev.
// 1.8.2), the form GDAL, QGIS and io/geotiff.cpp read.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/geo_raster.h"

namespace terravol::io {

// Text GIS tools show: the description goes to ImageDescription and, with the units, to
// GDAL_METADATA as the band's description and unit type.
struct GeoTiffText {
  std::string description;  // e.g. "path_loss_db (dB) at 10 m above ground"
  std::string units;        // e.g. "dB"
};

// The GeoTIFF bytes of `raster`: float32, one sample per pixel, in strips of 16 rows,
// deflate-compressed with the floating-point predictor; GeoKeys ModelTypeGeographic,
// RasterPixelIsArea, GCS_WGS_84 (EPSG:4326) in degrees (section 2.5.2.2: raster (0, 0) is the
// outer corner of pixel (0, 0)); ModelTiepoint (0, 0, 0) -> (west, north, 0) and
// ModelPixelScale (dlon, dlat, 0); GDAL_NODATA "nan", so NaN pixels are no data.
// Throws std::invalid_argument for an empty raster, values.size() != rows * cols, a spacing
// that is not finite and positive or corners that are not finite; std::runtime_error (with
// libtiff's message) when libtiff fails.
std::vector<std::uint8_t> encode_geotiff(const GeoRaster& raster, const GeoTiffText& text = {});

}  // namespace terravol::io
