// The ITM point-to-point model: NTIA's published cases, the auxiliary functions against values
// worked out by hand from the Algorithm's equations, and seeded properties over random profiles.
#include "volume/itm.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "volume/itm_reference.h"

namespace terravol::volume {
namespace {

struct PublishedCase {
  double h_tx = 0, h_rx = 0, eps = 0, sigma = 0, n0 = 0, f = 0;
  int pol = 0, climate = 0;
  double time = 0, location = 0, situation = 0;
  int mdvar = 0;
  double loss_db = 0;
  std::vector<double> profile;  // the samples
  double spacing = 0;
};

std::vector<double> numbers(const std::string& line) {
  std::vector<double> v;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ',')) v.push_back(std::stod(field));
  return v;
}

std::vector<PublishedCase> published_cases() {
  std::ifstream in(std::string(TERRAVOL_SOURCE_DIR) + "/tests/volume/data/ntia_itm_p2p.txt");
  if (!in) throw std::runtime_error("cannot read tests/volume/data/ntia_itm_p2p.txt");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != '#') lines.push_back(line);
  }
  std::vector<PublishedCase> cases;
  for (std::size_t n = 0; n + 1 < lines.size(); n += 2) {
    const auto p = numbers(lines[n]);
    const auto z = numbers(lines[n + 1]);
    PublishedCase c;
    c.h_tx = p.at(0);
    c.h_rx = p.at(1);
    c.eps = p.at(2);
    c.sigma = p.at(3);
    c.n0 = p.at(4);
    c.f = p.at(5);
    c.pol = static_cast<int>(p.at(6));
    c.climate = static_cast<int>(p.at(7));
    c.time = p.at(8) / 100.0;
    c.location = p.at(9) / 100.0;
    c.situation = p.at(10) / 100.0;
    c.mdvar = static_cast<int>(p.at(11));
    c.loss_db = p.at(12);
    c.spacing = z.at(1);
    c.profile.assign(z.begin() + 2, z.end());
    EXPECT_EQ(c.profile.size(), static_cast<std::size_t>(z.at(0)) + 1);
    cases.push_back(c);
  }
  return cases;
}

ItmParameters parameters_of(const PublishedCase& c) {
  ItmParameters p;
  p.polarization = c.pol == 1 ? ItmPolarization::kVertical : ItmPolarization::kHorizontal;
  p.permittivity = c.eps;
  p.conductivity = c.sigma;
  p.refractivity = c.n0;
  p.climate = static_cast<ItmClimate>(c.climate);
  p.time = c.time;
  p.location = c.location;
  p.situation = c.situation;
  p.variability = static_cast<ItmVariability>(c.mdvar % 10);
  p.location_variability = (c.mdvar % 20) < 10;
  p.situation_variability = c.mdvar < 20;
  return p;
}

TEST(Itm, MatchesNtiaPublishedPointToPointCases) {
  const auto cases = published_cases();
  ASSERT_EQ(cases.size(), 5u);
  for (const auto& c : cases) {
    SCOPED_TRACE(std::to_string(c.f) + " MHz, " + std::to_string(c.profile.size()) + " samples");
    const ItmParameters p = parameters_of(c);
    EXPECT_EQ(p.mdvar(), c.mdvar);
    const ItmLoss r = itm_point_to_point(c.profile, c.spacing, c.h_tx, c.h_rx, c.f, p);
    // NTIA prints two decimals (one for the command-line example, 114.5).
    EXPECT_NEAR(r.loss_db, c.loss_db, c.f == 3500.0 ? 0.05 : 0.0051);
  }
}

TEST(Itm, NtiaCommandLineExampleIntermediateValues) {
  const PublishedCase c = published_cases().back();  // cmd_examples/o_p2pcr.txt
  ASSERT_EQ(c.f, 3500.0);
  const ItmLoss r = itm_point_to_point(c.profile, c.spacing, c.h_tx, c.h_rx, c.f, parameters_of(c));
  EXPECT_NEAR(r.free_space_db, 114.5, 0.05);
  EXPECT_NEAR(r.loss_db, 114.5, 0.05);
  EXPECT_NEAR(c.spacing * (c.profile.size() - 1) / 1000.0, 3.635, 0.001);
  EXPECT_NEAR(r.surface_refractivity, 251.5, 0.05);
  EXPECT_NEAR(r.delta_h_m, 3.2, 0.05);
  EXPECT_NEAR(r.effective_height_m[0], 15.0, 0.05);
  EXPECT_NEAR(r.effective_height_m[1], 3.0, 0.05);
  EXPECT_NEAR(r.horizon_distance_m[0], 14868.0, 0.5);
  EXPECT_NEAR(r.horizon_distance_m[1], 6494.0, 0.5);
  EXPECT_NEAR(r.horizon_angle_rad[0] * 1000.0, -1.949, 0.0005);
  EXPECT_NEAR(r.horizon_angle_rad[1] * 1000.0, -0.856, 0.0005);
  EXPECT_NEAR(r.reference_db, 0.0, 0.05);
  EXPECT_EQ(r.mode, ItmMode::kLineOfSight);
  EXPECT_EQ(r.warning, 0);
}

TEST(Itm, EffectiveEarthFromSurfaceRefractivity) {
  // NTIA's QKPFL test prints K = 1.368 for N_s = 314: gamma_a / gamma_e =
  // 1 / (1 - 0.04665 exp(314 / 179.3)).
  ItmParameters p;
  p.refractivity = 314.0;
  const std::vector<double> sea(101, 0.0);
  const ItmLoss r = itm_point_to_point(sea, 100.0, 30.0, 10.0, 100.0, p);
  EXPECT_NEAR(r.surface_refractivity, 314.0, 1e-12);
  EXPECT_NEAR(157e-9 / r.earth_curvature, 1.368, 0.0005);
  // Over ground 1000 m up, N_s = 301 exp(-1000 / 9460) = 270.806 and k = 1.2678.
  p.refractivity = 301.0;
  const std::vector<double> plateau(101, 1000.0);
  const ItmLoss up = itm_point_to_point(plateau, 100.0, 30.0, 10.0, 100.0, p);
  EXPECT_NEAR(up.surface_refractivity, 270.806, 0.001);
  EXPECT_NEAR(157e-9 / up.earth_curvature, 1.2678, 0.0001);
}

// The straightforward evaluation the fast path is checked against (volume/itm_reference.h)
// gives NTIA's published losses too.
TEST(ItmReference, MatchesNtiaPublishedPointToPointCases) {
  for (const auto& c : published_cases()) {
    SCOPED_TRACE(std::to_string(c.f) + " MHz");
    const reference::ReferenceLoss r = reference::itm_reference(c.profile, c.spacing, c.h_tx, c.h_rx, c.f, parameters_of(c));
    EXPECT_NEAR(r.loss_db, c.loss_db, c.f == 3500.0 ? 0.05 : 0.0051);
  }
}

// ItmPath, which shares the profile's work between the heights of a column (horizons from an
// envelope, prefix sums, Delta h kept and its quantiles guessed) and evaluates the rest of the
// chain four heights at a time with its own exponential and logarithm (itm_kernel.h), against
// the straightforward evaluation of each point on its own: random profiles from flat to
// mountainous, short to troposcatter range, every climate, both polarizations, all four
// variability modes; the heights of a column at once (as terravol rf runs them, on both copies
// of the kernel, and equal to loss() height by height), then one by one in rising and in random
// order.
TEST(ItmFastPath, EqualsTheStraightforwardEvaluationOfEachPoint) {
  std::mt19937 rng(190419);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int points = 0, undefined = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 400; ++trial) {
    const int n = 2 + static_cast<int>(600 * unit(rng) * unit(rng));
    const double spacing = 20.0 + (unit(rng) < 0.1 ? 2000.0 : 150.0) * unit(rng);
    const double relief = 1500.0 * unit(rng) * unit(rng);
    const double base = 2500.0 * unit(rng);
    const double wave = 2.0 + 60.0 * unit(rng);
    const double noise = unit(rng) < 0.3 ? 0.0 : 50.0 * unit(rng);
    std::vector<double> z;
    for (int i = 0; i <= n; ++i) {
      const double v = base + relief * (0.5 + 0.5 * std::sin(i / wave + trial)) + noise * unit(rng);
      z.push_back(unit(rng) < 0.2 ? std::round(v) : v);  // DEMs hold whole metres
    }
    ItmParameters p;
    p.polarization = unit(rng) < 0.5 ? ItmPolarization::kHorizontal : ItmPolarization::kVertical;
    p.permittivity = 4.0 + 76.0 * unit(rng);
    p.conductivity = 0.001 * std::pow(5000.0, unit(rng));
    p.refractivity = 250.0 + 150.0 * unit(rng);
    p.climate = static_cast<ItmClimate>(1 + static_cast<int>(7 * unit(rng)) % 7);
    p.time = 0.01 + 0.98 * unit(rng);
    p.location = 0.01 + 0.98 * unit(rng);
    p.situation = 0.01 + 0.98 * unit(rng);
    p.variability = static_cast<ItmVariability>(static_cast<int>(4 * unit(rng)) % 4);
    p.location_variability = unit(rng) < 0.5;
    p.situation_variability = unit(rng) < 0.8;
    const double f = 20.0 * std::pow(1000.0, unit(rng));
    const double tx = 0.5 + (unit(rng) < 0.5 ? 50.0 : 1000.0) * unit(rng);
    std::vector<double> heights;
    const double first = 0.5 + 20.0 * unit(rng), step = 1.0 + 60.0 * unit(rng);
    for (int k = 0; k < 31; ++k) heights.push_back(first + step * k);
    std::vector<double> shuffled = heights;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    shuffled.insert(shuffled.begin(), heights.begin(), heights.end());
    ItmPath path(f, p);
    path.set_profile(z, spacing, tx);
    // The column at once (as terravol rf runs it) on both copies of the kernel, which agree
    // to the bit.
    std::vector<double> column(heights.size()), baseline(heights.size());
    path.losses(heights, column);
    itm_detail::force_baseline_kernel(true);
    path.losses(heights, baseline);
    itm_detail::force_baseline_kernel(false);
    for (std::size_t k = 0; k < heights.size(); ++k) {
      ASSERT_TRUE(column[k] == baseline[k] || (std::isnan(column[k]) && std::isnan(baseline[k])))
          << "trial " << trial << ": " << column[k] << " (" << itm_detail::kernel_name() << ") against " << baseline[k];
      const ItmLoss one = path.loss(heights[k]);
      ASSERT_TRUE(column[k] == one.loss_db || (std::isnan(column[k]) && std::isnan(one.loss_db))) << "trial " << trial;
    }
    for (const double h : shuffled) {
      const ItmLoss fast = path.loss(h);
      const reference::ReferenceLoss plain = reference::itm_reference(z, spacing, tx, h, f, p);
      ++points;
      if (std::isnan(plain.loss_db)) {
        // The Algorithm itself fails on a few short paths with tall masts at low frequencies
        // (a logarithm of a negative number); then so must the fast path.
        ASSERT_TRUE(std::isnan(fast.loss_db)) << "trial " << trial << ", receiver " << h << " m";
        ++undefined;
        continue;
      }
      ASSERT_NEAR(fast.loss_db, plain.loss_db, 1e-6) << "trial " << trial << ", " << n << " samples of " << spacing << " m, "
                                                     << f << " MHz, antennas " << tx << " m and " << h << " m";
      ASSERT_EQ(fast.warning, plain.warning) << "trial " << trial << ", receiver " << h << " m";
      worst = std::max(worst, std::abs(fast.loss_db - plain.loss_db));
    }
  }
  EXPECT_EQ(points, 400 * 62);
  EXPECT_LT(undefined, points / 100);
  std::printf("largest difference %.3g dB over %d points (%d undefined in both)\n", worst, points, undefined);
}

// The kernel's own functions (itm_kernel.h) against the C library's: within a few units in the
// last place over the ranges the model uses and beyond, and the special values.
TEST(ItmFunctions, KernelMathAgreesWithTheCLibrary) {
  using itm_detail::kernel_cbrt;
  using itm_detail::kernel_exp;
  using itm_detail::kernel_log;
  std::mt19937 rng(1995);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  constexpr double kUlp = 2.220446049250313e-16;
  double worst_exp = 0.0, worst_log = 0.0, worst_cbrt = 0.0, worst_trig = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double x = -708.0 + 1417.0 * unit(rng);
    const double e = std::exp(x);
    worst_exp = std::max(worst_exp, std::abs(kernel_exp(x) - e) / e);
    const double small = (unit(rng) - 0.5) * 2.0;  // near 0, where ITM's arguments mostly are
    worst_exp = std::max(worst_exp, std::abs(kernel_exp(small) - std::exp(small)) / std::exp(small));
    const double y = std::exp(-745.0 + 1454.0 * unit(rng));  // subnormal to 1e308
    worst_log = std::max(worst_log, std::abs(kernel_log(y) - std::log(y)) / std::max(1.0, std::abs(std::log(y))));
    const double near_one = 1.0 + (unit(rng) - 0.5) * 1e-3;
    worst_log = std::max(worst_log, std::abs(kernel_log(near_one) - std::log(near_one)));
    const double c = std::exp(-100.0 + 200.0 * unit(rng));
    worst_cbrt = std::max(worst_cbrt, std::abs(kernel_cbrt(c) - std::cbrt(c)) / std::cbrt(c));
    const double a = M_PI * unit(rng);
    double s = 0.0, co = 0.0;
    itm_detail::kernel_sincos(a, s, co);
    worst_trig = std::max({worst_trig, std::abs(s - std::sin(a)), std::abs(co - std::cos(a))});
  }
  EXPECT_LT(worst_exp, 4.0 * kUlp);
  EXPECT_LT(worst_log, 4.0 * kUlp);
  EXPECT_LT(worst_cbrt, 40.0 * kUlp);  // through ln and exp of a third of it (ln x up to 230)
  EXPECT_LT(worst_trig, 4.0 * kUlp);
  std::printf("largest errors: exp %.2g, log %.2g, cbrt %.2g, sin/cos %.2g (units in the last place: %.2g)\n", worst_exp,
              worst_log, worst_cbrt, worst_trig, kUlp);
  EXPECT_EQ(kernel_exp(0.0), 1.0);
  EXPECT_EQ(kernel_exp(-1000.0), 0.0);
  EXPECT_EQ(kernel_exp(1000.0), INFINITY);
  EXPECT_TRUE(std::isnan(kernel_exp(std::nan(""))));
  EXPECT_EQ(kernel_log(1.0), 0.0);
  EXPECT_EQ(kernel_log(0.0), -INFINITY);
  EXPECT_EQ(kernel_log(INFINITY), INFINITY);
  EXPECT_TRUE(std::isnan(kernel_log(-1.0)));
  EXPECT_TRUE(std::isnan(kernel_log(std::nan(""))));
}

TEST(ItmFunctions, KnifeEdgeIsAboutSixDbAtGrazingAndContinuous) {
  EXPECT_NEAR(itm_functions::knife_edge_db(0.0), 6.02, 1e-12);
  // The two branches meet at v = 2.4: 6.02 + 9.11 * 2.4 - 1.27 * 5.76 = 20.569 and
  // 12.953 + 4.343 ln 5.76 = 20.557.
  EXPECT_NEAR(itm_functions::knife_edge_db(5.76 - 1e-9), 20.569, 0.001);
  EXPECT_NEAR(itm_functions::knife_edge_db(5.76), 20.557, 0.001);
  EXPECT_NEAR(itm_functions::knife_edge_db(100.0), 12.953 + 20.0, 0.001);  // 4.343 ln 100 = 20.0
}

TEST(ItmFunctions, InverseNormalQuantiles) {
  EXPECT_NEAR(itm_functions::inverse_normal(0.5), 0.0, 1e-8);  // the approximation's own error
  EXPECT_NEAR(itm_functions::inverse_normal(0.1), 1.28155, 5e-4);
  EXPECT_NEAR(itm_functions::inverse_normal(0.9), -1.28155, 5e-4);
  EXPECT_NEAR(itm_functions::inverse_normal(0.01), 2.32635, 5e-4);
  EXPECT_NEAR(itm_functions::inverse_normal(0.0228), 2.0, 5e-3);
}

TEST(ItmFunctions, FrequencyGainAndScatterFunctionBranches) {
  // H_0 for eta_s = 1 and r = 1: 4.343 ln(25 + 24 + 1) = 16.99; halfway to eta_s = 2 it is
  // the mean of that and 4.343 ln(80 + 45 + 1) = 21.00.
  EXPECT_NEAR(itm_functions::frequency_gain_db(1.0, 1.0), 16.990, 0.001);
  EXPECT_NEAR(itm_functions::frequency_gain_db(1.0, 1.5), 0.5 * (16.990 + 21.004), 0.001);
  EXPECT_NEAR(itm_functions::frequency_gain_db(1.0, 9.0), 4.343 * std::log(705.0 + 105.0 + 1.0), 1e-9);
  // F(theta d) at 10 km: 133.4 + 3.32 - 4.343 ln 1e4 = 96.72.
  EXPECT_NEAR(itm_functions::scatter_f_db(10e3), 96.72, 0.01);
}

TEST(ItmFunctions, DeltaHIsTheInterdecileRangeAboutTheTrend) {
  // A sine of amplitude 50 m on a slope, over 1000 km: the slope is removed by the line, and
  // the 10% quantiles of a sine are +-A cos(0.1 pi) = +-0.951 A, so Delta h = 1.902 A (the
  // 50 km term is negligible; 245 resampled points leave a few per cent).
  std::vector<double> z;
  for (int i = 0; i <= 1000; ++i) z.push_back(300.0 + 0.02 * i * 1000.0 + 50.0 * std::sin(2.0 * M_PI * i / 37.3));
  EXPECT_NEAR(itm_functions::delta_h(z, 1000.0, 0.0, 1.0e6), 1.902 * 50.0, 0.04 * 95.1);
  // A straight slope has none; a window under two samples has none.
  std::vector<double> slope;
  for (int i = 0; i <= 300; ++i) slope.push_back(100.0 + 3.0 * i);
  EXPECT_NEAR(itm_functions::delta_h(slope, 90.0, 500.0, 20000.0), 0.0, 1e-9);
  EXPECT_EQ(itm_functions::delta_h(z, 1000.0, 5000.0, 6500.0), 0.0);
}

TEST(Itm, RejectsParametersOutsideTheirRanges) {
  const ItmParameters ok;
  EXPECT_NO_THROW(check_itm(20.0, ok));
  EXPECT_NO_THROW(check_itm(20000.0, ok));
  auto message = [](double f, const ItmParameters& p) {
    try {
      check_itm(f, p);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(19.9, ok), "ITM frequency 19.9 MHz: must be within [20, 20000] MHz");
  EXPECT_EQ(message(20001.0, ok), "ITM frequency 20001 MHz: must be within [20, 20000] MHz");
  ItmParameters p = ok;
  p.climate = static_cast<ItmClimate>(8);
  EXPECT_EQ(message(900.0, p).rfind("ITM climate 8: must be within 1..7", 0), 0u);
  p = ok;
  p.permittivity = 0.5;
  EXPECT_EQ(message(900.0, p), "ITM permittivity 0.5: must be within (1, 100]");
  p = ok;
  p.conductivity = -1.0;
  EXPECT_EQ(message(900.0, p), "ITM conductivity -1 S/m: must be within (0, 100] S/m");
  p = ok;
  p.refractivity = 500.0;
  EXPECT_EQ(message(900.0, p), "ITM refractivity 500 N-units: must be within [250, 400] N-units");
  p = ok;
  p.time = 1.0;
  EXPECT_EQ(message(900.0, p), "ITM time fraction 1: must be within (0, 1)");
  p = ok;
  p.situation = std::nan("");
  EXPECT_EQ(message(900.0, p), "ITM situation fraction nan: must be within (0, 1)");
  EXPECT_THROW(ItmPath(5.0, ok), std::invalid_argument);
  ItmPath path(900.0, ok);
  const std::vector<double> one{100.0};
  EXPECT_THROW(path.set_profile(one, 90.0, 30.0), std::invalid_argument);
  const std::vector<double> two{100.0, std::nan("")};
  EXPECT_THROW(path.set_profile(two, 90.0, 30.0), std::invalid_argument);
  EXPECT_THROW(path.set_profile(std::vector<double>{1.0, 2.0}, 0.0, 30.0), std::invalid_argument);
}

TEST(Itm, ManyHeightsOnOnePathEqualSeparateCalls) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> z;
  for (int i = 0; i <= 250; ++i) z.push_back(1500.0 + 400.0 * std::sin(i / 17.0) + 60.0 * unit(rng));
  const ItmParameters p;
  ItmPath path(450.0, p);
  path.set_profile(z, 85.0, 25.0);
  for (double h = 1.0; h < 400.0; h += 13.0) {
    const ItmLoss many = path.loss(h);
    const ItmLoss one = itm_point_to_point(z, 85.0, 25.0, h, 450.0, p);
    ASSERT_EQ(many.loss_db, one.loss_db) << h;
  }
}

// The horizons of a trans-horizon path are the profile's steepest samples from each end, on
// the Earth of curvature gamma_e: checked by brute force over random profiles and receiver
// heights in random order (the path keeps state from one height to the next).
TEST(ItmProperty, HorizonsAreTheSteepestSamples) {
  std::mt19937 rng(31337);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 20 + static_cast<int>(300 * unit(rng));
    const double spacing = 30.0 + 100.0 * unit(rng);
    std::vector<double> z;
    for (int i = 0; i <= n; ++i) z.push_back(500.0 + 300.0 * std::sin(i / (2.0 + 20.0 * unit(rng))) * unit(rng));
    const double tx = 1.0 + 50.0 * unit(rng);
    ItmPath path(300.0 + 3000.0 * unit(rng), ItmParameters{});
    path.set_profile(z, spacing, tx);
    for (int k = 0; k < 20; ++k) {
      const double rx = 1.0 + 300.0 * unit(rng);
      const ItmLoss r = path.loss(rx);
      const double qc = 0.5 * r.earth_curvature, d = n * spacing;
      const double za = z[0] + tx, zb = z[static_cast<std::size_t>(n)] + rx;
      double best0 = (zb - za) / d - qc * d, best1 = (za - zb) / d - qc * d, dl0 = d, dl1 = d;
      for (int i = 1; i < n; ++i) {
        const double s = i * spacing, sb = d - s, zi = z[static_cast<std::size_t>(i)];
        if ((zi - za) / s - qc * s > best0) {
          best0 = (zi - za) / s - qc * s;
          dl0 = s;
        }
        if ((zi - zb) / sb - qc * sb > best1) {
          best1 = (zi - zb) / sb - qc * sb;
          dl1 = sb;
        }
      }
      if (dl0 + dl1 > 1.5 * d) continue;  // line of sight or nearly: the Algorithm re-derives the horizons
      ASSERT_NEAR(r.horizon_distance_m[0], dl0, 1e-6) << trial << " " << k;
      ASSERT_NEAR(r.horizon_distance_m[1], dl1, 1e-6) << trial << " " << k;
      ASSERT_NEAR(r.horizon_angle_rad[1], best1, 1e-12) << trial << " " << k;
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
}

// Random profiles: the model is finite, symmetric in its ends (the Algorithm treats both
// terminals alike), and more variability never lowers the loss quantile beyond the median.
TEST(ItmProperty, FiniteAndSymmetricInItsEnds) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = 1 + static_cast<int>(400 * unit(rng));
    const double spacing = 20.0 + 200.0 * unit(rng);
    const double relief = 1500.0 * unit(rng) * unit(rng);
    const double base = 2000.0 * unit(rng);
    std::vector<double> z;
    const double wave = 3.0 + 40.0 * unit(rng);
    for (int i = 0; i <= n; ++i) z.push_back(base + relief * (0.5 + 0.5 * std::sin(i / wave)) * unit(rng));
    std::vector<double> reversed(z.rbegin(), z.rend());
    const double ha = 0.5 + 300.0 * unit(rng), hb = 0.5 + 300.0 * unit(rng);
    const double f = 20.0 * std::pow(1000.0, unit(rng));
    ItmParameters p;
    p.polarization = unit(rng) < 0.5 ? ItmPolarization::kHorizontal : ItmPolarization::kVertical;
    p.climate = static_cast<ItmClimate>(1 + static_cast<int>(7 * unit(rng)) % 7);
    p.time = 0.05 + 0.9 * unit(rng);
    p.situation = 0.05 + 0.9 * unit(rng);
    const ItmLoss forward = itm_point_to_point(z, spacing, ha, hb, f, p);
    const ItmLoss backward = itm_point_to_point(reversed, spacing, hb, ha, f, p);
    ASSERT_TRUE(std::isfinite(forward.loss_db)) << "trial " << trial;
    ASSERT_NEAR(forward.loss_db, backward.loss_db, 1e-6 * forward.loss_db) << "trial " << trial << " n " << n;
    ASSERT_NEAR(forward.delta_h_m, backward.delta_h_m, 1e-6 * (1.0 + forward.delta_h_m)) << "trial " << trial;
    ASSERT_NEAR(forward.effective_height_m[0], backward.effective_height_m[1], 1e-6 * (1.0 + ha)) << "trial " << trial;
  }
}

// Over smooth flat ground the loss grows with distance, for any antennas and frequency: the
// line-of-sight curve has k_1, k_2 >= 0 and joins the diffraction line at d_Ls.
TEST(ItmProperty, LossGrowsWithDistanceOverFlatGround) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int paths = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const double spacing = 30.0 + 70.0 * unit(rng);
    const double ground = 1000.0 * unit(rng);
    const double ha = 1.0 + 200.0 * unit(rng), hb = 1.0 + 50.0 * unit(rng);
    const double f = 20.0 * std::pow(1000.0, unit(rng));
    ItmParameters p;
    p.time = 0.1 + 0.8 * unit(rng);
    ItmPath path(f, p);
    double previous = 0.0;
    const int n_max = static_cast<int>(80000.0 / spacing);
    for (int n = static_cast<int>(1000.0 / spacing) + 1; n <= n_max; n += 1 + n / 20) {
      const std::vector<double> z(static_cast<std::size_t>(n) + 1, ground);
      path.set_profile(z, spacing, ha);
      const double loss = path.loss(hb).loss_db;
      ASSERT_GT(loss, previous) << "trial " << trial << ": " << n * spacing << " m, " << f << " MHz, " << ha << " m / " << hb << " m";
      previous = loss;
      ++paths;
    }
  }
  EXPECT_GT(paths, 50000);
}

}  // namespace
}  // namespace terravol::volume
