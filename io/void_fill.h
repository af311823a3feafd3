// Filling voids for rendering.
#pragma once

#include <cstddef>

#include "io/grid.h"

namespace terravol::io {

// Gives every sample whose mask is not kValid a height interpolated from the valid samples
// around it, leaving the mask as it is (so callers can still count and show voids). The fill
// is the discrete harmonic (Laplace) interpolant with the valid samples held fixed, started
// from a breadth-first propagation inward from the void's rim and relaxed with `iterations`
// Gauss-Seidel sweeps over the void samples. Cost: O(voids * iterations). A grid without any
// valid sample is filled with 0. Returns the number of samples filled.
// Hand-written: no allowed library fills DEM voids (VTK and OpenVDB have no such filter).
std::size_t fill_voids(Grid& grid, int iterations = 64);

}  // namespace terravol::io
