#include "bench/plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "image_compare.h"
#include "require_display.h"
#include "temp_dir.h"

namespace terravol::bench {
namespace {

using test::Rgb8;

Series line(const std::string& name, double slope, bool points_only = false) {
  Series s{name, {}, {}, points_only};
  for (int i = 1; i <= 20; ++i) {
    s.x.push_back(i);
    s.y.push_back(slope * i + 1.0);
  }
  return s;
}

Rgb8 rgb(const std::array<std::uint8_t, 3>& c) {
  return {c[0], c[1], c[2]};
}

std::size_t count_color(const test::Image& img, const Rgb8& color, int tolerance) {
  std::size_t n = 0;
  for (const Rgb8& p : img.pixels) n += test::same_color(p, color, tolerance);
  return n;
}

TEST(Plot, WritesADecodablePngOfTheRequestedSize) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto path = dir.path() / "chart.png";
  ChartSpec spec{"Frame time", "frame", "milliseconds", {line("terravol", 0.5)}};
  spec.width = 640;
  spec.height = 360;
  write_chart_png(path, spec);

  const test::Image img = test::read_png(path);
  ASSERT_EQ(img.width, 640);
  ASSERT_EQ(img.height, 360);
  const std::set<Rgb8> colors(img.pixels.begin(), img.pixels.end());
  EXPECT_GT(colors.size(), 2u);
  EXPECT_TRUE(test::same_color(img.at(2, 2), {255, 255, 255}, 0)) << "white background";
  EXPECT_GT(test::color_share(img, {255, 255, 255}, 0), 0.5);
  EXPECT_GT(count_color(img, rgb(series_color(0)), 40), 100u) << "the curve is drawn";
  // Only the chart is left in the folder: the temporary file was renamed.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator()),
            1);
}

TEST(Plot, TwoSeriesAppearInDistinctColours) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto path = dir.path() / "two.png";
  ChartSpec spec{"Two series", "x", "y", {line("rising", 2.0), line("flat", 0.1)}};
  write_chart_png(path, spec);

  const test::Image img = test::read_png(path);
  ASSERT_EQ(img.width, 900);
  ASSERT_EQ(img.height, 500);
  const Rgb8 first = rgb(series_color(0)), second = rgb(series_color(1));
  ASSERT_FALSE(test::same_color(first, second, 60));
  EXPECT_GT(count_color(img, first, 40), 200u);
  EXPECT_GT(count_color(img, second, 40), 200u);
}

TEST(Plot, PointsAndLogAxesRender) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto path = dir.path() / "log.png";
  ChartSpec spec{"Log-log", "triangles", "ms", {line("measured", 3.0, true), line("model", 2.0)}};
  spec.log_x = spec.log_y = true;
  write_chart_png(path, spec);

  const test::Image img = test::read_png(path);
  ASSERT_EQ(img.width, 900);
  EXPECT_GT(count_color(img, rgb(series_color(0)), 40), 100u) << "the markers are drawn";
  EXPECT_GT(count_color(img, rgb(series_color(1)), 40), 100u);
}

TEST(Plot, ReplacesAnExistingFile) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto path = dir.path() / "chart.png";
  std::ofstream(path) << "old";
  write_chart_png(path, ChartSpec{"", "", "", {line("", 1.0)}});
  EXPECT_EQ(test::read_png(path).width, 900);
}

TEST(Plot, UnwritablePathThrowsRuntimeError) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const ChartSpec spec{"t", "x", "y", {line("a", 1.0)}};
  EXPECT_THROW(write_chart_png(dir.path() / "missing" / "chart.png", spec), std::runtime_error);
}

TEST(Plot, BadInputThrowsBeforeWriting) {
  test::TempDir dir;
  const auto path = dir.path() / "bad.png";
  const auto expect_invalid = [&](const ChartSpec& spec, const char* what) {
    EXPECT_THROW(write_chart_png(path, spec), std::invalid_argument) << what;
    EXPECT_FALSE(std::filesystem::exists(path)) << what;
  };
  expect_invalid(ChartSpec{}, "no series");
  expect_invalid(ChartSpec{"t", "x", "y", {Series{"empty", {}, {}}}}, "empty series");
  expect_invalid(ChartSpec{"t", "x", "y", {Series{"short y", {1, 2, 3}, {1, 2}}}}, "mismatch");
  expect_invalid(ChartSpec{"t", "x", "y", {line("ok", 1.0), Series{"bad", {1}, {}}}},
                 "second series mismatched");
  expect_invalid(ChartSpec{"t", "x", "y", {Series{"nan", {1, 2}, {1, std::nan("")}}}}, "NaN");
  expect_invalid(ChartSpec{"t", "x", "y", {Series{"inf", {1, HUGE_VAL}, {1, 2}}}}, "infinity");
  ChartSpec log_zero{"t", "x", "y", {Series{"zero", {0, 1}, {1, 2}}}};
  log_zero.log_x = true;
  expect_invalid(log_zero, "zero on a log x axis");
  ChartSpec log_negative{"t", "x", "y", {Series{"negative", {1, 2}, {-1, 2}}}};
  log_negative.log_y = true;
  expect_invalid(log_negative, "negative on a log y axis");
  ChartSpec no_size{"t", "x", "y", {line("a", 1.0)}};
  no_size.height = 0;
  expect_invalid(no_size, "zero height");
}

TEST(Plot, SeriesColoursDiffer) {
  std::set<std::array<std::uint8_t, 3>> seen;
  for (std::size_t i = 0; i < 30; ++i) seen.insert(series_color(i));
  EXPECT_EQ(seen.size(), 30u);
}

}  // namespace
}  // namespace terravol::bench
