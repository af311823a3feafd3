// Colour maps: matplotlib's values at known indices, the names, clamping, and seeded checks
// that every map is a continuous piecewise-linear interpolation of its stops.
#include "volume/colormap.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace terravol::volume {
namespace {

struct Reference {
  int index;  // into matplotlib's 256-entry table, t = index / 255
  glm::u8vec3 rgb;
};

// Entries of matplotlib 3.6.3's _cm_listed.py tables, rounded to 8 bits.
void expect_matches(std::string_view name, std::initializer_list<Reference> refs, int tolerance) {
  const Colormap m = colormap_by_name(name);
  for (const Reference& r : refs) {
    const glm::u8vec3 got = m.map(r.index / 255.0);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(got[c], r.rgb[c], tolerance) << name << " index " << r.index << " channel " << c;
    }
  }
}

TEST(Colormap, MatchesMatplotlibTablesWithinThreeLevels) {
  expect_matches("viridis", {{0, {68, 1, 84}}, {37, {70, 51, 127}}, {100, {42, 118, 142}}, {128, {33, 145, 140}},
                             {201, {115, 208, 86}}, {255, {253, 231, 37}}}, 3);
  expect_matches("plasma", {{0, {13, 8, 135}}, {37, {85, 2, 164}}, {100, {174, 40, 146}}, {128, {204, 71, 120}},
                            {201, {251, 162, 56}}, {255, {240, 249, 33}}}, 3);
  expect_matches("inferno", {{0, {0, 0, 4}}, {37, {41, 11, 85}}, {100, {144, 37, 104}}, {128, {188, 55, 84}},
                             {201, {252, 159, 7}}, {255, {252, 255, 164}}}, 3);
  expect_matches("magma", {{0, {0, 0, 4}}, {37, {36, 18, 83}}, {100, {137, 40, 129}}, {128, {183, 55, 121}},
                           {201, {253, 154, 106}}, {255, {252, 253, 191}}}, 3);
  expect_matches("turbo", {{0, {48, 18, 59}}, {37, {71, 120, 240}}, {100, {63, 246, 138}}, {128, {164, 252, 60}},
                           {201, {243, 99, 21}}, {255, {122, 4, 3}}}, 3);
}

TEST(Colormap, EndsAndStopsAreExact) {
  EXPECT_EQ(colormap_by_name("viridis").map(0.0), glm::u8vec3(68, 1, 84));
  EXPECT_EQ(colormap_by_name("viridis").map(1.0), glm::u8vec3(253, 231, 37));
  EXPECT_EQ(colormap_by_name("viridis").map(0.5), glm::u8vec3(33, 145, 140));  // matplotlib index 128
  EXPECT_EQ(colormap_by_name("coolwarm").map(0.0), glm::u8vec3(59, 76, 192));
  EXPECT_EQ(colormap_by_name("coolwarm").map(0.5), glm::u8vec3(221, 221, 221));
  EXPECT_EQ(colormap_by_name("coolwarm").map(1.0), glm::u8vec3(180, 4, 38));
  EXPECT_EQ(colormap_by_name("jet").map(0.0), glm::u8vec3(0, 0, 128));
  EXPECT_EQ(colormap_by_name("jet").map(1.0), glm::u8vec3(128, 0, 0));
  EXPECT_EQ(colormap_by_name("grey").map(0.0), glm::u8vec3(0, 0, 0));
  EXPECT_EQ(colormap_by_name("grey").map(0.5), glm::u8vec3(128, 128, 128));
  EXPECT_EQ(colormap_by_name("grey").map(1.0), glm::u8vec3(255, 255, 255));
}

TEST(Colormap, JetFollowsMatplotlibsBreakpoints) {
  // matplotlib: red 0 until 0.35, 1 from 0.66; green 1 over [0.375, 0.64]; blue 1 over [0.11, 0.34].
  const Colormap jet = colormap_by_name("jet");
  const glm::u8vec3 a = jet.map(0.2), b = jet.map(0.75);
  const double want_a[3] = {0.0, (0.2 - 0.125) / 0.25 * 255.0, 255.0};
  const double want_b[3] = {255.0, (0.91 - 0.75) / 0.27 * 255.0, 0.0};
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(a[c], want_a[c], 1.0) << c;
    EXPECT_NEAR(b[c], want_b[c], 1.0) << c;
  }
}

TEST(Colormap, GrayIsAnAliasOfGrey) {
  const Colormap a = colormap_by_name("gray"), b = colormap_by_name("grey");
  EXPECT_EQ(a.name(), "grey");
  for (double t : {0.0, 0.3, 0.7, 1.0}) EXPECT_EQ(a.map(t), b.map(t));
}

TEST(Colormap, UnknownNameListsTheKnownOnes) {
  try {
    colormap_by_name("Viridis");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "unknown colour map 'Viridis' (known: viridis, plasma, inferno, magma, turbo, coolwarm, jet, grey, gray, categorical)");
  }
  EXPECT_EQ(colormap_names().size(), 8u);
  for (const std::string& name : colormap_names()) EXPECT_NO_THROW(colormap_by_name(name));
}

TEST(Colormap, ClampsOutOfRangeAndMapsNanAsZero) {
  for (const std::string& name : colormap_names()) {
    const Colormap m = colormap_by_name(name);
    EXPECT_EQ(m.map(-3.0), m.map(0.0)) << name;
    EXPECT_EQ(m.map(7.0), m.map(1.0)) << name;
    EXPECT_EQ(m.map(std::nan("")), m.map(0.0)) << name;
    EXPECT_EQ(m.map(-INFINITY), m.map(0.0)) << name;
    EXPECT_EQ(m.map(INFINITY), m.map(1.0)) << name;
  }
}

TEST(Colormap, StopsSpanZeroToOneInIncreasingOrder) {
  for (const std::string& name : colormap_names()) {
    const auto stops = colormap_by_name(name).stops();
    ASSERT_GE(stops.size(), 2u) << name;
    EXPECT_EQ(stops.front().t, 0.0f) << name;
    EXPECT_EQ(stops.back().t, 1.0f) << name;
    for (std::size_t i = 1; i < stops.size(); ++i) EXPECT_LT(stops[i - 1].t, stops[i].t) << name << " stop " << i;
  }
}

// Between two stops every channel lies between the stops' values, and it moves at the slope of
// the segment: |map(t + dt) - map(t)| <= slope * dt + 1 (rounding).
TEST(Colormap, InterpolatesBetweenItsStops) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (const std::string& name : colormap_names()) {
    const Colormap m = colormap_by_name(name);
    const auto stops = m.stops();
    for (int n = 0; n < 2000; ++n) {
      const double t = uniform(rng);
      const auto b = std::upper_bound(stops.begin(), stops.end(), t, [](double x, const ColorStop& s) { return x < s.t; });
      ASSERT_NE(b, stops.begin());
      ASSERT_NE(b, stops.end());
      const auto a = b - 1;
      const glm::u8vec3 c = m.map(t);
      const double dt = std::min(1e-3, (b->t - t) * 0.999);
      const glm::u8vec3 d = m.map(t + dt);
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_GE(c[ch], std::min(a->rgb[ch], b->rgb[ch])) << name << " t=" << t;
        EXPECT_LE(c[ch], std::max(a->rgb[ch], b->rgb[ch])) << name << " t=" << t;
        const double slope = std::abs(double(b->rgb[ch]) - a->rgb[ch]) / (b->t - a->t);
        EXPECT_LE(std::abs(int(d[ch]) - int(c[ch])), slope * dt + 1.0) << name << " t=" << t;
      }
    }
  }
}

// Tableau 20 as matplotlib lists it (_tab20_data, here as its hex codes): darks first.
TEST(CategoryColor, DarksThenLightsOfTab20CycledAfterTwenty) {
  EXPECT_EQ(category_color(1), glm::u8vec3(0x1f, 0x77, 0xb4));
  EXPECT_EQ(category_color(2), glm::u8vec3(0xff, 0x7f, 0x0e));
  EXPECT_EQ(category_color(10), glm::u8vec3(0x17, 0xbe, 0xcf));
  EXPECT_EQ(category_color(11), glm::u8vec3(0xae, 0xc7, 0xe8));
  EXPECT_EQ(category_color(20), glm::u8vec3(0x9e, 0xda, 0xe5));
  EXPECT_EQ(category_color(21), category_color(1));
  EXPECT_EQ(category_color(0), category_color(20));
  EXPECT_TRUE(is_categorical("categorical"));
  EXPECT_THROW(colormap_by_name("categorical"), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::volume
