// Objects on the terrain drawn through the tree (app/scene/object_layer.h in the scene pipeline),
// checked against an independent projection: each point's position relative to the eye by
// GeographicLib's LocalCartesian, a pinhole camera written here from the pose.
#include <gtest/gtest.h>

#include <GeographicLib/LocalCartesian.hpp>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "app/render/scene_renderer.h"
#include "app/scene/scene_file.h"
#include "require_display.h"
#include "temp_dir.h"

namespace terravol::app::render {
namespace {

std::string bundled_dem() { return std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"; }

constexpr int kWidth = 320, kHeight = 180;
constexpr double kFov = 45.0;
const scene::CameraPose kPose{45.50, 6.50, 3000.0, 0.0, -45.0};  // 3 km above the ground, looking north and down
constexpr double kBoxLat = 45.5135, kBoxLon = 6.50, kBoxAgl = 300.0;

// An OBJ box (+Y up), x and z in [-h, h], y in [0, tall], one material.
void write_box(const std::filesystem::path& obj, double h, double tall, const std::string& kd, double d) {
  const std::filesystem::path mtl = obj.string() + ".mtl";
  std::ofstream(mtl) << "newmtl m\nKd " << kd << "\nd " << d << "\n";
  std::ofstream o(obj);
  o << "mtllib " << mtl.filename().string() << "\n";
  for (int c = 0; c < 8; ++c) o << "v " << (c & 1 ? h : -h) << " " << (c & 2 ? tall : 0.0) << " " << (c & 4 ? h : -h) << "\n";
  o << "usemtl m\n";
  // Six quads (1-based), each wound outward.
  o << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
}

struct Pixel {
  double col = 0, row = 0;  // from the left and from the top, pixel centres at .5
  bool in_front = false;
};

// Where the pinhole camera of kPose (eye `eye_h` metres above the datum) shows (lat, lon, h).
Pixel project(double eye_h, double lat, double lon, double h) {
  const GeographicLib::LocalCartesian enu(kPose.lat, kPose.lon, eye_h);
  double e = 0, n = 0, u = 0;
  enu.Forward(lat, lon, h, e, n, u);
  const double p = kPose.pitch_deg * M_PI / 180.0;  // heading 0: forward north and down
  const double z = n * std::cos(p) + u * std::sin(p), y = -n * std::sin(p) + u * std::cos(p), x = e;
  const double focal = kHeight / (2.0 * std::tan(kFov * M_PI / 360.0));
  return {kWidth / 2.0 + focal * x / z, kHeight / 2.0 - focal * y / z, z > 0};
}

struct Render {
  std::vector<std::uint8_t> rgb;
  double eye_h = 0, box_ground = 0;
  std::uint8_t at(int col, int row, int ch) const { return rgb[static_cast<std::size_t>((row * kWidth + col) * 3 + ch)]; }
};

Render render(const std::vector<scene::ObjectSpec>& objects) {
  scene::SceneSpec spec;
  spec.dems = {bundled_dem()};
  spec.objects = objects;
  spec.camera = scene::SceneCamera{kPose, true, kFov};
  RenderSettings s;
  s.width = kWidth;
  s.height = kHeight;
  s.gradient = false;
  s.haze_distance = 0.0;
  SceneOptions o;
  o.max_window = 256;
  SceneRenderer r(spec, s, o);
  r.render(kPose, true, kFov, {});
  return {r.rgb(), r.eye_height(kPose, true), r.ground_height(kBoxLat, kBoxLon)};
}

scene::ObjectSpec at_box(const std::filesystem::path& file, double agl, double opacity = 1.0) {
  scene::ObjectSpec o;
  o.file = file;
  o.pose.lat = kBoxLat;
  o.pose.lon = kBoxLon;
  o.pose.height = agl;
  o.opacity = opacity;
  return o;
}

TEST(ObjectRender, OpaqueBoxIsDrawnWhereTheProjectionSaysAndNowhereElse) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  write_box(dir.path() / "box.obj", 150.0, 200.0, "1 0 1", 1.0);
  const Render r = render({at_box(dir.path() / "box.obj", kBoxAgl)});
  const double base = r.box_ground + kBoxAgl;
  // The box's centre, and the rectangle its corners span on the screen.
  const Pixel c = project(r.eye_h, kBoxLat, kBoxLon, base + 100.0);
  ASSERT_TRUE(c.in_front);
  ASSERT_GT(c.col, 10);
  ASSERT_LT(c.col, kWidth - 10);
  ASSERT_GT(c.row, 10);
  ASSERT_LT(c.row, kHeight - 10);
  const GeographicLib::LocalCartesian at(kBoxLat, kBoxLon, base);
  double c0 = 1e9, c1 = -1e9, r0 = 1e9, r1 = -1e9;
  for (int k = 0; k < 8; ++k) {
    double lat = 0, lon = 0, h = 0;
    at.Reverse(k & 1 ? 150.0 : -150.0, k & 4 ? 150.0 : -150.0, k & 2 ? 200.0 : 0.0, lat, lon, h);
    const Pixel p = project(r.eye_h, lat, lon, h);
    c0 = std::min(c0, p.col);
    c1 = std::max(c1, p.col);
    r0 = std::min(r0, p.row);
    r1 = std::max(r1, p.row);
  }
  const int col = static_cast<int>(c.col), row = static_cast<int>(c.row);
  for (int dc = -1; dc <= 1; ++dc) {
    for (int dr = -1; dr <= 1; ++dr) {
      EXPECT_EQ(r.at(col + dc, row + dr, 0), 255);
      EXPECT_EQ(r.at(col + dc, row + dr, 1), 0);
      EXPECT_EQ(r.at(col + dc, row + dr, 2), 255);
    }
  }
  std::size_t magenta = 0, outside = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if (r.at(x, y, 0) != 255 || r.at(x, y, 1) != 0 || r.at(x, y, 2) != 255) continue;
      ++magenta;
      if (x + 0.5 < c0 - 1 || x + 0.5 > c1 + 1 || y + 0.5 < r0 - 1 || y + 0.5 > r1 + 1) ++outside;
    }
  }
  EXPECT_GT(magenta, 100u);
  EXPECT_EQ(outside, 0u) << "magenta pixels outside the box's projected rectangle [" << c0 << ", " << c1 << "] x [" << r0
                         << ", " << r1 << "]";
  // And without the object, none.
  const Render bare = render({});
  EXPECT_FALSE(bare.at(col, row, 0) == 255 && bare.at(col, row, 1) == 0 && bare.at(col, row, 2) == 255);
}

TEST(ObjectRender, TranslucentPlateOverTheBoxBlendsInTreeOrder) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  write_box(dir.path() / "box.obj", 150.0, 200.0, "1 0 1", 1.0);
  write_box(dir.path() / "plate.obj", 600.0, 5.0, "0 1 1", 1.0);
  // The plate (cyan, half opaque) 300 m above the box's top: every ray to the box passes it.
  const Render r = render({at_box(dir.path() / "box.obj", kBoxAgl), at_box(dir.path() / "plate.obj", kBoxAgl + 500.0, 0.5)});
  const Pixel c = project(r.eye_h, kBoxLat, kBoxLon, r.box_ground + kBoxAgl + 100.0);
  ASSERT_TRUE(c.in_front);
  // Over the opaque magenta, two faces of the plate (its bottom, then its top), each alpha
  // a = 128/255 of cyan: R = 255 (1 - a)^2 = 63, G = 255 (1 - (1 - a)^2) = 192, B = 255. Drawn
  // in any other order (the box over the plate) the pixel would be magenta.
  const int col = static_cast<int>(c.col), row = static_cast<int>(c.row);
  for (int dc = -1; dc <= 1; ++dc) {
    for (int dr = -1; dr <= 1; ++dr) {
      EXPECT_NEAR(r.at(col + dc, row + dr, 0), 63, 2);
      EXPECT_NEAR(r.at(col + dc, row + dr, 1), 192, 2);
      EXPECT_NEAR(r.at(col + dc, row + dr, 2), 255, 2);
    }
  }
}

}  // namespace
}  // namespace terravol::app::render
