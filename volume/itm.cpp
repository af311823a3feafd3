// The ITS Irregular Terrain Model, point-to-point mode (itm.h).
//
// Sources. G. A. Hufford, "The ITS Irregular Terrain Model, version 1.2.2: the Algorithm"
// (NTIA/ITS, 1995), "the Algorithm" below, with its equation numbers in parentheses; NTIA Report
// 82-100 (Hufford, Longley and Kissick 1982) for the parameters, their ranges and the climate
// curves. The Algorithm was written down by Hufford as the description of the ITM's Fortran
// version 1.2.2, so where it is terse the behaviour of that version is meant; NTIA's published
// point-to-point cases (tests/volume/data/ntia_itm_p2p.txt) check the whole chain.
//
// The chain, per path (ItmPath::loss, ItmPath::losses):
//  1. General preparation (the Algorithm, "preparatory calculations"): wave number
//     k = f / 47.7 MHz m; surface refractivity N_s = N_0 exp(-z_s / 9460 m) with z_s the mean
//     elevation of the middle 80% of the profile; effective Earth curvature
//     gamma_e = gamma_a (1 - 0.04665 exp(N_s / 179.3 N-units)), gamma_a = 157e-9 / m; ground
//     transfer impedance Z_g = sqrt(eps' - 1) (horizontal) or sqrt(eps' - 1) / eps'
//     (vertical), eps' = eps_r + i Z_0 sigma / k, Z_0 = 376.62 ohm.
//  2. Point-to-point preparation: each terminal's horizon (the profile sample of steepest
//     elevation angle, on an Earth of curvature gamma_e; the other terminal if none rises
//     above the line between them); the terrain irregularity Delta h over the profile less
//     min(15 h_g, 0.1 d_L) at each end: the interdecile range of the heights about their
//     least-squares line, resampled at 10 k_a - 5 points (k_a = 0.1 (samples + 8), within
//     4..25), divided by 1 - 0.8 exp(-d / 50 km); effective heights from least-squares lines:
//     for a line-of-sight or nearly line-of-sight path (d_L1 + d_L2 > 1.5 d) one line over that
//     same stretch, with the horizons and their angles then re-derived from the effective
//     heights as on smooth ground; otherwise one line over each terminal's foreground up to
//     0.9 of its horizon distance, the horizons staying those of the profile.
//  3. The reference attenuation A_ref (the Algorithm, "the reference attenuation"): a
//     straight line through the diffraction attenuation (4.11) at two distances beyond the
//     smooth-Earth horizon -- a weighted mean of double knife edge (F(v), 4.21, 6.1) and
//     smooth-Earth (three radii, height-gain 4.20, 6.2-6.7) losses, plus the clutter factor
//     A_fo; before the smooth-Earth horizon distance d_Ls, A_el + k_1 d + k_2 ln d through the
//     line-of-sight attenuation (4.44, two rays over rough ground) at two distances and the
//     diffraction line at d_Ls; far beyond the horizons, the troposcatter line (frequency gain
//     H_0, 6.13) where it falls below the diffraction line.
//  4. Variability (the Algorithm, "statistics"): the climate's median adjustment V(d_e) and
//     the time, location and situation deviations combined as MDVAR says; small attenuations
//     below zero are compressed, A (29 - A) / (29 - 10 A).
//  Basic transmission loss = 32.45 + 20 log10(f / MHz) + 20 log10(d / km) + A.
//
// Where this departs from a plain transcription, it is for speed and gives the same values (to
// rounding; tests/volume/itm_reference.h is the plain transcription the tests hold it to): the
// transmitter's steepest interior sample is found once per profile, the receiver's from an
// upper envelope of its horizon lines built once per profile; least-squares lines over the
// profile come from prefix sums; Delta h is kept while its window does not change, and its
// quantiles are searched first among the values near the last ones found. The rest of the
// chain, from the effective heights on (the end of step 2, steps 3 and 4), runs four heights
// at a time (volume/itm_kernel.h, compiled twice: for the baseline instruction set and for
// AVX2), each branch of the Algorithm a choice between lanes, with the exponential,
// logarithm, cube root, sine and cosine written out in plain arithmetic to about one unit in
// the last place; troposcatter is evaluated only for paths long enough that it could matter
// (beyond max(d_Ls, d_L + 0.3 X_ae ln(47.7 k)), the least the crossover distance can be). One
// change of substance, at rounding level: positions and counts within 1e-9 of a whole number
// are taken as that number before the Algorithm rounds them (snap()), so that a path and its
// reverse give the same loss; otherwise a window end at 0.9 of a horizon distance of ten
// samples falls on either side of a sample depending on the direction of computation.
//
// Limits: the model's own (20 MHz - 20 GHz; paths of 1 - 2000 km; antennas 0.5 - 3000 m; it
// reports "warning" 3 or 4 outside them, and still gives a number); a single profile stands
// for the whole path (no clutter, buildings or trees beyond A_fo's statistical allowance); the
// statistics are those of the Algorithm's climate curves, fitted to measurements of the 1960s.
#include "volume/itm.h"

#define TERRAVOL_ITM_KERNEL baseline
#include "volume/itm_kernel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <complex>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace terravol::volume {

namespace {

using Complex = std::complex<double>;

constexpr double kGammaA = 157e-9;  // the Earth's actual curvature, 1/m
constexpr double kZ0 = 376.62;      // the Algorithm's impedance of free space, ohm

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

// The climate curves (NTIA Report 82-100; the Algorithm, "statistics"): for each curve
// C(d_e) = (c1 + c2 / (1 + ((d_e - x2) / x3)^2)) (d_e / x1)^2 / (1 + (d_e / x1)^2), the
// median adjustment V and the deviations sigma_T- and sigma_T+ below and above the median;
// sigma_T+ beyond z_D is sigma_TD = s_d sigma_T+ plus a tail; frequency factors g = f1 + f2 /
// ((f3 ln(0.133 k))^2 + 1) for below and above the median.
struct Curve {
  double c1, c2, x1, x2, x3;
  double operator()(double de) const {
    const double a = (de - x2) / x3, b = de / x1;
    return (c1 + c2 / (1.0 + a * a)) * (b * b) / (1.0 + b * b);
  }
};
struct FrequencyFactor {
  double f1, f2, f3;
  double operator()(double ln_k) const {
    const double a = f3 * ln_k;
    return f1 + f2 / (a * a + 1.0);
  }
};
struct Climate {
  Curve median, sigma_minus, sigma_plus;
  double sd, zd;
  FrequencyFactor g_minus, g_plus;
};
constexpr Climate kClimates[7] = {
    // 1 equatorial
    {{-9.67, 12.7, 144.9e3, 190.3e3, 133.8e3}, {2.13, 159.5, 762.2e3, 123.6e3, 94.5e3},
     {2.11, 102.3, 636.9e3, 134.8e3, 95.6e3}, 1.224, 1.282, {1.0, 0.0, 0.0}, {1.0, 0.0, 0.0}},
    // 2 continental subtropical
    {{-0.62, 9.19, 228.9e3, 205.2e3, 143.6e3}, {2.66, 7.67, 100.4e3, 172.5e3, 136.4e3},
     {6.87, 15.53, 138.7e3, 143.7e3, 98.6e3}, 0.801, 2.161, {1.0, 0.0, 0.0}, {0.93, 0.31, 2.00}},
    // 3 maritime subtropical
    {{1.26, 15.5, 262.6e3, 185.2e3, 99.8e3}, {6.11, 6.65, 138.2e3, 242.2e3, 178.6e3},
     {10.08, 9.60, 165.3e3, 225.7e3, 129.7e3}, 1.380, 1.282, {1.0, 0.0, 0.0}, {1.0, 0.0, 0.0}},
    // 4 desert
    {{-9.21, 9.05, 84.1e3, 101.1e3, 98.6e3}, {1.98, 13.11, 139.1e3, 132.7e3, 193.5e3},
     {3.68, 159.3, 464.4e3, 93.1e3, 94.2e3}, 1.000, 20.0, {1.0, 0.0, 0.0}, {0.93, 0.19, 1.79}},
    // 5 continental temperate
    {{-0.62, 9.19, 228.9e3, 205.2e3, 143.6e3}, {2.68, 7.16, 93.7e3, 186.8e3, 133.5e3},
     {4.75, 8.12, 93.2e3, 135.9e3, 113.4e3}, 1.224, 1.282, {0.92, 0.25, 1.77}, {0.93, 0.31, 2.00}},
    // 6 maritime temperate, over land
    {{-0.39, 2.86, 141.7e3, 315.9e3, 167.4e3}, {6.86, 10.38, 187.8e3, 169.6e3, 108.9e3},
     {8.58, 13.97, 216.0e3, 152.0e3, 122.7e3}, 1.518, 1.282, {1.0, 0.0, 0.0}, {1.0, 0.0, 0.0}},
    // 7 maritime temperate, over sea
    {{3.15, 857.9, 2222.0e3, 164.8e3, 116.3e3}, {8.51, 169.8, 609.8e3, 119.9e3, 106.6e3},
     {8.43, 8.19, 136.2e3, 188.5e3, 122.9e3}, 1.518, 1.282, {1.0, 0.0, 0.0}, {1.0, 0.0, 0.0}},
};

namespace kernel = itm_kernel::baseline;

std::atomic<bool> baseline_forced{false};

// The kernel of this processor: AVX2 where it has it (and the operating system saves its
// registers), else the baseline one; the same values either way.
bool use_avx2() { return __builtin_cpu_supports("avx2") && !baseline_forced.load(std::memory_order_relaxed); }

void evaluate(const itm_kernel::Path& path, itm_kernel::Lanes& lanes) {
  if (use_avx2()) {
    itm_kernel::avx2::evaluate(path, lanes);
  } else {
    kernel::evaluate(path, lanes);
  }
}


// A line fitted by least squares, with the trapezoidal rule's weights (half at both ends), to
// samples ja..jb (unit spacing) given their sums: the Algorithm's fit of a line to a profile.
struct Line {
  double mean = 0.0, slope = 0.0, centre = 0.0;
  double at(double i) const { return mean + slope * (i - centre); }
};
Line trapezoid_fit(double sum_z, double sum_iz, double z_first, double z_last, int ja, int jb) {
  Line line;
  const double length = jb - ja;
  line.centre = 0.5 * (ja + jb);
  const double moment0 = sum_z - 0.5 * (z_first + z_last);
  const double moment1 = (sum_iz - line.centre * sum_z) -
                         0.5 * ((ja - line.centre) * z_first + (jb - line.centre) * z_last);
  line.mean = moment0 / length;
  line.slope = 12.0 * moment1 / (length * (length * length + 2.0));
  return line;
}

// x with rounding noise around whole numbers removed. The Algorithm rounds sample positions
// and counts down to whole numbers, and they fall exactly on whole numbers often (a window's
// end at 0.9 or 0.1 of a horizon distance that is a multiple of ten samples): which way they
// go must not depend on the direction the path was computed in.
double snap(double x) {
  // The nearest whole number by adding and taking off 1.5 * 2^52 (the baseline instruction set
  // has no rounding instruction, and std::round is a call); only |x| < 2^51 gets near one.
  constexpr double kShift = 6755399441055744.0;
  if (!(std::abs(x) < 2251799813685248.0)) return x;
  const double r = (x + kShift) - kShift;
  return std::abs(x - r) < 1e-9 * std::max(1.0, std::abs(x)) ? r : x;
}
double in_samples(double x, double xi) { return snap(x / xi); }

// The samples a fit between x1 and x2 (metres) uses: from the one at or before x1 to the one
// at or after x2, clipped to the profile, widened by one each side when that leaves fewer
// than two.
void fit_window(double x1, double x2, double xi, int n, int& ja, int& jb) {
  double a = std::floor(std::max(in_samples(x1, xi), 0.0));
  double b = n - std::floor(std::max(n - in_samples(x2, xi), 0.0));
  if (b <= a) {
    a = std::max(a - 1.0, 0.0);
    b = n - std::max(n - (b + 1.0), 0.0);
  }
  ja = static_cast<int>(a);
  jb = static_cast<int>(b);
}

// The k-th smallest (0-based; kLargest: the k-th largest) of c[0..count), count > k, reordering
// c (room for count rounded up to kSumParts). With few values beyond it, by taking the extreme
// off count - 1 - k times (the kernel's, four values at a time); else std::nth_element.
template <bool kLargest>
double kth_extreme(double* c, std::size_t count, std::size_t k) {
  if (count - 1 - k > 8) {
    if constexpr (kLargest) {
      std::nth_element(c, c + k, c + count, std::greater<double>());
    } else {
      std::nth_element(c, c + k, c + count);
    }
    return c[k];
  }
  return use_avx2() ? itm_kernel::avx2::kth_extreme(c, count, k, kLargest) : kernel::kth_extreme(c, count, k, kLargest);
}

double delta_h_of(const double* z, int np, double xi, double x1, double x2, DeltaHScratch& w) {
  const double xa = in_samples(x1, xi), xb = in_samples(x2, xi);
  const double span = snap(xb - xa);
  if (span < 2.0) return 0.0;
  const int ka = std::clamp(static_cast<int>(snap(0.1 * (span + 8.0))), 4, 25);
  const int n = 10 * ka - 5;
  const auto size = static_cast<std::size_t>(n);
  constexpr auto kParts = static_cast<std::size_t>(itm_kernel::kSumParts);
  w.samples.resize((size + kParts - 1) / kParts * kParts);
  w.low.resize(size + kParts);
  w.high.resize(size + kParts);
  w.spare.resize(size + kParts);
  double* s = w.samples.data();
  // Linear interpolation at n equally spaced points p from xa to xb, each on the interval that
  // ends at sample k = ceil(p), within [floor(xa) + 1, np]; the sums for the line.
  const double step = (xb - xa) / (n - 1);
  const int k0 = std::clamp(static_cast<int>(std::floor(xa)) + 1, 1, np);
  const bool avx2 = use_avx2();
  const itm_kernel::Sums sums = avx2 ? itm_kernel::avx2::resample(z, np, k0, xa, step, n, s)
                                     : kernel::resample(z, np, k0, xa, step, n, s);
  const double sum = sums.sum, sum_i = sums.sum_i;
  const Line line = trapezoid_fit(sum, sum_i, s[0], s[n - 1], 0, n - 1);
  const double at0 = line.at(0.0), slope = line.slope;
  // The ka-th smallest and the ka-th largest deviation from the line. Their candidates are
  // gathered in one pass: the deviations beyond thresholds a margin inside the last ones
  // found, each side's margin (a fraction of their distance) grown after a miss and shrunk
  // after a haul much larger than needed; a side with too few gathers again with its margin 4,
  // 16 and 64 times wider, then all. Exact whatever the guess: it only decides how much is
  // gathered. Deviation i is s[i] - (at0 + slope i), computed alike wherever it is needed.
  const auto rank = static_cast<std::size_t>(ka - 1);
  DeltaHGuess& g = w.guess;
  const bool guessed = std::isfinite(g.lower) && std::isfinite(g.upper) && g.upper > g.lower;
  const double range = guessed ? g.upper - g.lower : 0.0;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double* low = w.low.data();
  double* high = w.high.data();
  double* spare = w.spare.data();  // where a side that has enough gathers nothing
  auto beyond = [&](bool redo_low, double low_threshold, bool redo_high, double high_threshold) {
    const double lt = redo_low ? low_threshold : -kInf, ht = redo_high ? high_threshold : kInf;
    double* l = redo_low ? low : spare;
    double* h = redo_high ? high : spare;
    return avx2 ? itm_kernel::avx2::beyond(s, n, at0, slope, lt, ht, l, h) : kernel::beyond(s, n, at0, slope, lt, ht, l, h);
  };
  std::size_t n_low = 0, n_high = 0;
  if (guessed) {
    const itm_kernel::Counts c = beyond(true, g.lower + g.low_margin * range, true, g.upper - g.high_margin * range);
    n_low = c.low;
    n_high = c.high;
    auto adapt = [&](double& margin, std::size_t count) {
      if (count <= rank) {
        margin = std::min(2.0 * margin, 0.5);
      } else if (count > rank + 6) {
        margin = std::max(0.75 * margin, 0.002);
      }
    };
    adapt(g.low_margin, n_low);
    adapt(g.high_margin, n_high);
    for (double widen = 4.0; widen <= 64.0 && (n_low <= rank || n_high <= rank); widen *= 4.0) {
      const bool redo_low = n_low <= rank, redo_high = n_high <= rank;
      const itm_kernel::Counts again =
          beyond(redo_low, g.lower + widen * g.low_margin * range, redo_high, g.upper - widen * g.high_margin * range);
      if (redo_low) n_low = again.low;
      if (redo_high) n_high = again.high;
    }
  }
  if (n_low <= rank || n_high <= rank) {
    const bool redo_low = n_low <= rank, redo_high = n_high <= rank;
    const itm_kernel::Counts all = beyond(redo_low, kInf, redo_high, -kInf);
    if (redo_low) n_low = all.low;
    if (redo_high) n_high = all.high;
  }
  const double lower = kth_extreme<false>(low, n_low, rank);
  const double upper = kth_extreme<true>(high, n_high, rank);
  g.lower = lower;
  g.upper = upper;
  return (upper - lower) / (1.0 - 0.8 * std::exp(-(x2 - x1) / 50e3));
}

}  // namespace

namespace itm_detail {
std::string kernel_name() { return use_avx2() ? "avx2" : "baseline"; }
void force_baseline_kernel(bool force) { baseline_forced.store(force, std::memory_order_relaxed); }
double kernel_exp(double x) { return kernel::vexp(kernel::splat(x))[0]; }
double kernel_log(double x) { return kernel::vlog(kernel::splat(x))[0]; }
double kernel_cbrt(double x) {
  kernel::V ln_root;
  return kernel::vcbrt(kernel::splat(x), ln_root)[0];
}
void kernel_sincos(double x, double& sine, double& cosine) {
  kernel::V s, c;
  kernel::vsincos(kernel::splat(x), s, c);
  sine = s[0];
  cosine = c[0];
}
}  // namespace itm_detail

int ItmParameters::mdvar() const {
  return static_cast<int>(variability) + (location_variability ? 0 : 10) + (situation_variability ? 0 : 20);
}

void check_itm(double frequency_mhz, const ItmParameters& p) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("ITM " + what); };
  auto fraction = [&](const char* name, double v) {
    if (!(v > 0.0 && v < 1.0)) bad(std::string(name) + " fraction " + num(v) + ": must be within (0, 1)");
  };
  if (!(frequency_mhz >= 20.0 && frequency_mhz <= 20000.0)) {
    bad("frequency " + num(frequency_mhz) + " MHz: must be within [20, 20000] MHz");
  }
  if (!(p.permittivity > 1.0 && p.permittivity <= 100.0)) {
    bad("permittivity " + num(p.permittivity) + ": must be within (1, 100]");
  }
  if (!(p.conductivity > 0.0 && p.conductivity <= 100.0)) {
    bad("conductivity " + num(p.conductivity) + " S/m: must be within (0, 100] S/m");
  }
  if (!(p.refractivity >= 250.0 && p.refractivity <= 400.0)) {
    bad("refractivity " + num(p.refractivity) + " N-units: must be within [250, 400] N-units");
  }
  const int climate = static_cast<int>(p.climate);
  if (climate < 1 || climate > 7) {
    bad("climate " + std::to_string(climate) + ": must be within 1..7 (1 equatorial ... 7 maritime temperate over sea)");
  }
  const int variability = static_cast<int>(p.variability);
  if (variability < 0 || variability > 3) bad("variability mode " + std::to_string(variability) + ": must be within 0..3");
  if (p.polarization != ItmPolarization::kHorizontal && p.polarization != ItmPolarization::kVertical) {
    bad("polarization: must be horizontal or vertical");
  }
  fraction("time", p.time);
  fraction("location", p.location);
  fraction("situation", p.situation);
}

std::string itm_climate_name(ItmClimate climate) {
  switch (climate) {
    case ItmClimate::kEquatorial: return "equatorial";
    case ItmClimate::kContinentalSubtropical: return "continental subtropical";
    case ItmClimate::kMaritimeSubtropical: return "maritime subtropical";
    case ItmClimate::kDesert: return "desert";
    case ItmClimate::kContinentalTemperate: return "continental temperate";
    case ItmClimate::kMaritimeTemperateOverLand: return "maritime temperate over land";
    case ItmClimate::kMaritimeTemperateOverSea: return "maritime temperate over sea";
  }
  return "unknown";
}

ItmPath::ItmPath(double frequency_mhz, const ItmParameters& parameters)
    : frequency_mhz_(frequency_mhz), p_(parameters) {
  check_itm(frequency_mhz, parameters);
  wn_ = frequency_mhz / 47.7;
  const Complex eps(parameters.permittivity, kZ0 * parameters.conductivity / wn_);
  Complex zg = std::sqrt(eps - 1.0);
  if (parameters.polarization == ItmPolarization::kVertical) zg /= eps;
  zg_re_ = zg.real();
  zg_im_ = zg.imag();
  inverse_abs_zg_ = 1.0 / std::abs(zg);
  const Climate& climate = kClimates[static_cast<int>(parameters.climate) - 1];
  const double ln_k = std::log(0.133 * wn_);
  g_minus_ = climate.g_minus(ln_k);
  g_plus_ = climate.g_plus(ln_k);
  dexa_frequency_m_ = std::cbrt(575.7e12 / wn_);
  // Terms of the frequency and the ground alone, for every path.
  free_space_frequency_db_ = 32.45 + 20.0 * std::log10(frequency_mhz);
  ln_inverse_abs_zg_ = std::log(inverse_abs_zg_);
  ln_scatter_wn_ = std::log(47.7 * wn_);
  z_time_ = itm_functions::inverse_normal(parameters.time);
  z_location_ = itm_functions::inverse_normal(parameters.location);
  z_situation_ = itm_functions::inverse_normal(parameters.situation);
}

void ItmPath::set_profile(std::span<const double> ground_m, double spacing_m, double tx_height_m) {
  if (ground_m.size() < 2) throw std::invalid_argument("ITM profile: needs at least 2 samples");
  if (!(spacing_m > 0.0) || !std::isfinite(spacing_m)) throw std::invalid_argument("ITM profile spacing " + num(spacing_m) + ": must be > 0");
  if (!std::isfinite(tx_height_m)) throw std::invalid_argument("ITM transmitter height: not finite");
  n_ = static_cast<int>(ground_m.size()) - 1;
  xi_ = spacing_m;
  dist_ = n_ * xi_;
  hg_tx_ = tx_height_m;
  z_.assign(ground_m.begin(), ground_m.end());
  const auto size = static_cast<std::size_t>(n_) + 2;
  sum_z_.resize(size);
  sum_iz_.resize(size);
  sum_z_[0] = sum_iz_[0] = 0.0;
  double sum = 0.0, sum_i = 0.0;  // running, so that no sum waits on a store and a load
  for (int i = 0; i <= n_; ++i) {
    const double z = z_[static_cast<std::size_t>(i)];
    if (!std::isfinite(z)) throw std::invalid_argument("ITM profile: sample " + std::to_string(i) + " is not finite");
    sum += z;
    sum_i += i * z;
    sum_z_[static_cast<std::size_t>(i) + 1] = sum;
    sum_iz_[static_cast<std::size_t>(i) + 1] = sum_i;
  }
  // N_s and gamma_e from the mean elevation of the middle 80% of the profile.
  const int p10 = static_cast<int>(0.1 * n_);
  const double zs = (sum_z_[static_cast<std::size_t>(n_ - p10 + 1)] - sum_z_[static_cast<std::size_t>(p10)]) /
                    (n_ - 2 * p10 + 1);
  ns_ = p_.refractivity * std::exp(-zs / 9460.0);
  free_space_path_db_ = free_space_frequency_db_ + 20.0 * std::log10(dist_ / 1000.0);
  gme_ = kGammaA * (1.0 - 0.04665 * std::exp(ns_ / 179.3));

  // Horizon terms: elevation angles on the Earth of curvature gamma_e (heights relative to the
  // terminal, less the drop qc s^2 of the curved Earth, over the distance s). 1 / s from a
  // table of 1 / i (kept between profiles), without a division per sample.
  const double qc = 0.5 * gme_;
  const double za = z_[0] + hg_tx_;
  const auto samples = static_cast<std::size_t>(n_) + 1;
  for (std::size_t i = std::max<std::size_t>(inverse_.size(), 1); i < samples; ++i) {
    if (inverse_.empty()) inverse_.push_back(0.0);
    inverse_.push_back(1.0 / static_cast<double>(i));
  }
  rx_a_.resize(samples);
  rx_u_.resize(samples);
  tx_angle_.resize(samples);
  const double inverse_xi = 1.0 / xi_;
  for (int i = 1; i < n_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double z = z_[k];
    const double s = i * xi_, sb = dist_ - s;
    const double inverse_sb = inverse_xi * inverse_[static_cast<std::size_t>(n_ - i)];
    tx_angle_[k] = (z - za) * (inverse_xi * inverse_[k]) - qc * s;
    rx_a_[k] = z * inverse_sb - qc * sb;
    rx_u_[k] = inverse_sb;
  }
  tx_best_angle_ = -std::numeric_limits<double>::infinity();
  tx_best_distance_ = dist_;
  for (int i = 1; i < n_; ++i) {
    if (tx_angle_[static_cast<std::size_t>(i)] > tx_best_angle_) {
      tx_best_angle_ = tx_angle_[static_cast<std::size_t>(i)];
      tx_best_distance_ = i * xi_;
    }
  }
  dh_x1_ = dh_x2_ = -1.0;
  if (std::isfinite(dh_first_guess_.lower)) dh_scratch_.guess = dh_first_guess_;
  dh_first_ = true;
  rx_hull_built_ = false;
  xae_ = std::cbrt(1.0 / (wn_ * gme_ * gme_));
}

int ItmPath::receiver_horizon(double zb) {
  // The elevation angle of sample i seen from the receiver at height zb is the line
  // a_i - u_i zb, u_i = 1 / (distance to it) growing with i; the steepest sample is the upper
  // envelope of these lines at zb, which moves to smaller i as zb grows. The envelope is built
  // once per profile (in order of increasing slope -u_i), and successive heights walk along
  // it.
  if (!rx_hull_built_) {
    rx_hull_.clear();
    for (int i = n_ - 1; i >= 1; --i) {
      const double a3 = rx_a_[static_cast<std::size_t>(i)], u3 = rx_u_[static_cast<std::size_t>(i)];
      while (rx_hull_.size() >= 2) {
        const auto l1 = static_cast<std::size_t>(rx_hull_[rx_hull_.size() - 2]);
        const auto l2 = static_cast<std::size_t>(rx_hull_.back());
        // l2 is never above both neighbours when l1 and l3 cross at or before l1 and l2 do.
        if ((rx_a_[l1] - a3) * (rx_u_[l1] - rx_u_[l2]) <= (rx_a_[l1] - rx_a_[l2]) * (rx_u_[l1] - u3)) {
          rx_hull_.pop_back();
        } else {
          break;
        }
      }
      rx_hull_.push_back(i);
    }
    rx_hull_built_ = true;
    rx_hull_at_ = 0;
    rx_hull_last_zb_ = -std::numeric_limits<double>::infinity();
  }
  if (zb < rx_hull_last_zb_) rx_hull_at_ = 0;
  rx_hull_last_zb_ = zb;
  auto value = [&](std::size_t h) {
    const auto i = static_cast<std::size_t>(rx_hull_[h]);
    return rx_a_[i] - zb * rx_u_[i];
  };
  while (rx_hull_at_ + 1 < rx_hull_.size() && value(rx_hull_at_ + 1) >= value(rx_hull_at_)) ++rx_hull_at_;
  return rx_hull_[rx_hull_at_];
}

double ItmPath::delta_h(double x1, double x2) {
  if (x1 != dh_x1_ || x2 != dh_x2_) {
    dh_x1_ = x1;
    dh_x2_ = x2;
    dh_value_ = delta_h_of(z_.data(), n_, xi_, x1, x2, dh_scratch_);
    if (dh_first_) dh_first_guess_ = dh_scratch_.guess;
    dh_first_ = false;
  }
  return dh_value_;
}

void ItmPath::geometry(double rx_height_m, itm_kernel::Lanes& lanes, int lane) {
  const auto k = static_cast<std::size_t>(lane);
  const double za = z_[0] + hg_tx_, zb = z_[static_cast<std::size_t>(n_)] + rx_height_m;
  const double qc = 0.5 * gme_;

  // The horizons: the other terminal, unless a sample rises above the line between them (then
  // each terminal's steepest sample; the first of equals from the transmitter).
  const double chord = (zb - za) / dist_;
  double the[2] = {chord - qc * dist_, -chord - qc * dist_};
  double dl[2] = {dist_, dist_};
  if (tx_best_angle_ > the[0]) {
    the[0] = tx_best_angle_;
    dl[0] = tx_best_distance_;
    const int i = receiver_horizon(zb);
    const double angle = rx_a_[static_cast<std::size_t>(i)] - zb * rx_u_[static_cast<std::size_t>(i)];
    if (angle > the[1]) {
      the[1] = angle;
      dl[1] = dist_ - i * xi_;
    }
  }

  // Terrain irregularity between the foregrounds, then the effective heights (of a
  // line-of-sight path before the kernel re-derives its horizons from them).
  const double xl0 = std::min(15.0 * hg_tx_, 0.1 * dl[0]);
  const double xl1 = dist_ - std::min(15.0 * rx_height_m, 0.1 * dl[1]);
  const double dh = delta_h(xl0, xl1);
  auto fit = [&](double x1, double x2) {
    int ja = 0, jb = 0;
    fit_window(x1, x2, xi_, n_, ja, jb);
    const auto a = static_cast<std::size_t>(ja), b = static_cast<std::size_t>(jb);
    return trapezoid_fit(sum_z_[b + 1] - sum_z_[a], sum_iz_[b + 1] - sum_iz_[a], z_[a], z_[b], ja, jb);
  };
  const double z_first = z_[0], z_last = z_[static_cast<std::size_t>(n_)];
  const bool los_geometry = dl[0] + dl[1] > 1.5 * dist_;
  if (los_geometry) {
    const Line line = fit(xl0, xl1);
    lanes.he[0][k] = hg_tx_ + std::max(z_first - line.at(0), 0.0);
    lanes.he[1][k] = rx_height_m + std::max(z_last - line.at(n_), 0.0);
  } else {
    lanes.he[0][k] = hg_tx_ + std::max(z_first - fit(xl0, 0.9 * dl[0]).at(0), 0.0);
    lanes.he[1][k] = rx_height_m + std::max(z_last - fit(dist_ - 0.9 * dl[1], xl1).at(n_), 0.0);
  }
  lanes.hg_rx[k] = rx_height_m;
  lanes.dh[k] = dh;
  lanes.los_geometry[k] = los_geometry ? 1.0 : 0.0;
  for (int j = 0; j < 2; ++j) {
    lanes.dl[j][k] = dl[j];
    lanes.the[j][k] = the[j];
  }
}

void ItmPath::kernel_path(itm_kernel::Path& k) const {
  k.wn = wn_;
  k.ens = ns_;
  k.gme = gme_;
  k.xae = xae_;
  k.zg_re = zg_re_;
  k.zg_im = zg_im_;
  k.inverse_abs_zg = inverse_abs_zg_;
  k.ln_inverse_abs_zg = ln_inverse_abs_zg_;
  k.dist = dist_;
  k.ln_dist = std::log(dist_);
  k.hg_tx = hg_tx_;
  k.free_space_db = free_space_path_db_;
  k.decay_d4 = std::exp(-2.7574 * xae_ / 50e3);
  k.decay_dist = std::exp(-dist_ / 50e3);
  k.scatter_offset = 0.3 * xae_ * ln_scatter_wn_;
  // The warnings of the frequency, the medium, the transmitter and the path length (the
  // Algorithm's range checks less the receiver's).
  double w = 0.0;
  if (wn_ < 0.838 || wn_ > 210.0 || hg_tx_ < 1.0 || hg_tx_ > 1000.0 || dist_ > 1000e3) w = 1.0;
  if (std::abs(z_time_) > 3.1 || std::abs(z_location_) > 3.1 || std::abs(z_situation_) > 3.1) w = 1.0;
  if (ns_ < 250.0 || ns_ > 400.0 || gme_ < 75e-9 || gme_ > 250e-9 || zg_re_ <= std::abs(zg_im_) || wn_ < 0.419 ||
      wn_ > 420.0 || hg_tx_ < 0.5 || hg_tx_ > 3000.0 || dist_ < 1e3 || dist_ > 2000e3) {
    w = 4.0;
  }
  k.base_warning = w;
  const Climate& c = kClimates[static_cast<int>(p_.climate) - 1];
  const Curve* curves[3] = {&c.median, &c.sigma_minus, &c.sigma_plus};
  double* out[3] = {k.median, k.sigma_minus, k.sigma_plus};
  for (int i = 0; i < 3; ++i) {
    const double values[5] = {curves[i]->c1, curves[i]->c2, curves[i]->x1, curves[i]->x2, curves[i]->x3};
    std::copy(values, values + 5, out[i]);
  }
  k.sd = c.sd;
  k.zd = c.zd;
  k.g_minus = g_minus_;
  k.g_plus = g_plus_;
  k.dexa_frequency = dexa_frequency_m_;
  // MDVAR's choices of deviates: single message takes the situation's for all three,
  // accidental the situation's for locations, mobile the time's for locations.
  k.zt = z_time_;
  k.zl = z_location_;
  k.zc = z_situation_;
  switch (p_.variability) {
    case ItmVariability::kSingleMessage: k.zt = k.zl = k.zc; break;
    case ItmVariability::kAccidental: k.zl = k.zc; break;
    case ItmVariability::kMobile: k.zl = k.zt; break;
    case ItmVariability::kBroadcast: break;
  }
  k.variability = static_cast<int>(p_.variability);
  k.location_variability = p_.location_variability;
  k.situation_variability = p_.situation_variability;
}

ItmLoss ItmPath::loss(double rx_height_m) {
  itm_kernel::Path path;
  kernel_path(path);
  itm_kernel::Lanes lanes;
  for (int k = 0; k < itm_kernel::kLanes; ++k) geometry(rx_height_m, lanes, k);
  evaluate(path, lanes);
  ItmLoss out;
  out.loss_db = lanes.loss_db[0];
  out.free_space_db = free_space_path_db_;
  out.attenuation_db = lanes.attenuation_db[0];
  out.reference_db = lanes.reference_db[0];
  out.mode = static_cast<ItmMode>(static_cast<int>(lanes.mode[0]));
  out.warning = static_cast<int>(lanes.warning[0]);
  out.surface_refractivity = ns_;
  out.earth_curvature = gme_;
  out.delta_h_m = lanes.dh[0];
  for (int j = 0; j < 2; ++j) {
    out.effective_height_m[j] = lanes.he[j][0];
    out.horizon_distance_m[j] = lanes.dl[j][0];
    out.horizon_angle_rad[j] = lanes.the[j][0];
  }
  return out;
}

std::size_t ItmPath::losses(std::span<const double> rx_heights_m, std::span<double> out) {
  if (out.size() != rx_heights_m.size()) throw std::invalid_argument("ItmPath::losses: as many outputs as heights");
  itm_kernel::Path path;
  kernel_path(path);
  itm_kernel::Lanes lanes;
  std::size_t warned = 0;
  constexpr auto kLanes = static_cast<std::size_t>(itm_kernel::kLanes);
  for (std::size_t first = 0; first < rx_heights_m.size(); first += kLanes) {
    const std::size_t count = std::min(kLanes, rx_heights_m.size() - first);
    // A last, partial group repeats its last height in the spare lanes.
    for (std::size_t k = 0; k < kLanes; ++k) geometry(rx_heights_m[first + std::min(k, count - 1)], lanes, static_cast<int>(k));
    evaluate(path, lanes);
    for (std::size_t k = 0; k < count; ++k) {
      out[first + k] = lanes.loss_db[k];
      if (lanes.warning[k] >= 3.0) ++warned;
    }
  }
  return warned;
}

ItmLoss itm_point_to_point(std::span<const double> ground_m, double spacing_m, double tx_height_m, double rx_height_m,
                           double frequency_mhz, const ItmParameters& parameters) {
  ItmPath path(frequency_mhz, parameters);
  path.set_profile(ground_m, spacing_m, tx_height_m);
  return path.loss(rx_height_m);
}

namespace itm_functions {

// The kernel's functions on one value (in every lane; the first lane's result).
double knife_edge_db(double v2) { return kernel::knife_edge(kernel::splat(v2))[0]; }

double height_gain_db(double x, double k) {
  const kernel::V xv = kernel::splat(x), kv = kernel::splat(k);
  return kernel::height_gain(xv, kv, kernel::vlog(xv), kernel::vlog(kv))[0];
}

double frequency_gain_db(double r, double eta) { return kernel::frequency_gain(kernel::splat(r), kernel::splat(eta))[0]; }

double scatter_f_db(double theta_d) { return kernel::scatter_function(kernel::splat(theta_d))[0]; }


double inverse_normal(double q) {
  // Hastings' rational approximation (Abramowitz and Stegun 26.2.23), |error| < 4.5e-4.
  constexpr double c0 = 2.515516698, c1 = 0.802853, c2 = 0.010328;
  constexpr double d1 = 1.432788, d2 = 0.189269, d3 = 0.001308;
  const double x = 0.5 - q;
  double t = std::max(0.5 - std::abs(x), 0.000001);
  t = std::sqrt(-2.0 * std::log(t));
  const double v = t - ((c2 * t + c1) * t + c0) / (((d3 * t + d2) * t + d1) * t + 1.0);
  return x < 0.0 ? -v : v;
}

double delta_h(std::span<const double> ground_m, double spacing_m, double x1_m, double x2_m) {
  if (ground_m.size() < 2 || !(spacing_m > 0.0)) throw std::invalid_argument("delta_h: needs 2 samples and a spacing > 0");
  DeltaHScratch scratch;
  return delta_h_of(ground_m.data(), static_cast<int>(ground_m.size()) - 1, spacing_m, x1_m, x2_m, scratch);
}

}  // namespace itm_functions

}  // namespace terravol::volume
