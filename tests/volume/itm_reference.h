// A straightforward ITM point-to-point evaluation, one path and one receiver height at a time,
// to check the fast path (volume/itm.h: ItmPath, which shares work between the heights of a
// column) against. Written from the same sources as itm.cpp (G. A. Hufford, "The ITS Irregular
// Terrain Model, version 1.2.2: the Algorithm", NTIA/ITS 1995; NTIA Report 82-100 for the
// climate curves) but on its own: it follows the Algorithm's order of work step by step -- the
// horizons by the Algorithm's running search over the samples, Delta h from a fresh
// resampling sorted in full, every least-squares line summed directly over its samples, the
// C library's functions throughout, nothing kept from one call to the next -- and shares no
// code with itm.cpp. It keeps the one rule itm.cpp adds to the Algorithm: positions and counts
// within 1e-9 of a whole number are that number before they are rounded down (so that a
// window end exactly on a sample is on it in both).
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <span>
#include <vector>

#include "volume/itm.h"

namespace terravol::volume::reference {

struct ReferenceLoss {
  double loss_db = 0.0;
  int warning = 0;
};

namespace detail {

inline double whole(double x) {
  const double r = std::round(x);
  return std::abs(x - r) < 1e-9 * std::max(1.0, std::abs(x)) ? r : x;
}

// The climate curves of NTIA Report 82-100 by climate 1..7, as the report tabulates them.
struct ClimateTable {
  double bv1[7] = {-9.67, -0.62, 1.26, -9.21, -0.62, -0.39, 3.15};
  double bv2[7] = {12.7, 9.19, 15.5, 9.05, 9.19, 2.86, 857.9};
  double xv1[7] = {144.9e3, 228.9e3, 262.6e3, 84.1e3, 228.9e3, 141.7e3, 2222.e3};
  double xv2[7] = {190.3e3, 205.2e3, 185.2e3, 101.1e3, 205.2e3, 315.9e3, 164.8e3};
  double xv3[7] = {133.8e3, 143.6e3, 99.8e3, 98.6e3, 143.6e3, 167.4e3, 116.3e3};
  double bsm1[7] = {2.13, 2.66, 6.11, 1.98, 2.68, 6.86, 8.51};
  double bsm2[7] = {159.5, 7.67, 6.65, 13.11, 7.16, 10.38, 169.8};
  double xsm1[7] = {762.2e3, 100.4e3, 138.2e3, 139.1e3, 93.7e3, 187.8e3, 609.8e3};
  double xsm2[7] = {123.6e3, 172.5e3, 242.2e3, 132.7e3, 186.8e3, 169.6e3, 119.9e3};
  double xsm3[7] = {94.5e3, 136.4e3, 178.6e3, 193.5e3, 133.5e3, 108.9e3, 106.6e3};
  double bsp1[7] = {2.11, 6.87, 10.08, 3.68, 4.75, 8.58, 8.43};
  double bsp2[7] = {102.3, 15.53, 9.60, 159.3, 8.12, 13.97, 8.19};
  double xsp1[7] = {636.9e3, 138.7e3, 165.3e3, 464.4e3, 93.2e3, 216.0e3, 136.2e3};
  double xsp2[7] = {134.8e3, 143.7e3, 225.7e3, 93.1e3, 135.9e3, 152.0e3, 188.5e3};
  double xsp3[7] = {95.6e3, 98.6e3, 129.7e3, 94.2e3, 113.4e3, 122.7e3, 122.9e3};
  double bsd1[7] = {1.224, 0.801, 1.380, 1.000, 1.224, 1.518, 1.518};
  double bzd1[7] = {1.282, 2.161, 1.282, 20., 1.282, 1.282, 1.282};
  double bfm1[7] = {1.0, 1.0, 1.0, 1.0, 0.92, 1.0, 1.0};
  double bfm2[7] = {0.0, 0.0, 0.0, 0.0, 0.25, 0.0, 0.0};
  double bfm3[7] = {0.0, 0.0, 0.0, 0.0, 1.77, 0.0, 0.0};
  double bfp1[7] = {1.0, 0.93, 1.0, 0.93, 0.93, 1.0, 1.0};
  double bfp2[7] = {0.0, 0.31, 0.0, 0.19, 0.31, 0.0, 0.0};
  double bfp3[7] = {0.0, 2.00, 0.0, 1.79, 2.00, 0.0, 0.0};
};

inline double curve(double c1, double c2, double x1, double x2, double x3, double de) {
  const double a = (de - x2) / x3, b = de / x1;
  return (c1 + c2 / (1.0 + a * a)) * (b * b) / (1.0 + b * b);
}

// Hastings' inverse of the complementary normal distribution (Abramowitz and Stegun 26.2.23).
inline double qerfi(double q) {
  const double x = 0.5 - q;
  double t = std::max(0.5 - std::abs(x), 0.000001);
  t = std::sqrt(-2.0 * std::log(t));
  const double v = t - ((0.010328 * t + 0.802853) * t + 2.515516698) / (((0.001308 * t + 0.189269) * t + 1.432788) * t + 1.0);
  return x < 0.0 ? -v : v;
}

// The line fitted to the samples from x1 to x2 (metres), trapezoidal weights: its heights at
// the profile's first and last samples.
inline void fit_line(const std::vector<double>& z, double xi, double x1, double x2, double& z0, double& zn) {
  const int np = static_cast<int>(z.size()) - 1;
  const double xn = np;
  double xa = std::floor(std::max(whole(x1 / xi), 0.0));
  double xb = xn - std::floor(std::max(xn - whole(x2 / xi), 0.0));
  if (xb <= xa) {
    xa = std::max(xa - 1.0, 0.0);
    xb = xn - std::max(xn - (xb + 1.0), 0.0);
  }
  const int ja = static_cast<int>(xa), jb = static_cast<int>(xb);
  const double centre = 0.5 * (ja + jb), length = jb - ja;
  double s0 = 0.0, s1 = 0.0;
  for (int i = ja; i <= jb; ++i) {
    const double w = (i == ja || i == jb) ? 0.5 : 1.0;
    s0 += w * z[static_cast<std::size_t>(i)];
    s1 += w * z[static_cast<std::size_t>(i)] * (i - centre);
  }
  const double mean = s0 / length, slope = 12.0 * s1 / (length * (length * length + 2.0));
  z0 = mean + slope * (0.0 - centre);
  zn = mean + slope * (xn - centre);
}

// Delta h between x1 and x2 (metres).
inline double delta_h(const std::vector<double>& z, double xi, double x1, double x2) {
  const int np = static_cast<int>(z.size()) - 1;
  const double xa = whole(x1 / xi), xb = whole(x2 / xi);
  if (whole(xb - xa) < 2.0) return 0.0;
  const int ka = std::clamp(static_cast<int>(whole(0.1 * (whole(xb - xa) + 8.0))), 4, 25);
  const int n = 10 * ka - 5;
  const double step = (xb - xa) / (n - 1);
  std::vector<double> s(static_cast<std::size_t>(n));
  const int first = std::clamp(static_cast<int>(std::floor(xa)) + 1, 1, np);
  for (int j = 0; j < n; ++j) {
    const double p = xa + j * step;
    // The interval (k - 1, k] holding p, within the profile and not before xa's.
    const int k = std::clamp(static_cast<int>(std::ceil(p)), first, np);
    const double zk = z[static_cast<std::size_t>(k)], zm = z[static_cast<std::size_t>(k) - 1];
    s[static_cast<std::size_t>(j)] = zk + (zk - zm) * (p - k);
  }
  // The trapezoid-weighted line through the resampled points, then the deviations from it.
  const double centre = 0.5 * (n - 1), length = n - 1;
  double s0 = 0.0, s1 = 0.0;
  for (int j = 0; j < n; ++j) {
    const double w = (j == 0 || j == n - 1) ? 0.5 : 1.0;
    s0 += w * s[static_cast<std::size_t>(j)];
    s1 += w * s[static_cast<std::size_t>(j)] * (j - centre);
  }
  const double mean = s0 / length, slope = 12.0 * s1 / (length * (length * length + 2.0));
  for (int j = 0; j < n; ++j) s[static_cast<std::size_t>(j)] -= mean + slope * (j - centre);
  std::sort(s.begin(), s.end());
  const double range = s[static_cast<std::size_t>(n - ka)] - s[static_cast<std::size_t>(ka - 1)];
  return range / (1.0 - 0.8 * std::exp(-(x2 - x1) / 50e3));
}

inline double knife(double v2) {
  return v2 < 5.76 ? 6.02 + 9.11 * std::sqrt(v2) - 1.27 * v2 : 12.953 + 4.343 * std::log(v2);
}

inline double height_gain(double x, double pk) {
  if (x < 200.0) {
    const double w = -std::log(pk);
    if (pk < 1e-5 || x * w * w * w > 5495.0) return x > 1.0 ? 17.372 * std::log(x) - 117.0 : -117.0;
    return 2.5e-5 * x * x / pk - 8.686 * w - 15.0;
  }
  double f = 0.05751 * x - 4.343 * std::log(x);
  if (x < 2000.0) {
    const double w = 0.0134 * x * std::exp(-0.005 * x);
    f = (1.0 - w) * f + w * (17.372 * std::log(x) - 117.0);
  }
  return f;
}

inline double h0_curve(double r, double et) {
  const double a[5] = {25.0, 80.0, 177.0, 395.0, 705.0}, b[5] = {24.0, 45.0, 68.0, 80.0, 105.0};
  int it = static_cast<int>(et);
  double q = 0.0;
  if (it <= 0) {
    it = 1;
  } else if (it >= 5) {
    it = 5;
  } else {
    q = et - it;
  }
  const double x = (1.0 / r) * (1.0 / r);
  double h = 4.343 * std::log((a[it - 1] * x + b[it - 1]) * x + 1.0);
  if (q != 0.0) h = (1.0 - q) * h + q * 4.343 * std::log((a[it] * x + b[it]) * x + 1.0);
  return h;
}

inline double scatter_function(double td) {
  if (td <= 10e3) return 133.4 + 0.332e-3 * td - 4.343 * std::log(td);
  if (td <= 70e3) return 104.6 + 0.212e-3 * td - 1.086 * std::log(td);
  return 71.8 + 0.157e-3 * td + 2.171 * std::log(td);
}

}  // namespace detail

// The basic transmission loss of one path: ground heights z at equal steps xi (metres) from
// the transmitter to the receiver, antennas h_tx and h_rx above the ends.
inline ReferenceLoss itm_reference(std::span<const double> profile, double xi, double h_tx, double h_rx,
                                   double frequency_mhz, const ItmParameters& p) {
  using detail::whole;
  using Complex = std::complex<double>;
  const std::vector<double> z(profile.begin(), profile.end());
  const int np = static_cast<int>(z.size()) - 1;
  const double dist = np * xi;
  const double hg[2] = {h_tx, h_rx};
  int kwx = 0;

  // General preparation: the mean elevation of the middle 80%, N_s, gamma_e, Z_g.
  const int ja = static_cast<int>(0.1 * np);
  double zsys = 0.0;
  for (int i = ja; i <= np - ja; ++i) zsys += z[static_cast<std::size_t>(i)];
  zsys /= (np - 2 * ja + 1);
  const double wn = frequency_mhz / 47.7;
  const double ens = p.refractivity * std::exp(-zsys / 9460.0);
  const double gme = 157e-9 * (1.0 - 0.04665 * std::exp(ens / 179.3));
  const Complex zq(p.permittivity, 376.62 * p.conductivity / wn);
  Complex zgnd = std::sqrt(zq - 1.0);
  if (p.polarization == ItmPolarization::kVertical) zgnd = zgnd / zq;

  // The horizons: the Algorithm's running search from the transmitter.
  const double za = z[0] + hg[0], zb = z[static_cast<std::size_t>(np)] + hg[1];
  const double qc = 0.5 * gme;
  double the[2], dl[2] = {dist, dist};
  the[1] = (zb - za) / dist;
  the[0] = the[1] - qc * dist;
  the[1] = -the[1] - qc * dist;
  {
    double sa = 0.0, sb = dist;
    bool clear = true;
    for (int i = 1; i < np; ++i) {
      sa = i * xi;
      sb = dist - sa;
      const double zi = z[static_cast<std::size_t>(i)];
      double q = zi - (qc * sa + the[0]) * sa - za;
      if (q > 0.0) {
        the[0] += q / sa;
        dl[0] = sa;
        clear = false;
      }
      if (!clear) {
        q = zi - (qc * sb + the[1]) * sb - zb;
        if (q > 0.0) {
          the[1] += q / sb;
          dl[1] = sb;
        }
      }
    }
  }

  // Terrain irregularity and effective heights.
  double xl[2] = {std::min(15.0 * hg[0], 0.1 * dl[0]), std::min(15.0 * hg[1], 0.1 * dl[1])};
  xl[1] = dist - xl[1];
  const double dh = detail::delta_h(z, xi, xl[0], xl[1]);
  double he[2];
  if (dl[0] + dl[1] > 1.5 * dist) {
    double z0 = 0.0, zn = 0.0;
    detail::fit_line(z, xi, xl[0], xl[1], z0, zn);
    he[0] = hg[0] + std::max(z[0] - z0, 0.0);
    he[1] = hg[1] + std::max(z[static_cast<std::size_t>(np)] - zn, 0.0);
    for (int j = 0; j < 2; ++j) dl[j] = std::sqrt(2.0 * he[j] / gme) * std::exp(-0.07 * std::sqrt(dh / std::max(he[j], 5.0)));
    const double q = dl[0] + dl[1];
    if (q <= dist) {
      const double r = (dist / q) * (dist / q);
      for (int j = 0; j < 2; ++j) {
        he[j] *= r;
        dl[j] = std::sqrt(2.0 * he[j] / gme) * std::exp(-0.07 * std::sqrt(dh / std::max(he[j], 5.0)));
      }
    }
    for (int j = 0; j < 2; ++j) {
      const double q2 = std::sqrt(2.0 * he[j] / gme);
      the[j] = (0.65 * dh * (q2 / dl[j] - 1.0) - 2.0 * he[j]) / q2;
    }
  } else {
    double z0 = 0.0, zn = 0.0, unused = 0.0;
    detail::fit_line(z, xi, xl[0], 0.9 * dl[0], z0, unused);
    detail::fit_line(z, xi, dist - 0.9 * dl[1], xl[1], unused, zn);
    he[0] = hg[0] + std::max(z[0] - z0, 0.0);
    he[1] = hg[1] + std::max(z[static_cast<std::size_t>(np)] - zn, 0.0);
  }

  // The reference attenuation: the terminals' smooth-Earth horizons and the range checks.
  const double dls[2] = {std::sqrt(2.0 * he[0] / gme), std::sqrt(2.0 * he[1] / gme)};
  const double dlsa = dls[0] + dls[1], dla = dl[0] + dl[1];
  const double tha = std::max(the[0] + the[1], -dla * gme);
  if (wn < 0.838 || wn > 210.0) kwx = std::max(kwx, 1);
  for (int j = 0; j < 2; ++j) {
    if (hg[j] < 1.0 || hg[j] > 1000.0) kwx = std::max(kwx, 1);
    if (std::abs(the[j]) > 200e-3 || dl[j] < 0.1 * dls[j] || dl[j] > 3.0 * dls[j]) kwx = std::max(kwx, 3);
  }
  if (ens < 250.0 || ens > 400.0 || gme < 75e-9 || gme > 250e-9 || zgnd.real() <= std::abs(zgnd.imag()) || wn < 0.419 ||
      wn > 420.0) {
    kwx = 4;
  }
  for (int j = 0; j < 2; ++j) {
    if (hg[j] < 0.5 || hg[j] > 3000.0) kwx = 4;
  }
  const double dmin = std::abs(he[0] - he[1]) / 200e-3;

  // Diffraction (its initialisation, then A_diff at d3 and d4).
  const double hgg = hg[0] * hg[1];
  const double wd1 = std::sqrt(1.0 + (he[0] * he[1] - hgg) / (hgg + 10.0));
  const double xd1 = dla + tha / gme;
  double q = (1.0 - 0.8 * std::exp(-dlsa / 50e3)) * dh;
  q *= 0.78 * std::exp(-std::pow(q / 16.0, 0.25));
  const double afo = std::min(15.0, 2.171 * std::log(1.0 + 4.77e-4 * hg[0] * hg[1] * wn * q));
  const double qk = 1.0 / std::abs(zgnd);
  double aht = 20.0, xht = 0.0;
  for (int j = 0; j < 2; ++j) {
    const double a = 0.5 * dl[j] * dl[j] / he[j];
    const double wa = std::cbrt(a * wn);
    const double pk = qk / wa;
    const double x = (1.607 - pk) * 151.0 * wa * dl[j] / a;
    xht += x;
    aht += detail::height_gain(x, pk);
  }
  auto adiff = [&](double d) {
    const double th = tha + d * gme;
    const double ds = d - dla;
    const double v2 = 0.0795775 * wn * ds * th * th;
    const double knives = detail::knife(v2 * dl[0] / (ds + dl[0])) + detail::knife(v2 * dl[1] / (ds + dl[1]));
    const double a = ds / th;
    const double wa = std::cbrt(a * wn);
    const double pk = qk / wa;
    const double x = (1.607 - pk) * 151.0 * wa * th + xht;
    const double ar = 0.05751 * x - 4.343 * std::log(x) - aht;
    const double qq = (wd1 + xd1 / d) * std::min((1.0 - 0.8 * std::exp(-d / 50e3)) * dh * wn, 6283.2);
    const double wd = 25.1 / (25.1 + std::sqrt(qq));
    return ar * wd + (1.0 - wd) * knives + afo;
  };
  const double xae = 1.0 / std::cbrt(wn * gme * gme);
  const double d3 = std::max(dlsa, 1.3787 * xae + dla), d4 = d3 + 2.7574 * xae;
  const double a3 = adiff(d3), a4 = adiff(d4);
  const double emd = (a4 - a3) / (d4 - d3), aed = a3 - emd * d3;

  const double d = dist;
  if (d > 1000e3) kwx = std::max(kwx, 1);
  if (d < dmin) kwx = std::max(kwx, 3);
  if (d < 1e3 || d > 2000e3) kwx = 4;
  double aref = 0.0;
  if (d < dlsa) {
    // Line of sight.
    const double wls = 0.021 / (0.021 + wn * dh / std::max(10e3, dlsa));
    auto alos = [&](double dd) {
      double qq = (1.0 - 0.8 * std::exp(-dd / 50e3)) * dh;
      const double s = 0.78 * qq * std::exp(-std::pow(qq / 16.0, 0.25));
      qq = he[0] + he[1];
      const double sps = qq / std::sqrt(dd * dd + qq * qq);
      Complex r = (sps - zgnd) / (sps + zgnd) * std::exp(-std::min(10.0, wn * s * sps));
      qq = std::norm(r);
      if (qq < 0.25 || qq < sps) r = r * std::sqrt(sps / qq);
      const double extended = emd * dd + aed;
      qq = wn * he[0] * he[1] * 2.0 / dd;
      if (qq > 1.57) qq = 3.14 - 2.4649 / qq;
      return (-4.343 * std::log(std::norm(Complex(std::cos(qq), -std::sin(qq)) + r)) - extended) * wls + extended;
    };
    const double d2 = dlsa, a2 = aed + d2 * emd;
    double d0 = 1.908 * wn * he[0] * he[1], d1;
    if (aed >= 0.0) {
      d0 = std::min(d0, 0.5 * dla);
      d1 = d0 + 0.25 * (dla - d0);
    } else {
      d1 = std::max(-aed / emd, 0.25 * dla);
    }
    const double a1 = alos(d1);
    bool fitted = false;
    double ak1 = 0.0, ak2 = 0.0;
    if (d0 < d1) {
      const double a0 = alos(d0);
      const double lq = std::log(d2 / d0);
      ak2 = std::max(0.0, ((d2 - d0) * (a1 - a0) - (d1 - d0) * (a2 - a0)) / ((d2 - d0) * std::log(d1 / d0) - (d1 - d0) * lq));
      fitted = aed >= 0.0 || ak2 > 0.0;
      if (fitted) {
        ak1 = (a2 - a0 - ak2 * lq) / (d2 - d0);
        if (ak1 < 0.0) {
          ak1 = 0.0;
          ak2 = std::max(a2 - a0, 0.0) / lq;
          if (ak2 == 0.0) ak1 = emd;
        }
      }
    }
    if (!fitted) {
      ak1 = std::max(a2 - a1, 0.0) / (d2 - d1);
      ak2 = 0.0;
      if (ak1 == 0.0) ak1 = emd;
    }
    const double ael = a2 - ak1 * d2 - ak2 * std::log(d2);
    aref = ael + ak1 * d + ak2 * std::log(d);
  } else {
    // Diffraction, or troposcatter beyond where its line falls below.
    double ad = dl[0] - dl[1], rr = he[1] / he[0];
    if (ad < 0.0) {
      ad = -ad;
      rr = 1.0 / rr;
    }
    const double etq = (5.67e-6 * ens - 2.32e-3) * ens + 0.031;
    double h0s = -15.0;
    auto ascat = [&](double dd) {
      double h0 = 0.0;
      if (h0s > 15.0) {
        h0 = h0s;
      } else {
        const double th = the[0] + the[1] + dd * gme;
        const double r1 = 2.0 * wn * th * he[0], r2 = 2.0 * wn * th * he[1];
        if (r1 < 0.2 && r2 < 0.2) return 1001.0;
        double ss = (dd - ad) / (dd + ad);
        double qq = rr / ss;
        ss = std::max(0.1, ss);
        qq = std::min(std::max(0.1, qq), 10.0);
        const double z0 = (dd - ad) * (dd + ad) * th * 0.25 / dd;
        const double et = (etq * std::exp(-std::pow(std::min(1.7, z0 / 8.0e3), 6.0)) + 1.0) * z0 / 1.7556e3;
        const double ett = std::max(et, 1.0);
        h0 = (detail::h0_curve(r1, ett) + detail::h0_curve(r2, ett)) * 0.5;
        h0 += std::min(h0, (1.38 - std::log(ett)) * std::log(ss) * std::log(qq) * 0.49);
        h0 = std::max(h0, 0.0);
        if (et < 1.0) {
          h0 = et * h0 + (1.0 - et) * 4.343 *
                             std::log(std::pow((1.0 + 1.4142 / r1) * (1.0 + 1.4142 / r2), 2.0) * (r1 + r2) / (r1 + r2 + 2.8284));
        }
        if (h0 > 15.0 && h0s >= 0.0) h0 = h0s;
      }
      h0s = h0;
      const double th = tha + dd * gme;
      return detail::scatter_function(th * dd) + 4.343 * std::log(47.7 * wn * std::pow(th, 4.0)) -
             0.1 * (ens - 301.0) * std::exp(-th * dd / 40e3) + h0;
    };
    const double d5 = dla + 200e3, d6 = d5 + 200e3;
    const double a6 = ascat(d6), a5 = ascat(d5);
    double ems = emd, aes = aed, dx = 10e6;
    if (a5 < 1000.0) {
      ems = (a6 - a5) / 200e3;
      dx = std::max({dlsa, dla + 0.3 * xae * std::log(47.7 * wn), (a5 - aed - ems * d5) / (emd - ems)});
      aes = (emd - ems) * dx + aed;
    }
    aref = d > dx ? aes + ems * d : aed + emd * d;
  }
  aref = std::max(aref, 0.0);

  // Variability.
  const detail::ClimateTable c;
  const int k = static_cast<int>(p.climate) - 1;
  const double lnk = std::log(0.133 * wn);
  const double gm = c.bfm1[k] + c.bfm2[k] / ((c.bfm3[k] * lnk) * (c.bfm3[k] * lnk) + 1.0);
  const double gp = c.bfp1[k] + c.bfp2[k] / ((c.bfp3[k] * lnk) * (c.bfp3[k] * lnk) + 1.0);
  const double dexa = std::sqrt(18e6 * he[0]) + std::sqrt(18e6 * he[1]) + std::cbrt(575.7e12 / wn);
  const double de = dist < dexa ? 130e3 * dist / dexa : 130e3 + dist - dexa;
  const double vmd = detail::curve(c.bv1[k], c.bv2[k], c.xv1[k], c.xv2[k], c.xv3[k], de);
  const double sgtm = detail::curve(c.bsm1[k], c.bsm2[k], c.xsm1[k], c.xsm2[k], c.xsm3[k], de) * gm;
  const double sgtp = detail::curve(c.bsp1[k], c.bsp2[k], c.xsp1[k], c.xsp2[k], c.xsp3[k], de) * gp;
  const double sgtd = sgtp * c.bsd1[k], tgtd = (sgtp - sgtd) * c.bzd1[k];
  double sgl = 0.0;
  if (p.location_variability) {
    const double qq = (1.0 - 0.8 * std::exp(-dist / 50e3)) * dh * wn;
    sgl = 10.0 * qq / (qq + 13.0);
  }
  const double vs0 = p.situation_variability ? std::pow(5.0 + 3.0 * std::exp(-de / 100e3), 2.0) : 0.0;
  double zt = detail::qerfi(p.time), zl = detail::qerfi(p.location);
  const double zc = detail::qerfi(p.situation);
  switch (p.variability) {
    case ItmVariability::kSingleMessage: zt = zl = zc; break;
    case ItmVariability::kAccidental: zl = zc; break;
    case ItmVariability::kMobile: zl = zt; break;
    case ItmVariability::kBroadcast: break;
  }
  if (std::abs(zt) > 3.1 || std::abs(zl) > 3.1 || std::abs(zc) > 3.1) kwx = std::max(kwx, 1);
  const double zd = c.bzd1[k];
  const double sgt = zt < 0.0 ? sgtm : zt <= zd ? sgtp : sgtd + tgtd / zt;
  const double vs = vs0 + (sgt * zt) * (sgt * zt) / (7.8 + zc * zc) + (sgl * zl) * (sgl * zl) / (24.0 + zc * zc);
  double yr = 0.0, sgc = 0.0;
  switch (p.variability) {
    case ItmVariability::kSingleMessage: sgc = std::sqrt(sgt * sgt + sgl * sgl + vs); break;
    case ItmVariability::kAccidental:
      yr = sgt * zt;
      sgc = std::sqrt(sgl * sgl + vs);
      break;
    case ItmVariability::kMobile:
      yr = std::sqrt(sgt * sgt + sgl * sgl) * zt;
      sgc = std::sqrt(vs);
      break;
    case ItmVariability::kBroadcast:
      yr = sgt * zt + sgl * zl;
      sgc = std::sqrt(vs);
      break;
  }
  double a = aref - vmd - yr - sgc * zc;
  if (a < 0.0) a = a * (29.0 - a) / (29.0 - 10.0 * a);

  ReferenceLoss out;
  out.loss_db = 32.45 + 20.0 * std::log10(frequency_mhz) + 20.0 * std::log10(dist / 1000.0) + a;
  out.warning = kwx;
  return out;
}

}  // namespace terravol::volume::reference
