// Parsing the transmitter and receiver-height options that `terravol rf` and
// `terravol splat-volume` share. Errors are std::runtime_error with one line naming the option.
#pragma once

#include <string>
#include <vector>

#include "volume/propagation.h"

namespace terravol::app::cli {

// "--tx LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]]": degrees (latitude within [-85, 85], longitude
// within [-180, 180]), metres above ground within [0, 100000], MHz within (0, 100000] (900
// when absent), W within (0, 1e9]. Throws "--tx TEXT: what is wrong".
volume::Transmitter parse_tx(const std::string& text);

// "--heights": "START:STOP:STEP" (STOP included when it falls on a step), "H1,H2,..." or "H";
// metres above ground within [0, 100000], increasing and evenly spaced (to 1e-6 m).
// Throws "--heights TEXT: what is wrong".
std::vector<double> parse_heights(const std::string& text);

}  // namespace terravol::app::cli
