// app/scene/style.h: the compound option values, and which source of a value wins.
#include <gtest/gtest.h>

#include <stdexcept>

#include "app/scene/scene_file.h"
#include "app/scene/style.h"

namespace terravol::app::scene {
namespace {

TEST(RenderOptions, SizeIsWidthByHeight) {
  int w = 0, h = 0;
  parse_size("1280x720", w, h);
  EXPECT_EQ(w, 1280);
  EXPECT_EQ(h, 720);
  for (const char* bad : {"0x0", "1280", "x720", "1280x", "-5x5", "12a0x720", "99999x10", "1280x720x3"})
    EXPECT_THROW(parse_size(bad, w, h), std::invalid_argument) << bad;
}

TEST(RenderOptions, BackgroundIsThreeBytes) {
  EXPECT_EQ(parse_rgb("--background", "255,0,255"), (Rgb{255, 0, 255}));
  for (const char* bad : {"1,2", "1,2,3,4", "256,0,0", "a,b,c", "", "1,,3"})
    EXPECT_THROW(parse_rgb("--background", bad), std::invalid_argument) << bad;
}

TEST(RenderOptions, NamedValues) {
  EXPECT_EQ(parse_metric("area"), mrbsp::LodMetric::kArea);
  EXPECT_EQ(parse_metric("error"), mrbsp::LodMetric::kError);
  EXPECT_THROW(parse_metric("Error"), std::invalid_argument);
  EXPECT_EQ(parse_order("zbuffer"), DrawOrder::kZBuffer);
  EXPECT_THROW(parse_order("painter"), std::invalid_argument);
  EXPECT_EQ(parse_tint("relative"), Tint::kRelative);
  EXPECT_THROW(parse_tint("sepia"), std::invalid_argument);
}

TEST(RenderOptions, ThresholdComesFromTheOptionThenTheSceneFileThenTheMetric) {
  EXPECT_EQ(resolve_threshold(true, 3.0, 5.0, mrbsp::LodMetric::kError), 3.0f);
  EXPECT_EQ(resolve_threshold(false, 3.0, 5.0, mrbsp::LodMetric::kError), 5.0f);
  EXPECT_EQ(resolve_threshold(false, 3.0, std::nullopt, mrbsp::LodMetric::kArea), 500.0f);
  EXPECT_THROW(resolve_threshold(true, 0.0, std::nullopt, mrbsp::LodMetric::kError), std::invalid_argument);
  EXPECT_THROW(resolve_threshold(false, 1.0, -2.0, mrbsp::LodMetric::kError), std::invalid_argument);
}

TEST(RenderOptions, CameraComesFromTheOptionElseTheSceneFileWithItsAglAndFov) {
  SceneSpec file;
  bool agl = false;
  double fov = 45.0;
  EXPECT_FALSE(resolve_camera(file, nullptr, false, agl, fov));
  file.camera = SceneCamera{CameraPose{45.2, 6.3, 500.0, 10.0, -5.0}, true, 60.0};
  const std::string text = "45.1,6.1,2000,90,-10";
  EXPECT_EQ(resolve_camera(file, &text, false, agl, fov)->alt, 2000.0);
  EXPECT_FALSE(agl);
  EXPECT_EQ(fov, 45.0);
  EXPECT_EQ(resolve_camera(file, nullptr, true, agl, fov)->alt, 500.0);
  EXPECT_TRUE(agl);
  EXPECT_EQ(fov, 45.0) << "--fov given wins";
  EXPECT_EQ(resolve_camera(file, nullptr, false, agl, fov)->lat, 45.2);
  EXPECT_EQ(fov, 60.0);
}

}  // namespace
}  // namespace terravol::app::scene
