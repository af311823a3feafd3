// SSIM as defined in
//   Z. Wang, A. C. Bovik, H. R. Sheikh, E. P. Simoncelli, "Image quality assessment: from error
//   visibility to structural similarity", IEEE Transactions on Image Processing 13(4), 600-612,
//   2004: equation (13) evaluated with the 11x11 circular-symmetric Gaussian weighting of
//   section III-C (sigma 1.5, normalised to sum 1), the local statistics of equations (14)-(16),
//   C1 = (K1 L)^2, C2 = (K2 L)^2, and the mean SSIM of equation (17) over all windows inside
//   the image (the reference code's 'valid' filtering).
// Written here because VTK 9.1 has no SSIM filter (vtkImageSSIM came with VTK 9.2).
// Departures from the paper: it works on luma (Rec. 601 weights; the reference MATLAB code's
// rgb2gray rounds them to 0.2989, 0.5870, 0.1140) rather than on a given grey image, and the
// five local sums are computed with the separable form of the Gaussian (a horizontal then a
// vertical 11-tap pass, rows streamed through a ring of 11), equal up to rounding.
#include "bench/image_metrics.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace terravol::bench {

namespace {

constexpr int kWindow = 11;     // the Gaussian window's side, pixels
constexpr double kSigma = 1.5;  // its standard deviation, pixels
constexpr double kK1 = 0.01, kK2 = 0.03, kPeak = 255.0;

// The number of channel bytes; throws unless both spans hold exactly width * height * 3.
std::size_t checked_bytes(const char* function, std::span<const std::uint8_t> a,
                          std::span<const std::uint8_t> b, int width, int height) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument(std::string(function) + ": image size " + std::to_string(width) +
                                "x" + std::to_string(height) + " is empty");
  }
  const std::size_t bytes = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3;
  if (a.size() != bytes || b.size() != bytes) {
    throw std::invalid_argument(std::string(function) + ": " + std::to_string(a.size()) + " and " +
                                std::to_string(b.size()) + " bytes for " + std::to_string(width) +
                                "x" + std::to_string(height) + " RGB (" + std::to_string(bytes) +
                                " expected)");
  }
  return bytes;
}

// The 1D Gaussian whose outer product with itself is the paper's 11x11 window (sum 1).
std::array<double, kWindow> gaussian_taps() {
  std::array<double, kWindow> g{};
  double sum = 0;
  for (int k = 0; k < kWindow; ++k) {
    const double d = k - kWindow / 2;
    g[k] = std::exp(-d * d / (2 * kSigma * kSigma));
    sum += g[k];
  }
  for (double& v : g) v /= sum;
  return g;
}

std::vector<double> luma(std::span<const std::uint8_t> rgb) {
  std::vector<double> y(rgb.size() / 3);
  for (std::size_t i = 0; i < y.size(); ++i) {
    y[i] = 0.299 * rgb[3 * i] + 0.587 * rgb[3 * i + 1] + 0.114 * rgb[3 * i + 2];
  }
  return y;
}

// The five maps filtered: means of a, b, a^2, b^2 and ab under the window.
enum Map { kA, kB, kAA, kBB, kAB, kMaps };

}  // namespace

double psnr(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, int width,
            int height) {
  const std::size_t n = checked_bytes("psnr", a, b, width, height);
  std::uint64_t sum = 0;  // at most 255^2 per value: exact below 2.8e14 values
  for (std::size_t i = 0; i < n; ++i) {
    const int d = int(a[i]) - int(b[i]);
    sum += static_cast<std::uint64_t>(d * d);
  }
  if (sum == 0) return std::numeric_limits<double>::infinity();
  const double mse = static_cast<double>(sum) / static_cast<double>(n);
  return 10.0 * std::log10(kPeak * kPeak / mse);
}

double ssim(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, int width,
            int height) {
  checked_bytes("ssim", a, b, width, height);
  if (width < kWindow || height < kWindow) {
    throw std::invalid_argument("ssim: image size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is smaller than the 11x11 window");
  }
  const std::array<double, kWindow> g = gaussian_taps();
  const std::vector<double> ya = luma(a), yb = luma(b);
  const std::size_t w = static_cast<std::size_t>(width);
  const std::size_t out_w = w - (kWindow - 1);

  // The last kWindow input rows, filtered horizontally, in a ring:
  // ring[((y % kWindow) * kMaps + map) * out_w + x].
  std::vector<double> ring(static_cast<std::size_t>(kWindow) * kMaps * out_w);
  std::vector<double> products(kMaps * w);    // one input row's five maps before filtering
  std::vector<double> column(kMaps * out_w);  // one output row's five filtered maps
  const double c1 = (kK1 * kPeak) * (kK1 * kPeak), c2 = (kK2 * kPeak) * (kK2 * kPeak);
  double total = 0;

  for (int y = 0; y < height; ++y) {
    const double* ra = ya.data() + static_cast<std::size_t>(y) * w;
    const double* rb = yb.data() + static_cast<std::size_t>(y) * w;
    double* p = products.data();
    for (std::size_t x = 0; x < w; ++x) {
      p[kA * w + x] = ra[x];
      p[kB * w + x] = rb[x];
      p[kAA * w + x] = ra[x] * ra[x];
      p[kBB * w + x] = rb[x] * rb[x];
      p[kAB * w + x] = ra[x] * rb[x];
    }
    double* slot = ring.data() + static_cast<std::size_t>(y % kWindow) * kMaps * out_w;
    for (int m = 0; m < kMaps; ++m) {
      double* dst = slot + m * out_w;
      const double* src = p + m * w;
      for (std::size_t x = 0; x < out_w; ++x) dst[x] = 0;
      for (int k = 0; k < kWindow; ++k) {
        const double gk = g[k];
        for (std::size_t x = 0; x < out_w; ++x) dst[x] += gk * src[x + k];
      }
    }
    if (y < kWindow - 1) continue;

    // The window rows y - 10 .. y are complete: filter vertically, then evaluate equation (13).
    for (std::size_t i = 0; i < column.size(); ++i) column[i] = 0;
    for (int k = 0; k < kWindow; ++k) {
      const double gk = g[k];
      const double* src =
          ring.data() + static_cast<std::size_t>((y - (kWindow - 1) + k) % kWindow) * kMaps * out_w;
      for (std::size_t i = 0; i < column.size(); ++i) column[i] += gk * src[i];
    }
    const double* mu_a = column.data() + kA * out_w;
    const double* mu_b = column.data() + kB * out_w;
    const double* e_aa = column.data() + kAA * out_w;
    const double* e_bb = column.data() + kBB * out_w;
    const double* e_ab = column.data() + kAB * out_w;
    double row_sum = 0;
    for (std::size_t x = 0; x < out_w; ++x) {
      const double mab = mu_a[x] * mu_b[x];
      const double maa = mu_a[x] * mu_a[x], mbb = mu_b[x] * mu_b[x];
      const double var_a = e_aa[x] - maa, var_b = e_bb[x] - mbb, cov = e_ab[x] - mab;
      row_sum += ((2.0 * mab + c1) * (2.0 * cov + c2)) / ((maa + mbb + c1) * (var_a + var_b + c2));
    }
    total += row_sum;
  }
  const std::size_t windows = out_w * static_cast<std::size_t>(height - (kWindow - 1));
  return total / static_cast<double>(windows);
}

double share_differing(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, int width,
                       int height, int threshold) {
  const std::size_t n = checked_bytes("share_differing", a, b, width, height);
  if (threshold < 0) {
    throw std::invalid_argument("share_differing: negative threshold " + std::to_string(threshold));
  }
  std::size_t differing = 0;
  for (std::size_t i = 0; i < n; i += 3) {
    bool differs = false;
    for (std::size_t k = 0; k < 3; ++k)
      differs |= std::abs(int(a[i + k]) - int(b[i + k])) > threshold;
    differing += differs;
  }
  return static_cast<double>(differing) / static_cast<double>(n / 3);
}

}  // namespace terravol::bench
