// `terravol profile --from LAT,LON,AGL --to LAT,LON,AGL --dem DEM... [--model deygout|itm]
// [-o profile.png] [--csv FILE]`: a point-to-point link profile (volume/profile.h) with its plot
// (app/profile_plot.h), its samples as CSV, and a verdict line on stdout.
#include <GeographicLib/Geodesic.hpp>

#include <algorithm>
#include <array>
#include <cctype>
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
#include "app/output/png_output.h"
#include "app/output/profile_plot.h"
#include "app/output/write_file.h"
#include "app/render/terrain_renderer.h"
#include "io/mosaic.h"
#include "volume/profile.h"
#include "volume/propagation.h"

namespace terravol::app::cli {

namespace {

struct ProfileOptions {
  std::string from, to, k_factor = "4/3", size = "1200x600";
  std::vector<std::filesystem::path> dems;
  std::filesystem::path output, csv;
  double frequency_mhz = 900.0;
  int edge_depth = 2;
  ModelArgs model;  // --model and ITM's parameters
  CLI::Option* edge_depth_option = nullptr;
  bool force = false;

  std::string frequency_text() const {
    char b[48];
    std::snprintf(b, sizeof b, "%g", frequency_mhz);
    return b;
  }
};

bool whole_number(const std::string& text, double& out) {
  if (text.empty()) return false;
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return *end == '\0' && std::isfinite(out);
}

// "A" or "A/B", positive.
double parse_k_factor(const std::string& text) {
  const std::size_t slash = text.find('/');
  double a = 0.0, b = 1.0;
  const bool ok = slash == std::string::npos
                      ? whole_number(text, a)
                      : whole_number(text.substr(0, slash), a) && whole_number(text.substr(slash + 1), b) && b != 0.0;
  const double k = a / b;
  if (!ok || !(k > 0.0 && k <= 100.0)) {
    throw std::runtime_error("--k-factor " + text + ": expected a number or a fraction within (0, 100], e.g. 4/3");
  }
  return k;
}

// "LAT,LON,AGL" only.
std::array<double, 3> parse_point(const std::string& text, const std::string& option) {
  std::array<double, 3> v{};
  std::size_t start = 0;
  for (int n = 0; n < 3; ++n) {
    const std::size_t end = text.find(',', start);
    if ((n < 2) != (end != std::string::npos) || !whole_number(text.substr(start, end - start), v[n])) {
      throw std::runtime_error(option + " " + text + ": expected LAT,LON,HEIGHT_AGL (degrees, metres above ground)");
    }
    start = end + 1;
  }
  if (std::abs(v[0]) > 85.0) throw std::runtime_error(option + " " + text + ": latitude must be within [-85, 85] degrees");
  if (std::abs(v[1]) > 180.0) throw std::runtime_error(option + " " + text + ": longitude must be within [-180, 180] degrees");
  if (v[2] < 0.0 || v[2] > 100000.0) throw std::runtime_error(option + " " + text + ": height must be within [0, 100000] m above ground");
  return v;
}

std::string csv_text(const volume::LinkProfile& l, double tx_lat, double tx_lon, double rx_lat, double rx_lon) {
  const volume::PathProfile& p = l.path.profile;
  const volume::FresnelAnalysis& f = l.fresnel;
  std::vector<double> edge_loss(p.d_m.size(), 0.0);
  for (const volume::KnifeEdge& e : l.path.edges) edge_loss[e.sample] = e.loss_db;
  std::string s =
      "distance_km,lat,lon,ground_m,bulge_m,terrain_with_bulge_m,line_of_sight_m,f1_radius_m,f1_lower_m,"
      "f1_60_lower_m,clearance_m,clearance_f1,knife_edge_db\n";
  char b[512];
  auto row = [&](double d, double lat, double lon, double ground, double bulge, double los, double f1, double clearance,
                 double edge) {
    std::snprintf(b, sizeof b, "%.6f,%.8f,%.8f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.4f,%.3f\n", d / 1000.0, lat,
                  lon, ground, bulge, ground + bulge, los, f1, los - f1, los - 0.6 * f1, clearance,
                  f1 > 0.0 ? clearance / f1 : std::nan(""), edge);
    s += b;
  };
  row(0.0, tx_lat, tx_lon, l.tx_ground_m, 0.0, p.tx_height_m, 0.0, p.tx_height_m - l.tx_ground_m, 0.0);
  for (std::size_t i = 0; i < p.d_m.size(); ++i) {
    row(p.d_m[i], l.lat[i], l.lon[i], p.z_m[i], f.bulge_m[i], f.los_m[i], f.f1_m[i], f.clearance_m[i], edge_loss[i]);
  }
  row(p.distance_m, rx_lat, rx_lon, l.rx_ground_m, 0.0, p.rx_height_m, 0.0, p.rx_height_m - l.rx_ground_m, 0.0);
  return s;
}

void run_profile(const ProfileOptions& o) {
  if (o.output.empty() && o.csv.empty()) throw std::runtime_error("give -o PROFILE.png, --csv PROFILE.csv or both");
  // --from takes --tx's fields without the frequency and the ERP (--freq gives the frequency).
  const std::size_t keyed = o.from.find('=');
  const std::string numbers = o.from.substr(0, keyed == std::string::npos ? o.from.size() : o.from.rfind(',', keyed));
  parse_point(numbers, "--from");
  volume::Transmitter tx = parse_tx(o.from, "--from " + o.from);
  const auto rx = parse_point(o.to, "--to");
  if (!(o.frequency_mhz > 0.0 && o.frequency_mhz <= 100000.0)) {
    throw std::runtime_error("--freq " + o.frequency_text() + ": must be within (0, 100000] MHz");
  }
  tx.frequency_mhz = o.frequency_mhz;
  volume::RfOptions options;
  options.model = parse_model(o.model);
  // The k-factor raises the terrain for the clearance (and Deygout's loss); ITM takes its own
  // Earth from the refractivity, as in terravol rf.
  options.k_factor = parse_k_factor(o.k_factor);
  if (options.model == volume::RfModel::kItm) {
    if (o.edge_depth_option->count() > 0) throw std::runtime_error("--edge-depth: only with --model deygout");
    options.itm = itm_parameters(o.model);
    if (tx.frequency_mhz < 20.0 || tx.frequency_mhz > 20000.0) {
      throw std::runtime_error("--freq " + o.frequency_text() + ": ITM takes frequencies within [20, 20000] MHz");
    }
    const auto antenna = [](const std::string& option, const std::string& text, double agl) {
      if (agl < 0.5 || agl > 3000.0) {
        throw std::runtime_error(option + " " + text + ": ITM takes antenna heights within [0.5, 3000] m above ground");
      }
    };
    antenna("--from", o.from, tx.height_agl);
    antenna("--to", o.to, rx[2]);
  }
  if (o.edge_depth < 1 || o.edge_depth > 16) {
    throw std::runtime_error("--edge-depth " + std::to_string(o.edge_depth) + ": must be within [1, 16]");
  }
  options.edge_depth = o.edge_depth;
  int width = 0, height = 0;
  char extra = 0;
  if (std::sscanf(o.size.c_str(), "%dx%d%c", &width, &height, &extra) != 2 || width < 200 || width > 8000 ||
      height < 200 || height > 8000) {
    throw std::runtime_error("--size " + o.size + ": expected WIDTHxHEIGHT, each within [200, 8000] pixels");
  }
  if (!o.output.empty()) output::check_output_path(o.output, "-o", ".png", o.force);
  if (!o.csv.empty()) output::check_output_path(o.csv, "--csv", ".csv", o.force);
  if (!o.output.empty()) render::require_x_display("profile -o");  // before any work
  double distance = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(tx.lat, tx.lon, rx[0], rx[1], distance);
  if (distance < 1.0) throw std::runtime_error("--to " + o.to + ": the same point as --from (less than 1 m away)");

  const io::Mosaic mosaic = io::Mosaic::open(o.dems);
  const volume::DemExtent e = volume::dem_extent(mosaic.georef(), mosaic.rows(), mosaic.cols());
  auto check_inside = [&](double lat, double lon, const std::string& what) {
    if (lat < e.south || lat > e.north || lon < e.west || lon > e.east) {
      char b[160];
      std::snprintf(b, sizeof b, ": the point lies outside the DEM (%g..%g N, %g..%g E)", e.south, e.north, e.west, e.east);
      throw std::runtime_error(what + b);
    }
  };
  check_inside(tx.lat, tx.lon, "--from " + o.from);
  check_inside(rx[0], rx[1], "--to " + o.to);
  const volume::RfWindow window = volume::read_rf_window(
      mosaic, {std::min(tx.lat, rx[0]), std::max(tx.lat, rx[0]), std::min(tx.lon, rx[1]), std::max(tx.lon, rx[1])});
  volume::LinkProfile l;
  try {
    l = volume::link_profile(window.grid, tx, rx[0], rx[1], rx[2], options);
  } catch (const std::invalid_argument& ex) {
    throw std::runtime_error(ex.what());
  }
  const std::string verdict = volume::verdict(l);

  // Outputs: complete files or nothing (each is written to a temporary name, then renamed).
  std::vector<std::uint8_t> png;
  if (!o.output.empty()) png = output::profile_png(l, verdict, width, height);
  if (!o.csv.empty()) {
    const std::string text = csv_text(l, tx.lat, tx.lon, rx[0], rx[1]);
    output::write_file_atomically(o.csv, std::vector<std::uint8_t>(text.begin(), text.end()), o.force);
  }
  if (!o.output.empty()) output::write_png(o.output, png, o.force);

  const volume::RfPath& p = l.path;
  std::printf("profile %.6f, %.6f (%g m) to %.6f, %.6f (%g m): %.3f km, azimuth %.2f deg, %g MHz, k = %.4g\n", tx.lat,
              tx.lon, tx.height_agl, rx[0], rx[1], rx[2], p.profile.distance_m / 1000.0, p.azimuth_deg, tx.frequency_mhz,
              options.k_factor);
  std::printf("  ground %.1f m and %.1f m, antenna tops %.1f m and %.1f m above the datum; %zu terrain samples\n",
              l.tx_ground_m, l.rx_ground_m, p.profile.tx_height_m, p.profile.rx_height_m, p.profile.d_m.size());
  for (const volume::KnifeEdge& edge : p.edges) {
    std::printf("  knife edge at %.3f km (%.6f, %.6f), %.1f m: v = %.3f, J = %.2f dB (level %d)\n",
                p.profile.d_m[edge.sample] / 1000.0, l.lat[edge.sample], l.lon[edge.sample], p.profile.z_m[edge.sample],
                edge.v, edge.loss_db, edge.level);
  }
  const volume::FresnelAnalysis& f = l.fresnel;
  if (f.worst < p.profile.d_m.size()) {
    std::printf("  worst obstruction at %.3f km (%.6f, %.6f): clearance %.2f m = %.3f F1 (F1 %.2f m)\n",
                p.profile.d_m[f.worst] / 1000.0, l.lat[f.worst], l.lon[f.worst], f.worst_clearance_m,
                f.worst_clearance_f1, f.f1_m[f.worst]);
  }
  std::printf("  path loss %.3f dB = free space %.3f dB + %s %.3f dB", p.path_loss_db, p.free_space_db,
              options.model == volume::RfModel::kItm ? "ITM beyond free space" : "diffraction", p.diffraction_db);
  if (tx.antenna) std::printf(" - antenna pattern %.3f dB (departure %+.3f deg)", p.antenna_gain_db, p.departure_deg);
  std::printf("\n");
  if (!o.output.empty()) std::printf("  wrote %s\n", o.output.string().c_str());
  if (!o.csv.empty()) std::printf("  wrote %s\n", o.csv.string().c_str());
  for (const auto& n : window.notes) std::printf("  note: %s\n", n.c_str());
  std::printf("verdict: %s\n", verdict.c_str());
}

}  // namespace

void add_profile_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("profile",
                                 "Point-to-point link profile: terrain with the Earth's bulge, line of sight, first "
                                 "Fresnel zone, worst obstruction and the built-in model's path loss; a plot and CSV");
  auto o = std::make_shared<ProfileOptions>();
  cmd->add_option("--from", o->from,
                  "Transmitter LAT,LON,HEIGHT_AGL[,name=..][,pattern=FILE.az[:FILE.el]][,azimuth=DEG][,tilt=DEG]")
      ->required();
  cmd->add_option("--to", o->to, "Receiver LAT,LON,HEIGHT_AGL")->required();
  cmd->add_option("--dem", o->dems, "DEM files or folders of tiles (one mosaic)")->required();
  cmd->add_option("--freq", o->frequency_mhz, "Frequency, MHz")->capture_default_str();
  cmd->add_option("--k-factor", o->k_factor,
                  "Effective Earth radius factor, a number or a fraction: the terrain's bulge for the clearance "
                  "(and Deygout's loss; ITM takes its Earth from --refractivity)")
      ->capture_default_str();
  o->edge_depth_option =
      cmd->add_option("--edge-depth", o->edge_depth, "Deygout recursion levels, as for terravol rf")->capture_default_str();
  add_model_options(*cmd, o->model);
  cmd->add_option("-o,--output", o->output, "The plot, .png (needs an X display)");
  cmd->add_option("--csv", o->csv, "The samples, .csv");
  cmd->add_option("--size", o->size, "The plot's size, WIDTHxHEIGHT pixels")->capture_default_str();
  cmd->add_flag("--force", o->force, "Replace existing output files");
  cmd->callback([o] { run_profile(*o); });
}

}  // namespace terravol::app::cli
