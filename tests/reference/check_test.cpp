// The parts of the check around the reference image: pixel agreement, PNG I/O, the stats, and
// running the real command.
#include <gtest/gtest.h>

#include <fstream>

#include "reference/check.h"
#include "temp_dir.h"

namespace terravol::reference {
namespace {

Image flat(int w, int h, std::uint8_t v) { return {w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 3, v)}; }

TEST(ShareWithin, CountsPixelsWhoseEveryChannelIsWithinTheTolerance) {
  Image a = flat(4, 1, 100), b = flat(4, 1, 100);
  b.rgb[0] = 108;       // pixel 0: 8 off in red: within 8
  b.rgb[3 + 2] = 91;    // pixel 1: 9 off in blue
  b.rgb[6 + 1] = 97;    // pixel 2: 3 off
  EXPECT_DOUBLE_EQ(share_within(a, b, 8), 0.75);
  EXPECT_DOUBLE_EQ(share_within(a, b, 3), 0.5);
  EXPECT_DOUBLE_EQ(share_within(a, b, 9), 1.0);
  EXPECT_DOUBLE_EQ(share_within(a, a, 0), 1.0);
  EXPECT_THROW(share_within(a, flat(2, 2, 0), 8), std::invalid_argument);
  EXPECT_THROW(share_within(a, b, -1), std::invalid_argument);
}

TEST(DifferenceImage, MarksTheDifferingPixelsRed) {
  Image a = flat(2, 1, 100), b = flat(2, 1, 100);
  b.rgb[3] = 0;
  const Image d = difference_image(a, b, 8);
  EXPECT_EQ(d.rgb[0], d.rgb[1]);  // grey
  EXPECT_EQ(d.rgb[3], 255);
  EXPECT_EQ(d.rgb[4], 0);
  EXPECT_EQ(d.rgb[5], 0);
}

TEST(Png, RoundTripsTopRowFirst) {
  test::TempDir dir;
  Image a = flat(3, 2, 0);
  for (std::size_t k = 0; k < a.rgb.size(); ++k) a.rgb[k] = static_cast<std::uint8_t>(k * 13);
  write_png(dir.path() / "a.png", a);
  const Image b = read_png(dir.path() / "a.png");
  EXPECT_EQ(b.width, 3);
  EXPECT_EQ(b.height, 2);
  EXPECT_EQ(b.rgb, a.rgb);
  std::ofstream(dir.path() / "bad.png") << "not a png";
  EXPECT_THROW(read_png(dir.path() / "bad.png"), std::runtime_error);
  EXPECT_THROW(read_png(dir.path() / "none.png"), std::runtime_error);
}

TEST(ReadStats, TakesTheSizeAndTheFramesOriginOrThrows) {
  test::TempDir dir;
  const auto p = dir.path() / "stats.json";
  std::ofstream(p) << R"({"width": 640, "height": 360, "window": {"origin_lat": 44.5, "origin_lon": -71.25,
    "cells": 256, "south": 44.4, "north": 44.6, "west": -71.5, "east": -71.0}})";
  const RenderStats s = read_stats(p);
  EXPECT_EQ(s.width, 640);
  EXPECT_EQ(s.height, 360);
  EXPECT_EQ(s.origin_lat, 44.5);
  EXPECT_EQ(s.origin_lon, -71.25);
  EXPECT_EQ(s.window.cells, 256);
  EXPECT_EQ(s.window.east, -71.0);
  std::ofstream(p) << R"({"width": 640, "height": 360})";
  EXPECT_THROW(read_stats(p), std::runtime_error);
}

TEST(RunRender, AFailingRenderThrowsWithItsMessage) {
  test::TempDir dir;
  std::ofstream(dir.path() / "scene.json") << R"({"volumes": 3})";
  try {
    run_render(TERRAVOL_EXE, dir.path() / "scene.json", dir.path(), "x", {}, 60);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("scene.json"), std::string::npos) << e.what();
  }
  EXPECT_THROW(run_render(dir.path() / "no-such-terravol", dir.path() / "scene.json", dir.path(), "y", {}, 60),
               std::runtime_error);
}

}  // namespace
}  // namespace terravol::reference
