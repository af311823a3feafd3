// The part of the ITM (itm.cpp) that runs once per receiver height, several heights at a time:
// from the terrain's geometry at each height (horizons, effective heights, Delta h; itm.cpp's
// profile stage) to the basic transmission loss. Private to volume/: itm.cpp compiles it for the
// baseline x86-64 instruction set and itm_kernel_avx2.cpp for AVX2, each into its own namespace
// (TERRAVOL_ITM_KERNEL), and itm.cpp calls the AVX2 one where the processor has it. Both do the
// same IEEE operations in the same order (no fused multiply-add), so they give the same bits.
//
// The equations are those of itm.cpp's chain, steps 2 (the end of it: effective heights and
// horizons of a line-of-sight path) to 4, lane by lane: each branch of the Algorithm becomes a
// selection between lanes, and a branch no lane takes is skipped. The exponential, logarithm,
// cube root, sine and cosine are written here (below) in plain arithmetic, to about one unit in
// the last place: the C library has no functions of several values at once.
//
// Nothing here may call a function of the standard library that the compiler could emit out of
// line: such a function compiled for AVX2 in one file could be the copy the linker keeps for
// all of them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

namespace terravol::volume::itm_kernel {

inline constexpr int kLanes = 4;  // receiver heights per evaluation
inline constexpr int kSumParts = 4;  // Delta h's running sums

// What does not change between the heights of one path.
struct Path {
  double wn = 0.0, ens = 0.0, gme = 0.0, xae = 0.0;  // wave number, N_s, gamma_e, (k gamma_e^2)^(-1/3)
  double zg_re = 0.0, zg_im = 0.0, inverse_abs_zg = 0.0;  // ground impedance
  double ln_inverse_abs_zg = 0.0;
  double dist = 0.0, ln_dist = 0.0, hg_tx = 0.0;  // ln_dist: ln(d / 1 m)
  double free_space_db = 0.0;
  double decay_d4 = 0.0;        // exp(-2.7574 X_ae / 50 km): exp(-d / 50 km) from d3 to d4
  double decay_dist = 0.0;      // exp(-d / 50 km) at the path's length
  double scatter_offset = 0.0;  // 0.3 X_ae ln(47.7 k): the least troposcatter adds to d_L
  double base_warning = 0.0;  // the warnings of the frequency, medium and path length alone
  // Statistics: the climate's curves (c1, c2, x1, x2, x3 each), s_d, z_D, the frequency
  // factors g-, g+, the frequency's part of d_e's scale, the deviates after MDVAR's choices.
  double median[5] = {}, sigma_minus[5] = {}, sigma_plus[5] = {};
  double sd = 0.0, zd = 0.0, g_minus = 0.0, g_plus = 0.0, dexa_frequency = 0.0;
  double zt = 0.0, zl = 0.0, zc = 0.0;
  int variability = 0;  // MDVAR mod 10
  bool location_variability = false, situation_variability = false;
};

// One height per lane: the geometry in (from the profile stage), the loss and what led to it out.
struct Lanes {
  // In. he: effective heights before a line-of-sight path's horizons are re-derived; dl, the:
  // the horizons of a trans-horizon path (ignored where los_geometry).
  double hg_rx[kLanes] = {};
  double he[2][kLanes] = {}, dl[2][kLanes] = {}, the[2][kLanes] = {};
  double dh[kLanes] = {};
  double los_geometry[kLanes] = {};  // 1: d_L1 + d_L2 > 1.5 d (horizons from smooth ground), else 0
  // Out: he, dl, the final; and the results.
  double loss_db[kLanes] = {}, attenuation_db[kLanes] = {}, reference_db[kLanes] = {};
  double mode[kLanes] = {};  // 0 line of sight, 1 diffraction, 2 troposcatter
  double warning[kLanes] = {};
  // The transmitter's terms of the last evaluation (its horizon distance and effective height
  // in, its rounded-Earth distance, height gain and d_e term out): a trans-horizon column's are
  // the same at every height, so they are reused while their inputs are equal in every lane.
  bool tx_kept = false;
  double tx_dl[kLanes] = {}, tx_he[kLanes] = {}, tx_x[kLanes] = {}, tx_gain[kLanes] = {}, tx_dexa[kLanes] = {};
};

// Delta h's resampling (itm.cpp's delta_h_of): n points p_j = xa + j step, xa >= 0 and the
// last at most np, each interpolated linearly on the interval that ends at sample k = ceil(p_j)
// clamped to [k0, np], into s (room for n rounded up to kSumParts; the spare places get 0);
// and the sums of the values and of j times the values, each summed in kSumParts parts (part
// l the points j = l mod kSumParts, in order), the parts added pairwise at the end.
struct Sums {
  double sum = 0.0, sum_i = 0.0;
};
// The deviations s_j - (at0 + slope j) of s[0..n) at or below low_threshold into low and at or
// above high_threshold into high, in any order (room for n + kSumParts each); their counts.
struct Counts {
  std::size_t low = 0, high = 0;
};

// Each instruction set's copy: the lanes' losses (Lanes' "out" fields) from their geometry,
// Delta h's two passes, and its quantiles among the values gathered: kth_extreme, the k-th
// smallest (0-based; largest: the k-th largest) of c[0..count), count > k, by taking the
// extreme off count - 1 - k times, four values at a time (for few values beyond the k-th);
// it reorders c, which has room for count rounded up to kSumParts (the spare places written).
namespace baseline {
void evaluate(const Path& p, Lanes& lanes);
Sums resample(const double* z, int np, int k0, double xa, double step, int n, double* s);
Counts beyond(const double* s, int n, double at0, double slope, double low_threshold, double high_threshold, double* low,
              double* high);
double kth_extreme(double* c, std::size_t count, std::size_t k, bool largest);
}  // namespace baseline
namespace avx2 {
void evaluate(const Path& p, Lanes& lanes);
Sums resample(const double* z, int np, int k0, double xa, double step, int n, double* s);
Counts beyond(const double* s, int n, double at0, double slope, double low_threshold, double high_threshold, double* low,
              double* high);
double kth_extreme(double* c, std::size_t count, std::size_t k, bool largest);
}  // namespace avx2

}  // namespace terravol::volume::itm_kernel

#if defined(TERRAVOL_ITM_KERNEL)

#if defined(__AVX__)
#include <immintrin.h>
#elif defined(__SSE2__)
#include <emmintrin.h>
#endif

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace terravol::volume::itm_kernel::TERRAVOL_ITM_KERNEL {

using V = double __attribute__((vector_size(8 * kLanes)));
using I = std::int64_t __attribute__((vector_size(8 * kLanes)));  // also the type of V's comparisons

inline V splat(double x) { return V{} + x; }
inline V load(const double* p) {
  V v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
inline void store(double* p, V v) { __builtin_memcpy(p, &v, sizeof v); }
inline I bits(V x) {
  I i;
  __builtin_memcpy(&i, &x, sizeof i);
  return i;
}
inline V from_bits(I i) {
  V x;
  __builtin_memcpy(&x, &i, sizeof x);
  return x;
}
inline bool any(I mask) {
  for (int k = 0; k < kLanes; ++k) {
    if (mask[k] != 0) return true;
  }
  return false;
}
inline bool all(I mask) {
  for (int k = 0; k < kLanes; ++k) {
    if (mask[k] == 0) return false;
  }
  return true;
}
inline V select(I mask, V a, V b) { return mask ? a : b; }
// The C library's std::min(a, b) and std::max(a, b), lane by lane (the same choice with NaN).
inline V vmin(V a, V b) { return b < a ? b : a; }
inline V vmax(V a, V b) { return a < b ? b : a; }
inline V vabs(V x) { return from_bits(bits(x) & (I{} + 0x7fffffffffffffffLL)); }

inline V vsqrt(V x) {
#if defined(__AVX__)
  static_assert(kLanes % 4 == 0);
  V out;
  for (int k = 0; k < kLanes; k += 4) {
    __m256d part;
    __builtin_memcpy(&part, reinterpret_cast<const double*>(&x) + k, sizeof part);
    part = _mm256_sqrt_pd(part);
    __builtin_memcpy(reinterpret_cast<double*>(&out) + k, &part, sizeof part);
  }
  return out;
#elif defined(__SSE2__)
  static_assert(kLanes % 2 == 0);
  V out;
  for (int k = 0; k < kLanes; k += 2) {
    __m128d half;
    __builtin_memcpy(&half, reinterpret_cast<const double*>(&x) + k, sizeof half);
    half = _mm_sqrt_pd(half);
    __builtin_memcpy(reinterpret_cast<double*>(&out) + k, &half, sizeof half);
  }
  return out;
#else
  V out;
  for (int k = 0; k < kLanes; ++k) out[k] = __builtin_sqrt(x[k]);
  return out;
#endif
}

constexpr double kLn2Hi = 6.93147180369123816490e-01;  // ln 2 in 33 bits (n ln2_hi exact)
constexpr double kLn2Lo = 1.90821492927058770002e-10;
constexpr double kRoundShift = 6755399441055744.0;     // 1.5 * 2^52: x + it rounds x to a whole number
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// c[0] + c[1] x + ... + c[9] x^9 and c[0] + ... + c[13] x^13 by Estrin's scheme (pairs, then
// pairs of pairs with x^2, x^4, x^8): a few multiplications deep instead of one per term, for
// the kernel's chains are long.
inline V estrin10(V x, const double (&c)[10]) {
  const V x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
  auto pair = [&](int i) { return splat(c[i]) + splat(c[i + 1]) * x; };
  return (pair(0) + pair(2) * x2) + (pair(4) + pair(6) * x2) * x4 + pair(8) * x8;
}
inline V estrin14(V x, const double (&c)[14]) {
  const V x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
  auto pair = [&](int i) { return splat(c[i]) + splat(c[i + 1]) * x; };
  return ((pair(0) + pair(2) * x2) + (pair(4) + pair(6) * x2) * x4) +
         ((pair(8) + pair(10) * x2) + pair(12) * x4) * x8;
}

// e^x to 2 units in the last place for x within [-708, 709]; 0 below, +inf above, NaN for NaN.
// x = n ln 2 + r, |r| <= ln 2 / 2 (Cody and Waite's two-part ln 2), e^r by its Taylor series
// to r^13 (the next term is below 2e-17 of it), times 2^n through the exponent bits.
inline V vexp(V x) {
  static constexpr double kTaylor[14] = {1.0,          1.0,           1.0 / 2,        1.0 / 6,         1.0 / 24,
                                         1.0 / 120,    1.0 / 720,     1.0 / 5040,     1.0 / 40320,     1.0 / 362880,
                                         1.0 / 3628800, 1.0 / 39916800, 1.0 / 479001600, 1.0 / 6227020800};
  const V xc = vmin(vmax(x, splat(-708.0)), splat(709.0));
  const V t = xc * splat(1.4426950408889634) + splat(kRoundShift);
  const V n = t - splat(kRoundShift);
  const V r = (xc - n * splat(kLn2Hi)) - n * splat(kLn2Lo);
  const V p = estrin14(r, kTaylor);
  const I ni = bits(t) - bits(splat(kRoundShift));
  V e = from_bits(bits(p) + (ni << 52));
  e = select(x < splat(-708.0), splat(0.0), e);
  e = select(x > splat(709.0), splat(kInf), e);
  return select(x != x, x, e);
}

// ln x to about 2e-16 absolute (x near 1) or 2 units in the last place; -inf at 0, NaN below 0
// or for NaN, +inf at +inf. x = 2^e m, m within [sqrt(1/2), sqrt 2), ln m = 2 atanh(s) with
// s = (m - 1) / (m + 1), |s| <= 0.1716, by its series to s^21 (the next term is below 1e-17).
inline V vlog(V x) {
  static constexpr double kAtanh[10] = {2.0 / 3,  2.0 / 5,  2.0 / 7,  2.0 / 9,  2.0 / 11,
                                        2.0 / 13, 2.0 / 15, 2.0 / 17, 2.0 / 19, 2.0 / 21};
  constexpr double kMinNormal = std::numeric_limits<double>::min();
  const I subnormal = x < splat(kMinNormal);
  const V xs = select(subnormal, x * splat(18014398509481984.0), x);  // 2^54
  const I offset = bits(xs) - (I{} + 0x3fe6a09e667f3bcdLL);           // the bits of sqrt(1/2)
  // offset >> 52 with its sign (a logical shift of the 12-bit field, then sign-extended:
  // AVX2 has no arithmetic shift of 64-bit lanes).
  using U = std::uint64_t __attribute__((vector_size(8 * kLanes)));
  const I e = ((I)((U)offset >> 52) ^ 0x800) - 0x800;
  const V m = from_bits(bits(xs) - (e << 52));
  V ed = from_bits(e + bits(splat(kRoundShift))) - splat(kRoundShift);
  ed = select(subnormal, ed - splat(54.0), ed);
  const V s = (m - splat(1.0)) / (m + splat(1.0));
  const V s2 = s * s;
  const V ln_m = s * splat(2.0) + estrin10(s2, kAtanh) * s2 * s;
  V out = ed * splat(kLn2Hi) + (ln_m + ed * splat(kLn2Lo));
  out = select(x == splat(kInf), x, out);
  out = select(x == splat(0.0), splat(-kInf), out);
  return select((x < splat(0.0)) | (x != x), splat(kNaN), out);
}

// x^(1/3) (relative error under 1e-15) and its logarithm, for x > 0.
inline V vcbrt(V x, V& ln_cube_root) {
  ln_cube_root = vlog(x) * splat(1.0 / 3.0);
  return vexp(ln_cube_root);
}

// sin and cos of x within [0, pi] (ITM's phase difference), to about 2e-16 absolute: of
// y = x - pi/2 within [-pi/2, pi/2], cos x = -sin y and sin x = cos y by their Taylor series
// (the first terms left out are below 2e-17).
inline void vsincos(V x, V& sine, V& cosine) {
  static constexpr double kSin[10] = {-1.0 / 6,           1.0 / 120,           -1.0 / 5040,          1.0 / 362880,
                                      -1.0 / 39916800,    1.0 / 6227020800,    -1.0 / 1307674368000, 1.0 / 355687428096000,
                                      -1.0 / 121645100408832000, 1.0 / 51090942171709440000.0};
  static constexpr double kCos[10] = {-1.0 / 2,           1.0 / 24,            -1.0 / 720,           1.0 / 40320,
                                      -1.0 / 3628800,     1.0 / 479001600,     -1.0 / 87178291200,   1.0 / 20922789888000,
                                      -1.0 / 6402373705728000, 1.0 / 2432902008176640000};
  const V y = (x - splat(1.5707963267948966)) - splat(6.123233995736766e-17);
  const V y2 = y * y;
  const V sin_y = y + estrin10(y2, kSin) * y2 * y;
  const V cos_y = splat(1.0) + estrin10(y2, kCos) * y2;
  sine = cos_y;
  cosine = -sin_y;
}

// Delta h(d) = (1 - 0.8 exp(-d / 50 km)) Delta h, from exp(-d / 50 km).
inline V delta_h_over(V decay, V dh) { return (splat(1.0) - splat(0.8) * decay) * dh; }
// sigma_h(Delta h) = 0.78 Delta h exp(-(Delta h / 16 m)^(1/4)).
inline V sigma_h(V dh) { return splat(0.78) * dh * vexp(-vsqrt(vsqrt(dh * splat(1.0 / 16.0)))); }

// F(v) of one knife edge from v^2 (the Algorithm's 6.1).
inline V knife_edge(V v2) {
  const I near = v2 < splat(5.76);
  const V low = splat(6.02) + splat(9.11) * vsqrt(v2) - splat(1.27) * v2;
  if (!any(~near)) return low;
  return select(near, low, splat(12.953) + splat(4.343) * vlog(v2));
}

// The smooth-Earth height-gain F(x, K) (6.2-6.7), from ln x and ln K.
inline V height_gain(V x, V k, V ln_x, V ln_k) {
  const V w = -ln_k;
  const V flat = select(x > splat(1.0), splat(17.372) * ln_x - splat(117.0), splat(-117.0));
  const V small = splat(2.5e-5) * x * x / k - splat(8.686) * w - splat(15.0);
  const V below = select((k < splat(1e-5)) | (x * w * w * w > splat(5495.0)), flat, small);
  const V f = splat(0.05751) * x - splat(4.343) * ln_x;
  const I near = x < splat(200.0), mixed_range = ~near & (x < splat(2000.0));
  if (!any(mixed_range)) return select(near, below, f);
  const V wg = splat(0.0134) * x * vexp(splat(-0.005) * x);
  const V mixed = (splat(1.0) - wg) * f + wg * (splat(17.372) * ln_x - splat(117.0));
  return select(near, below, select(mixed_range, mixed, f));
}

// The troposcatter frequency gain H_0(r, eta_s) (6.13) for eta_s >= 1.
inline V frequency_gain(V r, V eta) {
  // i = int(eta) within 1..5, q its fraction (0 at and beyond 5).
  V i = (eta + splat(kRoundShift)) - splat(kRoundShift);  // eta rounded to a whole number
  i = select(i > eta, i - splat(1.0), i);                  // down
  const V q = select(i >= splat(5.0), splat(0.0), eta - i);
  i = vmin(vmax(i, splat(1.0)), splat(5.0));
  auto coefficient = [&](V index, const double (&table)[5]) {
    V c = splat(table[0]);
    for (int n = 1; n < 5; ++n) c = select(index == splat(n + 1.0), splat(table[n]), c);
    return c;
  };
  static constexpr double a[5] = {25.0, 80.0, 177.0, 395.0, 705.0};
  static constexpr double b[5] = {24.0, 45.0, 68.0, 80.0, 105.0};
  const V x = (splat(1.0) / r) * (splat(1.0) / r);
  const V next = vmin(i + splat(1.0), splat(5.0));
  const V h = splat(4.343) * vlog((coefficient(i, a) * x + coefficient(i, b)) * x + splat(1.0));
  const V h_next = splat(4.343) * vlog((coefficient(next, a) * x + coefficient(next, b)) * x + splat(1.0));
  return select(q != splat(0.0), (splat(1.0) - q) * h + q * h_next, h);
}

// The scatter function F(theta d) of troposcatter.
inline V scatter_function(V td) {
  const I first = td <= splat(10e3), second = td <= splat(70e3);
  const V a = select(first, splat(133.4), select(second, splat(104.6), splat(71.8)));
  const V b = select(first, splat(0.332e-3), select(second, splat(0.212e-3), splat(0.157e-3)));
  const V c = select(first, splat(-4.343), select(second, splat(-1.086), splat(2.171)));
  return a + b * td + c * vlog(td);
}

// A climate curve C(d_e) = (c1 + c2 / (1 + ((d_e - x2) / x3)^2)) (d_e / x1)^2 / (1 + (d_e / x1)^2).
inline V climate_curve(const double (&c)[5], V de) {
  const V a = (de - splat(c[3])) / splat(c[4]), b = de / splat(c[2]);
  return (splat(c[0]) + splat(c[1]) / (splat(1.0) + a * a)) * (b * b) / (splat(1.0) + b * b);
}

// One terminal's terms: the smooth-Earth horizon distance sqrt(2 h_e / gamma_e) (given), and
// from its horizon distance d_L and effective height h_e the rounded-Earth distance x of
// (4.20) and its height-gain, and sqrt(18e6 m h_e) for d_e.
struct Terminal {
  V dls, x, gain, dexa;
};
inline Terminal terminal(V dl, V he, V dls, const Path& p) {
  Terminal t;
  t.dls = dls;
  const V a = splat(0.5) * dl * dl / he;  // the horizon's radius
  V ln_wa;
  const V wa = vcbrt(a * splat(p.wn), ln_wa);
  const V pk = splat(p.inverse_abs_zg) / wa;
  t.x = (splat(1.607) - pk) * splat(151.0) * wa * dl / a;
  t.gain = height_gain(t.x, pk, vlog(t.x), splat(p.ln_inverse_abs_zg) - ln_wa);
  t.dexa = vsqrt(splat(18e6) * he);
  return t;
}

// The lanes' losses (Lanes' "out" fields) from their geometry.
inline void evaluate_lanes(const Path& p, Lanes& lanes) {
  const V gme = splat(p.gme), wn = splat(p.wn), dist = splat(p.dist), hg0 = splat(p.hg_tx);
  const V hg1 = load(lanes.hg_rx), dh = load(lanes.dh);
  V he[2] = {load(lanes.he[0]), load(lanes.he[1])};
  V dl[2] = {load(lanes.dl[0]), load(lanes.dl[1])};
  V the[2] = {load(lanes.the[0]), load(lanes.the[1])};
  V dls[2] = {vsqrt(splat(2.0) * he[0] / gme), vsqrt(splat(2.0) * he[1] / gme)};

  // A line-of-sight path's horizons from smooth ground of the effective heights, which are
  // raised when those horizons do not reach across the path.
  const I los_geometry = load(lanes.los_geometry) != splat(0.0);
  if (any(los_geometry)) {
    auto horizon = [&](V h, V smooth) { return smooth * vexp(splat(-0.07) * vsqrt(dh / vmax(h, splat(5.0)))); };
    V sdl[2] = {horizon(he[0], dls[0]), horizon(he[1], dls[1])};
    const V sum = sdl[0] + sdl[1];
    const I short_sum = los_geometry & (sum <= dist);
    if (any(short_sum)) {
      const V scale = (dist / sum) * (dist / sum);
      for (int j = 0; j < 2; ++j) {
        const V raised = he[j] * scale;
        const V raised_dls = vsqrt(splat(2.0) * raised / gme);
        he[j] = select(short_sum, raised, he[j]);
        dls[j] = select(short_sum, raised_dls, dls[j]);
        sdl[j] = select(short_sum, horizon(raised, raised_dls), sdl[j]);
      }
    }
    for (int j = 0; j < 2; ++j) {
      dl[j] = select(los_geometry, sdl[j], dl[j]);
      const V angle = (splat(0.65) * dh * (dls[j] / dl[j] - splat(1.0)) - splat(2.0) * he[j]) / dls[j];
      the[j] = select(los_geometry, angle, the[j]);
    }
  }
  // The transmitter's terms depend on its horizon distance and effective height alone (d_Ls
  // follows from h_e): those of the last evaluation where both are equal in every lane.
  Terminal tx;
  if (lanes.tx_kept && all((dl[0] == load(lanes.tx_dl)) & (he[0] == load(lanes.tx_he)))) {
    tx = {dls[0], load(lanes.tx_x), load(lanes.tx_gain), load(lanes.tx_dexa)};
  } else {
    tx = terminal(dl[0], he[0], dls[0], p);
    store(lanes.tx_dl, dl[0]);
    store(lanes.tx_he, he[0]);
    store(lanes.tx_x, tx.x);
    store(lanes.tx_gain, tx.gain);
    store(lanes.tx_dexa, tx.dexa);
    lanes.tx_kept = true;
  }
  const Terminal terms[2] = {tx, terminal(dl[1], he[1], dls[1], p)};

  // The reference attenuation (the Algorithm's point-to-point mode at the path's own length).
  const V dlsa = dls[0] + dls[1], dla = dl[0] + dl[1];
  const V tha = vmax(the[0] + the[1], -dla * gme);
  V warning = splat(p.base_warning);
  auto warn = [&](I condition, double level) { warning = vmax(warning, select(condition, splat(level), splat(0.0))); };
  warn((hg1 < splat(1.0)) | (hg1 > splat(1000.0)), 1.0);
  for (int j = 0; j < 2; ++j) {
    warn((vabs(the[j]) > splat(200e-3)) | (dl[j] < splat(0.1) * dls[j]) | (dl[j] > splat(3.0) * dls[j]), 3.0);
  }
  warn((hg1 < splat(0.5)) | (hg1 > splat(3000.0)), 4.0);
  warn(dist < vabs(he[0] - he[1]) / splat(200e-3), 3.0);

  // Diffraction, A_diff(d) (4.11): w A_r + (1 - w) A_k + A_fo, as a line through d3 and d4.
  const V hgg = hg0 * hg1;
  const V wd1 = vsqrt(splat(1.0) + (he[0] * he[1] - hgg) / (hgg + splat(10.0)));
  const V xd1 = dla + tha / gme;
  const V decay_dlsa = vexp(-dlsa * splat(1.0 / 50e3));
  const V afo = vmin(splat(15.0), splat(2.171) * vlog(splat(1.0) + splat(4.77e-4) * hgg * wn * sigma_h(delta_h_over(decay_dlsa, dh))));
  const V xht = terms[0].x + terms[1].x, aht = splat(20.0) + terms[0].gain + terms[1].gain;
  auto diffraction = [&](V d, V decay) {
    const V th = tha + d * gme;
    const V ds = d - dla;
    const V v2 = splat(0.0795775) * wn * ds * th * th;  // 1 / (4 pi)
    const V knife = knife_edge(v2 * dl[0] / (ds + dl[0])) + knife_edge(v2 * dl[1] / (ds + dl[1]));
    const V a = ds / th;
    V ln_wa;
    const V wa = vcbrt(a * wn, ln_wa);
    const V pk = splat(p.inverse_abs_zg) / wa;
    const V x = (splat(1.607) - pk) * splat(151.0) * wa * th + xht;
    const V rounded = splat(0.05751) * x - splat(4.343) * vlog(x) - aht;
    const V q = (wd1 + xd1 / d) * vmin(delta_h_over(decay, dh) * wn, splat(6283.2));
    const V w = splat(25.1) / (splat(25.1) + vsqrt(q));
    return rounded * w + (splat(1.0) - w) * knife + afo;
  };
  const V xae = splat(p.xae);
  const V d3 = vmax(dlsa, splat(1.3787) * xae + dla), d4 = d3 + splat(2.7574) * xae;
  const V decay3 = select(d3 == dlsa, decay_dlsa, vexp(-d3 * splat(1.0 / 50e3)));
  const V a3 = diffraction(d3, decay3), a4 = diffraction(d4, decay3 * splat(p.decay_d4));
  const V emd = (a4 - a3) / (d4 - d3), aed = a3 - emd * d3;

  V aref = splat(0.0), mode = splat(0.0);
  const I line_of_sight = dist < dlsa;
  if (any(line_of_sight)) {
    // A_el + k_1 d + k_2 ln d through the line-of-sight attenuation (4.44, two rays over rough
    // ground) at d0 and d1 and the diffraction line at d2 = d_Ls, with k_1, k_2 >= 0.
    const V wls = splat(0.021) / (splat(0.021) + wn * dh / vmax(splat(10e3), dlsa));
    const V hsum = he[0] + he[1], hprod = he[0] * he[1];
    auto los = [&](V d) {
      const V sh = sigma_h(delta_h_over(vexp(-d * splat(1.0 / 50e3)), dh));
      const V sin_psi = hsum / vsqrt(d * d + hsum * hsum);
      // R = (sin psi - Z_g) / (sin psi + Z_g) exp(-min(10, k sigma_h sin psi)), in real arithmetic.
      const V zr = splat(p.zg_re), zi = splat(p.zg_im);
      const V nr = sin_psi - zr, dr = sin_psi + zr;
      const V scale = vexp(-vmin(splat(10.0), wn * sh * sin_psi)) / (dr * dr + zi * zi);
      V rr = (nr * dr - zi * zi) * scale, ri = (-zi * dr - nr * zi) * scale;
      const V r2 = rr * rr + ri * ri;
      const I raise = (r2 < splat(0.25)) | (r2 < sin_psi);
      const V f = select(raise, vsqrt(sin_psi / r2), splat(1.0));
      rr = rr * f;
      ri = ri * f;
      const V extended = emd * d + aed;
      V delta = splat(2.0) * wn * hprod / d;  // the rays' phase difference
      delta = select(delta > splat(1.57), splat(3.14) - splat(2.4649) / delta, delta);
      V sine, cosine;
      vsincos(delta, sine, cosine);
      const V sum_r = cosine + rr, sum_i = -sine + ri;
      const V two_ray = splat(-4.343) * vlog(sum_r * sum_r + sum_i * sum_i);
      return (two_ray - extended) * wls + extended;
    };
    const V d2 = dlsa, a2 = aed + d2 * emd;
    const I aed_positive = aed >= splat(0.0);
    V d0 = splat(1.908) * wn * hprod;
    d0 = select(aed_positive, vmin(d0, splat(0.5) * dla), d0);
    const V d1 = select(aed_positive, d0 + splat(0.25) * (dla - d0), vmax(-aed / emd, splat(0.25) * dla));
    const V a1 = los(d1);
    const V ln_d2 = vlog(d2);
    const I two_points = d0 < d1;
    V ak1 = splat(0.0), ak2 = splat(0.0);
    I fitted = I{};
    if (any(two_points)) {
      const V a0 = los(d0);
      const V ln_d0 = vlog(d0);
      const V q = ln_d2 - ln_d0;  // ln(d2 / d0)
      const V k2 = vmax(splat(0.0), ((d2 - d0) * (a1 - a0) - (d1 - d0) * (a2 - a0)) / ((d2 - d0) * (vlog(d1) - ln_d0) - (d1 - d0) * q));
      fitted = two_points & (aed_positive | (k2 > splat(0.0)));
      V k1 = (a2 - a0 - k2 * q) / (d2 - d0);
      const I negative = k1 < splat(0.0);
      const V k2_flat = vmax(a2 - a0, splat(0.0)) / q;
      const V k1_flat = select(k2_flat == splat(0.0), emd, splat(0.0));
      ak2 = select(fitted, select(negative, k2_flat, k2), ak2);
      ak1 = select(fitted, select(negative, k1_flat, k1), ak1);
    }
    const V k1_two = vmax(a2 - a1, splat(0.0)) / (d2 - d1);
    ak1 = select(fitted, ak1, select(k1_two == splat(0.0), emd, k1_two));
    ak2 = select(fitted, ak2, splat(0.0));
    const V ael = a2 - ak1 * d2 - ak2 * ln_d2;
    aref = select(line_of_sight, ael + ak1 * dist + select(ak2 != splat(0.0), ak2 * splat(p.ln_dist), splat(0.0)), aref);
  }
  const I beyond = ~line_of_sight;
  if (any(beyond)) {
    // The diffraction line, or the troposcatter line beyond the distance d_x where it crosses
    // below; d_x is at least dx_floor, so shorter paths need no scatter at all.
    const V dx_floor = vmax(dlsa, dla + splat(p.scatter_offset));
    V dx = dx_floor, ems = emd, aes = aed;
    const I scatter_needed = beyond & (dist > dx_floor);
    if (any(scatter_needed)) {
      V ad = dl[0] - dl[1], rr = he[1] / he[0];
      const I swap = ad < splat(0.0);
      ad = select(swap, -ad, ad);
      rr = select(swap, splat(1.0) / rr, rr);
      const V etq = splat((5.67e-6 * p.ens - 2.32e-3) * p.ens + 0.031);
      // H_0 carries from one distance to the next (kept when the new one would exceed
      // 15 dB), so the farther distance is evaluated first, as in the Algorithm.
      V h0s = splat(-15.0);
      auto scatter = [&](V d) {
        const I fresh = h0s <= splat(15.0);
        const V th = the[0] + the[1] + d * gme;
        const V r1 = splat(2.0) * wn * th * he[0], r2 = splat(2.0) * wn * th * he[1];
        const I none = fresh & (r1 < splat(0.2)) & (r2 < splat(0.2));
        V ss = (d - ad) / (d + ad);
        const V q = vmin(vmax(splat(0.1), rr / ss), splat(10.0));
        ss = vmax(splat(0.1), ss);
        const V z0 = (d - ad) * (d + ad) * th * splat(0.25) / d;  // height of the crossing rays
        const V z0c = vmin(splat(1.7), z0 / splat(8.0e3));
        const V z0c2 = z0c * z0c;
        const V et = (etq * vexp(-(z0c2 * z0c2 * z0c2)) + splat(1.0)) * z0 / splat(1.7556e3);
        const V ett = vmax(et, splat(1.0));
        V h0 = splat(0.5) * (frequency_gain(r1, ett) + frequency_gain(r2, ett));
        h0 = h0 + vmin(h0, (splat(1.38) - vlog(ett)) * vlog(ss) * vlog(q) * splat(0.49));
        h0 = vmax(h0, splat(0.0));
        const V f = (splat(1.0) + splat(1.4142) / r1) * (splat(1.0) + splat(1.4142) / r2);
        const V low = et * h0 + (splat(1.0) - et) * splat(4.343) * vlog(f * f * (r1 + r2) / (r1 + r2 + splat(2.8284)));
        h0 = select(et < splat(1.0), low, h0);
        h0 = select((h0 > splat(15.0)) & (h0s >= splat(0.0)), h0s, h0);
        h0 = select(fresh, h0, h0s);
        h0s = select(none, h0s, h0);
        const V th2 = tha + d * gme;
        const V th4 = (th2 * th2) * (th2 * th2);
        const V value = scatter_function(th2 * d) + splat(4.343) * vlog(splat(47.7) * wn * th4) -
                        splat(0.1) * (splat(p.ens) - splat(301.0)) * vexp(-th2 * d / splat(40e3)) + h0;
        return select(none, splat(1001.0), value);
      };
      const V d5 = dla + splat(200e3), d6 = d5 + splat(200e3);
      const V a6 = scatter(d6);
      const V a5 = scatter(d5);
      const I has_scatter = scatter_needed & (a5 < splat(1000.0));
      const V slope = (a6 - a5) / splat(200e3);
      const V crossing = vmax(dx_floor, (a5 - aed - slope * d5) / (emd - slope));
      ems = select(has_scatter, slope, ems);
      dx = select(has_scatter, crossing, select(scatter_needed, splat(10e6), dx));
      aes = select(has_scatter, (emd - slope) * crossing + aed, aes);
    }
    const I tropo = dist > dx;
    aref = select(beyond, select(tropo, aes + ems * dist, aed + emd * dist), aref);
    mode = select(beyond, select(tropo, splat(2.0), splat(1.0)), mode);
  }
  aref = vmax(aref, splat(0.0));

  // Variability: the climate's median adjustment V(d_e) and the deviations of time, location
  // and situation combined as MDVAR says; attenuations below zero compressed.
  const V dexa = terms[0].dexa + terms[1].dexa + splat(p.dexa_frequency);
  const V de = select(dist < dexa, splat(130e3) * dist / dexa, splat(130e3) + dist - dexa);
  const V vmd = climate_curve(p.median, de);
  const V sgtm = climate_curve(p.sigma_minus, de) * splat(p.g_minus);
  const V sgtp = climate_curve(p.sigma_plus, de) * splat(p.g_plus);
  const V sgtd = sgtp * splat(p.sd), tgtd = (sgtp - sgtd) * splat(p.zd);
  V sgl = splat(0.0);
  if (p.location_variability) {
    const V q = delta_h_over(splat(p.decay_dist), dh) * wn;
    sgl = splat(10.0) * q / (q + splat(13.0));
  }
  V vs0 = splat(0.0);
  if (p.situation_variability) {
    const V a = splat(5.0) + splat(3.0) * vexp(-de * splat(1.0 / 100e3));
    vs0 = a * a;
  }
  const double zt = p.zt, zl = p.zl, zc = p.zc;
  const V sgt = zt < 0.0 ? sgtm : zt <= p.zd ? sgtp : sgtd + tgtd / splat(zt);
  const V vs = vs0 + (sgt * splat(zt)) * (sgt * splat(zt)) / splat(7.8 + zc * zc) +
               (sgl * splat(zl)) * (sgl * splat(zl)) / splat(24.0 + zc * zc);
  V yr = splat(0.0), sgc = splat(0.0);
  switch (p.variability) {
    case 0: sgc = vsqrt(sgt * sgt + sgl * sgl + vs); break;
    case 1:
      yr = sgt * splat(zt);
      sgc = vsqrt(sgl * sgl + vs);
      break;
    case 2:
      yr = vsqrt(sgt * sgt + sgl * sgl) * splat(zt);
      sgc = vsqrt(vs);
      break;
    default:
      yr = sgt * splat(zt) + sgl * splat(zl);
      sgc = vsqrt(vs);
      break;
  }
  V a = aref - vmd - yr - sgc * splat(zc);
  a = select(a < splat(0.0), a * (splat(29.0) - a) / (splat(29.0) - splat(10.0) * a), a);

  store(lanes.attenuation_db, a);
  store(lanes.loss_db, splat(p.free_space_db) + a);
  store(lanes.reference_db, aref);
  store(lanes.mode, mode);
  store(lanes.warning, warning);
  for (int j = 0; j < 2; ++j) {
    store(lanes.he[j], he[j]);
    store(lanes.dl[j], dl[j]);
    store(lanes.the[j], the[j]);
  }
}

// Delta h's passes, four points at a time.
using Q = double __attribute__((vector_size(8 * kSumParts)));
using QI = std::int64_t __attribute__((vector_size(8 * kSumParts)));
inline Q qsplat(double x) { return Q{} + x; }
inline QI qbits(Q x) {
  QI i;
  __builtin_memcpy(&i, &x, sizeof i);
  return i;
}
inline Q qload(const double* p) {
  Q v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
inline Q lane_numbers() {
  Q v;
  for (int l = 0; l < kSumParts; ++l) v[l] = l;
  return v;
}

inline Sums resample_lanes(const double* z, int np, int k0, double xa, double step, int n, double* s) {
  const Q lo = qsplat(k0), hi = qsplat(np), count = qsplat(n), first = lane_numbers(), shift = qsplat(kRoundShift);
  Q sum = qsplat(0.0), sum_i = qsplat(0.0);
  for (int j = 0; j < n; j += kSumParts) {
    const Q jv = qsplat(j) + first;
    const Q p = qsplat(xa) + jv * qsplat(step);
    Q k = (p + shift) - shift;        // p rounded to a whole number
    k = k < p ? k + qsplat(1.0) : k;  // up
    k = k < lo ? lo : k;
    k = hi < k ? hi : k;
    const QI index = qbits(k + shift) - qbits(shift);
#if defined(__AVX2__)
    // Each lane's two samples in one load, then the lanes' first and second halves together.
    static_assert(kSumParts == 4);
    const __m128d p0 = _mm_loadu_pd(z + index[0] - 1), p1 = _mm_loadu_pd(z + index[1] - 1);
    const __m128d p2 = _mm_loadu_pd(z + index[2] - 1), p3 = _mm_loadu_pd(z + index[3] - 1);
    const __m256d a = _mm256_insertf128_pd(_mm256_castpd128_pd256(p0), p2, 1);  // z[k0-1] z[k0] z[k2-1] z[k2]
    const __m256d b = _mm256_insertf128_pd(_mm256_castpd128_pd256(p1), p3, 1);
    const Q zm = __builtin_bit_cast(Q, _mm256_unpacklo_pd(a, b));  // z[k0-1] z[k1-1] z[k2-1] z[k3-1]
    const Q zk = __builtin_bit_cast(Q, _mm256_unpackhi_pd(a, b));
#else
    Q zk, zm;
    for (int l = 0; l < kSumParts; ++l) {
      zk[l] = z[index[l]];
      zm[l] = z[index[l] - 1];
    }
#endif
    const Q v = jv < count ? zk + (zk - zm) * (p - k) : qsplat(0.0);
    __builtin_memcpy(s + j, &v, sizeof v);
    sum = sum + v;
    sum_i = sum_i + jv * v;
  }
  Sums out;
  for (int l = 0; l < kSumParts; l += 2) {
    out.sum += sum[l] + sum[l + 1];
    out.sum_i += sum_i[l] + sum_i[l + 1];
  }
  return out;
}

inline Counts beyond_lanes(const double* s, int n, double at0, double slope, double low_threshold, double high_threshold,
                           double* low, double* high) {
  const Q first = lane_numbers(), lt = qsplat(low_threshold), ht = qsplat(high_threshold), count = qsplat(n);
  Counts c;
  for (int j = 0; j < n; j += kSumParts) {
    const Q jv = qsplat(j) + first;
    const Q r = qload(s + j) - (qsplat(at0) + qsplat(slope) * jv);
    const QI inside = jv < count;
    const QI below = inside & (r <= lt), above = inside & (r >= ht);
#if defined(__AVX2__)
    // Each side's lanes moved to the front (a permutation per 4-bit mask), stored whole, the
    // count advanced by how many there were.
    static_assert(kSumParts == 4);
    static constexpr int kOrder[16][8] = {
        {0, 1, 2, 3, 4, 5, 6, 7}, {0, 1, 2, 3, 4, 5, 6, 7}, {2, 3, 0, 1, 4, 5, 6, 7}, {0, 1, 2, 3, 4, 5, 6, 7},
        {4, 5, 0, 1, 2, 3, 6, 7}, {0, 1, 4, 5, 2, 3, 6, 7}, {2, 3, 4, 5, 0, 1, 6, 7}, {0, 1, 2, 3, 4, 5, 6, 7},
        {6, 7, 0, 1, 2, 3, 4, 5}, {0, 1, 6, 7, 2, 3, 4, 5}, {2, 3, 6, 7, 0, 1, 4, 5}, {0, 1, 2, 3, 6, 7, 4, 5},
        {4, 5, 6, 7, 0, 1, 2, 3}, {0, 1, 4, 5, 6, 7, 2, 3}, {2, 3, 4, 5, 6, 7, 0, 1}, {0, 1, 2, 3, 4, 5, 6, 7}};
    static constexpr std::size_t kCount[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
    const __m256 values = __builtin_bit_cast(__m256, r);
    auto put = [&](QI mask, double* out, std::size_t& n_out) {
      const int m = _mm256_movemask_pd(__builtin_bit_cast(__m256d, mask));
      const __m256i order = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kOrder[m]));
      _mm256_storeu_ps(reinterpret_cast<float*>(out + n_out), _mm256_permutevar8x32_ps(values, order));
      n_out += kCount[m];
    };
    put(below, low, c.low);
    put(above, high, c.high);
#else
    for (int l = 0; l < kSumParts; ++l) {
      low[c.low] = r[l];
      c.low += below[l] != 0 ? 1 : 0;
      high[c.high] = r[l];
      c.high += above[l] != 0 ? 1 : 0;
    }
#endif
  }
  return c;
}

// This copy's entry points (declared above); each file that includes this header with its
// own TERRAVOL_ITM_KERNEL defines its copy's.
void evaluate(const Path& p, Lanes& lanes) { evaluate_lanes(p, lanes); }
template <bool kLargest>
inline double kth_extreme_lanes(double* c, std::size_t count, std::size_t k) {
  // The values beyond the k-th smallest lie above it: the largest is taken off (for the k-th
  // largest, the smallest), exact in any order.
  auto extreme = [](auto a, auto b) { return kLargest ? (b < a ? b : a) : (a < b ? b : a); };
  for (std::size_t beyond = count - 1 - k;; --beyond) {
    for (std::size_t i = count; i % kSumParts != 0; ++i) c[i] = kLargest ? kInf : -kInf;
    Q top = qload(c);
    for (std::size_t i = kSumParts; i < count; i += kSumParts) top = extreme(top, qload(c + i));
    double value = top[0];
    for (int l = 1; l < kSumParts; ++l) value = extreme(value, top[l]);
    if (beyond == 0) return value;
    std::size_t at = 0;
    while (c[at] != value) ++at;
    c[at] = c[--count];
  }
}

Sums resample(const double* z, int np, int k0, double xa, double step, int n, double* s) {
  return resample_lanes(z, np, k0, xa, step, n, s);
}
double kth_extreme(double* c, std::size_t count, std::size_t k, bool largest) {
  return largest ? kth_extreme_lanes<true>(c, count, k) : kth_extreme_lanes<false>(c, count, k);
}
Counts beyond(const double* s, int n, double at0, double slope, double low_threshold, double high_threshold, double* low,
              double* high) {
  return beyond_lanes(s, n, at0, slope, low_threshold, high_threshold, low, high);
}

}  // namespace terravol::volume::itm_kernel::TERRAVOL_ITM_KERNEL

#pragma GCC diagnostic pop

#endif  // TERRAVOL_ITM_KERNEL
