// The in-memory elevation grid every DEM reader returns.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace terravol::io {

// Horizontal reference system of a grid.
enum class Crs : std::uint8_t {
  kGeographic,  // x = longitude, y = latitude, degrees, WGS84 (or the file's datum, see Grid)
  kUtm,         // x = easting, y = northing, metres, WGS84 UTM
};

// Where the samples are. Samples are points (SRTM/DTED convention): column c lies at
// x0 + c * dx and row r at y0 - r * dy, so row 0 is the northernmost row and column 0 the
// westernmost. Formats that store cell corners (ESRI xllcorner, GeoTIFF PixelIsArea) are
// converted to sample centres by their readers.
struct Georef {
  Crs crs = Crs::kGeographic;
  int utm_zone = 0;        // 1..60 when crs == kUtm, else 0
  bool utm_north = true;   // hemisphere when crs == kUtm
  double x0 = 0.0;         // x of column 0 (degrees or metres)
  double y0 = 0.0;         // y of row 0 (degrees or metres)
  double dx = 0.0;         // column spacing, > 0
  double dy = 0.0;         // row spacing, > 0
};

// Values of Grid::mask.
enum class Sample : std::uint8_t {
  kValid = 0,
  kVoid = 1,     // the file says "no data" here
  kOutside = 2,  // no file covers this sample (a mosaic gap, or outside a resampled footprint)
};

// A DEM grid in a reader's native reference system.
// Invariants: heights.size() == mask.size() == rows * cols; row-major, row 0 north.
// Heights are metres; where mask != kValid the height is 0 until fill_voids() runs.
struct Grid {
  std::string format;          // short name: "srtm", "dted", "usgs-dem", "esri-ascii", "geotiff", "sdf"
  int rows = 0;
  int cols = 0;
  Georef georef;
  std::string vertical_datum;  // as far as the file says, e.g. "EGM96 geoid (SRTM)"; "unknown" if silent
  std::vector<float> heights;
  std::vector<Sample> mask;
  std::size_t checksum_errors = 0;  // records whose checksum failed (DTED); their data is kept
  std::vector<std::string> notes;   // facts worth telling the user (resampled from UTM, ...)

  std::size_t size() const { return static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols); }
  std::size_t index(int row, int col) const {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(col);
  }
  // Allocates rows x cols samples, all valid and 0. Precondition: rows, cols > 0 and already
  // checked against the input size by the reader (see check_dimensions in bytes.h).
  void allocate(int n_rows, int n_cols);
};

// Counts samples with the given mask value.
std::size_t count(const Grid& grid, Sample what);

// Minimum and maximum height over valid samples; {0, 0} when there is none.
struct HeightRange {
  float min = 0.0f;
  float max = 0.0f;
  bool any = false;
};
HeightRange height_range(const Grid& grid);

}  // namespace terravol::io
