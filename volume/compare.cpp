#include "volume/compare.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace terravol::volume {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTolerance = 1e-6;  // of a spacing

// The lattice coordinate f on one axis: the lower index and the weight of the upper one.
// False outside the axis.
bool locate(const Lattice& l, int axis, double w, int& i0, double& t) {
  const double f = (w - l.origin[axis]) / l.spacing[axis];
  const int n = l.dims[axis];
  if (!std::isfinite(f) || f < -kTolerance || f > (n - 1) + kTolerance) return false;
  if (n == 1) {
    i0 = 0;
    t = 0.0;
    return true;
  }
  const double c = std::clamp(f, 0.0, static_cast<double>(n - 1));
  i0 = std::min(static_cast<int>(std::floor(c)), n - 2);
  t = c - i0;
  if (t < kTolerance) t = 0.0;
  if (t > 1.0 - kTolerance) t = 1.0;
  return true;
}

double median(std::vector<double>& v) {
  if (v.empty()) return kNaN;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double upper = v[mid];
  if (v.size() % 2 == 1) return upper;
  const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

}  // namespace

LayerComparison compare_values(std::span<const double> a, std::span<const double> b, double w2) {
  LayerComparison r;
  r.w2 = w2;
  r.points = a.size();
  const double n = static_cast<double>(a.size());
  double ma = 0.0, mb = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    ma += a[k];
    mb += b[k];
  }
  ma /= n;
  mb /= n;
  double saa = 0.0, sbb = 0.0, sab = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    saa += (a[k] - ma) * (a[k] - ma);
    sbb += (b[k] - mb) * (b[k] - mb);
    sab += (a[k] - ma) * (b[k] - mb);
  }
  r.pearson = (a.size() >= 2 && saa > 0.0 && sbb > 0.0) ? sab / std::sqrt(saa * sbb) : kNaN;
  std::vector<double> d(a.size()), ad(a.size()), ca(a.begin(), a.end()), cb(b.begin(), b.end());
  for (std::size_t k = 0; k < a.size(); ++k) {
    d[k] = b[k] - a[k];
    ad[k] = std::abs(d[k]);
  }
  r.median_difference = median(d);
  r.median_abs_difference = median(ad);
  r.median_a = median(ca);
  r.median_b = median(cb);
  return r;
}

std::optional<double> sample_trilinear(const Volume& v, double w0, double w1, double w2) {
  const Lattice& l = v.lattice;
  int i[3];
  double t[3];
  const double w[3] = {w0, w1, w2};
  for (int a = 0; a < 3; ++a) {
    if (!locate(l, a, w[a], i[a], t[a])) return std::nullopt;
  }
  double sum = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    double weight = 1.0;
    int idx[3];
    for (int a = 0; a < 3; ++a) {
      const bool upper = (corner >> a) & 1;
      weight *= upper ? t[a] : 1.0 - t[a];
      idx[a] = i[a] + (upper ? 1 : 0);
    }
    if (weight == 0.0) continue;
    const float value = v.at(idx[0], idx[1], idx[2]);
    if (!std::isfinite(value)) return std::nullopt;
    sum += weight * value;
  }
  return sum;
}

Comparison compare_volumes(const Volume& a, const Volume& b) {
  if (!(a.frame == b.frame)) {
    throw std::invalid_argument("the frames differ: " + format_frame(a.frame) + " vs " +
                                format_frame(b.frame));
  }
  Comparison out;
  const Lattice& l = a.lattice;
  std::vector<double> all_a, all_b;
  for (int k = 0; k < l.dims[2]; ++k) {
    std::vector<double> va, vb;
    const double w2 = l.world(2, k);
    for (int j = 0; j < l.dims[1]; ++j) {
      const double w1 = l.world(1, j);
      for (int i = 0; i < l.dims[0]; ++i) {
        const float x = a.at(i, j, k);
        if (!std::isfinite(x)) continue;
        const auto y = sample_trilinear(b, l.world(0, i), w1, w2);
        if (!y) continue;
        va.push_back(x);
        vb.push_back(*y);
      }
    }
    out.layers.push_back(compare_values(va, vb, w2));
    all_a.insert(all_a.end(), va.begin(), va.end());
    all_b.insert(all_b.end(), vb.begin(), vb.end());
  }
  out.all = compare_values(all_a, all_b, kNaN);
  return out;
}

}  // namespace terravol::volume
