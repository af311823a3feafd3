// Ground heights over a rectangle of a DEM mosaic, voids filled, sampled bilinearly: the
// ground under a volume (heights above ground, terrain-following slices) wherever the
// terrain window is.
#pragma once

#include <optional>

#include "io/grid.h"
#include "io/mosaic.h"

namespace terravol::app::scene {

class GroundGrid {
 public:
  GroundGrid() = default;
  // Reads the mosaic's samples covering [south, north] x [west, east] degrees plus two
  // samples on every side (at most 20000 x 20000) and fills their voids (io::fill_voids;
  // samples no tile covers count as voids). Throws io::FormatError from the mosaic.
  GroundGrid(const io::Mosaic& mosaic, double south, double north, double west, double east);
  // The same from the mosaic's cached tiles alone (io::Mosaic::read_cached_window): nullopt,
  // and nothing decoded, when a tile it needs is not cached.
  static std::optional<GroundGrid> cached(const io::Mosaic& mosaic, double south, double north,
                                          double west, double east);

  // Metres in the DEM's datum at a geographic point, bilinear; clamped to the rectangle.
  // Precondition: built by the reading constructor.
  double operator()(double lat, double lon) const;

 private:
  struct Span {  // the lattice's rows and columns a rectangle reads
    int r0, c0, rows, cols;
  };
  static Span span(const io::Mosaic& mosaic, double south, double north, double west, double east);
  GroundGrid(const io::Mosaic& mosaic, const Span& s, io::Grid grid);
  io::Grid grid_;
  double lat0_ = 0, lon0_ = 0, dlat_ = 1, dlon_ = 1;
};

}  // namespace terravol::app::scene
