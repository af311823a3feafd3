// Comparing two volumes of the same quantity over their common lattice points, layer by layer:
// how well one model (or run) agrees with another (docs/rf-model.md compares the built-in
// model with SPLAT! this way).
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "volume/volume.h"

namespace terravol::volume {

// The value of `v` at world coordinates (w0, w1, w2) of its frame by trilinear interpolation
// between its lattice points. nullopt outside the lattice (beyond a tolerance of 1e-6 of a
// spacing) or when a lattice point with a non-zero weight is not finite (NaN marks "no value":
// stack_ano, splat.h). An axis with one point only matches its own coordinate (to 1e-6 of
// its spacing); there the value is that point's.
std::optional<double> sample_trilinear(const Volume& v, double w0, double w1, double w2);

// One layer of A (k = const): the points where A is finite and B, resampled there, is too.
struct LayerComparison {
  double w2 = 0.0;  // the layer's third coordinate (height, metres, for volumes
                    // in a geographic frame)
  std::size_t points = 0;
  double pearson = 0.0;                // Pearson correlation of A and B; NaN with fewer than 2
                                       // points or a constant A or B
  double median_difference = 0.0;      // median of B - A; NaN without points
  double median_abs_difference = 0.0;  // median of |B - A|; NaN without points
  double median_a = 0.0, median_b = 0.0;
};

struct Comparison {
  std::vector<LayerComparison> layers;  // one per layer of A, bottom up
  LayerComparison all;                  // every layer together (w2 = NaN)
};

// The figures of LayerComparison for paired values a[k], b[k] (same size), at layer w2.
// Medians of an even count are the mean of the two middle values.
LayerComparison compare_values(std::span<const double> a, std::span<const double> b, double w2);

// Resamples B at every lattice point of A (sample_trilinear) and compares, per layer of A.
// Medians of an even count are the mean of the two middle values.
// Throws std::invalid_argument("the frames differ: F_A vs F_B") unless a.frame == b.frame
// (format_frame spelling), since their world coordinates would mean different things.
Comparison compare_volumes(const Volume& a, const Volume& b);

}  // namespace terravol::volume
