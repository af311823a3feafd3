// `terravol rf --tx LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]] --dem DEM... -o out.vdb`: a path-loss
// volume from a built-in propagation model (volume/propagation.h: Deygout knife edges, or the
// Longley-Rice ITM with --model itm), written as OpenVDB.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/cli/commands.h"
#include "app/cli/rf_args.h"
#include "io/mosaic.h"
#include "volume/propagation.h"
#include "volume/vdb_write.h"

namespace terravol::app::cli {

namespace {

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

struct RfCommandOptions {
  std::string tx, heights;
  std::string model = "deygout";
  // ITM's parameters, SPLAT!'s .lrp defaults.
  std::string polarization = "horizontal";
  double permittivity = 15.0, conductivity = 0.005, refractivity = 301.0;
  int climate = 5, mdvar = 12;
  double time = 0.5, location = 0.5, situation = 0.5;
  std::vector<std::string> given;  // the model-specific options given on the command line
  std::vector<std::filesystem::path> dems;
  std::filesystem::path output;
  double radius_km = 20.0;
  double spacing_arcsec = 0.0;
  bool disc = false;
  double k_factor = 4.0 / 3.0;
  int edge_depth = 2;
  bool force = false;
  bool quiet = false;
};

// The options only one model takes.
constexpr const char* kDeygoutOptions[] = {"--k-factor", "--edge-depth"};
constexpr const char* kItmOptions[] = {"--polarization", "--permittivity", "--conductivity", "--refractivity", "--climate",
                                       "--time", "--location", "--situation", "--mdvar"};

bool given(const RfCommandOptions& o, const std::string& name) {
  return std::find(o.given.begin(), o.given.end(), name) != o.given.end();
}

// The ITM parameters from the command line; each bad value is one line naming its option.
volume::ItmParameters itm_parameters(const RfCommandOptions& o) {
  volume::ItmParameters p;
  if (o.polarization == "horizontal" || o.polarization == "h") {
    p.polarization = volume::ItmPolarization::kHorizontal;
  } else if (o.polarization == "vertical" || o.polarization == "v") {
    p.polarization = volume::ItmPolarization::kVertical;
  } else {
    throw std::runtime_error("--polarization " + o.polarization + ": must be horizontal or vertical");
  }
  auto range = [](const char* option, double v, bool ok, const char* what) {
    if (!ok) throw std::runtime_error(std::string(option) + " " + fmt(v) + ": must be within " + what);
  };
  range("--permittivity", o.permittivity, o.permittivity > 1.0 && o.permittivity <= 100.0, "(1, 100]");
  range("--conductivity", o.conductivity, o.conductivity > 0.0 && o.conductivity <= 100.0, "(0, 100] S/m");
  range("--refractivity", o.refractivity, o.refractivity >= 250.0 && o.refractivity <= 400.0, "[250, 400] N-units");
  range("--time", o.time, o.time > 0.0 && o.time < 1.0, "(0, 1)");
  range("--location", o.location, o.location > 0.0 && o.location < 1.0, "(0, 1)");
  range("--situation", o.situation, o.situation > 0.0 && o.situation < 1.0, "(0, 1)");
  if (o.climate < 1 || o.climate > 7) {
    throw std::runtime_error("--climate " + std::to_string(o.climate) +
                             ": must be within 1..7 (1 equatorial, 2 continental subtropical, 3 maritime subtropical, 4 "
                             "desert, 5 continental temperate, 6 maritime temperate over land, 7 maritime temperate over sea)");
  }
  const int mode = o.mdvar % 10;
  if (o.mdvar < 0 || o.mdvar > 33 || mode > 3) {
    throw std::runtime_error("--mdvar " + std::to_string(o.mdvar) +
                             ": must be 0..3 (single message, accidental, mobile, broadcast), plus 10 without location "
                             "variability, plus 20 without direct situation variability");
  }
  p.permittivity = o.permittivity;
  p.conductivity = o.conductivity;
  p.refractivity = o.refractivity;
  p.climate = static_cast<volume::ItmClimate>(o.climate);
  p.time = o.time;
  p.location = o.location;
  p.situation = o.situation;
  p.variability = static_cast<volume::ItmVariability>(mode);
  p.location_variability = (o.mdvar % 20) < 10;
  p.situation_variability = o.mdvar < 20;
  return p;
}

void run_rf(const RfCommandOptions& o) {
  volume::RfOptions options;
  if (o.model == "itm") {
    options.model = volume::RfModel::kItm;
  } else if (o.model != "deygout") {
    throw std::runtime_error("--model " + o.model + ": must be itm or deygout");
  }
  const bool itm = options.model == volume::RfModel::kItm;
  for (const char* name : kDeygoutOptions) {
    if (itm && given(o, name)) throw std::runtime_error(std::string(name) + ": only with --model deygout");
  }
  for (const char* name : kItmOptions) {
    if (!itm && given(o, name)) throw std::runtime_error(std::string(name) + ": only with --model itm");
  }
  volume::Transmitter tx = parse_tx(o.tx);
  volume::RfGrid grid;
  const std::string heights = o.heights.empty() ? (itm ? "10:2010:50" : "0:2000:50") : o.heights;
  grid.heights_agl = parse_heights(heights);
  if (itm) {
    options.itm = itm_parameters(o);
    if (tx.frequency_mhz < 20.0 || tx.frequency_mhz > 20000.0) {
      throw std::runtime_error("--tx " + o.tx + ": ITM takes frequencies within [20, 20000] MHz");
    }
    if (tx.height_agl < 0.5 || tx.height_agl > 3000.0) {
      throw std::runtime_error("--tx " + o.tx + ": ITM takes antenna heights within [0.5, 3000] m above ground");
    }
    for (const double h : grid.heights_agl) {
      if (h < 0.5 || h > 3000.0) {
        throw std::runtime_error("--heights " + heights + ": ITM takes receiver heights within [0.5, 3000] m above ground");
      }
    }
  }
  grid.radius_km = o.radius_km;
  grid.spacing_arcsec = o.spacing_arcsec;
  grid.disc = o.disc;
  if (!(o.radius_km > 0.0 && o.radius_km <= 500.0)) {
    throw std::runtime_error("--radius-km " + fmt(o.radius_km) + ": must be within (0, 500]");
  }
  if (!(o.spacing_arcsec >= 0.0 && o.spacing_arcsec <= 3600.0)) {
    throw std::runtime_error("--spacing " + fmt(o.spacing_arcsec) + ": must be within (0, 3600] arc seconds");
  }
  if (!(o.k_factor > 0.0 && o.k_factor <= 100.0)) throw std::runtime_error("--k-factor " + fmt(o.k_factor) + ": must be within (0, 100]");
  if (o.edge_depth < 1 || o.edge_depth > 16) {
    throw std::runtime_error("--edge-depth " + std::to_string(o.edge_depth) + ": must be within [1, 16]");
  }
  const std::string out = o.output.string();
  std::string ext = o.output.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".vdb") throw std::runtime_error("-o " + out + ": expected a .vdb file name");
  if (!o.force && std::filesystem::exists(o.output)) throw std::runtime_error(out + ": exists (use --force to overwrite)");
  const auto folder = o.output.parent_path();
  if (!folder.empty() && !std::filesystem::is_directory(folder)) {
    throw std::runtime_error("-o " + out + ": folder " + folder.string() + " does not exist");
  }

  const io::Mosaic mosaic = io::Mosaic::open(o.dems);
  const io::Georef& g = mosaic.georef();
  const double south = g.y0 - (mosaic.rows() - 1) * g.dy, east = g.x0 + (mosaic.cols() - 1) * g.dx;
  if (tx.lat < south || tx.lat > g.y0 || tx.lon < g.x0 || tx.lon > east) {
    throw std::runtime_error("--tx " + o.tx + ": the transmitter lies outside the DEM (" + fmt(south) + ".." + fmt(g.y0) +
                             " N, " + fmt(g.x0) + ".." + fmt(east) + " E)");
  }

  options.k_factor = o.k_factor;
  options.edge_depth = o.edge_depth;
  const bool show_progress = !o.quiet && ::isatty(2);
  if (show_progress) {
    options.progress = [](double f) { std::fprintf(stderr, "\rrf: %3d%%", static_cast<int>(100.0 * f)); };
  }
  volume::RfResult r;
  try {
    r = volume::compute_rf(mosaic, tx, grid, options);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  if (show_progress) std::fprintf(stderr, "\r        \r");

  std::vector<const volume::Volume*> grids{&r.path_loss};
  if (r.signal) grids.push_back(&*r.signal);
  volume::write_vdb(o.output, grids, o.force);

  const auto& l = r.path_loss.lattice;
  float lo = INFINITY, hi = -INFINITY;  // of the finite values (ITM: NaN at the transmitter)
  for (const float v : r.path_loss.values) {
    if (!std::isfinite(v)) continue;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  const double arcsec = l.spacing[1] * 3600.0;
  std::printf("wrote %s: %s%s, %d x %d x %d points (lon x lat x height above ground)\n", out.c_str(),
              r.path_loss.name.c_str(), r.signal ? " and signal_dbm" : "", l.dims[0], l.dims[1], l.dims[2]);
  std::printf("  spacing %g\" (lon %.6f..%.6f, lat %.6f..%.6f), heights %g..%g m above ground\n", arcsec, l.origin[0],
              l.world(0, l.dims[0] - 1), l.origin[1], l.world(1, l.dims[1] - 1), l.origin[2], l.world(2, l.dims[2] - 1));
  std::printf("  path loss %.1f..%.1f dB", lo, hi);
  if (r.signal) {
    const double eirp = std::stod(r.signal->attributes.at("eirp_dbm"));
    std::printf(", signal %.1f..%.1f dBm (EIRP %.2f dBm)", eirp - hi, eirp - lo, eirp);
  }
  std::printf("\n  %.2f s, %zu columns, %.0f profile samples each on average\n", r.seconds, r.columns,
              r.mean_profile_samples);
  for (const auto& n : r.notes) std::printf("  note: %s\n", n.c_str());
}

}  // namespace

void add_rf_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("rf",
                                 "Path-loss volume of a transmitter over a DEM (free space + Deygout diffraction, or "
                                 "Longley-Rice ITM with --model itm), written as .vdb");
  auto o = std::make_shared<RfCommandOptions>();
  cmd->add_option("--model", o->model, "Propagation model: deygout or itm (Longley-Rice point-to-point)")
      ->capture_default_str();
  cmd->add_option("--tx", o->tx,
                  "Transmitter LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]]: degrees, metres above ground, MHz (default "
                  "900), W relative to a dipole (adds a signal_dbm grid)")
      ->required();
  cmd->add_option("--dem", o->dems, "DEM files or folders of tiles (one mosaic)")->required();
  cmd->add_option("-o,--output", o->output, "The .vdb file to write")->required();
  cmd->add_option("--radius-km", o->radius_km, "Half side of the square box around the transmitter, km")
      ->capture_default_str();
  cmd->add_option("--heights", o->heights,
                  "Receiver heights above ground, metres: START:STOP:STEP or an evenly spaced list H1,H2,... "
                  "(default 0:2000:50, with ITM 10:2010:50)");
  cmd->add_option("--spacing", o->spacing_arcsec,
                  "Lattice spacing in latitude and longitude, arc seconds (default: a multiple of the DEM's "
                  "spacing giving at most 256 intervals across the box)");
  cmd->add_flag("--disc", o->disc,
                "Compute only the columns within --radius-km of the transmitter (the box's corners are "
                "NaN): the disc SPLAT! computes");
  cmd->add_option("--k-factor", o->k_factor, "Deygout: effective Earth radius factor")->capture_default_str();
  cmd->add_option("--edge-depth", o->edge_depth,
                  "Deygout: recursion levels (1: principal edge only; 2: plus one secondary edge each side)")
      ->capture_default_str();
  cmd->add_option("--polarization", o->polarization, "ITM: horizontal or vertical")->capture_default_str();
  cmd->add_option("--permittivity", o->permittivity, "ITM: relative permittivity of the ground")->capture_default_str();
  cmd->add_option("--conductivity", o->conductivity, "ITM: ground conductivity, S/m")->capture_default_str();
  cmd->add_option("--refractivity", o->refractivity,
                  "ITM: surface refractivity at sea level N_0, N-units (SPLAT!'s bending constant)")
      ->capture_default_str();
  cmd->add_option("--climate", o->climate,
                  "ITM: radio climate 1..7 (1 equatorial, 2 continental subtropical, 3 maritime subtropical, 4 desert, "
                  "5 continental temperate, 6 maritime temperate over land, 7 maritime temperate over sea)")
      ->capture_default_str();
  cmd->add_option("--time", o->time, "ITM: fraction of time the loss is not exceeded")->capture_default_str();
  cmd->add_option("--location", o->location, "ITM: fraction of locations")->capture_default_str();
  cmd->add_option("--situation", o->situation, "ITM: fraction of situations (confidence)")->capture_default_str();
  cmd->add_option("--mdvar", o->mdvar,
                  "ITM: variability mode 0..3 (single message, accidental, mobile, broadcast), +10 without location "
                  "variability, +20 without direct situation variability (SPLAT!: 12)")
      ->capture_default_str();
  cmd->add_flag("--force", o->force, "Replace an existing output file");
  cmd->add_flag("--quiet", o->quiet, "No progress on stderr");
  cmd->callback([o, cmd] {
    for (const char* name : kDeygoutOptions)
      if (cmd->count(name) > 0) o->given.push_back(name);
    for (const char* name : kItmOptions)
      if (cmd->count(name) > 0) o->given.push_back(name);
    run_rf(*o);
  });
}

}  // namespace terravol::app::cli
