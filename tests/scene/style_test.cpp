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

TEST(SceneStyle, EachKeyGivenWinsOverTheFilesAndTheOthersStay) {
  SceneStyle file;
  file.width = 640;
  file.height = 360;
  file.threshold = 3.0;
  file.lod_metric = "area";
  file.order = "peel";
  file.tint = "grey";
  file.window = 512;
  file.haze_km = 10.0;
  file.sun_azimuth = 90.0;
  file.sun_elevation = 20.0;
  file.legend = true;
  file.surface_triangles = 2000;
  SceneStyle given;
  given.order = "sort";
  given.surface_triangles = 4000;
  given.legend = false;
  const SceneStyle s = overlay(file, given);
  EXPECT_EQ(s.order, "sort");
  EXPECT_EQ(s.surface_triangles, 4000u);
  EXPECT_EQ(s.legend, false);
  EXPECT_EQ(s.width, 640);
  EXPECT_EQ(s.height, 360);
  EXPECT_EQ(s.threshold, 3.0);
  EXPECT_EQ(s.lod_metric, "area");
  EXPECT_EQ(s.tint, "grey");
  EXPECT_EQ(s.window, 512);
  EXPECT_EQ(s.haze_km, 10.0);
  EXPECT_EQ(s.sun_azimuth, 90.0);
  EXPECT_EQ(s.sun_elevation, 20.0);
  EXPECT_FALSE(overlay({}, {}).width) << "a key set nowhere stays unset";
}

TEST(SceneStyle, UnsetKeysResolveToTheDefaults) {
  const Style s = resolve_style({});
  EXPECT_EQ(s.width, 1280);
  EXPECT_EQ(s.height, 720);
  EXPECT_EQ(s.traversal.metric, mrbsp::LodMetric::kError);
  EXPECT_EQ(s.traversal.threshold_px, 2.0f);
  EXPECT_EQ(s.order, DrawOrder::kBsp);
  EXPECT_EQ(s.shading.tint, Tint::kAtlas);
  EXPECT_EQ(s.shading.sun_azimuth_deg, 315.0);
  EXPECT_EQ(s.shading.sun_elevation_deg, 35.0);
  EXPECT_EQ(s.window, 1024);
  EXPECT_EQ(s.haze_km, 60.0);
  EXPECT_TRUE(s.legend);
  EXPECT_EQ(s.surface_triangles, 12000u);
}

TEST(SceneStyle, SetKeysResolveToTheirValuesAndBadNamesFail) {
  SceneStyle in;
  in.lod_metric = "area";
  in.order = "zbuffer";
  in.tint = "relative";
  in.surface_triangles = 0;
  Style s = resolve_style(in);
  EXPECT_EQ(s.traversal.metric, mrbsp::LodMetric::kArea);
  EXPECT_EQ(s.traversal.threshold_px, 500.0f) << "the area metric's default";
  EXPECT_EQ(s.order, DrawOrder::kZBuffer);
  EXPECT_EQ(s.shading.tint, Tint::kRelative);
  EXPECT_EQ(s.surface_triangles, 0u);
  in.threshold = 800.0;
  EXPECT_EQ(resolve_style(in).traversal.threshold_px, 800.0f);
  in.threshold = -1.0;
  EXPECT_THROW(resolve_style(in), std::invalid_argument);
  in.threshold.reset();
  in.order = "painter";
  EXPECT_THROW(resolve_style(in), std::invalid_argument);
}

TEST(SceneStyle, NamesReadBackThroughTheirParsers) {
  for (auto m : {mrbsp::LodMetric::kError, mrbsp::LodMetric::kArea}) EXPECT_EQ(parse_metric(metric_name(m)), m);
  for (auto o : {DrawOrder::kBsp, DrawOrder::kZBuffer, DrawOrder::kPeel, DrawOrder::kVtk, DrawOrder::kSort})
    EXPECT_EQ(parse_order(order_name(o)), o);
  for (auto t : {Tint::kAtlas, Tint::kRelative, Tint::kGrey}) EXPECT_EQ(parse_tint(tint_name(t)), t);
}

TEST(SceneStyle, ViewOptionsOutOfRangeNameTheOption) {
  Style s;
  EXPECT_NO_THROW(check_view_options(45.0, s, false, 0));
  const auto message = [&](double fov, const Style& style, bool levels_given, int levels) {
    try {
      check_view_options(fov, style, levels_given, levels);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(180.0, s, false, 0).rfind("--fov", 0), 0u);
  EXPECT_EQ(message(45.0, s, true, 0).rfind("--levels", 0), 0u);
  s.window = 1000;
  EXPECT_EQ(message(45.0, s, false, 0).rfind("--window", 0), 0u);
  s = {};
  s.haze_km = -1.0;
  EXPECT_EQ(message(45.0, s, false, 0).rfind("--haze", 0), 0u);
  s = {};
  s.shading.sun_elevation_deg = 0.0;
  EXPECT_EQ(message(45.0, s, false, 0).rfind("--sun-elevation", 0), 0u);
}

}  // namespace
}  // namespace terravol::app::scene
