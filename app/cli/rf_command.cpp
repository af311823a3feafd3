// `terravol rf --tx LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]][,...] [--tx ...] --dem DEM... -o out.vdb`:
// path-loss volumes from a built-in propagation model (volume/propagation.h: Deygout knife
// edges, or the Longley-Rice ITM with --model itm) for one transmitter, or signal volumes and
// the best server for several (volume/plan.h), written as OpenVDB. Under mpirun the rows of the
// transmitters' boxes are dealt out over the ranks; rank 0 gathers them and writes
// (app/mpi_session.h).
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "app/cli/commands.h"
#include "app/cli/mpi_session.h"
#include "app/cli/rf_args.h"
#include "app/output/write_file.h"
#include "io/mosaic.h"
#include "volume/plan.h"
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
  std::vector<std::string> txs;
  std::string tx_file, heights;
  ModelArgs model;  // --model and ITM's parameters
  std::vector<std::string> given;  // the Deygout options given on the command line
  std::vector<std::filesystem::path> dems;
  std::filesystem::path output;
  double radius_km = 20.0;
  double spacing_arcsec = 0.0;
  bool disc = false;
  double k_factor = 4.0 / 3.0;
  int edge_depth = 2;
  int threads = 0;
  bool force = false;
  bool quiet = false;
};

// Everything a rank needs, from the options: checked identically on every rank.
struct Setup {
  std::vector<volume::Transmitter> transmitters;
  volume::RfGrid grid;
  volume::RfOptions options;
};

// The options only Deygout takes.
constexpr const char* kDeygoutOptions[] = {"--k-factor", "--edge-depth"};

bool given(const RfCommandOptions& o, const std::string& name) {
  return std::find(o.given.begin(), o.given.end(), name) != o.given.end();
}

// How a message names transmitter t: its --tx text when it is the only one given.
std::string tx_label(const RfCommandOptions& o, const std::vector<volume::Transmitter>& txs, std::size_t t) {
  if (txs.size() == 1 && o.txs.size() == 1) return "--tx " + o.txs.front();
  return "transmitter " + (txs[t].name.empty() ? "tx" + std::to_string(t + 1) : txs[t].name);
}

Setup check_options(const RfCommandOptions& o) {
  Setup s;
  s.options.model = parse_model(o.model);
  const bool itm = s.options.model == volume::RfModel::kItm;
  for (const char* name : kDeygoutOptions) {
    if (itm && given(o, name)) throw std::runtime_error(std::string(name) + ": only with --model deygout");
  }
  if (o.txs.empty() && o.tx_file.empty()) throw std::runtime_error("give the transmitters: --tx (once or more) or --tx-file");
  for (const auto& t : o.txs) s.transmitters.push_back(parse_tx(t));
  if (!o.tx_file.empty()) {
    auto more = read_tx_file(o.tx_file);
    s.transmitters.insert(s.transmitters.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
  }
  const std::string heights = o.heights.empty() ? (itm ? "10:2010:50" : "0:2000:50") : o.heights;
  s.grid.heights_agl = parse_heights(heights);
  if (itm) {
    s.options.itm = itm_parameters(o.model);
    for (std::size_t t = 0; t < s.transmitters.size(); ++t) {
      const volume::Transmitter& tx = s.transmitters[t];
      if (tx.frequency_mhz < 20.0 || tx.frequency_mhz > 20000.0) {
        throw std::runtime_error(tx_label(o, s.transmitters, t) + ": ITM takes frequencies within [20, 20000] MHz");
      }
      if (tx.height_agl < 0.5 || tx.height_agl > 3000.0) {
        throw std::runtime_error(tx_label(o, s.transmitters, t) +
                                 ": ITM takes antenna heights within [0.5, 3000] m above ground");
      }
    }
    for (const double h : s.grid.heights_agl) {
      if (h < 0.5 || h > 3000.0) {
        throw std::runtime_error("--heights " + heights + ": ITM takes receiver heights within [0.5, 3000] m above ground");
      }
    }
  }
  s.grid.radius_km = o.radius_km;
  s.grid.spacing_arcsec = o.spacing_arcsec;
  s.grid.disc = o.disc;
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
  if (o.threads < 0 || o.threads > 1024) throw std::runtime_error("--threads " + std::to_string(o.threads) + ": must be within [0, 1024]");
  if (s.transmitters.size() > 1) {
    if (s.transmitters.size() > 1000) throw std::runtime_error("at most 1000 transmitters");
    std::set<std::string> names;
    for (std::size_t t = 0; t < s.transmitters.size(); ++t) {
      volume::Transmitter& tx = s.transmitters[t];
      if (tx.name.empty()) tx.name = "tx" + std::to_string(t + 1);
      if (!names.insert(tx.name).second) throw std::runtime_error("transmitter name " + tx.name + " is given twice");
      if (!tx.erp_w) {
        throw std::runtime_error("transmitter " + tx.name +
                                 ": several transmitters need an ERP each (LAT,LON,HEIGHT_AGL,FREQ_MHZ,ERP_W) for "
                                 "their signals and the best server");
      }
    }
  }
  output::check_output_path(o.output, "-o", ".vdb", o.force);
  s.options.k_factor = o.k_factor;
  s.options.edge_depth = o.edge_depth;
  return s;
}

struct Range {
  float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();
};
Range finite_range(const std::vector<float>& values) {
  Range r;
  for (const float v : values) {
    if (!std::isfinite(v)) continue;
    r.lo = std::min(r.lo, v);
    r.hi = std::max(r.hi, v);
  }
  return r;
}

void print_lattice(const volume::Lattice& l) {
  std::printf("  spacing %g\" (lon %.6f..%.6f, lat %.6f..%.6f), heights %g..%g m above ground\n", l.spacing[1] * 3600.0,
              l.origin[0], l.world(0, l.dims[0] - 1), l.origin[1], l.world(1, l.dims[1] - 1), l.origin[2],
              l.world(2, l.dims[2] - 1));
}

// Rank 0: the volumes, written, and what they hold.
void write_results(const RfCommandOptions& o, const volume::RfPlan& plan, std::vector<volume::Volume> losses,
                   const volume::RfWindow& window) {
  for (auto& v : losses) v.attributes["dem"] = window.tiles;
  const std::string out = o.output.string();
  if (plan.transmitters.size() == 1) {
    const volume::Volume& loss = losses.front();
    std::optional<volume::Volume> signal;
    if (plan.transmitters.front().erp_w) signal = volume::signal_from_path_loss(loss, *plan.transmitters.front().erp_w);
    std::vector<const volume::Volume*> grids{&loss};
    if (signal) grids.push_back(&*signal);
    volume::write_vdb(o.output, grids, o.force);
    const auto& l = loss.lattice;
    const Range r = finite_range(loss.values);
    std::printf("wrote %s: %s%s, %d x %d x %d points (lon x lat x height above ground)\n", out.c_str(), loss.name.c_str(),
                signal ? " and signal_dbm" : "", l.dims[0], l.dims[1], l.dims[2]);
    print_lattice(l);
    std::printf("  path loss %.1f..%.1f dB", r.lo, r.hi);
    if (signal) {
      const double eirp = std::stod(signal->attributes.at("eirp_dbm"));
      std::printf(", signal %.1f..%.1f dBm (EIRP %.2f dBm)", eirp - r.hi, eirp - r.lo, eirp);
    }
    std::printf("\n");
    return;
  }
  std::vector<volume::Volume> signals;
  for (std::size_t t = 0; t < losses.size(); ++t) {
    signals.push_back(volume::signal_from_path_loss(std::move(losses[t]), *plan.transmitters[t].erp_w));
  }
  losses.clear();
  volume::BestServer best = volume::best_server(plan, signals);
  std::vector<const volume::Volume*> grids;
  for (std::size_t t = 0; t < signals.size(); ++t) {
    signals[t].name = "signal_dbm_" + plan.transmitters[t].name;
    grids.push_back(&signals[t]);
  }
  grids.push_back(&best.best_signal);
  grids.push_back(&best.best_server);
  volume::write_vdb(o.output, grids, o.force);
  const auto& l = plan.lattice;
  std::printf("wrote %s: %zu transmitters, signal_dbm_NAME each, best_signal_dbm and best_server over %d x %d x %d points\n",
              out.c_str(), signals.size(), l.dims[0], l.dims[1], l.dims[2]);
  print_lattice(l);
  std::vector<std::size_t> served(signals.size(), 0);
  std::size_t covered = 0;
  for (const float s : best.best_server.values) {
    if (!std::isfinite(s)) continue;
    ++served[static_cast<std::size_t>(s) - 1];
    ++covered;
  }
  int width = 0;
  for (const auto& tx : plan.transmitters) width = std::max(width, static_cast<int>(tx.name.size()));
  for (std::size_t t = 0; t < signals.size(); ++t) {
    const Range r = finite_range(signals[t].values);
    const auto& b = plan.boxes[t];
    std::printf("  %-*s %d x %d columns, signal %.1f..%.1f dBm, best server at %.1f%% of the covered points\n",
                width, plan.transmitters[t].name.c_str(), b.dims[0], b.dims[1], r.lo, r.hi,
                covered ? 100.0 * static_cast<double>(served[t]) / static_cast<double>(covered) : 0.0);
  }
}

void run_rf(const RfCommandOptions& o) {
  const MpiSession mpi;
  const int threads = o.threads > 0 ? o.threads
                                    : std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / mpi.local_size());
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  const bool root = mpi.rank() == 0;

  // Every rank checks, reads and computes its share; failures are agreed on before gathering,
  // so that no rank waits for one that has given up.
  std::string error;
  std::optional<volume::RfPlan> plan;
  volume::RfWindow window;
  volume::RowShare share;
  std::vector<float> values;
  volume::RfStats stats;
  volume::RfOptions options;
  const bool show_progress = root && !o.quiet && ::isatty(2);
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  const auto t_start = Clock::now();
  double read_seconds = 0.0;
  try {
    Setup setup = check_options(o);
    options = setup.options;
    const io::Mosaic mosaic = io::Mosaic::open(o.dems);
    const io::Georef& g = mosaic.georef();
    const volume::DemExtent extent = volume::dem_extent(g, mosaic.rows(), mosaic.cols());
    for (std::size_t t = 0; t < setup.transmitters.size(); ++t) {
      const volume::Transmitter& tx = setup.transmitters[t];
      if (tx.lat < extent.south || tx.lat > extent.north || tx.lon < extent.west || tx.lon > extent.east) {
        throw std::runtime_error(tx_label(o, setup.transmitters, t) + ": the transmitter lies outside the DEM (" + fmt(extent.south) + ".." +
                                 fmt(extent.north) + " N, " + fmt(extent.west) + ".." + fmt(extent.east) + " E)");
      }
    }
    plan = volume::plan_rf(extent, g.dy * 3600.0, std::move(setup.transmitters), setup.grid, options);
    window = volume::read_rf_window(mosaic, volume::plan_area(*plan));
    read_seconds = since(t_start);
    share = volume::share_of(*plan, mpi.rank(), mpi.size());
    if (show_progress) {
      options.progress = [](double f) { std::fprintf(stderr, "\rrf: %3d%%", static_cast<int>(100.0 * f)); };
    }
    values = volume::compute_share(window.grid, *plan, share, options, &stats);
    if (show_progress) std::fprintf(stderr, "\r        \r");
  } catch (const std::exception& e) {
    error = e.what();
  }
  error = mpi.first_error(error);
  if (!error.empty()) {
    if (root) throw std::runtime_error(error);
    throw QuietFailure();
  }
  const double columns = mpi.sum(static_cast<double>(stats.columns));
  const double samples = mpi.sum(static_cast<double>(stats.samples));
  stats.itm_warned = static_cast<std::size_t>(mpi.sum(static_cast<double>(stats.itm_warned)));
  stats.columns = static_cast<std::size_t>(columns);
  const double seconds = mpi.max(stats.seconds), fastest = mpi.min(stats.seconds);
  read_seconds = mpi.max(read_seconds);
  if (!root) {
    mpi.send_to_root(values);
    return;
  }
  std::vector<volume::Volume> losses;
  const auto t_gather = Clock::now();
  try {
    volume::PlanAssembler assembler(*plan, options, window.grid.vertical_datum);
    assembler.add(share, values);
    values = {};
    for (int r = 1; r < mpi.size(); ++r) {
      const volume::RowShare theirs = volume::share_of(*plan, r, mpi.size());
      std::vector<float> received(theirs.values(*plan));
      mpi.receive(r, received);
      assembler.add(theirs, received);
    }
    losses = assembler.take();
  } catch (const std::exception& e) {
    if (mpi.active()) mpi.abort(e.what());  // other ranks may still be sending
    throw;
  }
  const double gather_seconds = since(t_gather);
  const auto t_write = Clock::now();
  write_results(o, *plan, std::move(losses), window);
  const double write_seconds = since(t_write);
  std::printf("  %.2f s, %.0f columns, %.0f profile samples each on average, %d rank%s x %d thread%s\n", seconds, columns,
              samples / std::max(1.0, columns), mpi.size(), mpi.size() == 1 ? "" : "s", threads, threads == 1 ? "" : "s");
  std::printf("  time: options and DEM %.1f s, model %.1f s", read_seconds, seconds);
  if (mpi.size() > 1) std::printf(" (ranks %.1f..%.1f s)", fastest, seconds);
  std::printf(", gathering %.1f s, writing %.1f s, in all %.1f s\n", gather_seconds, write_seconds, since(t_start));
  for (const auto& n : plan->notes) std::printf("  note: %s\n", n.c_str());
  for (const auto& n : window.notes) std::printf("  note: %s\n", n.c_str());
  std::size_t box_columns = 0, points = 0;
  for (const auto& b : plan->boxes) {
    box_columns += static_cast<std::size_t>(b.dims[0]) * static_cast<std::size_t>(b.dims[1]);
    points += b.size();
  }
  for (const auto& n : volume::rf_notes(stats, box_columns, points, plan->grid, options)) {
    std::printf("  note: %s\n", n.c_str());
  }
}

}  // namespace

void add_rf_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "rf",
      "Path-loss volume of a transmitter over a DEM (free space + Deygout diffraction, or Longley-Rice ITM with "
      "--model itm), or the signals and best server of several, written as .vdb; under mpirun the work is split "
      "over the ranks");
  auto o = std::make_shared<RfCommandOptions>();
  add_model_options(*cmd, o->model);
  cmd->add_option("--tx", o->txs,
                  "Transmitter LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]][,name=NAME][,pattern=FILE.az[:FILE.el]]"
                  "[,azimuth=DEG][,tilt=DEG]: degrees, metres above ground, MHz (default 900), W relative to a "
                  "dipole (adds a signal_dbm grid); a SPLAT! antenna pattern, its rotation and downtilt. Give it "
                  "several times for several transmitters (each then needs an ERP)");
  cmd->add_option("--tx-file", o->tx_file, "A file of transmitters, one --tx text per line ('#' starts a comment line)");
  cmd->add_option("--dem", o->dems, "DEM files or folders of tiles (one mosaic)")->required();
  cmd->add_option("-o,--output", o->output, "The .vdb file to write")->required();
  cmd->add_option("--radius-km", o->radius_km, "Half side of the square box around each transmitter, km")
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
  cmd->add_option("--threads", o->threads,
                  "Threads per process (default: the cores, shared among the ranks on a node under mpirun)");
  cmd->add_flag("--force", o->force, "Replace an existing output file");
  cmd->add_flag("--quiet", o->quiet, "No progress on stderr");
  cmd->callback([o, cmd] {
    for (const char* name : kDeygoutOptions)
      if (cmd->count(name) > 0) o->given.push_back(name);
    run_rf(*o);
  });
}

}  // namespace terravol::app::cli
