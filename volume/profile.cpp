// Link profiles (profile.h). The geometry is the textbook flat-Earth-with-bulge profile (ITU-R
// P.530-18, section 2.2, "Path clearance"; the first Fresnel zone of ITU-R P.526-15, section 3);
// the loss and the knife edges are the built-in model's (propagation.h) on the very same samples.
#include "volume/profile.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace terravol::volume {

namespace {

constexpr double kEarthRadius = 6371000.0;     // metres, as propagation.cpp
constexpr double kSpeedOfLight = 299792458.0;  // m/s

std::string format(const char* f, double a) {
  char b[64];
  std::snprintf(b, sizeof b, f, a);
  return b;
}

}  // namespace

FresnelAnalysis analyse_fresnel(const PathProfile& p, double frequency_mhz, double k_factor) {
  if (!(frequency_mhz > 0.0) || !(k_factor > 0.0)) {
    throw std::invalid_argument("analyse_fresnel: frequency and k-factor must be > 0");
  }
  FresnelAnalysis a;
  a.wavelength_m = kSpeedOfLight / (frequency_mhz * 1e6);
  const double D = p.distance_m, two_ka = 2.0 * k_factor * kEarthRadius;
  const std::size_t n = p.d_m.size();
  a.worst = n;
  double worst_ratio = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const double d1 = p.d_m[i], d2 = D - d1;
    const double bulge = d1 * d2 / two_ka;
    const double los = p.tx_height_m + (p.rx_height_m - p.tx_height_m) * d1 / D;
    const double f1 = std::sqrt(a.wavelength_m * d1 * d2 / D);
    const double clearance = los - (p.z_m[i] + bulge);
    a.bulge_m.push_back(bulge);
    a.los_m.push_back(los);
    a.f1_m.push_back(f1);
    a.clearance_m.push_back(clearance);
    const double ratio = clearance / f1;
    if (ratio < worst_ratio) {
      worst_ratio = ratio;
      a.worst = i;
    }
  }
  if (a.worst < n) {
    a.worst_clearance_m = a.clearance_m[a.worst];
    a.worst_clearance_f1 = worst_ratio;
    a.line_of_sight = worst_ratio >= 0.0;
    a.fresnel_60 = worst_ratio >= 0.6;
  }
  return a;
}

LinkProfile link_profile(const io::Grid& dem, const Transmitter& tx, double rx_lat, double rx_lon,
                         double rx_height_agl, const RfOptions& options) {
  LinkProfile l;
  l.path = rf_path(dem, tx, rx_lat, rx_lon, rx_height_agl, options);
  l.fresnel = analyse_fresnel(l.path.profile, tx.frequency_mhz, options.k_factor);
  const PathProfile& p = l.path.profile;
  for (const double d : p.d_m) {
    const double t = d / p.distance_m;
    l.lat.push_back(tx.lat + t * (rx_lat - tx.lat));
    l.lon.push_back(tx.lon + t * (rx_lon - tx.lon));
  }
  l.tx_ground_m = p.tx_height_m - tx.height_agl;
  l.rx_ground_m = p.rx_height_m - rx_height_agl;
  l.model = options.model;
  return l;
}

std::string verdict(const LinkProfile& l) {
  const FresnelAnalysis& f = l.fresnel;
  std::string s;
  if (f.worst >= f.clearance_m.size()) {
    s = "clear: no terrain between the antennas";
  } else {
    const std::string where = " at " + format("%.2f", l.path.profile.d_m[f.worst] / 1000.0) + " km (" +
                              format("%+.2f", f.worst_clearance_f1) + " F1)";
    if (!f.line_of_sight) {
      s = "obstructed: terrain " + format("%.1f", -f.worst_clearance_m) + " m above the line of sight" + where;
    } else if (!f.fresnel_60) {
      s = "line of sight, but less than 60% of the first Fresnel zone clear: " + format("%.1f", f.worst_clearance_m) +
          " m of clearance" + where;
    } else {
      s = "clear: 60% of the first Fresnel zone is free, least clearance " + format("%.1f", f.worst_clearance_m) + " m" +
          where;
    }
  }
  const RfPath& p = l.path;
  s += "; path loss " + format("%.1f", p.path_loss_db) + " dB (free space " + format("%.1f", p.free_space_db);
  if (l.model == RfModel::kItm) {
    s += " dB + ITM " + format("%.1f", p.diffraction_db) + " dB beyond free space";
  } else {
    s += " dB + diffraction " + format("%.1f", p.diffraction_db) + " dB over " + std::to_string(p.edges.size()) +
         (p.edges.size() == 1 ? " edge" : " edges");
  }
  if (p.antenna_gain_db != 0.0) s += " + antenna pattern " + format("%.1f", -p.antenna_gain_db) + " dB";
  return s + ")";
}

}  // namespace terravol::volume
