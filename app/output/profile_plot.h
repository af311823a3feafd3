// The plot of a link profile (`terravol profile`), drawn by VTK's 2D charts (vtkChartXY).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "volume/profile.h"

namespace terravol::app::output {

// A width x height PNG (white background) of the profile: distance along the path in km on x,
// height above the DEM's datum in m on y, and
// - the terrain raised by the Earth's bulge for the k-factor, filled down to the lowest ground
//   raised the same way (so the fill's lower edge shows the bulge);
// - the antennas (vertical lines from the ground to their tops), the line of sight between
//   them, the first Fresnel zone's boundaries (line of sight +- F1) and the 60% boundary below
//   the line (line of sight - 0.6 F1);
// - Deygout's knife edges (the model's diffraction edges) and the worst obstruction, as markers;
// - `title` above the chart (e.g. the verdict).
// Needs an X display (drawn on the process's one connection, render::use_shared_display: VTK
// 9.1 renders through GLX even offscreen).
// Throws std::invalid_argument for a size outside [200, 8000] pixels and std::runtime_error when
// no display can be opened or encoding fails.
std::vector<std::uint8_t> profile_png(const volume::LinkProfile& profile, const std::string& title, int width,
                                      int height);

}  // namespace terravol::app::output
