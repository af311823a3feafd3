// Image quality between two renders of the same view: PSNR, mean SSIM and the share of pixels
// that differ. Used by the benchmark suite to compare Terravol's frames with reference frames.
//
// Every function takes two RGB images as bytes: width * height * 3 of them, row by row, top row
// first, channels R, G, B (8 bits each). Neither image is modified. Each throws
// std::invalid_argument (naming the function and the sizes) when width or height is not positive
// or when a span's size is not width * height * 3.
#pragma once

#include <cstdint>
#include <span>

namespace terravol::bench {

// Peak signal-to-noise ratio in decibels over all three channels:
// 10 * log10(255^2 / MSE), where MSE is the mean of the squared differences of the
// 3 * width * height channel values. Symmetric in a and b. Identical images (MSE 0) return
// +infinity (std::numeric_limits<double>::infinity()); callers print it as "inf".
double psnr(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, int width,
            int height);

// Mean structural similarity (Wang, Bovik, Sheikh, Simoncelli 2004, IEEE TIP 13(4)) of the luma
// Y = 0.299 R + 0.587 G + 0.114 B of both images, with the paper's parameters: an 11x11 Gaussian
// window of sigma 1.5 pixels (weights summing to 1), K1 = 0.01, K2 = 0.03, L = 255. The mean is
// over every window lying fully inside the image ((width - 10) * (height - 10) of them; no
// padding), and is 1 exactly for identical images. In [-1, 1], symmetric in a and b; higher is
// more similar. No downsampling of large images (the reference MATLAB code's later option).
// Also throws std::invalid_argument when width or height is below 11 (no window fits).
// Cost: O(width * height), about 22 multiply-adds per pixel for each of five maps.
double ssim(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, int width,
            int height);

// Share (0..1) of the width * height pixels where some channel differs by more than `threshold`
// (|a - b| > threshold, in 8-bit steps): 0 for identical images; threshold 0 counts every change.
// Also throws std::invalid_argument when threshold is negative.
double share_differing(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, int width,
                       int height, int threshold);

}  // namespace terravol::bench
