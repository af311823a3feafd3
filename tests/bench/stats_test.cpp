#include "bench/stats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace terravol::bench {
namespace {

TEST(BenchStats, MedianOfOddAndEvenCountsAndThePercentiles) {
  const Summary odd = summarize({5, 1, 4, 2, 3});
  EXPECT_EQ(odd.median, 3);
  EXPECT_EQ(odd.min, 1);
  EXPECT_EQ(odd.max, 5);
  EXPECT_EQ(odd.n, 5u);
  EXPECT_EQ(summarize({4, 1, 3, 2}).median, 2.5);
  std::vector<double> v;
  for (int k = 1; k <= 101; ++k) v.push_back(k);
  std::shuffle(v.begin(), v.end(), std::mt19937(7));
  const Summary s = summarize(v);
  EXPECT_EQ(s.p10, 11);
  EXPECT_EQ(s.p90, 91);
  EXPECT_EQ(s.median, 51);
}

TEST(BenchStats, AnEmptyListHasNoMedian) {
  const Summary s = summarize({});
  EXPECT_EQ(s.n, 0u);
  EXPECT_TRUE(std::isnan(s.median));
}

}  // namespace
}  // namespace terravol::bench
