// The Longley-Rice Irregular Terrain Model (ITM), version 1.2.2, in its point-to-point mode:
// the basic transmission loss between two antennas over a terrain profile, as the quantile of
// given fractions of time, locations and situations. Written from G. A. Hufford, "The ITS
// Irregular Terrain Model, version 1.2.2: the Algorithm" (NTIA/ITS, 1995), with the parameters
// of G. A. Hufford, A. G. Longley and W. A. Kissick, "A guide to the use of the ITS Irregular
// Terrain Model in the area prediction mode", NTIA Report 82-100 (1982). The model, the
// sections it follows and its limits are stated at the top of itm.cpp.
//
// Nothing here reads files, prints or exits. Bad parameters throw std::invalid_argument with
// one line naming the parameter and its range (check_itm()).
#pragma once

#include <cmath>
#include <span>
#include <string>
#include <vector>

namespace terravol::volume {

// The Algorithm's radio climates (its KLIM, 1..7).
enum class ItmClimate : int {
  kEquatorial = 1,
  kContinentalSubtropical = 2,
  kMaritimeSubtropical = 3,
  kDesert = 4,
  kContinentalTemperate = 5,
  kMaritimeTemperateOverLand = 6,
  kMaritimeTemperateOverSea = 7,
};

enum class ItmPolarization { kHorizontal, kVertical };

// How the three variabilities combine into one quantile (the Algorithm's MDVAR, 0..3): single
// message (time, location and situation at one fraction: the situation's), accidental
// (location taken at the situation's fraction), mobile (location at the time's fraction),
// broadcast (each its own fraction).
enum class ItmVariability { kSingleMessage = 0, kAccidental = 1, kMobile = 2, kBroadcast = 3 };

// Everything but the frequency and the antennas. The defaults are SPLAT!'s .lrp defaults
// (man splat) and the way SPLAT! calls the model (MDVAR 12: mobile, location variability
// eliminated).
struct ItmParameters {
  ItmPolarization polarization = ItmPolarization::kHorizontal;
  double permittivity = 15.0;   // relative permittivity of the ground, (1, 100]
  double conductivity = 0.005;  // of the ground, S/m, (0, 100]
  // N_0: the surface refractivity reduced to sea level, N-units, [250, 400]. Each path uses
  // N_s = N_0 exp(-z_s / 9460 m), z_s the mean elevation of the middle 80% of its profile
  // (as SPLAT! and NTIA's own point-to-point driver do).
  double refractivity = 301.0;
  ItmClimate climate = ItmClimate::kContinentalTemperate;
  // Fractions, each within (0, 1): the loss is the one not exceeded in this fraction of the
  // time, of locations, of situations (confidence).
  double time = 0.5, location = 0.5, situation = 0.5;
  ItmVariability variability = ItmVariability::kMobile;
  bool location_variability = false;  // false: eliminated (MDVAR + 10, point-to-point use)
  bool situation_variability = true;  // false: direct situation variability eliminated (+ 20)

  int mdvar() const;  // the Algorithm's MDVAR code for the three settings above
};

// Throws std::invalid_argument("ITM PARAMETER VALUE: must be within RANGE") for a frequency
// outside [20, 20000] MHz or a parameter outside the ranges above (an unknown climate too).
void check_itm(double frequency_mhz, const ItmParameters& parameters);

// Which of the Algorithm's three formulas gave the reference attenuation.
enum class ItmMode { kLineOfSight, kDiffraction, kTroposcatter };

struct ItmLoss {
  double loss_db = 0.0;         // basic transmission loss, free_space_db + attenuation_db
  double free_space_db = 0.0;   // 32.45 + 20 log10(f / MHz) + 20 log10(d / km)
  double attenuation_db = 0.0;  // A: the requested quantile of attenuation below free space
  double reference_db = 0.0;    // A_ref: the median reference attenuation
  ItmMode mode = ItmMode::kLineOfSight;
  // The Algorithm's KWX: 0 none; 1 parameters close to the model's limits; 3 a combination of
  // parameters outside them ("results probably invalid"); 4 a parameter outside them.
  int warning = 0;
  // Intermediate values of the preparatory stage.
  double surface_refractivity = 0.0;     // N_s, N-units
  double earth_curvature = 0.0;          // gamma_e, the effective Earth's curvature, 1/m
  double delta_h_m = 0.0;                // terrain irregularity
  double effective_height_m[2] = {0, 0};  // transmitter, receiver
  double horizon_distance_m[2] = {0, 0};
  double horizon_angle_rad[2] = {0, 0};  // elevation of each horizon ray
};

// Scratch space of the terrain irregularity: the resampled profile, the candidates for its
// quantiles, and the guess: the last quantiles found with the margins to search within (for
// the next, which only decides how fast they are found).
struct DeltaHGuess {
  double lower = std::nan(""), upper = std::nan("");
  double low_margin = 0.02, high_margin = 0.02;  // fractions of upper - lower
};
struct DeltaHScratch {
  std::vector<double> samples, low, high, spare;
  DeltaHGuess guess;
};

namespace itm_kernel {
struct Path;
struct Lanes;
}  // namespace itm_kernel

namespace itm_detail {
// Which copy of the per-height kernel (itm_kernel.h) runs: "avx2" where the processor has AVX2,
// else "baseline"; both give the same values.
std::string kernel_name();
// For tests: run the baseline copy even where AVX2 is there (false, the default: the best one).
void force_baseline_kernel(bool force);
// For tests: the kernel's own exponential, logarithm, cube root, sine and cosine (x within
// [0, pi]) of one value.
double kernel_exp(double x);
double kernel_log(double x);
double kernel_cbrt(double x);
void kernel_sincos(double x, double& sine, double& cosine);
}  // namespace itm_detail

// One path's terrain, to be evaluated for many receiver heights: what depends on the profile
// and the transmitter alone is computed once (set_profile); then each height's horizons, Delta h
// and effective heights (O(profile length) at most), and the rest of the chain for several
// heights at once (losses()). Holds scratch space: one per thread.
class ItmPath {
 public:
  // Throws as check_itm().
  ItmPath(double frequency_mhz, const ItmParameters& parameters);

  // The profile: ground heights (metres above a datum) at equal steps spacing_m > 0 from the
  // transmitter (ground[0]) to the receiver (ground.back()), at least 2 samples; the antenna
  // heights above the ground at the ends. The profile is copied. Throws std::invalid_argument
  // for fewer than 2 samples, a spacing that is not > 0 or a non-finite value.
  void set_profile(std::span<const double> ground_m, double spacing_m, double tx_height_m);

  // The loss with the receiving antenna rx_height_m above the profile's last sample.
  // Precondition: set_profile() was called. Heights outside [0.5, 3000] m are outside the
  // model (warning 4); at 0 the effective height can be 0 and the result NaN.
  ItmLoss loss(double rx_height_m);

  // The basic transmission loss (dB) with the receiving antenna at each of rx_heights_m into
  // out (the same values as loss() at each height, computed several at a time, fastest in
  // rising order); returns how many carry warning 3 or 4. Precondition: set_profile();
  // throws std::invalid_argument unless out has one value per height.
  std::size_t losses(std::span<const double> rx_heights_m, std::span<double> out);

 private:
  // One height's geometry (horizons, Delta h, effective heights) into lane `lane`.
  void geometry(double rx_height_m, itm_kernel::Lanes& lanes, int lane);
  void kernel_path(itm_kernel::Path& path) const;  // the kernel's constants of this path
  double delta_h(double x1_m, double x2_m);
  int receiver_horizon(double zb);  // the interior sample of steepest elevation seen from zb

  double wn_ = 0.0;                   // wave number, 1/m (the Algorithm's k = f / 47.7 MHz m)
  double zg_re_ = 0.0, zg_im_ = 0.0;  // surface transfer impedance of the ground
  double inverse_abs_zg_ = 0.0, ln_inverse_abs_zg_ = 0.0;
  double g_minus_ = 0.0, g_plus_ = 0.0, dexa_frequency_m_ = 0.0;  // the statistics' frequency terms
  double frequency_mhz_ = 0.0;
  double free_space_frequency_db_ = 0.0;  // 32.45 + 20 log10(f / MHz)
  double ln_scatter_wn_ = 0.0;            // ln(47.7 k), of troposcatter's least distance
  ItmParameters p_;
  double z_time_ = 0.0, z_location_ = 0.0, z_situation_ = 0.0;  // standard normal deviates

  // The profile and what follows from it and the transmitter alone.
  std::vector<double> z_;
  std::vector<double> sum_z_, sum_iz_;   // prefix sums of z_i and i z_i, for line fits
  std::vector<double> rx_a_, rx_u_;      // the receiver's horizon angle of sample i is
                                         // rx_a_[i] - z_rx * rx_u_[i]
  std::vector<double> tx_angle_;         // the transmitter's horizon angle of sample i
  std::vector<double> inverse_;          // 1 / i, as far as the longest profile yet
  // The upper envelope of those lines in z_rx (sample indices, from low z_rx to high; built
  // when a receiver first has a horizon), and the last query's place on it.
  std::vector<int> rx_hull_;
  bool rx_hull_built_ = false;
  std::size_t rx_hull_at_ = 0;
  double rx_hull_last_zb_ = 0.0;
  int n_ = 0;                            // intervals
  double xi_ = 0.0, dist_ = 0.0, hg_tx_ = 0.0;
  double ns_ = 0.0, gme_ = 0.0, free_space_path_db_ = 0.0;
  double xae_ = 0.0;  // (k gamma_e^2)^(-1/3), the diffraction's distance scale
  double tx_best_angle_ = 0.0, tx_best_distance_ = 0.0;  // steepest interior sample from the
                                                        // transmitter
  // Delta h depends on the window (x1, x2) only: the last one is kept.
  double dh_x1_ = -1.0, dh_x2_ = -1.0, dh_value_ = 0.0;
  DeltaHScratch dh_scratch_;
  // The guess after a profile's first Delta h, the guess for the next profile's first: a
  // column's lowest receiver is more like its neighbour's lowest than its highest.
  DeltaHGuess dh_first_guess_;
  bool dh_first_ = true;
};

// One path, one receiver height: ItmPath(frequency, parameters), set_profile(), loss().
ItmLoss itm_point_to_point(std::span<const double> ground_m, double spacing_m, double tx_height_m,
                           double rx_height_m, double frequency_mhz, const ItmParameters& parameters);

std::string itm_climate_name(ItmClimate climate);  // "continental temperate", ...

// The Algorithm's auxiliary functions, exposed for tests (section 6 of the Algorithm).
namespace itm_functions {
double knife_edge_db(double v2);              // F(v) of one knife edge, from v^2 (eq. 6.1)
double height_gain_db(double x, double k);    // the smooth-Earth height-gain F(x, K) (6.2-6.7)
double frequency_gain_db(double r, double eta);  // H_0(r, eta_s) of troposcatter (6.13)
double scatter_f_db(double theta_d);          // F(theta d) of troposcatter
double inverse_normal(double q);              // z with Q(z) = q, Q the complementary normal
// Delta h of a profile between x1 and x2 (metres from its start, x1 < x2): the interdecile
// range of its heights about their least-squares line, divided by 1 - 0.8 exp(-(x2-x1)/50 km).
double delta_h(std::span<const double> ground_m, double spacing_m, double x1_m, double x2_m);
}  // namespace itm_functions

}  // namespace terravol::volume
