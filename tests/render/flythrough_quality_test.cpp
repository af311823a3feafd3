// Issue acceptance for the tree's LOD, measured on real terrain: along a flythrough of 24
// views over N44W072 at 1280x720, the default threshold (2 px screen-space error) must draw
// at least 20x fewer triangles than the full-resolution terrain (median over the views), and
// every image must keep a PSNR of 35 dB or more against the full-resolution image. The
// figures are printed for the record.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "app/render/terrain_renderer.h"
#include "app/scene/camera.h"
#include "app/scene/terrain_colors.h"
#include "app/scene/terrain_scene.h"
#include "image_compare.h"
#include "require_display.h"
#include "shared_data.h"

namespace terravol::app::render {
namespace {

double psnr(const test::Image& a, const test::Image& b) {
  double se = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double d = static_cast<double>(a.pixels[i][k]) - b.pixels[i][k];
      se += d * d;
    }
  const double mse = se / (3.0 * static_cast<double>(a.pixels.size()));
  return mse == 0.0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

TEST(FlythroughQuality, DefaultThresholdDrawsTwentyTimesFewerTrianglesAt35DbOverN44W072) {
  const auto dem = test::shared_dem("N44W072.hgt");
  TERRAVOL_REQUIRE_SHARED(dem);
  TERRAVOL_REQUIRE_DISPLAY();
  const io::Mosaic mosaic = io::Mosaic::open({dem});
  const scene::WindowChoice window = scene::choose_window(mosaic.rows(), mosaic.cols(), 600.0, 600.0, 1024);
  const scene::TerrainScene scene(mosaic, window, scene::default_levels(window.cells));
  const mrbsp::TerrainTree& tree = scene.tree();
  const scene::TerrainShading lattice =
      scene::shade_terrain(scene.cells(), scene.xs(), scene.ys(), scene.z(), scene.heights(), {});
  const scene::TerrainShading shading = scene::vertex_shading(lattice, tree.merged_base(), tree.merged_colors());
  RenderSettings settings;
  settings.gradient = false;  // one background colour for every view
  settings.haze_distance = 0.0;
  TerrainRenderer renderer(tree.positions(), shading, settings, ColorTexture{scene.cells() + 1, lattice.rgba});

  std::vector<double> ratios, psnrs;
  mrbsp::Frame frame;
  for (int k = 0; k < 24; ++k) {
    // A path across the window: low oblique views (pitch -5 to -20 degrees, 600 to 2500 m above
    // the ground) turning through all headings, and a few high overviews.
    const double t = k / 23.0;
    scene::CameraPose pose;
    pose.lat = 44.25 + 0.5 * t;
    pose.lon = -71.75 + 0.5 * std::sin(3.0 * t);
    pose.heading_deg = 15.0 * k;
    const bool overview = k % 6 == 5;
    pose.pitch_deg = overview ? -45.0 : -5.0 - 15.0 * std::abs(std::sin(1.7 * k));
    const double ground = scene.ground_height(pose.lat, pose.lon);
    const double clearance = overview ? 8000.0 : 600.0 + 1900.0 * std::abs(std::cos(1.3 * k));
    const mrbsp::Camera camera =
        scene::make_scene_camera(scene.frame(), pose, ground + clearance, 45.0, settings.width, settings.height,
                                 scene::near_plane_for(clearance));
    renderer.set_camera(camera, 200000.0);

    mrbsp::TraversalOptions lod;
    tree.traverse(camera, lod, frame);
    const double lod_triangles = static_cast<double>(frame.indices.size() / 3);
    renderer.set_frame(frame);
    renderer.render();
    const test::Image lod_image = test::image_of_rgb(renderer.rgb(), settings.width, settings.height);

    mrbsp::TraversalOptions full;
    full.full_res = true;
    tree.traverse(camera, full, frame);
    const double full_triangles = static_cast<double>(frame.indices.size() / 3);
    renderer.set_frame(frame);
    renderer.render();
    const test::Image full_image = test::image_of_rgb(renderer.rgb(), settings.width, settings.height);

    ratios.push_back(full_triangles / lod_triangles);
    psnrs.push_back(psnr(lod_image, full_image));
    std::printf("view %2d: %8.0f triangles at 2 px, %8.0f full-res (%.1fx), PSNR %.1f dB\n", k, lod_triangles,
                full_triangles, ratios.back(), psnrs.back());
    EXPECT_GE(psnrs.back(), 35.0) << "view " << k;
  }
  std::printf("median triangle ratio %.1fx, median PSNR %.1f dB, lowest PSNR %.1f dB\n", median(ratios), median(psnrs),
              *std::min_element(psnrs.begin(), psnrs.end()));
  EXPECT_GE(median(ratios), 20.0);
}

}  // namespace
}  // namespace terravol::app::render
