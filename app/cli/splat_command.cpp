// `terravol splat-volume`: a path-loss volume from the real SPLAT! engine (volume/splat.h), one
// run per receiver height over SDF tiles, or from existing SPLAT! -ano files; written as .vdb.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/cli/commands.h"
#include "app/cli/rf_args.h"
#include "app/output/write_file.h"
#include "io/mosaic.h"
#include "volume/splat.h"
#include "volume/splat_paths.h"
#include "volume/vdb_write.h"

namespace terravol::app::cli {

namespace {

struct SplatCommandOptions {
  std::string tx, heights = "10:310:50";
  std::filesystem::path qth, lrp, sdf, splat = "/usr/bin/splat", output, ano_dir;
  std::vector<std::filesystem::path> imports;
  double radius_km = 20.0;
  double timeout_seconds = 600.0;
  int cells_per_degree = volume::kSplatCellsPerDegree;
  bool force = false;
  bool quiet = false;
  bool olditm = false;
  bool check_itm = false;
};

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

std::string read_text(const std::filesystem::path& path, const std::string& option) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(option + " " + path.string() + ": cannot read");
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error(option + " " + path.string() + ": cannot read");
  return s;
}

// The -ano file name kept under --ano-dir for a height.
std::filesystem::path ano_name(const std::filesystem::path& dir, double height) {
  return dir / ("splat-L" + fmt(height) + "m.ano");
}

// --check-itm: the built-in ITM on SPLAT!'s own profiles of each map (volume/splat_paths.h),
// over the tiles SPLAT! read, one line per height.
std::vector<std::string> check_itm(const SplatCommandOptions& o, const std::vector<std::string>& tiles,
                                   const std::vector<volume::AnoMap>& maps, const volume::SplatSite& site,
                                   const volume::SplatLrp& lrp, const std::vector<double>& heights) {
  std::vector<std::filesystem::path> paths;
  for (const auto& t : tiles) paths.push_back(o.sdf / t);
  const io::Mosaic mosaic = io::Mosaic::open(paths);
  const io::Grid dem = mosaic.read_window(0, 0, mosaic.rows(), mosaic.cols());
  std::vector<std::string> lines;
  for (std::size_t n = 0; n < maps.size(); ++n) {
    const volume::SplatItmCheck c =
        volume::check_itm_on_splat_profiles(dem, maps[n], site, lrp, heights[n], o.radius_km);
    const volume::LayerComparison& k = c.comparison;
    char b[400];
    std::snprintf(b, sizeof b,
                  "built-in ITM on SPLAT!'s profiles, %g m: %zu of %zu points reproduced (%zu computed "
                  "elsewhere); r %.6f, median SPLAT! - ITM %+.4f dB, median |difference| %.4f dB, "
                  "largest %.3f dB",
                  heights[n], c.reproduced, c.reported, c.unmatched, k.pearson, k.median_difference,
                  k.median_abs_difference, c.max_abs_difference);
    lines.push_back(b);
  }
  return lines;
}

void run_splat_volume(const SplatCommandOptions& o) {
  const bool importing = !o.imports.empty();
  // What describes the transmitter: --tx, --qth (+ .lrp), or nothing (an import).
  if (!o.tx.empty() && !o.qth.empty())
    throw std::runtime_error("--tx and --qth exclude each other");
  if (!o.lrp.empty() && o.qth.empty())
    throw std::runtime_error("--lrp " + o.lrp.string() + ": needs --qth");
  if (!importing && o.tx.empty() && o.qth.empty()) {
    throw std::runtime_error(
        "give the transmitter (--tx or --qth) and --sdf, or --import -ano files");
  }
  if (importing && !o.sdf.empty())
    throw std::runtime_error("--sdf " + o.sdf.string() + ": not used with --import");
  if (importing && !o.ano_dir.empty())
    throw std::runtime_error("--ano-dir: not used with --import");
  if (importing && o.olditm) throw std::runtime_error("--olditm: not used with --import");
  if (o.check_itm && (importing || !o.olditm))
    throw std::runtime_error("--check-itm: needs a SPLAT! run with --olditm (not --import)");
  if (!importing && o.sdf.empty())
    throw std::runtime_error("--sdf: the folder of SDF tiles is required to run SPLAT!");
  if (!importing && o.cells_per_degree != volume::kSplatCellsPerDegree) {
    throw std::runtime_error("--cells-per-degree: only with --import (splat itself uses 1200)");
  }
  if (o.cells_per_degree < 1 || o.cells_per_degree > 36000) {
    throw std::runtime_error("--cells-per-degree " + std::to_string(o.cells_per_degree) +
                             ": must be within [1, 36000]");
  }
  if (!(o.radius_km > 0.0 && o.radius_km <= 1000.0)) {
    throw std::runtime_error("--radius-km " + fmt(o.radius_km) + ": must be within (0, 1000]");
  }
  if (!(o.timeout_seconds > 0.0 && o.timeout_seconds <= 86400.0)) {
    throw std::runtime_error("--timeout " + fmt(o.timeout_seconds) +
                             ": must be within (0, 86400] s");
  }
  const std::vector<double> heights = parse_heights(o.heights);
  if (importing && heights.size() != o.imports.size()) {
    throw std::runtime_error("--heights " + o.heights + ": " + std::to_string(heights.size()) +
                             " heights for " + std::to_string(o.imports.size()) +
                             " --import files (one each, in order)");
  }

  std::optional<volume::SplatSite> site;
  volume::SplatLrp lrp;
  bool have_lrp = false;
  std::optional<volume::AntennaPattern> antenna;
  if (!o.tx.empty()) {
    const volume::Transmitter tx = parse_tx(o.tx);
    antenna = tx.antenna;
    if (antenna && o.check_itm) {
      throw std::runtime_error("--check-itm: compares the ITM alone, without an antenna pattern in --tx");
    }
    if (tx.frequency_mhz < 20.0 || tx.frequency_mhz > 20000.0) {
      throw std::runtime_error("--tx " + o.tx +
                               ": SPLAT! takes frequencies within [20, 20000] MHz");
    }
    site = volume::SplatSite{"terravol-tx", tx.lat, tx.lon, tx.height_agl};
    lrp.frequency_mhz = tx.frequency_mhz;
    lrp.erp_w = tx.erp_w;
    have_lrp = true;
  } else if (!o.qth.empty()) {
    site = volume::parse_qth(read_text(o.qth, "--qth"), o.qth.string());
    std::filesystem::path lrp_path = o.lrp;
    if (lrp_path.empty()) {
      lrp_path = std::filesystem::path(o.qth).replace_extension(".lrp");
      if (!std::filesystem::exists(lrp_path)) {
        throw std::runtime_error("--qth " + o.qth.string() + ": no " +
                                 lrp_path.filename().string() + " beside it (give --lrp FILE)");
      }
    }
    lrp = volume::parse_lrp(read_text(lrp_path, "--lrp"), lrp_path.string());
    have_lrp = true;
  }

  const std::string out = o.output.string();
  output::check_output_path(o.output, "-o", ".vdb", o.force);
  if (!o.ano_dir.empty()) {
    if (!std::filesystem::is_directory(o.ano_dir))
      throw std::runtime_error("--ano-dir " + o.ano_dir.string() + ": not a folder");
    for (const double h : heights) {
      const auto p = ano_name(o.ano_dir, h);
      if (!o.force && std::filesystem::exists(p))
        throw std::runtime_error(p.string() + ": exists (use --force to overwrite)");
    }
  }

  // The maps: SPLAT!'s runs, or the imported files.
  std::vector<volume::AnoMap> maps;
  std::map<std::string, std::string> attributes;
  std::string summary;
  std::vector<std::string> check_lines;
  if (importing) {
    std::string names;
    for (const auto& p : o.imports) {
      maps.push_back(volume::parse_ano(read_text(p, "--import"), p.string()));
      names += (names.empty() ? "" : ", ") + p.filename().string();
    }
    attributes["model"] = "SPLAT! path loss, imported from -ano files";
    attributes["splat_ano"] = names;
    summary = std::to_string(maps.size()) + " -ano files imported";
  } else {
    volume::SplatRunOptions run;
    run.executable = o.splat;
    run.sdf_folder = o.sdf;
    run.site = *site;
    run.lrp = lrp;
    run.heights_agl = heights;
    run.radius_km = o.radius_km;
    run.timeout_seconds = o.timeout_seconds;
    run.keep_ano_texts = !o.ano_dir.empty();
    run.antenna = antenna;
    run.olditm = o.olditm;
    const bool show_progress = !o.quiet && ::isatty(2);
    if (show_progress) {
      run.progress = [n = heights.size()](std::size_t done) {
        std::fprintf(stderr, "\rsplat: %zu/%zu heights", done, n);
      };
    }
    volume::SplatRunResult r;
    try {
      r = volume::run_splat(run);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(e.what());
    }
    if (show_progress) std::fprintf(stderr, "\r                        \r");
    std::string tiles;
    for (const auto& t : r.tiles) tiles += (tiles.empty() ? "" : ", ") + t;
    attributes["model"] =
        "SPLAT! " + (r.version.empty() ? std::string("(version unknown)") : "v" + r.version) +
        " area path loss (" + (o.olditm ? "ITM" : "ITWOM") + "), splat -L H -R " + fmt(o.radius_km) + " -metric " +
        (antenna ? "-erp " + fmt(lrp.erp_w.value_or(1.0)) + " -dbm (dBm turned back into loss)" : "-erp 0") +
        (o.olditm ? " -olditm" : "");
    if (antenna) {
      attributes["antenna_pattern"] = antenna->describe() + "; the loss includes the pattern's attenuation (SPLAT!'s)";
    }
    attributes["radius_km"] = fmt(o.radius_km);
    attributes["dem"] = tiles;
    summary = "SPLAT! " + r.version + ": " + std::to_string(heights.size()) + " runs in " +
              fmt(std::round(r.seconds * 10) / 10) + " s over " + tiles;
    maps = std::move(r.maps);
    for (std::size_t n = 0; n < r.ano_texts.size(); ++n) {
      const std::string& text = r.ano_texts[n];
      output::write_file_atomically(ano_name(o.ano_dir, heights[n]),
                                    std::vector<std::uint8_t>(text.begin(), text.end()), o.force);
    }
    if (o.check_itm) check_lines = check_itm(o, r.tiles, maps, *site, lrp, heights);
  }
  if (site) {
    char b[64];
    std::snprintf(b, sizeof b, "%.7f", site->lat);
    attributes["tx_lat"] = b;
    std::snprintf(b, sizeof b, "%.7f", site->lon);
    attributes["tx_lon"] = b;
    attributes["tx_height_agl_m"] = fmt(site->height_agl_m);
  }
  if (have_lrp) {
    attributes["frequency_mhz"] = fmt(lrp.frequency_mhz);
    attributes["splat_lrp"] =
        "dielectric " + fmt(lrp.dielectric) + ", conductivity " + fmt(lrp.conductivity) +
        " S/m, bending " + fmt(lrp.bending) + " N-units, climate " + std::to_string(lrp.climate) +
        ", polarization " + (lrp.polarization == 1 ? "vertical" : "horizontal") + ", situations " +
        fmt(lrp.situations) + ", time " + fmt(lrp.time);
    if (lrp.erp_w) attributes["erp_w"] = fmt(*lrp.erp_w);
  }

  std::vector<volume::AnoLayer> layers;
  for (std::size_t n = 0; n < maps.size(); ++n) layers.push_back({&maps[n], heights[n]});
  volume::AnoStack stack = volume::stack_ano(layers, o.cells_per_degree);
  volume::Volume& loss = stack.path_loss;
  for (const auto& [k, v] : attributes) loss.attributes[k] = v;
  std::optional<volume::Volume> signal;
  if (have_lrp && lrp.erp_w) signal = volume::signal_from_path_loss(loss, *lrp.erp_w);

  std::vector<const volume::Volume*> grids{&loss};
  if (signal) grids.push_back(&*signal);
  volume::write_vdb(o.output, grids, o.force);

  const auto& l = loss.lattice;
  float lo = INFINITY, hi = -INFINITY;
  for (const float v : loss.values) {
    if (std::isfinite(v)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  std::printf("wrote %s: %s%s, %d x %d x %d points (lon x lat x height above ground)\n",
              out.c_str(), loss.name.c_str(), signal ? " and signal_dbm" : "", l.dims[0], l.dims[1],
              l.dims[2]);
  std::printf("  spacing %g\" (lon %.6f..%.6f, lat %.6f..%.6f), heights %g..%g m above ground\n",
              l.spacing[1] * 3600.0, l.origin[0], l.world(0, l.dims[0] - 1), l.origin[1],
              l.world(1, l.dims[1] - 1), l.origin[2], l.world(2, l.dims[2] - 1));
  std::printf(
      "  path loss %.1f..%.1f dB at %zu of %zu points (%.1f%%; the rest NaN: not reported by "
      "SPLAT!)\n",
      lo, hi, stack.reported, l.size(),
      100.0 * static_cast<double>(stack.reported) / static_cast<double>(l.size()));
  std::printf("  %zu obstructed paths, %zu duplicate points dropped\n", stack.obstructed,
              stack.duplicates);
  std::printf("  %s\n", summary.c_str());
  for (const auto& line : check_lines) std::printf("  %s\n", line.c_str());
}

}  // namespace

void add_splat_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("splat-volume",
                                 "Path-loss volume from the SPLAT! engine (one run per receiver "
                                 "height over SDF tiles) or from its -ano files, "
                                 "written as .vdb");
  auto o = std::make_shared<SplatCommandOptions>();
  cmd->add_option("--tx", o->tx,
                  "Transmitter LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]][,pattern=FILE.az[:FILE.el]][,azimuth=DEG]"
                  "[,tilt=DEG] as for terravol rf (default 900 MHz; an ERP adds a signal_dbm grid; the pattern "
                  "goes to SPLAT! as tx.az/tx.el); SPLAT!'s other parameters are its defaults");
  cmd->add_option("--qth", o->qth, "Transmitter as a SPLAT! .qth file (instead of --tx)");
  cmd->add_option("--lrp", o->lrp,
                  "SPLAT! .lrp file for --qth (default: the .qth's name with .lrp)");
  cmd->add_option("--sdf", o->sdf,
                  "Folder of SDF tiles (.sdf, or compressed: .sdf.gz, .sdf.bz2, .sdf.xz, .sdf.zip; e.g. ../shared/data/dem/utah_sdf)");
  cmd->add_option("--import", o->imports,
                  "Stack existing SPLAT! -ano path-loss files instead of running SPLAT!");
  cmd->add_option("-o,--output", o->output, "The .vdb file to write")->required();
  cmd->add_option("--heights", o->heights,
                  "Receiver heights above ground, metres: START:STOP:STEP or an evenly spaced list "
                  "H1,H2,... "
                  "(with --import: one per file, in order)")
      ->capture_default_str();
  cmd->add_option("--radius-km", o->radius_km, "Radius of the disc SPLAT! computes (-R), km")
      ->capture_default_str();
  cmd->add_option("--cells-per-degree", o->cells_per_degree,
                  "Grid of --import files: 1200 (splat) or 3600 (splat-hd)")
      ->capture_default_str();
  cmd->add_option("--splat", o->splat, "The SPLAT! executable")->capture_default_str();
  cmd->add_option("--timeout", o->timeout_seconds, "Seconds allowed for each SPLAT! run")
      ->capture_default_str();
  cmd->add_option("--ano-dir", o->ano_dir, "Also keep SPLAT!'s -ano files there (splat-LHm.ano)");
  cmd->add_flag("--olditm", o->olditm,
                "Run SPLAT!'s Longley-Rice ITM (splat -olditm) instead of its default ITWOM");
  cmd->add_flag("--check-itm", o->check_itm,
                "With --olditm: also run the built-in ITM on each of SPLAT!'s own profiles and "
                "print, per height, how far it is from what SPLAT! wrote");
  cmd->add_flag("--force", o->force, "Replace existing output files");
  cmd->add_flag("--quiet", o->quiet, "No progress on stderr");
  cmd->callback([o] { run_splat_volume(*o); });
}

}  // namespace terravol::app::cli
