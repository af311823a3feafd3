// Summaries of repeated measurements: the benchmarks report medians and spreads, never a
// single time (a 2-core machine shared with other work is noisy).
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/scene/timing.h"

namespace terravol::bench {

struct Summary {
  double median = 0, p10 = 0, p90 = 0, min = 0, max = 0;
  std::size_t n = 0;
};

// Order statistics of `v` (nearest rank; the median of an even count is the mean of the middle
// two). An empty `v` gives n = 0 and NaN elsewhere.
inline Summary summarize(std::vector<double> v) {
  Summary s;
  s.n = v.size();
  if (v.empty()) {
    s.median = s.p10 = s.p90 = s.min = s.max = std::nan("");
    return s;
  }
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  s.p10 = v[static_cast<std::size_t>(std::floor(0.1 * static_cast<double>(n - 1)))];
  s.p90 = v[static_cast<std::size_t>(std::ceil(0.9 * static_cast<double>(n - 1)))];
  s.min = v.front();
  s.max = v.back();
  return s;
}

inline double median(const std::vector<double>& v) { return summarize(v).median; }

inline nlohmann::json to_json(const Summary& s) {
  return {{"median", s.median}, {"p10", s.p10}, {"p90", s.p90}, {"min", s.min}, {"max", s.max}, {"n", s.n}};
}

using app::scene::Clock;
using app::scene::ms_since;

}  // namespace terravol::bench
