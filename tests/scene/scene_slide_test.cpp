// Sliding the terrain window (app/scene/terrain_scene.h: plan_slide, TerrainScene::slide).
#include <gtest/gtest.h>

#include <string>

#include "app/scene/terrain_scene.h"
#include "io/mosaic.h"

namespace terravol::app::scene {
namespace {

const WindowChoice kWindow{400, 300, 256};  // rows 400..656, columns 300..556

TEST(PlanSlide, StaysWhileTheCameraIsInTheMiddleHalf) {
  for (double row : {400.0 + 64.0, 528.0, 400.0 + 192.0}) {
    for (double col : {300.0 + 64.0, 428.0, 300.0 + 192.0}) {
      const WindowChoice w = plan_slide(kWindow, 1201, 1201, row, col, 32);
      EXPECT_EQ(w.row0, kWindow.row0) << row << " " << col;
      EXPECT_EQ(w.col0, kWindow.col0) << row << " " << col;
    }
  }
}

TEST(PlanSlide, MovesByWholeStepsTowardTheCameraOnTheAxesNearAnEdge) {
  // 10 cells from the north edge: 118 cells north of the centre, rounded to 4 steps of 32.
  WindowChoice w = plan_slide(kWindow, 1201, 1201, 410.0, 428.0, 32);
  EXPECT_EQ(w.row0, 400 - 128);
  EXPECT_EQ(w.col0, 300);
  EXPECT_EQ(w.cells, 256);
  // Near the east edge only.
  w = plan_slide(kWindow, 1201, 1201, 528.0, 300.0 + 200.0, 32);
  EXPECT_EQ(w.row0, 400);
  EXPECT_EQ(w.col0, 300 + 64);  // 72 cells east of the centre: 2 steps
  // Near a corner: both axes.
  w = plan_slide(kWindow, 1201, 1201, 650.0, 310.0, 32);
  EXPECT_EQ(w.row0, 400 + 128);
  EXPECT_EQ(w.col0, 300 - 128);
}

TEST(PlanSlide, StopsAtTheMosaicEdgeOnTheSameStepLattice) {
  // Room for one step of 32 north (row0 40 -> 8), not two.
  WindowChoice w = plan_slide(WindowChoice{40, 300, 256}, 1201, 1201, 45.0, 428.0, 32);
  EXPECT_EQ(w.row0, 8);
  // No room at all: the window stays.
  w = plan_slide(WindowChoice{0, 300, 256}, 1201, 1201, 5.0, 428.0, 32);
  EXPECT_EQ(w.row0, 0);
  // South edge of a 1201-sample mosaic: the last first row is 944.
  w = plan_slide(WindowChoice{900, 300, 256}, 1201, 1201, 1190.0, 428.0, 32);
  EXPECT_EQ(w.row0, 932);
}

TEST(TerrainSceneSlide, KeepsTheFrameAndMatchesAFreshWindowThere) {
  const io::Mosaic mosaic = io::Mosaic::open({std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"});
  TerrainScene scene(mosaic, kWindow, 4);
  const double lat0 = scene.frame().lat0(), lon0 = scene.frame().lon0();
  const WindowChoice moved{kWindow.row0 - 64, kWindow.col0 + 32, kWindow.cells};
  scene.slide(mosaic, moved);
  EXPECT_EQ(scene.frame().lat0(), lat0);
  EXPECT_EQ(scene.frame().lon0(), lon0);
  EXPECT_EQ(scene.window().row0, moved.row0);
  EXPECT_EQ(scene.window().col0, moved.col0);

  const TerrainScene fresh(mosaic, moved, 4);  // its own frame, about the moved window's centre
  EXPECT_DOUBLE_EQ(scene.bounds().north, fresh.bounds().north);
  EXPECT_DOUBLE_EQ(scene.bounds().west, fresh.bounds().west);
  ASSERT_EQ(scene.heights().size(), fresh.heights().size());
  for (std::size_t k = 0; k < scene.heights().size(); ++k) ASSERT_EQ(scene.heights()[k], fresh.heights()[k]) << k;
  // The lattice lies where the old frame puts the moved window's meridians and parallels, and
  // a sample the two windows share has the same plane offsets in both, to the bit (what lets
  // the tree keep what lies on them).
  const io::Georef& g = mosaic.georef();
  for (int i : {0, 100, 256}) {
    EXPECT_NEAR(scene.xs()[i], scene.frame().x_of_lon(scene.bounds().west + i * g.dx), 1e-6);
    EXPECT_NEAR(scene.ys()[i], scene.frame().y_of_lat(scene.bounds().south + i * g.dy), 1e-6);
  }
  const TerrainScene before(mosaic, kWindow, 4);
  for (int i : {0, 100, 224}) {  // column i + 32 before the move is column i after it
    EXPECT_EQ(scene.xs()[i], before.xs()[i + 32]);
  }
  for (int j : {64, 100, 256}) {  // rows count from the south: 64 rows north
    EXPECT_EQ(scene.ys()[j - 64], before.ys()[j]);
  }
  // The tree's lattice vertices follow.
  const auto& p = scene.tree().positions();
  const std::size_t side = 257, v = 5 * side + 7;
  EXPECT_FLOAT_EQ(p[v].x, static_cast<float>(scene.xs()[7]));
  EXPECT_FLOAT_EQ(p[v].y, static_cast<float>(scene.ys()[5]));
  EXPECT_FLOAT_EQ(p[v].z, scene.z()[v]);
  // Ground heights are the moved window's.
  const double lat = fresh.bounds().south + 0.3 * (fresh.bounds().north - fresh.bounds().south);
  const double lon = fresh.bounds().west + 0.6 * (fresh.bounds().east - fresh.bounds().west);
  EXPECT_DOUBLE_EQ(scene.ground_height(lat, lon), fresh.ground_height(lat, lon));
}

TEST(TerrainSceneSlide, RefusesAnotherSize) {
  const io::Mosaic mosaic = io::Mosaic::open({std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"});
  TerrainScene scene(mosaic, kWindow, 3);
  EXPECT_THROW(scene.slide(mosaic, WindowChoice{0, 0, 128}), std::invalid_argument);
  EXPECT_EQ(scene.window().row0, kWindow.row0);
}

}  // namespace
}  // namespace terravol::app::scene
