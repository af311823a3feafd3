// Presenting any DEM as a geographic grid, which is what the tree needs (its split planes
// are meridians and parallels).
#pragma once

#include <string>

#include "io/grid.h"

namespace terravol::io {

// Returns a geographic copy of a projected (UTM) grid, resampled bilinearly at an equivalent
// spacing: dy / M and dx / (N cos lat) at the grid's central latitude (WGS84 radii of
// curvature, GeographicLib UTMUPS for the projection), over the geographic bounding box of the
// grid's footprint. A resampled sample takes the bilinear blend of its valid neighbours
// (weights renormalised when some are voids); with none valid it is kVoid if any neighbour is
// a void and kOutside otherwise. Adds a note saying so to Grid::notes. A grid that is already
// geographic is returned unchanged.
// Throws FormatError(source, ...) for a zone outside 1..60, a bad spacing or an absurd size.
Grid to_geographic(const Grid& grid, const std::string& source);

}  // namespace terravol::io
