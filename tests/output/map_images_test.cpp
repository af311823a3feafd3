#include "app/output/map_images.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "image_compare.h"

namespace terravol::app::output {
namespace {

TEST(OverlayPng, ValuesAreColourMappedAndNanIsTransparent) {
  io::GeoRaster r;
  r.rows = 2;
  r.cols = 3;
  r.dlon = r.dlat = 1;
  r.values = {60.0f, 80.0f, 100.0f, std::numeric_limits<float>::quiet_NaN(), 120.0f, 40.0f};
  const volume::Colormap viridis = volume::colormap_by_name("viridis");
  const test::Image img = test::decode_png(overlay_png(r, viridis, 60.0, 100.0));
  ASSERT_EQ(img.width, 3);
  ASSERT_EQ(img.height, 2);
  const double t[6] = {0.0, 0.5, 1.0, 0.0, 1.0, 0.0};  // clamped at both ends
  for (int p = 0; p < 6; ++p) {
    if (p == 3) {
      EXPECT_EQ(img.alpha[3], 0);
      continue;
    }
    const glm::u8vec3 want = viridis.map(t[p]);
    EXPECT_EQ(img.alpha[p], 255) << p;
    EXPECT_EQ(img.pixels[p], (test::Rgb8{want.r, want.g, want.b})) << p;
  }
}

TEST(LegendPng, ShowsTheMapFromLoAtTheBottomToHiAtTheTopOnATranslucentCard) {
  const volume::Colormap turbo = volume::colormap_by_name("turbo");
  const test::Image img = test::decode_png(legend_png(turbo, {"path_loss_db (dB)", "10 m above ground", 60, 170}));
  ASSERT_GT(img.width, 100);
  ASSERT_GT(img.height, 200);
  // The bar's column (17 to 39 pixels in): its topmost and bottommost opaque pixels are the map's ends.
  const int x = 25;
  int top = -1, bottom = -1;
  for (int y = 0; y < img.height; ++y) {
    const auto& p = img.at(x, y);
    if (img.alpha[static_cast<std::size_t>(y) * img.width + x] != 255) continue;
    if (test::same_color(p, {turbo.map(1.0).r, turbo.map(1.0).g, turbo.map(1.0).b}, 8) && top < 0) top = y;
    if (test::same_color(p, {turbo.map(0.0).r, turbo.map(0.0).g, turbo.map(0.0).b}, 8)) bottom = y;
  }
  EXPECT_GE(top, 0) << "hi's colour at the top of the bar";
  EXPECT_GT(bottom, top + 150) << "lo's colour at the bottom, 200 pixels below";
  EXPECT_EQ(img.alpha[0], 217) << "the card is white at 85% opacity";
  EXPECT_EQ(img.pixels[0], (test::Rgb8{255, 255, 255}));
  // Text: dark pixels in the title line.
  int dark = 0;
  for (int y = 0; y < 25; ++y)
    for (int xx = 0; xx < img.width; ++xx) dark += img.at(xx, y)[0] < 100;
  EXPECT_GT(dark, 30);
}

}  // namespace
}  // namespace terravol::app::output
