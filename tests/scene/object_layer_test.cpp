// The object layer (app/scene/object_layer.h): each instance's level by the screen-space-error
// rule, worked out here from the levels' errors and the distance; re-merging only the instances
// whose level changed; colour cubes for the far ones; surface ids apart from the volumes'.
#include "app/scene/object_layer.h"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <fstream>
#include <set>
#include <string>

#include "app/scene/camera.h"
#include "io/mosaic.h"
#include "temp_dir.h"

namespace terravol::app::scene {
namespace {

std::string bundled_dem() { return std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"; }

// A UV sphere of radius 5 (OBJ, +Y up) with 48 x 24 quads: 2,208 triangles after the poles'.
void write_sphere(const std::filesystem::path& p) {
  std::ofstream o(p);
  const int nu = 48, nv = 24;
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const double t = M_PI * j / nv, f = 2 * M_PI * i / nu;
      o << "v " << 5 * std::sin(t) * std::cos(f) << " " << 5 + 5 * std::cos(t) << " " << 5 * std::sin(t) * std::sin(f) << "\n";
    }
  }
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const int a = j * nu + i + 1, b = j * nu + (i + 1) % nu + 1, c = a + nu, d = b + nu;
      if (j == 0) {
        o << "f " << a << " " << d << " " << c << "\n";
      } else if (j == nv - 1) {
        o << "f " << a << " " << b << " " << c << "\n";
      } else {
        o << "f " << a << " " << b << " " << d << " " << c << "\n";
      }
    }
  }
}

struct Fixture {
  test::TempDir dir;
  io::Mosaic mosaic = io::Mosaic::open({bundled_dem()});
  std::unique_ptr<TerrainScene> scene;
  Fixture() {
    write_sphere(dir.path() / "sphere.obj");
    scene = std::make_unique<TerrainScene>(mosaic, choose_window(mosaic.rows(), mosaic.cols(), 600, 600, 256), 4);
  }
  ObjectSpec at(double lat, double lon) const {
    ObjectSpec o;
    o.file = dir.path() / "sphere.obj";
    o.pose.lat = lat;
    o.pose.lon = lon;
    return o;
  }
  ObjectLayer layer(const std::vector<ObjectSpec>& specs) const {
    const TerrainScene& s = *scene;
    return ObjectLayer(specs, [&s](double lat, double lon) { return s.ground_height(lat, lon); }, s.frame());
  }
  // A camera `metres` south of (lat, lon), 50 m above the ground there, looking north.
  mrbsp::Camera camera_south_of(double lat, double lon, double metres) const {
    const double lat_eye = lat - metres / 111000.0;
    const CameraPose pose{lat_eye, lon, 50.0, 0.0, 0.0};
    return make_scene_camera(scene->frame(), pose, scene->ground_height(lat_eye, lon) + 50.0, 45.0, 1280, 720, 1.0);
  }
};

TEST(ObjectLayer, LevelIsTheCoarsestWhoseErrorProjectsWithinTheThreshold) {
  Fixture f;
  ObjectLayer layer = f.layer({f.at(45.5, 6.5)});
  const auto& levels = layer.levels(0);
  ASSERT_GE(levels.size(), 4u);
  const mrbsp::TraversalOptions options;  // screen-space error, 2 px
  int last = -1;
  for (const double d : {30.0, 100.0, 300.0, 1000.0, 3000.0}) {
    const mrbsp::Camera cam = f.camera_south_of(45.5, 6.5, d);
    layer.update(*f.scene, cam, options);
    const int k = layer.level_of(0);
    EXPECT_GE(k, last) << d << " m";
    last = k;
    // The rule, worked out here: distance from the eye to the sphere's box (radius 5, on the ground).
    const glm::dvec3 centre = layer.placed(0, 0).vertices.front();  // a vertex: within 10 m of the box
    const double distance = glm::length(centre - cam.eye);
    const double focal = 720 / (2 * std::tan(22.5 * M_PI / 180));
    const auto px = [&](int level) { return levels[static_cast<std::size_t>(level)].error * focal / distance; };
    if (k < static_cast<int>(levels.size())) {
      EXPECT_LE(px(k), 2.0 * (distance / (distance - 10.0))) << d << " m, level " << k;
      if (k + 1 < static_cast<int>(levels.size())) {
        EXPECT_GT(px(k + 1), 2.0 * (distance / (distance + 10.0))) << d << " m";
      }
    }
  }
  EXPECT_GT(last, 0);
}

TEST(ObjectLayer, OnlyInstancesWhoseLevelChangedAreMergedAgain) {
  Fixture f;
  ObjectLayer layer = f.layer({f.at(45.5, 6.5), f.at(45.55, 6.55)});
  const mrbsp::TraversalOptions options;
  EXPECT_TRUE(layer.update(*f.scene, f.camera_south_of(45.5, 6.5, 2000.0), options));
  EXPECT_EQ(layer.figures().remerged, 2u);  // a tree it had not merged into: every instance
  EXPECT_EQ(f.scene->tree().merge_stats().surfaces, 2u);
  EXPECT_FALSE(layer.update(*f.scene, f.camera_south_of(45.5, 6.5, 2000.0), options));
  EXPECT_EQ(layer.figures().remerged, 0u);
  const int far = layer.level_of(1), first = layer.level_of(0);
  layer.update(*f.scene, f.camera_south_of(45.5, 6.5, 30.0), options);  // near the first only
  EXPECT_EQ(layer.figures().remerged, 1u);
  EXPECT_EQ(layer.level_of(1), far);
  EXPECT_LT(layer.level_of(0), first);
}

TEST(ObjectLayer, FarInstanceIsItsColourCube) {
  Fixture f;
  ObjectLayer layer = f.layer({f.at(45.5, 6.5)});
  // 10 m across from 15 km: 10 / 15000 * 869 px = 0.6 px.
  layer.update(*f.scene, f.camera_south_of(45.5, 6.5, 15000.0), {});
  EXPECT_EQ(layer.level_of(0), static_cast<int>(layer.levels(0).size()));
  EXPECT_EQ(layer.figures().cubes, 1u);
  EXPECT_EQ(layer.visible_mesh().triangle_count(), 12u);
  mrbsp::TraversalOptions full;
  full.full_res = true;
  layer.update(*f.scene, f.camera_south_of(45.5, 6.5, 15000.0), full);
  EXPECT_EQ(layer.level_of(0), 0);
}

TEST(ObjectLayer, FixedLevelAndSharedModel) {
  Fixture f;
  ObjectLayer layer = f.layer({f.at(45.5, 6.5), f.at(45.51, 6.5), f.at(45.52, 6.5)});
  EXPECT_EQ(layer.figures().models, 1u);  // one file, read once
  layer.set_fixed_level(1);
  layer.update(*f.scene, f.camera_south_of(45.5, 6.5, 30.0), {});
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(layer.level_of(i), 1);
  EXPECT_EQ(layer.figures().chosen_triangles, 3 * layer.levels(0)[1].mesh.triangle_count());
}

TEST(ObjectLayer, SurfaceIdsAreApartFromTheVolumes) {
  std::set<std::uint32_t> ids;
  for (std::size_t i : {0u, 1u, 16383u, 16384u, 100000u}) {
    const std::uint32_t id = object_surface_id(i);
    EXPECT_EQ((id >> 14) & 3u, 3u);  // VolumeLayer's kinds are 0, 1 and 2
    ids.insert(id);
  }
  EXPECT_EQ(ids.size(), 5u);
}

TEST(ObjectLayer, BadModelNamesTheFile) {
  Fixture f;
  std::ofstream(f.dir.path() / "bad.obj") << "this is not a model\n";
  ObjectSpec o = f.at(45.5, 6.5);
  o.file = f.dir.path() / "bad.obj";
  try {
    f.layer({o});
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_EQ(std::string(e.what()).rfind(o.file.string() + ": ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace terravol::app::scene
