// Parsing the transmitter and receiver-height options that `terravol rf` and
// `terravol splat-volume` share. Errors are std::runtime_error with one line naming the option.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "volume/propagation.h"

namespace terravol::app::cli {

// "--tx LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]][,KEY=VALUE...]": degrees (latitude within
// [-85, 85], longitude within [-180, 180]), metres above ground within [0, 100000], MHz within
// (0, 100000] (900 when absent), W within (0, 1e9]; then, in any order, at most once each:
//   name=NAME          1..32 letters, digits, '_', '-' or '.' (legends, grid names);
//   pattern=FILE.az[:FILE.el] or pattern=:FILE.el   a SPLAT! antenna pattern (volume/antenna.h);
//   azimuth=DEG        the pattern's rotation, replacing the .az file's (needs a .az file);
//   tilt=DEG           the mechanical downtilt, replacing the .el file's (needs a .el file).
// `where` names the text in messages (default "--tx TEXT"); relative pattern file names are
// taken relative to `base` when it is given. Throws std::runtime_error "WHERE: what is wrong" (a
// pattern file's own error follows the prefix).
volume::Transmitter parse_tx(const std::string& text, const std::string& where = "",
                             const std::filesystem::path& base = {});

// A file of transmitters, one --tx text per line; blank lines and lines starting with '#' are
// skipped; pattern files are relative to the file's folder. Throws std::runtime_error "FILE: cannot read", "FILE: no transmitter" or
// "FILE: line N: what is wrong".
std::vector<volume::Transmitter> read_tx_file(const std::string& path);

// "--heights": "START:STOP:STEP" (STOP included when it falls on a step), "H1,H2,..." or "H";
// metres above ground within [0, 100000], increasing and evenly spaced (to 1e-6 m).
// Throws "--heights TEXT: what is wrong".
std::vector<double> parse_heights(const std::string& text);

}  // namespace terravol::app::cli
