// app/scene/terrain_scene.h: the window around the camera and the default level count.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "app/scene/terrain_scene.h"
#include "io/mosaic.h"

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

TEST(TerrainSceneFarPlane, HoldsMergedSurfacesBeyondTheWindowAndAboveItsHighestSample) {
  const io::Mosaic mosaic = io::Mosaic::open({std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"});
  TerrainScene scene(mosaic, WindowChoice{400, 300, 64}, 3);
  const glm::dvec3 eye(scene.xs().front(), scene.ys().front(), scene.max_z() + 50.0);
  const double window_only = scene.far_plane(eye);
  // A triangle 20 km beyond the window's north-east corner and 3 km above its highest sample.
  const glm::dvec3 far(scene.xs().back() + 20000.0, scene.ys().back() + 20000.0, scene.max_z() + 3000.0);
  const std::array<glm::dvec3, 3> v{far, far + glm::dvec3(100.0, 0.0, 0.0), far + glm::dvec3(0.0, 100.0, 0.0)};
  const std::array<glm::u8vec4, 3> c{glm::u8vec4(255), glm::u8vec4(255), glm::u8vec4(255)};
  const std::array<std::uint32_t, 3> t{0, 1, 2};
  const std::uint32_t id = 7;
  const mrbsp::SurfaceInput input{v, c, t};
  scene.set_surfaces({&id, 1}, {&input, 1});
  const double with_surface = scene.far_plane(eye);
  EXPECT_GT(with_surface, glm::length(far + glm::dvec3(100.0, 0.0, 0.0) - eye));
  EXPECT_GT(with_surface, window_only);
  // Removing it gives the window's plane back.
  const mrbsp::SurfaceInput none{};
  scene.set_surfaces({&id, 1}, {&none, 1});
  EXPECT_DOUBLE_EQ(scene.far_plane(eye), window_only);
}

}  // namespace
}  // namespace terravol::app::scene
