// The built-in propagation models: path loss from a transmitter to a lattice of receivers over
// a DEM, either free-space loss plus knife-edge diffraction over the terrain profile (Deygout
// 1966 with ITU-R P.526's J(v)), or the Longley-Rice Irregular Terrain Model's point-to-point
// mode (volume/itm.h). The models, their assumptions and their limits are stated at the top of
// propagation.cpp and itm.cpp and in docs/architecture.md ("volume/").
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "io/grid.h"
#include "io/mosaic.h"
#include "volume/antenna.h"
#include "volume/itm.h"
#include "volume/volume.h"

namespace terravol::volume {

struct Transmitter {
  double lat = 0.0, lon = 0.0;   // degrees (WGS84)
  double height_agl = 30.0;      // antenna height above the ground under it, metres, >= 0
  double frequency_mhz = 900.0;  // (0, 100000]; the model is meant for about 30 MHz .. 10 GHz
  std::optional<double> erp_w;   // effective radiated power relative to a half-wave dipole, W, > 0
                                 // (in the pattern's strongest direction, given one)
  std::string name;              // a label (legends, grid names); may be empty
  // The transmitting antenna's pattern; none: the ERP in every direction. With one, each path's
  // loss grows by the pattern's attenuation along its departure direction (RfPath).
  std::optional<AntennaPattern> antenna;
};

// The receiver lattice: longitude x latitude x height above ground, centred on the
// transmitter (which is a lattice column), a square box of half-side radius_km in both
// directions, clipped to the DEM's extent.
struct RfGrid {
  double radius_km = 20.0;           // > 0, at most 500
  std::vector<double> heights_agl;   // metres above ground, >= 0 (ITM: within [0.5, 3000]),
                                     // increasing, evenly spaced (to 1e-6 m); empty: 0, 50, ...,
                                     // 2000 (ITM: 10, 60, ..., 2010)
  double spacing_arcsec = 0.0;       // lattice spacing in latitude and in longitude, arc seconds;
                                     // 0: default_spacing_arcsec()
  // Only the columns within radius_km of the transmitter (WGS84 geodesic) are computed, the
  // box's corners are NaN: the disc SPLAT! computes (its -R), at 79% of the box's cost.
  bool disc = false;
};

enum class RfModel {
  kDeygout,  // free space + Deygout knife edges (propagation.cpp)
  kItm,      // Longley-Rice ITM 1.2.2, point-to-point (itm.h)
};

struct RfOptions {
  RfModel model = RfModel::kDeygout;
  // Deygout's (with ITM only the antenna pattern's departure angle uses k_factor).
  double k_factor = 4.0 / 3.0;  // effective Earth radius factor (standard atmosphere)
  int edge_depth = 2;           // Deygout recursion levels: 1 = principal edge only, 2 = plus
                                // one secondary edge on each side (3 edges, the usual form)
  // ITM only (its effective Earth follows from the surface refractivity instead of k_factor).
  // The transmitter's height must be within [0.5, 3000] m, its frequency within [20, 20000] MHz.
  ItmParameters itm;
  // Called from worker threads (serialised) with the fraction of columns done, in [0, 1], at
  // most about 100 times per run.
  std::function<void(double)> progress;
};

struct RfResult {
  Volume path_loss;              // "path_loss_db", dB, geographic frame with heights above ground
  std::optional<Volume> signal;  // "signal_dbm", dBm, when the transmitter has an ERP
  std::size_t columns = 0;       // receiver columns (lat, lon) computed
  double mean_profile_samples = 0.0;
  double seconds = 0.0;          // wall time of the computation (not of reading the DEM)
  std::vector<std::string> notes;  // clipping, filled DEM samples, ...
};

// Free-space basic transmission loss, 20 log10(4 pi d / lambda) = 32.4478 + 20 log10(f / MHz)
// + 20 log10(d / km) dB. Preconditions: distance_m > 0, frequency_mhz > 0.
double free_space_loss_db(double distance_m, double frequency_mhz);

// ITU-R P.526 single knife-edge loss J(v) = 6.9 + 20 log10(sqrt((v - 0.1)^2 + 1) + v - 0.1) dB
// for v > -0.78, and 0 otherwise.
double knife_edge_loss_db(double v);

// One transmitter-receiver path in the flat geometry the model works in. Terrain samples
// (d, z) are strictly between the ends (0 < d < distance_m, increasing d); heights are metres
// above the datum, the antennas' including the ground under them.
struct PathProfile {
  double distance_m = 0.0;  // D, along the ground, >= 0
  double tx_height_m = 0.0, rx_height_m = 0.0;
  std::vector<double> d_m, z_m;
};

// Diffraction loss (dB, >= 0) over the profile: the Earth's bulge d (D - d) / (2 k a),
// a = 6371 km, is added to each terrain sample, then Deygout's construction is applied with
// `edge_depth` levels of recursion: L = J(v_principal) + L(tx -> edge) + L(edge -> rx), where
// on a sub-path the samples joined to its bounding edge by unbroken obstruction are part of
// that edge's obstacle (propagation.cpp). 0 when every sample clears the path (v <= -0.78).
// Symmetric in swapping the ends; never decreases with edge_depth.
double diffraction_loss_db(const PathProfile& profile, double frequency_mhz, double k_factor = 4.0 / 3.0,
                           int edge_depth = 2);

// free_space_loss_db(slant distance, at least 1 m) + diffraction_loss_db(profile), where the
// slant distance is sqrt(D^2 + (rx_height - tx_height)^2).
double path_loss_db(const PathProfile& profile, double frequency_mhz, double k_factor = 4.0 / 3.0,
                    int edge_depth = 2);

// One receiver column's terrain as the models see it: ground heights (metres above the DEM's
// datum) at equal steps distance_m / (size - 1) along the path from the transmitter (first) to
// the column (last), at least 2 samples.
struct TerrainProfile {
  double distance_m = 0.0;  // along the ground (WGS84 geodesic), >= 0
  double azimuth_deg = 0.0; // of the geodesic at the transmitter, [0, 360) clockwise from north
  std::vector<double> ground_m;
};

// The profile compute_rf() uses from (tx_lat, tx_lon) to (rx_lat, rx_lon), degrees: the
// straight line in latitude and longitude, cut into ceil(distance / step_m) equal intervals
// (at least 1), heights bilinear in the geographic grid (clamped to its edges), so the first
// and last samples are the ground under the ends. Precondition: step_m > 0.
void sample_profile(const io::Grid& dem, double tx_lat, double tx_lon, double rx_lat, double rx_lon, double step_m,
                    TerrainProfile& out);

// The default lattice spacing: the smallest multiple of the DEM's latitude spacing that puts
// at most 256 intervals across the box's north-south side (6" for a 20 km radius over SRTM3).
double default_spacing_arcsec(double dem_spacing_arcsec, double radius_km);

// Throws std::invalid_argument("what: must be ...") for a parameter out of range: the checks
// every function here makes.
void check_rf_parameters(const Transmitter& tx, const RfGrid& grid, const RfOptions& options);

// The grid with its defaults filled in: heights 0, 50, ..., 2000 (ITM: 10, 60, ..., 2010) when empty, the default
// spacing over a DEM of `dem_spacing_arcsec` (latitude) when 0.
RfGrid resolve_grid(const RfGrid& grid, double dem_spacing_arcsec, RfModel model = RfModel::kDeygout);

// A DEM's extent: the first and last sample positions, degrees.
struct DemExtent {
  double south = 0.0, north = 0.0, west = 0.0, east = 0.0;
};
DemExtent dem_extent(const io::Georef& georef, int rows, int cols);

// The receiver lattice of one transmitter: longitudes anchor_lon + i s and latitudes
// anchor_lat + j s (s = grid.spacing_arcsec / 3600) within radius_km of the transmitter in each
// direction (metres per degree at its latitude), clipped to the extent; heights grid.heights_agl.
// With the transmitter as its own anchor this is compute_rf's lattice, centred on it.
// Precondition: a resolved grid (resolve_grid). `clipped` tells whether the extent cut the box.
struct RfBox {
  Lattice lattice;
  bool clipped = false;
};
RfBox rf_box(const DemExtent& extent, const Transmitter& tx, const RfGrid& grid, double anchor_lat, double anchor_lon);

// One knife edge of Deygout's construction on a path.
struct KnifeEdge {
  std::size_t sample = 0;  // index into the path's PathProfile::d_m / z_m
  double v = 0.0;          // Fresnel-Kirchhoff parameter on the (sub-)path it was found on
  double loss_db = 0.0;    // J(v)
  int level = 1;           // 1: the principal edge, 2: a secondary one, ...
};

// One transmitter-receiver path exactly as compute_rf computes it (the same profile, the same
// arithmetic): path_loss_db is the value compute_rf stores (as a float) at that receiver.
struct RfPath {
  PathProfile profile;          // terrain samples above the datum, without the bulge
  double azimuth_deg = 0.0;     // of the geodesic at the transmitter, clockwise from true north
  double free_space_db = 0.0, diffraction_db = 0.0;
  // ITM: diffraction_db is the model's loss beyond free space (whatever its mode: line of
  // sight, diffraction or scatter), so the sum below still holds; no edges.
  std::vector<KnifeEdge> edges; // Deygout's edges, ordered along the path
  // Elevation of the path's first leg at the transmitter, degrees above its local horizontal
  // (k-factor Earth, options.k_factor for both models): Deygout, the steepest of the lines to
  // the edges and to the receiver, i.e. the first leg of the string stretched over the edges;
  // ITM, which has no edges, the steepest of the lines to every terrain sample and to the
  // receiver (the string stretched over the whole terrain: the horizon ray when obstructed).
  double departure_deg = 0.0;
  double antenna_gain_db = 0.0;  // the pattern's gain (<= 0) at (azimuth, departure); 0 without
  double path_loss_db = 0.0;     // free_space_db + diffraction_db - antenna_gain_db
  std::size_t itm_warning = 0;   // ITM's warning code (0: none; 3, 4: outside its range)
};

// The model RfOptions chooses, for one transmitter, applied one receiver column at a time: the
// column's profile once, the losses at all its heights. This is what compute_rf(),
// compute_rf_rows() (so every transmitter of a plan) and rf_path() run for every path, so the
// two models (Deygout, ITM) and the transmitter's antenna pattern are one thing to all of them:
// the model gives the basic transmission loss of the path, the pattern's gain (<= 0 dB) in the
// path's azimuth and departure elevation is subtracted from it (RfPath). Not thread-safe (it
// keeps scratch space): one per thread.
class ColumnModel {
 public:
  // Throws std::invalid_argument for bad parameters, as compute_rf().
  ColumnModel(const Transmitter& tx, const RfOptions& options);
  ~ColumnModel();
  ColumnModel(ColumnModel&&) noexcept;
  ColumnModel& operator=(ColumnModel&&) noexcept;

  // Path loss (dB, the pattern's gain included) with the receiver rx_heights_agl[k] above the
  // column's ground into out[k] (out.size() == rx_heights_agl.size(); heights as RfGrid's, not
  // checked here). ITM gives NaN within 1 m of the transmitter (no path).
  // Returns how many of the heights carry an ITM warning of 3 or 4 (parameters outside the
  // model's range, e.g. paths under 1 km); 0 for Deygout.
  std::size_t path_loss(const TerrainProfile& profile, std::span<const double> rx_heights_agl, std::span<float> out);

  // One height's path with its parts (rf_path's fields but the profile): out.path_loss_db is
  // path_loss()'s value at that height before its rounding to float.
  void path(const TerrainProfile& profile, double rx_height_agl, RfPath& out);

  // The "model" attribute compute_rf() writes for these options.
  std::string description() const;

 private:
  struct State;
  std::unique_ptr<State> s_;
};

// The path from tx to a receiver height_agl metres above the ground at (lat, lon), over a
// geographic DEM grid that holds the path (fill voids first). Throws std::invalid_argument for
// bad parameters and a transmitter or receiver outside the grid.
RfPath rf_path(const io::Grid& dem, const Transmitter& tx, double rx_lat, double rx_lon, double rx_height_agl,
               const RfOptions& options = {});

// The ground the model takes at (lat, lon), metres above the DEM's datum: bilinear between the
// grid's samples, clamped to its edges. Precondition: a geographic grid of at least 2 x 2.
double dem_height(const io::Grid& dem, double lat, double lon);

// What a computation did.
struct RfStats {
  std::size_t columns = 0;       // receiver columns computed
  std::size_t samples = 0;       // terrain profile samples taken, all columns
  std::size_t itm_warned = 0;    // points with ITM warning 3 or 4
  double seconds = 0.0;          // wall time
};

// The path loss (dB, float) at the lattice points of `rows` (indices j into the lattice's
// latitude axis, any order), every height and longitude: out[i + nx (r + R k)] for the r-th of
// the R rows, so all rows in order give the lattice's own layout. Parallel (TBB) over the columns.
// Precondition: out.size() == nx * R * nz; the grid holds the lattice's columns. Throws
// std::invalid_argument for bad parameters (as compute_rf). With disc_radius_km > 0 the
// columns farther than that from the transmitter (WGS84 geodesic) are NaN, not computed (RfGrid::disc).
RfStats compute_rf_rows(const io::Grid& dem, const Transmitter& tx, const Lattice& lattice,
                        std::span<const int> rows, const RfOptions& options, std::span<float> out,
                        double disc_radius_km = 0.0);

// What a computation's figures say (compute_rf's notes but the clipping): the disc's NaN columns
// (grid.disc; box_columns: the columns of the lattices computed), ITM's NaN at the transmitter
// and its warnings (points: the lattices' points).
std::vector<std::string> rf_notes(const RfStats& stats, std::size_t box_columns, std::size_t points, const RfGrid& grid,
                                  const RfOptions& options);

// The volume compute_rf returns for tx on `lattice` before its values are set: "path_loss_db",
// dB, geographic frame with heights above ground, values 0, and the attributes (transmitter,
// model (ColumnModel::description), the DEM's vertical datum).
Volume path_loss_volume(const Transmitter& tx, const Lattice& lattice, const RfOptions& options,
                        const std::string& vertical_datum);

// The signal grid of a path-loss volume as compute_rf makes it: "signal_dbm", dBm, EIRP (ERP +
// 2.15 dB, ERP relative to a half-wave dipole) minus path loss, in float; NaN stays NaN.
// Attributes erp_w, eirp_dbm and signal are added. Precondition: erp_w > 0
// (std::invalid_argument).
Volume signal_from_path_loss(Volume path_loss, double erp_w);

// The model over a geographic DEM grid (row 0 north). Every sample's height is used as it is,
// so fill voids first (io::fill_voids). Parallel (TBB) over receiver columns, each column's
// profile sampled once for all its heights (ColumnModel). With ITM the transmitter's own
// column is NaN.
// Throws std::invalid_argument for bad parameters (naming them and their range) and a
// transmitter outside the grid.
RfResult compute_rf(const io::Grid& dem, const Transmitter& tx, const RfGrid& grid, const RfOptions& options = {});

// The same over a mosaic: reads the window the box needs (rf_area, read_rf_window), and records
// the tiles in the volumes' attributes ("dem").
RfResult compute_rf(const io::Mosaic& dem, const Transmitter& tx, const RfGrid& grid, const RfOptions& options = {});

// The area (degrees) within radius_km of the transmitter in each direction, metres per degree
// at its latitude: what its box may cover.
DemExtent rf_area(const Transmitter& tx, double radius_km);

// The samples of a mosaic covering `area` plus two samples on each side (clipped to the mosaic),
// voids and gaps filled (io::fill_voids; said in notes), and the names of the tiles it overlaps.
// Throws std::invalid_argument when the area misses the mosaic, io::FormatError for tiles that
// fail to load.
struct RfWindow {
  io::Grid grid;
  std::vector<std::string> notes;
  std::string tiles;  // "N45E006.hgt, ..."
};
RfWindow read_rf_window(const io::Mosaic& dem, const DemExtent& area);

}  // namespace terravol::volume
