// The built-in propagation models: path loss from a transmitter to a lattice of receivers over
// a DEM, either free-space loss plus knife-edge diffraction over the terrain profile (Deygout
// 1966 with ITU-R P.526's J(v)), or the Longley-Rice Irregular Terrain Model's point-to-point
// mode (volume/itm.h). The models, their assumptions and their limits are stated at the top of
// propagation.cpp and itm.cpp and in docs/architecture.md ("volume/").
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "io/grid.h"
#include "io/mosaic.h"
#include "volume/itm.h"
#include "volume/volume.h"

namespace terravol::volume {

struct Transmitter {
  double lat = 0.0, lon = 0.0;   // degrees (WGS84)
  double height_agl = 30.0;      // antenna height above the ground under it, metres, >= 0
  double frequency_mhz = 900.0;  // (0, 100000]; the model is meant for about 30 MHz .. 10 GHz
  std::optional<double> erp_w;   // effective radiated power relative to a half-wave dipole, W, > 0
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
  // Deygout only.
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
  std::vector<double> ground_m;
};

// The profile compute_rf() uses from (tx_lat, tx_lon) to (rx_lat, rx_lon), degrees: the
// straight line in latitude and longitude, cut into ceil(distance / step_m) equal intervals
// (at least 1), heights bilinear in the geographic grid (clamped to its edges), so the first
// and last samples are the ground under the ends. Precondition: step_m > 0.
void sample_profile(const io::Grid& dem, double tx_lat, double tx_lon, double rx_lat, double rx_lon, double step_m,
                    TerrainProfile& out);

// The model RfOptions chooses, for one transmitter, applied one receiver column at a time: the
// column's profile once, the losses at all its heights. This is what compute_rf() runs for
// every column; other drivers (several transmitters, other partitions of the columns) can
// call it the same way. Not thread-safe (it keeps scratch space): one per thread.
class ColumnModel {
 public:
  // Throws std::invalid_argument for bad parameters, as compute_rf().
  ColumnModel(const Transmitter& tx, const RfOptions& options);
  ~ColumnModel();
  ColumnModel(ColumnModel&&) noexcept;
  ColumnModel& operator=(ColumnModel&&) noexcept;

  // Path loss (dB) with the receiver rx_heights_agl[k] above the column's ground into out[k]
  // (out.size() == rx_heights_agl.size(); heights as RfGrid's, not checked here). ITM gives
  // NaN at zero distance (no path).
  // Returns how many of the heights carry an ITM warning of 3 or 4 (parameters outside the
  // model's range, e.g. paths under 1 km); 0 for Deygout.
  std::size_t path_loss(const TerrainProfile& profile, std::span<const double> rx_heights_agl, std::span<float> out);

  // The "model" attribute compute_rf() writes for these options.
  std::string description() const;

 private:
  struct State;
  std::unique_ptr<State> s_;
};

// The default lattice spacing: the smallest multiple of the DEM's latitude spacing that puts
// at most 256 intervals across the box's north-south side (6" for a 20 km radius over SRTM3).
double default_spacing_arcsec(double dem_spacing_arcsec, double radius_km);

// The model over a geographic DEM grid (row 0 north). Every sample's height is used as it is,
// so fill voids first (io::fill_voids). Parallel (TBB) over receiver columns, each column's
// profile sampled once for all its heights (ColumnModel). With ITM the transmitter's own
// column is NaN.
// Throws std::invalid_argument for bad parameters (naming them and their range) and a
// transmitter outside the grid.
RfResult compute_rf(const io::Grid& dem, const Transmitter& tx, const RfGrid& grid, const RfOptions& options = {});

// The same over a mosaic: reads the window the box needs (plus a margin), fills its voids and
// gaps (noted in RfResult::notes), and records the tiles in the volumes' attributes.
RfResult compute_rf(const io::Mosaic& dem, const Transmitter& tx, const RfGrid& grid, const RfOptions& options = {});

}  // namespace terravol::volume
