// The ground under the volumes, read again for the independent reference (reference/check.h):
// DEM samples straight from SRTM .hgt tiles and SPLAT! .sdf / .sdf.bz2 tiles, joined on one
// geographic lattice and sampled bilinearly. Written here rather than taken from io/ or app/
// (io::Mosaic, app::GroundGrid) so that the check shares no placement code with the renderer.
// Voids are not filled: a point whose bilinear stencil touches a void or a gap throws, so the
// reference never guesses where the renderer would have filled.
#pragma once

#include <filesystem>
#include <vector>

namespace terravol::reference {

// A rectangle in degrees (east-positive longitudes).
struct Box {
  double south = 0, north = 0, west = 0, east = 0;
};

class Dem {
 public:
  // Reads the tiles among `paths` (files, or folders whose .hgt, .sdf and .sdf.bz2 files are
  // taken) whose extent meets `box` widened by 0.01 degree; the tiles' corners come from their
  // names (SRTM "N44W072" names the south-west corner; SDF "40_41_111_112" or "40:41:111:112"
  // is lat 40..41, west longitude 111..112). Formats:
  // - .hgt: 1201^2 or 3601^2 big-endian int16, rows from the north, the tile's edges included,
  //   -32768 = void;
  // - .sdf: SPLAT!'s ASCII tiles (io/sdf.cpp's header comment): four header lines (max west,
  //   min north, min west, max north), then 1200^2 (or 3600^2) heights, rows from the south,
  //   each from the east; no shared edges, so sample (row r from the south, column c from the
  //   west) lies at (south + r / n, west + c / n).
  // Throws std::runtime_error("PATH: what is wrong") for unreadable or malformed tiles, tiles
  // of different spacings, or when no tile meets the box.
  static Dem read(const std::vector<std::filesystem::path>& paths, const Box& box);

  // Metres (the DEM's datum) at (lat, lon) degrees: bilinear in the four samples around it.
  // Throws std::runtime_error when the point lies outside the samples read or a stencil sample
  // is a void or a gap.
  double height(double lat, double lon) const;

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  double spacing() const { return spacing_; }  // degrees, both axes
  double south() const { return south_; }      // latitude of row 0
  double west() const { return west_; }        // longitude of column 0
  // Row r from the south, column c from the west; NaN for voids and gaps.
  float sample(int r, int c) const { return samples_[static_cast<std::size_t>(r) * cols_ + c]; }

 private:
  int rows_ = 0, cols_ = 0;
  double spacing_ = 1, south_ = 0, west_ = 0;
  std::vector<float> samples_;
};

}  // namespace terravol::reference
