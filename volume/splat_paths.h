// SPLAT!'s own terrain profiles for an area map, so that the built-in ITM can be run on exactly
// the profiles `splat -olditm` runs its ITM on, and the two compared point by point (what
// remains between their volumes is then the sampling alone; docs/rf-model.md).
//
// What SPLAT! 1.4.2 does (J. A. Magliacane, KD2BD; its PlotLRMap(), PlotLRPath(), ReadPath(),
// GetElevation() and mask functions in splat.cpp, as its -ano output shows them): it draws
// radials from the transmitter to every SDF cell on the edge of the loaded region (the north
// edge west to east, the east edge north to south, the south edge west to east, the west edge
// south to north); each radial is sampled along the great circle (a sphere of 3959 miles) at
// equal steps, as many as the path spans cells (sqrt(dx^2 + dy^2) with dx, dy the path's
// longitude and latitude extents in cells), each sample the height of its nearest SDF cell;
// from the radial's third sample on, out to the range, a sample whose cell no earlier radial
// marked is computed and written at the sample's position: ITM over the samples before it
// (the profile ends one sample short of the point), the receiver over that last sample.
#pragma once

#include <functional>
#include <span>

#include "io/grid.h"
#include "volume/compare.h"
#include "volume/splat.h"

namespace terravol::volume {

// One point SPLAT! computes, with the profile it hands its ITM.
struct SplatPathPoint {
  double lat = 0.0, lon = 0.0;        // where SPLAT! writes it: degrees north, degrees EAST
  std::span<const double> ground_m;   // heights from the transmitter's cell on, >= 2 samples
  double spacing_m = 0.0;             // between samples (SPLAT!'s miles per sample, in metres)
};

// Calls visit() for every point SPLAT! computes for an area map of the region `bounds` (an
// -ano map's header: its loaded tiles) around the transmitter (tx_lat north, tx_lon EAST,
// degrees) out to radius_km, in SPLAT!'s order. dem: a geographic grid covering the region at
// SPLAT!'s cells_per_degree, row 0 north, samples on the cells (the mosaic of the same SDF
// tiles SPLAT! read). A cell the grid does not hold has SPLAT!'s "not in memory" height,
// -5000 ft. Precondition: the transmitter inside the region (std::invalid_argument).
void for_each_splat_point(const io::Grid& dem, const AnoMap& bounds, double tx_lat, double tx_lon,
                          double radius_km, int cells_per_degree,
                          const std::function<void(const SplatPathPoint&)>& visit);

// The built-in ITM (itm.h, with the .lrp's parameters and SPLAT!'s way of calling it: MDVAR
// 12) on each of SPLAT!'s profiles of one -ano map, against the value SPLAT! wrote there.
struct SplatItmCheck {
  std::size_t reported = 0;    // points in SPLAT!'s map
  std::size_t reproduced = 0;  // of them, computed here at the same position (to 1e-6 degree)
  std::size_t unmatched = 0;   // points computed here that SPLAT! did not write at their position
  LayerComparison comparison;  // A = the built-in ITM, B = SPLAT!, over the reproduced points
  double max_abs_difference = 0.0;  // dB, over the reproduced points
};

// Throws std::invalid_argument as for_each_splat_point() and check_itm() (the .lrp's frequency
// or parameters outside the ITM's ranges).
SplatItmCheck check_itm_on_splat_profiles(const io::Grid& dem, const AnoMap& map, const SplatSite& site,
                                          const SplatLrp& lrp, double rx_height_agl_m, double radius_km,
                                          int cells_per_degree = kSplatCellsPerDegree);

}  // namespace terravol::volume
