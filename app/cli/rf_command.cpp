// `terravol rf --tx LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]] --dem DEM... -o out.vdb`: a path-loss
// volume from the built-in propagation model (volume/propagation.h), written as OpenVDB.
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
  std::string tx, heights = "0:2000:50";
  std::vector<std::filesystem::path> dems;
  std::filesystem::path output;
  double radius_km = 20.0;
  double spacing_arcsec = 0.0;
  double k_factor = 4.0 / 3.0;
  int edge_depth = 2;
  bool force = false;
  bool quiet = false;
};

void run_rf(const RfCommandOptions& o) {
  volume::Transmitter tx = parse_tx(o.tx);
  volume::RfGrid grid;
  grid.heights_agl = parse_heights(o.heights);
  grid.radius_km = o.radius_km;
  grid.spacing_arcsec = o.spacing_arcsec;
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

  volume::RfOptions options;
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
  const auto [lo, hi] = std::minmax_element(r.path_loss.values.begin(), r.path_loss.values.end());
  const double arcsec = l.spacing[1] * 3600.0;
  std::printf("wrote %s: %s%s, %d x %d x %d points (lon x lat x height above ground)\n", out.c_str(),
              r.path_loss.name.c_str(), r.signal ? " and signal_dbm" : "", l.dims[0], l.dims[1], l.dims[2]);
  std::printf("  spacing %g\" (lon %.6f..%.6f, lat %.6f..%.6f), heights %g..%g m above ground\n", arcsec, l.origin[0],
              l.world(0, l.dims[0] - 1), l.origin[1], l.world(1, l.dims[1] - 1), l.origin[2], l.world(2, l.dims[2] - 1));
  std::printf("  path loss %.1f..%.1f dB", *lo, *hi);
  if (r.signal) {
    const double eirp = std::stod(r.signal->attributes.at("eirp_dbm"));
    std::printf(", signal %.1f..%.1f dBm (EIRP %.2f dBm)", eirp - *hi, eirp - *lo, eirp);
  }
  std::printf("\n  %.2f s, %zu columns, %.0f profile samples each on average\n", r.seconds, r.columns,
              r.mean_profile_samples);
  for (const auto& n : r.notes) std::printf("  note: %s\n", n.c_str());
}

}  // namespace

void add_rf_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "rf", "Path-loss volume of a transmitter over a DEM (free space + Deygout diffraction), written as .vdb");
  auto o = std::make_shared<RfCommandOptions>();
  cmd->add_option("--tx", o->tx,
                  "Transmitter LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]]: degrees, metres above ground, MHz (default "
                  "900), W relative to a dipole (adds a signal_dbm grid)")
      ->required();
  cmd->add_option("--dem", o->dems, "DEM files or folders of tiles (one mosaic)")->required();
  cmd->add_option("-o,--output", o->output, "The .vdb file to write")->required();
  cmd->add_option("--radius-km", o->radius_km, "Half side of the square box around the transmitter, km")
      ->capture_default_str();
  cmd->add_option("--heights", o->heights,
                  "Receiver heights above ground, metres: START:STOP:STEP or an evenly spaced list H1,H2,...")
      ->capture_default_str();
  cmd->add_option("--spacing", o->spacing_arcsec,
                  "Lattice spacing in latitude and longitude, arc seconds (default: a multiple of the DEM's "
                  "spacing giving at most 256 intervals across the box)");
  cmd->add_option("--k-factor", o->k_factor, "Effective Earth radius factor")->capture_default_str();
  cmd->add_option("--edge-depth", o->edge_depth,
                  "Deygout recursion levels (1: principal edge only; 2: plus one secondary edge each side)")
      ->capture_default_str();
  cmd->add_flag("--force", o->force, "Replace an existing output file");
  cmd->add_flag("--quiet", o->quiet, "No progress on stderr");
  cmd->callback([o] { run_rf(*o); });
}

}  // namespace terravol::app::cli
