// The built-in propagation model: path loss from a transmitter to a lattice of receivers over
// a DEM, as free-space loss plus knife-edge diffraction over the terrain profile (Deygout
// 1966 with ITU-R P.526's J(v)). The model, its assumptions and its limits are stated at the
// top of propagation.cpp and in docs/architecture.md ("volume/").
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "io/grid.h"
#include "io/mosaic.h"
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
  std::vector<double> heights_agl;   // metres above ground, >= 0, increasing, evenly spaced (to
                                     // 1e-6 m); empty: 0, 50, ..., 2000
  double spacing_arcsec = 0.0;       // lattice spacing in latitude and in longitude, arc seconds;
                                     // 0: default_spacing_arcsec()
};

struct RfOptions {
  double k_factor = 4.0 / 3.0;  // effective Earth radius factor (standard atmosphere)
  int edge_depth = 2;           // Deygout recursion levels: 1 = principal edge only, 2 = plus
                                // one secondary edge on each side (3 edges, the usual form)
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

// The default lattice spacing: the smallest multiple of the DEM's latitude spacing that puts
// at most 256 intervals across the box's north-south side (6" for a 20 km radius over SRTM3).
double default_spacing_arcsec(double dem_spacing_arcsec, double radius_km);

// The model over a geographic DEM grid (row 0 north). Every sample's height is used as it is,
// so fill voids first (io::fill_voids). Parallel (TBB) over receiver columns.
// Throws std::invalid_argument for bad parameters (naming them) and a transmitter outside the
// grid.
RfResult compute_rf(const io::Grid& dem, const Transmitter& tx, const RfGrid& grid, const RfOptions& options = {});

// The same over a mosaic: reads the window the box needs (plus a margin), fills its voids and
// gaps (noted in RfResult::notes), and records the tiles in the volumes' attributes.
RfResult compute_rf(const io::Mosaic& dem, const Transmitter& tx, const RfGrid& grid, const RfOptions& options = {});

}  // namespace terravol::volume
