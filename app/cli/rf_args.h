// Parsing the transmitter and receiver-height options that `terravol rf` and
// `terravol splat-volume` share, and the model options of `terravol rf` and `terravol profile`.
// Errors are std::runtime_error with one line naming the option.
#pragma once

#include <CLI/CLI.hpp>

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

// --model (deygout or itm) and ITM's parameters, at SPLAT!'s .lrp defaults.
struct ModelArgs {
  std::string model = "deygout";
  std::string polarization = "horizontal";
  double permittivity = 15.0, conductivity = 0.005, refractivity = 301.0;
  int climate = 5, mdvar = 12;
  double time = 0.5, location = 0.5, situation = 0.5;
  std::vector<CLI::Option*> itm_options;  // set by add_model_options
};
// Adds --model, --polarization, --permittivity, --conductivity, --refractivity, --climate,
// --time, --location, --situation and --mdvar to `cmd`, into `args` (which must outlive it).
void add_model_options(CLI::App& cmd, ModelArgs& args);
// The model --model names. Throws "--model TEXT: must be itm or deygout", and "--OPTION: only
// with --model itm" when an ITM option was given with Deygout.
volume::RfModel parse_model(const ModelArgs& args);
// ITM's parameters; each bad value is one line naming its option and its range.
volume::ItmParameters itm_parameters(const ModelArgs& args);

}  // namespace terravol::app::cli
