// SPLAT! (J. A. Magliacane, KD2BD; Debian package `splat`, `man splat`) as a source of
// path-loss volumes: its site (.qth) and model (.lrp) files, its alphanumeric area output
// (`-ano`), the stacking of one -ano map per receiver height into a Volume, and running
// /usr/bin/splat once per height over a folder of SDF tiles.
//
// Parsing and stacking are pure functions of text; only run_splat() touches files and
// processes. Nothing here prints or exits: bad files throw io::FormatError("SOURCE: ..."),
// a failing run std::runtime_error (one line each).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "volume/antenna.h"
#include "volume/propagation.h"
#include "volume/volume.h"

namespace terravol::volume {

// SPLAT!'s standard resolution, SDF samples per degree (3"); splat-hd uses 3600 (1").
inline constexpr int kSplatCellsPerDegree = 1200;

// A site (.qth): name, latitude, longitude, antenna height above ground.
struct SplatSite {
  std::string name;
  double lat = 0.0;           // degrees north, [-90, 90]
  double lon = 0.0;           // degrees EAST, [-180, 180) (SPLAT!'s files are west-positive)
  double height_agl_m = 0.0;  // metres above ground, >= 0
};

// Parses a .qth file: four lines, the site's name, latitude (north-positive), longitude
// (west-positive 0..360, or east as a negative number down to -360) and antenna height above
// ground (feet, unless followed by "m", "meter(s)" or "metre(s)" in any case; "ft", "foot" and
// "feet" are accepted too). Angles are decimal degrees or
// "D M S" (three numbers; a minus sign on D applies to all). Blank lines before the name and
// trailing whitespace are ignored. Throws io::FormatError("SOURCE: line N: ...").
SplatSite parse_qth(std::string_view text, const std::string& source);

// The .qth text of a site: name, latitude, west-positive longitude in [0, 360), height in
// metres ("30.000 m"); parse_qth reads it back to 1e-7 degrees and 1 mm.
std::string format_qth(const SplatSite& site);

// The Longley-Rice parameters of a .lrp file (man splat, "IRREGULAR TERRAIN MODEL PARAMETER").
struct SplatLrp {
  double dielectric = 15.0;      // relative permittivity of the ground
  double conductivity = 0.005;   // S/m
  double bending = 301.0;        // atmospheric bending constant, N-units
  double frequency_mhz = 900.0;  // SPLAT! accepts 20 .. 20000
  int climate = 5;               // 1..7; 5 = continental temperate
  int polarization = 0;          // 0 horizontal, 1 vertical
  double situations = 0.5;       // fraction of situations (location variability), (0, 1)
  double time = 0.5;             // fraction of time, (0, 1)
  std::optional<double> erp_w;   // effective radiated power, W, > 0 (optional ninth value)
};

// Parses a .lrp file: the first number on each of the first 8 (or 9) lines that hold one;
// text after ';' is a comment. Throws io::FormatError("SOURCE: ...") for fewer than 8 values,
// a value that is not a number, or one out of the range given above (a ninth value of 0 means
// no ERP, as SPLAT!'s -erp 0 does).
SplatLrp parse_lrp(std::string_view text, const std::string& source);
std::string format_lrp(const SplatLrp& lrp);  // without the ERP line; parse_lrp reads it back

// One point of an -ano file.
struct AnoPoint {
  double lat = 0.0;  // degrees north
  double lon = 0.0;  // degrees EAST (the file's west-positive value, negated and wrapped
                     // into [-180, 180))
  double azimuth_deg = 0.0, elevation_deg = 0.0;  // from the transmitter, as SPLAT! wrote them
  float value = 0.0f;       // path loss in dB when SPLAT! ran without an ERP (field strength in
                            // dBuV/m or power in dBm otherwise: the file does not say which)
  bool obstructed = false;  // the line ended with '*': the path is obstructed
};

struct AnoMap {
  std::string source;                   // for messages
  double max_west = 0, min_west = 0;    // the header's bounds, degrees west-positive
  double max_north = 0, min_north = 0;  // degrees north
  std::vector<AnoPoint> points;         // in file order
};

// Parses SPLAT!'s alphanumeric output (man splat, "EXPORTING AND IMPORTING REGIONAL CONTOUR DATA"):
// a header line "MAX_WEST, MIN_WEST ; ..." and a line "MAX_NORTH, MIN_NORTH ; ...", then one line
// per point, "LAT, LON, AZIMUTH, ELEVATION, VALUE" with an optional trailing '*' (LON
// west-positive). Text after ';' is a comment; blank lines and CR before LF are ignored. Every
// point must lie within the header's bounds (to 0.01 degree; the longitude check is skipped when
// the bounds wrap through 0/360). Throws io::FormatError("SOURCE: line N: what is wrong") for a
// missing header, a field that is not a finite number, a wrong count of fields, a latitude outside
// [-90, 90], a longitude outside [-360, 360], a point outside the bounds, and a file without
// points.
AnoMap parse_ano(std::string_view text, const std::string& source);

// One map and the receiver height (metres above ground) SPLAT! computed it for (-L).
struct AnoLayer {
  const AnoMap* map = nullptr;
  double height_agl_m = 0.0;
};

// What stack_ano() did, besides the volume.
struct AnoStack {
  Volume path_loss;            // "path_loss_db", dB, geographic frame, heights above ground
  std::size_t reported = 0;    // lattice points that received a point (all layers)
  std::size_t duplicates = 0;  // points dropped because a nearer one fell on the same lattice point
  std::size_t obstructed = 0;  // reported points SPLAT! marked obstructed
};

// Stacks maps into a volume. The lattice is SPLAT!'s own grid: longitudes and latitudes are
// integer multiples of 1 / cells_per_degree (SPLAT!'s SDF samples: 1200 for splat, 3600 for
// splat-hd), spacing 1 / cells_per_degree in both; the lattice is the smallest box of such
// points holding every point of every map after rounding each to its nearest lattice point;
// heights are the layers' (w2 = height above ground, HeightRef::kGround). Each point lands on
// its nearest lattice point; when several land on one, the point closest to it is kept (ties:
// the first in the file). Lattice points no map reported (outside SPLAT!'s radius, corners of
// the box, the rare cell between radials) are NaN, and so is the volume's background.
// Preconditions, each a std::invalid_argument: at least one layer, no null map, heights
// finite, >= 0, increasing and evenly spaced (to 1e-6 m), cells_per_degree in [1, 36000].
// Throws io::FormatError(first map's source, ...) when the lattice would exceed kMaxPoints.
// Attributes: "splat_unreported" says that NaN marks points SPLAT! did not report.
AnoStack stack_ano(const std::vector<AnoLayer>& layers,
                   int cells_per_degree = kSplatCellsPerDegree);

// The signal grid of a stacked path-loss volume: signal_from_path_loss (propagation.h).

struct SplatRunOptions {
  std::filesystem::path executable = "/usr/bin/splat";
  std::filesystem::path sdf_folder;  // .sdf tiles, compressed or not (.sdf.gz, .sdf.bz2, ...),
                                     // named as io/sdf_name.h accepts
  SplatSite site;                    // the transmitter
  SplatLrp lrp;                      // its model parameters (the ERP is not passed to SPLAT!)
  std::vector<double> heights_agl;   // receiver heights, metres above ground (-L), >= 0
  double radius_km = 20.0;           // SPLAT!'s -R: the radius of the computed disc, (0, 1000]
  double timeout_seconds = 600.0;    // per height; the child is killed after it
  bool olditm = false;               // -olditm: SPLAT!'s Longley-Rice ITM (1.2.2) instead of
                                     // its default ITWOM 3.0
  std::filesystem::path work_root;   // where the temporary working folder goes; empty: the
                                     // system's temporary folder
  bool keep_ano_texts = false;       // fill SplatRunResult::ano_texts
  // The transmitting antenna's pattern, written beside tx.qth as tx.az / tx.el (splat_az_text,
  // splat_el_text) for SPLAT! to apply. SPLAT! applies a pattern only to field strength and
  // power, so with one each run is `-erp E -dbm` (E the .lrp's ERP, else 1 W) and the maps'
  // values are turned back into the loss it used, 10 log10(E / 1 mW) + 2.14 - dBm (SPLAT!'s
  // EIRP = ERP + 2.14 dB): the path loss plus the pattern's attenuation towards each point.
  std::optional<AntennaPattern> antenna;
  // Called after each height with the count done (1 .. heights), from the calling thread.
  std::function<void(std::size_t done)> progress;
};

struct SplatRunResult {
  std::vector<AnoMap> maps;            // one per height, in order; values are path loss in dB
                                       // (with the pattern's attenuation, given an antenna)
  std::vector<std::string> ano_texts;  // the -ano files as SPLAT! wrote them, one per height,
                                       // when SplatRunOptions::keep_ano_texts
  std::vector<std::string> tiles;      // the SDF files given to SPLAT! (names in the folder)
  std::string version;                 // e.g. "1.4.2", from SPLAT!'s banner; empty if absent
  double seconds = 0.0;                // wall time of the SPLAT! runs (not of preparing tiles)
};

// Runs SPLAT! once per height in a fresh temporary folder (removed afterwards, also on errors):
// the tiles around the transmitter (those that intersect SPLAT!'s own load box, about
// radius / 57 miles per degree around it) are linked or decompressed there under SPLAT!'s
// colon names ("40:41:111:112.sdf": SPLAT! 1.4.2 silently assumes sea level for any tile it
// cannot find under that name); tx.qth and tx.lrp are written (the site's name reduced to
// letters, digits, '-', '_' and '.', since SPLAT! names its report after it); then, for each height
// H, `splat -t tx.qth -L H -R radius -metric -erp 0 -ano OUT [-olditm]` runs as a child (stdin /dev/null, its
// output kept for messages) and OUT is parsed with parse_ano. Throws std::runtime_error, one line
// each: the executable is missing; the folder holds no tile for part of the disc (SPLAT! would take
// it as sea level); a tile cannot be read or decompressed (io::FormatError); SPLAT! cannot be
// started, exits non-zero, is killed by a signal or the timeout, or writes no -ano file (the
// message quotes the last line SPLAT! printed); and io::FormatError for a malformed -ano file.
// Preconditions on the options (std::invalid_argument): heights non-empty and within [0, 100000],
// radius and timeout in range, frequency within SPLAT!'s 20 .. 20000 MHz.
SplatRunResult run_splat(const SplatRunOptions& options);

}  // namespace terravol::volume
