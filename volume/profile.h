// A point-to-point link profile (`terravol profile`): the terrain along the path with the
// Earth's bulge for the k-factor, the line of sight, the first Fresnel zone, the worst
// obstruction, and the built-in model's loss on the same path with its knife edges.
//
// Geometry (the textbook "flat Earth with bulge" profile, e.g. ITU-R P.530 section 2.2): every
// terrain sample is raised by the bulge d1 d2 / (2 k a), a = 6371 km; the line of sight is the
// straight line between the antennas' tops; the first Fresnel zone's radius at a sample is
// F1 = sqrt(lambda d1 d2 / D); a sample's clearance is the line of sight's height minus the
// raised terrain's there, in metres and in units of F1. The knife-edge parameter of a sample is
// v = -sqrt(2) clearance / F1, so these are the quantities the model's diffraction sees.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "io/grid.h"
#include "volume/propagation.h"

namespace terravol::volume {

// The clearance analysis of a profile (PathProfile's samples, between the ends).
struct FresnelAnalysis {
  double wavelength_m = 0.0;
  std::vector<double> bulge_m;      // per sample: d1 d2 / (2 k a)
  std::vector<double> los_m;        // the line of sight's height above the datum
  std::vector<double> f1_m;         // the first Fresnel zone's radius
  std::vector<double> clearance_m;  // los - (terrain + bulge); negative: terrain above the line
  // The worst obstruction: the sample of least clearance in F1 units (samples.size() when the
  // path has no samples between its ends).
  std::size_t worst = 0;
  double worst_clearance_m = 0.0, worst_clearance_f1 = 0.0;
  // The verdict: the line of sight is clear of the terrain (every clearance >= 0), and so is 60%
  // of the first Fresnel zone (every clearance >= 0.6 F1), the usual design criterion.
  bool line_of_sight = true, fresnel_60 = true;
};

// Preconditions: frequency_mhz > 0, k_factor > 0 (std::invalid_argument).
FresnelAnalysis analyse_fresnel(const PathProfile& profile, double frequency_mhz, double k_factor);

// The whole profile: the model's path (rf_path, so its loss is compute_rf's value at that
// receiver) and its clearance analysis, with each sample's position.
struct LinkProfile {
  RfPath path;
  FresnelAnalysis fresnel;
  std::vector<double> lat, lon;  // per sample, degrees: the straight line in latitude and
                                 // longitude the model samples
  double tx_ground_m = 0.0, rx_ground_m = 0.0;  // the DEM under the antennas
  RfModel model = RfModel::kDeygout;            // the model that gave path's loss
};

// Throws what rf_path throws.
LinkProfile link_profile(const io::Grid& dem, const Transmitter& tx, double rx_lat, double rx_lon,
                         double rx_height_agl, const RfOptions& options = {});

// One line for people: whether the link is clear, where and how badly it is obstructed, and the
// path loss, e.g. "obstructed: terrain 35.2 m above the line of sight at 5.12 km (-1.42 F1);
// path loss 143.2 dB (free space 113.3 dB + diffraction 29.9 dB over 2 edges)"; with ITM the
// loss's second term is "ITM 27.4 dB beyond free space".
std::string verdict(const LinkProfile& profile);

}  // namespace terravol::volume
