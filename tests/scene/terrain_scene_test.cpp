// app/scene/terrain_scene.h: the window around the camera and the default level count.
#include <gtest/gtest.h>

#include <stdexcept>

#include "app/scene/terrain_scene.h"

namespace terravol::app::scene {
namespace {

TEST(ChooseWindow, LargestPowerOfTwoThatFitsCappedByTheOption) {
  EXPECT_EQ(choose_window(1201, 1201, 600, 600, 1024).cells, 1024);
  EXPECT_EQ(choose_window(1201, 1201, 600, 600, 256).cells, 256);
  EXPECT_EQ(choose_window(3601, 3601, 1800, 1800, 4096).cells, 2048);
  EXPECT_EQ(choose_window(2400, 3600, 1200, 1800, 1 << 20).cells, 2048);
  EXPECT_EQ(choose_window(1025, 5000, 500, 500, 4096).cells, 1024);
  EXPECT_EQ(choose_window(1024, 5000, 500, 500, 4096).cells, 512);
  EXPECT_EQ(choose_window(3, 3, 1, 1, 1024).cells, 2);
  EXPECT_THROW(choose_window(2, 100, 1, 1, 1024), std::invalid_argument);
}

TEST(ChooseWindow, CentredOnTheCameraAndClampedIntoTheMosaic) {
  const WindowChoice mid = choose_window(1201, 1201, 600.2, 599.7, 256);
  EXPECT_EQ(mid.row0, 600 - 128);
  EXPECT_EQ(mid.col0, 600 - 128);
  const WindowChoice corner = choose_window(1201, 1201, 3.0, 1199.0, 256);
  EXPECT_EQ(corner.row0, 0);
  EXPECT_EQ(corner.col0, 1200 - 256);
  const WindowChoice whole = choose_window(1201, 1201, 0.0, 0.0, 1024);
  EXPECT_EQ(whole.row0, 0);
  EXPECT_EQ(whole.col0, 0);
}

TEST(DefaultLevels, CoarsestLevelIsEightCellsSquare) {
  EXPECT_EQ(default_levels(1024), 8);  // 1024 / 2^7 = 8
  EXPECT_EQ(default_levels(2048), 9);
  EXPECT_EQ(default_levels(8), 1);
  EXPECT_EQ(default_levels(4), 1);
  EXPECT_EQ(default_levels(2), 1);
}

}  // namespace
}  // namespace terravol::app::scene
