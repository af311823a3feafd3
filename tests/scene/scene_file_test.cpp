// The scene file: what it may say, how paths resolve, and one-line errors for what it may not.
#include <gtest/gtest.h>

#include "volume/geometry.h"
#include <nlohmann/json.hpp>

#include <fstream>
#include <stdexcept>
#include <string>

#include "app/scene/scene_file.h"
#include "temp_dir.h"

namespace terravol::app::scene {
namespace {

using nlohmann::json;

std::string error_of(const std::string& text) {
  try {
    parse_scene_json(json::parse(text), "/base", "scene.json");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(SceneFile, TheIssuesExampleParsesWithEveryValue) {
  const SceneSpec s = parse_scene_json(json::parse(R"({"dem": ["N44W072.hgt"], "volumes": [{"file": "rf.vdb",
      "isosurfaces": [{"value": 120, "color": [255, 200, 0], "opacity": 0.4}],
      "slices": [{"agl": 300, "opacity": 0.5, "colormap": "viridis"}]}],
      "camera": {"lat": 44.2, "lon": -71.4, "alt": 3000, "heading": 45, "pitch": -20, "fov": 45}})"),
                                       "/data/scenes", "scene.json");
  ASSERT_EQ(s.dems.size(), 1u);
  EXPECT_EQ(s.dems[0], std::filesystem::path("/data/scenes/N44W072.hgt")) << "relative to the scene file";
  ASSERT_EQ(s.volumes.size(), 1u);
  const VolumeSpec& v = s.volumes[0];
  EXPECT_EQ(v.file, std::filesystem::path("/data/scenes/rf.vdb"));
  EXPECT_TRUE(v.visible);
  ASSERT_EQ(v.isosurfaces.size(), 1u);
  EXPECT_EQ(v.isosurfaces[0].value, 120.0f);
  EXPECT_EQ(v.isosurfaces[0].color, glm::u8vec3(255, 200, 0));
  EXPECT_DOUBLE_EQ(v.isosurfaces[0].opacity, 0.4);
  ASSERT_EQ(v.slices.size(), 1u);
  EXPECT_EQ(v.slices[0].kind, volume::SliceKind::kAgl);
  EXPECT_DOUBLE_EQ(v.slices[0].value, 300.0);
  EXPECT_EQ(v.slices[0].colormap, "viridis");
  ASSERT_TRUE(s.camera.has_value());
  EXPECT_DOUBLE_EQ(s.camera->pose.lat, 44.2);
  EXPECT_DOUBLE_EQ(s.camera->pose.heading_deg, 45.0);
  EXPECT_DOUBLE_EQ(s.camera->pose.pitch_deg, -20.0);
  EXPECT_DOUBLE_EQ(s.camera->fov_y_deg, 45.0);
  EXPECT_FALSE(s.camera->agl);
}

TEST(SceneFile, AbsolutePathsStayAndOneDemMayBeAString) {
  const SceneSpec s = parse_scene_json(json::parse(R"({"dem": "/abs/tiles", "volumes": [{"file": "/abs/a.vdb"}]})"),
                                       "/base", "scene.json");
  ASSERT_EQ(s.dems.size(), 1u);
  EXPECT_EQ(s.dems[0], std::filesystem::path("/abs/tiles"));
  EXPECT_EQ(s.volumes[0].file, std::filesystem::path("/abs/a.vdb"));
}

TEST(SceneFile, IsosurfacesWithoutAColourGetDistinctOnes) {
  const SceneSpec s = parse_scene_json(
      json::parse(R"({"volumes": [{"file": "a.vdb", "isosurfaces": [{"value": 100}, {"value": 120}]}]})"), "/b", "s");
  EXPECT_NE(s.volumes[0].isosurfaces[0].color, s.volumes[0].isosurfaces[1].color);
  EXPECT_DOUBLE_EQ(s.volumes[0].isosurfaces[0].opacity, 0.5);
}

// Across volumes too: the palette follows an isosurface's place among all of the file's, so
// two transmitters' volumes do not draw their surfaces in the same two colours.
TEST(SceneFile, IsosurfacesOfDifferentVolumesWithoutAColourDiffer) {
  const SceneSpec s = parse_scene_json(json::parse(R"({"volumes": [
      {"file": "a.vdb", "isosurfaces": [{"value": 100}, {"value": 120}]},
      {"file": "b.vdb", "isosurfaces": [{"value": 110, "color": [1, 2, 3]}, {"value": 130}]}]})"),
                                       "/b", "s");
  const std::vector<glm::u8vec3> colours{s.volumes[0].isosurfaces[0].color, s.volumes[0].isosurfaces[1].color,
                                         s.volumes[1].isosurfaces[0].color, s.volumes[1].isosurfaces[1].color};
  for (std::size_t a = 0; a < colours.size(); ++a)
    for (std::size_t b = a + 1; b < colours.size(); ++b) EXPECT_NE(colours[a], colours[b]) << a << " " << b;
  EXPECT_EQ(colours[3], volume::default_isosurface_color(3));
}

TEST(SceneFile, RenderStyleKeysAreRead) {
  const SceneSpec s = parse_scene_json(json::parse(R"({"render": {"size": "640x360", "threshold": 1.5,
      "order": "peel", "tint": "grey", "window": 512, "haze_km": 0, "legend": false}})"),
                                       "/b", "s");
  EXPECT_EQ(s.style.width, 640);
  EXPECT_EQ(s.style.height, 360);
  EXPECT_EQ(s.style.threshold, 1.5);
  EXPECT_EQ(s.style.order, "peel");
  EXPECT_EQ(s.style.window, 512);
  EXPECT_EQ(s.style.legend, false);
}

TEST(SceneFile, ErrorsNameTheFileAndTheKeyPath) {
  EXPECT_EQ(error_of(R"({"dem": [], "volumez": []})"),
            "scene.json: volumez: unknown key (known: dem, volumes, objects, camera, render)");
  EXPECT_EQ(error_of(R"({"volumes": [{"file": "a.vdb", "slices": [{"agl": 300}, {"agl": 1, "lat": 2}]}]})"),
            "scene.json: volumes[0].slices[1]: needs exactly one of lat, lon, alt, agl");
  EXPECT_EQ(error_of(R"({"volumes": [{"file": "a.vdb", "isosurfaces": [{"value": 1, "opacity": 2}]}]})"),
            "scene.json: volumes[0].isosurfaces[0].opacity: must be within [0, 1], is 2");
  EXPECT_EQ(error_of(R"({"camera": {"lat": 44, "lon": -71}})"), "scene.json: camera: missing \"alt\"");
  EXPECT_EQ(error_of(R"({"camera": {"lat": "44", "lon": -71, "alt": 1}})"), "scene.json: camera.lat: expected a number, got \"44\"");
  EXPECT_EQ(error_of(R"({"volumes": [{"file": "a.vdb", "isosurfaces": [{"value": 1, "color": [1, 2]}]}]})"),
            "scene.json: volumes[0].isosurfaces[0].color: expected [R, G, B] with each 0..255");
  EXPECT_NE(error_of(R"({"volumes": [{"file": "a.vdb", "slices": [{"agl": 1, "colormap": "rainbowz"}]}]})")
                .find("scene.json: volumes[0].slices[0].colormap: unknown colour map"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"render": {"order": "painter"}})").find("scene.json: render.order: --order painter"),
            std::string::npos);
  EXPECT_EQ(error_of(R"({"render": {"window": 300}})"), "scene.json: render.window: must be a power of two");
  EXPECT_EQ(error_of(R"([1, 2])"), "scene.json: (top level): expected an object");
}

TEST(SceneFile, FilesThatAreNotScenesFailWithOneLine) {
  test::TempDir dir;
  const auto bad = dir.path() / "bad.json";
  std::ofstream(bad) << "{\"dem\": [\"a.hgt\",";
  try {
    load_scene_file(bad);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), bad.string() + ": not valid JSON (byte 18)");
  }
  try {
    load_scene_file(dir.path() / "missing.json");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("missing.json: cannot read"), std::string::npos) << e.what();
  }
}

TEST(SceneFile, ObjectsAreReadWithTheirPoses) {
  const SceneSpec s = parse_scene_json(
      json::parse(R"({"objects": [{"file": "truck.glb", "lat": 44.27, "lon": -71.3, "heading": 45, "pitch": 5,
                                     "roll": -3, "scale": 10, "opacity": 0.5, "up": "z"},
                                    {"file": "/m/mast.obj", "lat": 44.3, "lon": -71.2, "height": 900}]})"),
      "/base", "scene.json");
  ASSERT_EQ(s.objects.size(), 2u);
  const ObjectSpec& a = s.objects[0];
  EXPECT_EQ(a.file, std::filesystem::path("/base/truck.glb"));
  EXPECT_EQ(a.pose.lat, 44.27);
  EXPECT_EQ(a.pose.lon, -71.3);
  EXPECT_TRUE(a.agl);
  EXPECT_EQ(a.pose.height, 0.0);
  EXPECT_EQ(a.pose.heading_deg, 45.0);
  EXPECT_EQ(a.pose.pitch_deg, 5.0);
  EXPECT_EQ(a.pose.roll_deg, -3.0);
  EXPECT_EQ(a.pose.scale, 10.0);
  EXPECT_EQ(a.opacity, 0.5);
  EXPECT_EQ(a.pose.up, objects::UpAxis::kZ);
  const ObjectSpec& b = s.objects[1];
  EXPECT_EQ(b.file, std::filesystem::path("/m/mast.obj"));
  EXPECT_FALSE(b.agl);
  EXPECT_EQ(b.pose.height, 900.0);
  EXPECT_EQ(b.pose.up, objects::UpAxis::kY);
}

TEST(SceneFile, BadObjectsNameTheKey) {
  EXPECT_EQ(error_of(R"({"objects": [{"lat": 1, "lon": 2}]})"), "scene.json: objects[0]: missing \"file\"");
  EXPECT_EQ(error_of(R"({"objects": [{"file": "a.glb", "lat": 1, "lon": 2, "agl": 1, "height": 2}]})"),
            "scene.json: objects[0]: give height (above the datum) or agl (above the ground), not both");
  EXPECT_EQ(error_of(R"({"objects": [{"file": "a.glb", "lat": 1, "lon": 2, "scale": 0}]})"),
            "scene.json: objects[0].scale: must be > 0");
  EXPECT_EQ(error_of(R"({"objects": [{"file": "a.glb", "lat": 1, "lon": 2, "up": "x"}]})"),
            "scene.json: objects[0].up: expected \"y\" or \"z\", got \"x\"");
  EXPECT_EQ(error_of(R"({"objects": [{"file": "a.glb", "lat": 100, "lon": 2}]})"),
            "scene.json: objects[0].lat: must be within [-85, 85], is 100");
  EXPECT_EQ(error_of(R"({"objects": {"file": "a.glb"}})"), "scene.json: objects: expected a list");
}

TEST(ObjectOption, ParsesFileAtLatLonAglAndKeys) {
  const ObjectSpec o = parse_object("models/truck.gltf@44.27,-71.30,2.5,heading=45,scale=10,up=z");
  EXPECT_EQ(o.file, std::filesystem::path("models/truck.gltf"));
  EXPECT_EQ(o.pose.lat, 44.27);
  EXPECT_EQ(o.pose.lon, -71.30);
  EXPECT_TRUE(o.agl);
  EXPECT_EQ(o.pose.height, 2.5);
  EXPECT_EQ(o.pose.heading_deg, 45.0);
  EXPECT_EQ(o.pose.scale, 10.0);
  EXPECT_EQ(o.pose.up, objects::UpAxis::kZ);
  EXPECT_EQ(parse_object("a@b.obj@1,2,3").file, std::filesystem::path("a@b.obj"));  // the last '@' splits
}

TEST(ObjectOption, BadTextIsOneLineNamingTheOption) {
  const auto error = [](const std::string& text) {
    try {
      parse_object(text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error("truck.glb"), "--object 'truck.glb': expected FILE@LAT,LON,AGL[,heading=..][,scale=..]");
  EXPECT_EQ(error("truck.glb@1,2"), "--object 'truck.glb@1,2': expected LAT,LON,AGL after '@'");
  EXPECT_EQ(error("truck.glb@1,x,2"), "--object 'truck.glb@1,x,2': 'x' is not a number");
  EXPECT_EQ(error("truck.glb@1,2,3,size=4"),
            "--object 'truck.glb@1,2,3,size=4': unknown key 'size' (known: heading, pitch, roll, scale, opacity, up)");
  EXPECT_EQ(error("truck.glb@1,2,3,scale=-1"), "--object 'truck.glb@1,2,3,scale=-1': scale: must be within [0, 1e+06], is -1");
  EXPECT_EQ(error("truck.glb@1,2,3,heading"), "--object 'truck.glb@1,2,3,heading': 'heading' is not KEY=VALUE");
  EXPECT_EQ(error("truck.glb@1,2,3,scale=2,scale=3"), "--object 'truck.glb@1,2,3,scale=2,scale=3': 'scale' given twice");
}

}  // namespace
}  // namespace terravol::app::scene
