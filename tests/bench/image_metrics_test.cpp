#include "bench/image_metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace terravol::bench {
namespace {

using Bytes = std::vector<std::uint8_t>;

// A smooth RGB test pattern with some edges (gradients and a checker of 16-pixel squares).
Bytes pattern(int width, int height) {
  Bytes rgb(static_cast<std::size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      std::uint8_t* p = &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
      const bool dark = ((x / 16) + (y / 16)) % 2 == 0;
      p[0] = static_cast<std::uint8_t>(40 + (170 * x) / width);
      p[1] = static_cast<std::uint8_t>(40 + (170 * y) / height);
      p[2] = static_cast<std::uint8_t>(dark ? 60 : 190);
    }
  }
  return rgb;
}

// `image` plus Gaussian noise of the given standard deviation (8-bit steps), clamped; fixed seed.
Bytes noisy(const Bytes& image, double sigma, unsigned seed = 1234) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  Bytes out(image.size());
  for (std::size_t i = 0; i < image.size(); ++i) {
    out[i] = static_cast<std::uint8_t>(std::clamp(std::lround(image[i] + noise(rng)), 0L, 255L));
  }
  return out;
}

// Mean SSIM straight from the paper's equations (13)-(17): for each 11x11 window, the weighted
// mean, variances and covariance with the 2D Gaussian weights, variances as sums of squared
// deviations. Slow (121 taps per window) and independent of the separable implementation.
double reference_ssim(const Bytes& a, const Bytes& b, int width, int height) {
  const auto luma = [&](const Bytes& rgb, int x, int y) {
    const std::uint8_t* p = &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
    return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
  };
  double w[11][11], sum = 0;
  for (int i = 0; i < 11; ++i) {
    for (int j = 0; j < 11; ++j) {
      w[i][j] = std::exp(-((i - 5) * (i - 5) + (j - 5) * (j - 5)) / (2 * 1.5 * 1.5));
      sum += w[i][j];
    }
  }
  const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
  double total = 0;
  for (int y0 = 0; y0 + 11 <= height; ++y0) {
    for (int x0 = 0; x0 + 11 <= width; ++x0) {
      double mx = 0, my = 0;
      for (int i = 0; i < 11; ++i) {
        for (int j = 0; j < 11; ++j) {
          mx += w[i][j] / sum * luma(a, x0 + j, y0 + i);
          my += w[i][j] / sum * luma(b, x0 + j, y0 + i);
        }
      }
      double vx = 0, vy = 0, cxy = 0;
      for (int i = 0; i < 11; ++i) {
        for (int j = 0; j < 11; ++j) {
          const double dx = luma(a, x0 + j, y0 + i) - mx, dy = luma(b, x0 + j, y0 + i) - my;
          vx += w[i][j] / sum * dx * dx;
          vy += w[i][j] / sum * dy * dy;
          cxy += w[i][j] / sum * dx * dy;
        }
      }
      total += ((2 * mx * my + c1) * (2 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
    }
  }
  return total / ((width - 10.0) * (height - 10.0));
}

TEST(ImageMetrics, IdenticalImagesAreInfinitePsnrUnitSsimAndNoDifference) {
  const Bytes a = pattern(64, 48);
  EXPECT_EQ(psnr(a, a, 64, 48), std::numeric_limits<double>::infinity());
  EXPECT_DOUBLE_EQ(ssim(a, a, 64, 48), 1.0);
  EXPECT_EQ(share_differing(a, a, 64, 48, 0), 0.0);
}

TEST(ImageMetrics, ConstantOffsetGivesClosedFormPsnr) {
  // Every channel off by d: MSE = d^2, PSNR = 20 log10(255 / d).
  const Bytes a = pattern(32, 20);
  for (int d : {1, 5, 30}) {
    Bytes b = a;
    for (auto& v : b) v = static_cast<std::uint8_t>(v + d);  // the pattern's values are at most 209
    EXPECT_NEAR(psnr(a, b, 32, 20), 20.0 * std::log10(255.0 / d), 1e-12) << "offset " << d;
  }
}

TEST(ImageMetrics, PsnrOfOneChangedValue) {
  // One value off by 255 among 2 * 2 * 3: MSE = 255^2 / 12, PSNR = 10 log10(12).
  Bytes a(12, 0), b(12, 0);
  b[7] = 255;
  EXPECT_NEAR(psnr(a, b, 2, 2), 10.0 * std::log10(12.0), 1e-12);
}

TEST(ImageMetrics, SsimFallsAsNoiseGrows) {
  const Bytes a = pattern(96, 64);
  double previous = 1.0;
  for (double sigma : {2.0, 8.0, 20.0, 50.0}) {
    const double s = ssim(a, noisy(a, sigma), 96, 64);
    EXPECT_LT(s, previous) << "noise sigma " << sigma;
    EXPECT_GT(s, -1.0);
    previous = s;
  }
  EXPECT_LT(previous, 0.5);  // sigma 50 leaves little structure
}

TEST(ImageMetrics, SsimMatchesTheDirectEvaluationOfThePaper) {
  const Bytes a = pattern(37, 29);
  for (double sigma : {3.0, 25.0}) {
    const Bytes b = noisy(a, sigma, 99);
    EXPECT_NEAR(ssim(a, b, 37, 29), reference_ssim(a, b, 37, 29), 1e-9) << "noise sigma " << sigma;
  }
  Bytes inverted = a;
  for (auto& v : inverted) v = static_cast<std::uint8_t>(255 - v);  // anticorrelated: SSIM < 0
  const double s = ssim(a, inverted, 37, 29);
  EXPECT_NEAR(s, reference_ssim(a, inverted, 37, 29), 1e-9);
  EXPECT_LT(s, 0.0);
}

TEST(ImageMetrics, SsimIsSymmetric) {
  const Bytes a = pattern(40, 30), b = noisy(a, 15.0);
  EXPECT_EQ(ssim(a, b, 40, 30), ssim(b, a, 40, 30));
  EXPECT_EQ(psnr(a, b, 40, 30), psnr(b, a, 40, 30));
}

TEST(ImageMetrics, SsimOfConstantImagesFollowsTheLuminanceTerm) {
  // Flat images: every window has zero variance, so SSIM = (2 m n + C1) / (m^2 + n^2 + C1).
  const double m = 100, n = 120, c1 = (0.01 * 255) * (0.01 * 255);
  const Bytes a(20 * 15 * 3, 100), b(20 * 15 * 3, 120);
  EXPECT_NEAR(ssim(a, b, 20, 15), (2 * m * n + c1) / (m * m + n * n + c1), 1e-12);
}

TEST(ImageMetrics, SsimSeesStructureThatPsnrMisses) {
  // The same MSE either as a uniform brightness shift or as noise: SSIM ranks the shift higher.
  const Bytes a = pattern(64, 64);
  Bytes shifted = a;
  for (auto& v : shifted) v = static_cast<std::uint8_t>(v + 10);
  const Bytes noise = noisy(a, 10.0);
  EXPECT_NEAR(psnr(a, shifted, 64, 64), psnr(a, noise, 64, 64), 0.5);
  EXPECT_GT(ssim(a, shifted, 64, 64), ssim(a, noise, 64, 64) + 0.1);
}

TEST(ImageMetrics, ShareCountsExactlyTheChangedPixels) {
  const int w = 10, h = 10;
  const Bytes a = pattern(w, h);
  Bytes b = a;
  // 7 pixels changed: 3 by 1 in one channel, 4 by 40 in another.
  for (int i : {0, 13, 27}) b[static_cast<std::size_t>(i) * 3] ^= 1;
  for (int i : {50, 51, 88, 99}) b[static_cast<std::size_t>(i) * 3 + 2] -= 40;
  EXPECT_DOUBLE_EQ(share_differing(a, b, w, h, 0), 7.0 / 100.0);
  EXPECT_DOUBLE_EQ(share_differing(a, b, w, h, 1), 4.0 / 100.0);  // "more than" the threshold
  EXPECT_DOUBLE_EQ(share_differing(a, b, w, h, 39), 4.0 / 100.0);
  EXPECT_DOUBLE_EQ(share_differing(a, b, w, h, 40), 0.0);
}

TEST(ImageMetrics, MismatchedSizesThrow) {
  const Bytes a = pattern(16, 12), short_one(16 * 12 * 3 - 1, 0);
  EXPECT_THROW(psnr(a, short_one, 16, 12), std::invalid_argument);
  EXPECT_THROW(psnr(short_one, a, 16, 12), std::invalid_argument);
  EXPECT_THROW(ssim(a, short_one, 16, 12), std::invalid_argument);
  EXPECT_THROW(share_differing(a, short_one, 16, 12, 0), std::invalid_argument);
  EXPECT_THROW(psnr(a, a, 12, 16 + 1), std::invalid_argument);  // both wrong for the size
  EXPECT_THROW(psnr({}, {}, 0, 0), std::invalid_argument);
  EXPECT_THROW(psnr(a, a, -16, -12), std::invalid_argument);
  EXPECT_THROW(share_differing(a, a, 16, 12, -1), std::invalid_argument);
}

TEST(ImageMetrics, SsimNeedsRoomForOneWindow) {
  const Bytes a = pattern(10, 40), b = pattern(40, 10), c = pattern(11, 11);
  EXPECT_THROW(ssim(a, a, 10, 40), std::invalid_argument);
  EXPECT_THROW(ssim(b, b, 40, 10), std::invalid_argument);
  EXPECT_DOUBLE_EQ(ssim(c, c, 11, 11), 1.0);  // exactly one window
}

}  // namespace
}  // namespace terravol::bench
