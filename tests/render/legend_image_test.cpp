// Legend cards as the viewer, render and export-map show them: the bar, the isosurface
// swatches and their marks found in the pixels, the card shrinking to a height.
#include "app/render/legend_image.h"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

namespace terravol::app::render {
namespace {

TEST(LegendTicks, RoundStepsOfOneTwoOrFiveGiveThreeToSixLabels) {
  EXPECT_EQ(legend_ticks(60.37, 173.25), (std::vector<double>{80, 100, 120, 140, 160}));
  EXPECT_EQ(legend_ticks(-140, -60), (std::vector<double>{-140, -120, -100, -80, -60}));
  EXPECT_EQ(legend_ticks(0, 1), (std::vector<double>{0, 0.5, 1}));
  EXPECT_EQ(legend_ticks(100, 60), (std::vector<double>{60, 80, 100})) << "reversed range, ascending ticks";
  EXPECT_EQ(legend_ticks(7.5, 7.5), (std::vector<double>{7.5}));
  for (const auto& [lo, hi] : {std::pair{-3.2, 1e4}, std::pair{0.001, 0.0013}, std::pair{57.6, 178.6}}) {
    const auto t = legend_ticks(lo, hi);
    EXPECT_GE(t.size(), 3u) << lo << " " << hi;
    EXPECT_LE(t.size(), 6u) << lo << " " << hi;
    EXPECT_GE(t.front(), lo - 1e-12);
    EXPECT_LE(t.back(), hi + 1e-12);
  }
}

const std::uint8_t* pixel(const RgbaImage& img, int x, int y) {
  return img.rgba.data() + (static_cast<std::size_t>(y) * img.width + x) * 4;
}

// The rows of column x whose pixel is exactly `c`, opaque.
std::vector<int> rows_of(const RgbaImage& img, int x, glm::u8vec3 c) {
  std::vector<int> rows;
  for (int y = 0; y < img.height; ++y) {
    const std::uint8_t* p = pixel(img, x, y);
    if (p[0] == c.r && p[1] == c.g && p[2] == c.b && p[3] == 255) rows.push_back(y);
  }
  return rows;
}

LegendCard slice_and_two_levels() {
  LegendCard card;
  card.title = "path_loss_db (dB)";
  card.subtitle = "slice 300 m above ground: viridis";
  card.colormap = volume::colormap_by_name("viridis");
  card.lo = 80;
  card.hi = 160;
  card.entries_title = "isosurfaces";
  card.entries = {{"110 dB", {255, 0, 255}, 110.0}, {"130 dB", {255, 165, 225}, 130.0}};
  return card;
}

TEST(LegendImage, MarksEachIsosurfaceLevelOnTheBarAndGivesItASwatchBelow) {
  const LegendCard card = slice_and_two_levels();
  const RgbaImage img = legend_image(card);
  ASSERT_GT(img.width, 100);
  // The bar (200 px) in column 28: the longest run of opaque rows (the card is translucent,
  // text runs are a glyph tall), viridis from hi at the top to lo at the bottom.
  int bar_top = -1, bar_bottom = -1, longest = 0;
  for (int y = 0, run = 0; y < img.height; ++y) {
    run = pixel(img, 28, y)[3] == 255 ? run + 1 : 0;
    if (run > longest) {
      longest = run;
      bar_top = y - run + 1;
      bar_bottom = y;
    }
  }
  EXPECT_EQ(bar_bottom - bar_top + 1, 200);
  const volume::Colormap viridis = volume::colormap_by_name("viridis");
  for (const auto& [y, t] : {std::pair{bar_top, 1.0}, std::pair{bar_bottom, 0.0}}) {
    const std::uint8_t* p = pixel(img, 28, y);
    const glm::u8vec3 want = viridis.map(t);
    EXPECT_LE(std::abs(p[0] - want.r) + std::abs(p[1] - want.g) + std::abs(p[2] - want.b), 6) << y;
  }
  // Left of the bar (column 12), each level's colour marks its height on the bar, 3 px, and
  // its swatch below the bar is a square of 14 px.
  for (const LegendEntry& e : card.entries) {
    const std::vector<int> rows = rows_of(img, 12, e.color);
    ASSERT_EQ(rows.size(), 3u + 14u) << e.label;
    const double f = (e.value - card.lo) / (card.hi - card.lo);
    const double want = bar_top + (1.0 - f) * 199.0;
    EXPECT_NEAR(rows[1], want, 1.0) << e.label << ": the mark's centre row";
    EXPECT_GT(rows[3], bar_bottom) << e.label << ": the swatch is below the bar";
    EXPECT_EQ(rows.back() - rows[3] + 1, 14) << e.label;
  }
}

TEST(LegendImage, WithoutASliceOnlyTheSwatches) {
  LegendCard card = slice_and_two_levels();
  card.colormap.reset();
  const RgbaImage img = legend_image(card);
  EXPECT_LT(img.height, 120);
  for (const LegendEntry& e : card.entries) EXPECT_EQ(rows_of(img, 12, e.color).size(), 14u) << e.label;
}

TEST(LegendImage, ShrinksToTheHeightGivenAndStopsAtItsSmallest) {
  const LegendCard card = slice_and_two_levels();
  const int full = legend_image(card).height;
  for (const int h : {full, full - 60, 200, 150}) {
    const RgbaImage img = legend_image(card, h);
    EXPECT_LE(img.height, h) << h;
    EXPECT_EQ(img.rgba.size(), static_cast<std::size_t>(img.width) * img.height * 4);
  }
  EXPECT_EQ(legend_image(card, full + 100).height, full) << "room to spare: the full card";
  const RgbaImage tiny = legend_image(card, 20);
  EXPECT_GT(tiny.height, 20) << "a card that cannot fit comes out at its smallest";
  EXPECT_EQ(tiny.height, legend_image(card, 21).height);
}

}  // namespace
}  // namespace terravol::app::render
