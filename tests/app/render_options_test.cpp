// app/render_options.h: the compound option values of `terravol render`.
#include <gtest/gtest.h>

#include <stdexcept>

#include "app/render_options.h"

namespace terravol::app {
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

}  // namespace
}  // namespace terravol::app
