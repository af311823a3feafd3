// app/viewer/overlay_layout.h with text measured as fixed-pitch lines: exact boxes at 1280 x 720,
// and for seeded random window sizes and texts, every part inside the window and no two
// overlapping, checked pairwise by this file's own rectangle test.
#include "app/viewer/overlay_layout.h"

#include <gtest/gtest.h>

#include <random>
#include <string>

namespace terravol::app::viewer {
namespace {

// Text of `lines` lines of `chars` characters, each 0.6 font wide and 1.2 font tall.
std::function<std::array<int, 2>(int)> fixed_pitch(int chars, int lines) {
  return [=](int font) { return std::array<int, 2>{chars * font * 6 / 10, lines * font * 12 / 10}; };
}

// A card 150 px wide that shrinks from 420 px to 180 px at least.
std::array<int, 2> card(int max_height) { return {150, std::clamp(max_height, 180, 420)}; }

// The viewer's parts: its overlay text (5 lines of 80), its key list (19 of 78), shown.
OverlayInput viewer_like(int width, int height) {
  OverlayInput in;
  in.width = width;
  in.height = height;
  in.slider_height = 92;
  in.text = fixed_pitch(80, 5);
  in.keys = fixed_pitch(78, 19);
  in.keys_shown = true;
  in.legend = card;
  return in;
}

// Strictly overlapping interiors, written out here rather than with overlap().
bool share_area(const Box& a, const Box& b) {
  const int w = std::min(a.x + a.w, b.x + b.w) - std::max(a.x, b.x);
  const int h = std::min(a.y + a.h, b.y + b.h) - std::max(a.y, b.y);
  return a.w > 0 && a.h > 0 && b.w > 0 && b.h > 0 && w > 0 && h > 0;
}

TEST(OverlayLayout, At1280x720EverythingFitsAtItsLargestFont) {
  const OverlayInput in = viewer_like(1280, 720);
  const OverlayLayout l = lay_out_overlay(in);
  EXPECT_EQ(l.slider.x, 1280 - 8 - 460);
  EXPECT_EQ(l.slider.y, 720 - 8 - 92);
  EXPECT_EQ(l.slider.w, 460);
  EXPECT_EQ(l.legend.x, 1280 - 8 - 150);
  EXPECT_EQ(l.legend.y, 8);
  EXPECT_EQ(l.legend.h, 420) << "the card's full height: there is room";
  EXPECT_EQ(l.legend_max_height, 720 - 8 - 92 - 8 - 8);
  EXPECT_EQ(l.text_font, 15);
  EXPECT_EQ(l.text.w, 80 * 15 * 6 / 10);
  // The key list, 655 x 319 px at 14, fits left of the slider and below the text.
  EXPECT_EQ(l.keys_font, 14);
  EXPECT_EQ(l.keys.bottom(), 720 - 8);
  EXPECT_FALSE(share_area(l.keys, l.text));
}

TEST(OverlayLayout, NarrowWindowsShrinkTheFontsAndTinyOnesLeaveTextOut) {
  OverlayInput in = viewer_like(800, 600);
  const OverlayLayout l = lay_out_overlay(in);
  EXPECT_LT(l.text_font, 15);
  EXPECT_LE(l.text.right(), l.legend.x - 8);
  EXPECT_LT(l.keys_font, 14);
  EXPECT_LE(l.keys.right(), l.slider.x - 8);
  in.width = 200;
  in.height = 150;
  const OverlayLayout tiny = lay_out_overlay(in);
  EXPECT_TRUE(tiny.keys.empty());
  EXPECT_TRUE(tiny.legend.empty()) << "a 180 px card does not fit above the slider";
}

TEST(OverlayLayout, RandomWindowsAndTextsNeverOverlapOrLeaveTheWindow) {
  std::mt19937 rng(18);
  for (int trial = 0; trial < 2000; ++trial) {
    OverlayInput in;
    in.width = std::uniform_int_distribution<int>(120, 2560)(rng);
    in.height = std::uniform_int_distribution<int>(100, 1600)(rng);
    in.slider_height = std::uniform_int_distribution<int>(40, 120)(rng);
    in.text = fixed_pitch(std::uniform_int_distribution<int>(10, 120)(rng), std::uniform_int_distribution<int>(1, 8)(rng));
    in.keys = fixed_pitch(std::uniform_int_distribution<int>(10, 100)(rng), std::uniform_int_distribution<int>(1, 30)(rng));
    in.keys_shown = rng() % 2 == 0;
    const int lw = std::uniform_int_distribution<int>(60, 400)(rng), lmin = std::uniform_int_distribution<int>(50, 400)(rng);
    if (rng() % 4 != 0) in.legend = [=](int h) { return std::array<int, 2>{lw, std::clamp(h, lmin, 500)}; };
    const OverlayLayout l = lay_out_overlay(in);
    const Box parts[4] = {l.slider, l.legend, l.text, l.keys};
    for (int a = 0; a < 4; ++a) {
      const Box& p = parts[a];
      if (p.w <= 0 || p.h <= 0) continue;
      EXPECT_TRUE(p.x >= 0 && p.y >= 0 && p.x + p.w <= in.width && p.y + p.h <= in.height)
          << "trial " << trial << " part " << a;
      for (int b = 0; b < a; ++b) EXPECT_FALSE(share_area(p, parts[b])) << "trial " << trial << " parts " << b << ", " << a;
    }
    if (!in.keys_shown) {
      EXPECT_TRUE(l.keys.w <= 0 || l.keys.h <= 0);
    }
  }
}

// The font search against trying every size from the largest down: the same font for seeded
// random texts (proportional, and with a few pixels of padding and rounding that are not) and
// rooms, in at most 4 measures for proportional text (8 sizes to try).
TEST(OverlayLayout, FontSearchFindsWhatTryingEverySizeFindsInAFewMeasures) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 5000; ++trial) {
    const int chars = std::uniform_int_distribution<int>(1, 140)(rng), lines = std::uniform_int_distribution<int>(1, 30)(rng);
    const int pad = trial % 2 == 0 ? 0 : std::uniform_int_distribution<int>(1, 6)(rng);
    const auto text = [&](int font) {
      return std::array<int, 2>{(chars * font * 6 + 5) / 10 + pad, lines * font * 12 / 10 + pad};
    };
    const int w = std::uniform_int_distribution<int>(0, 1500)(rng), h = std::uniform_int_distribution<int>(0, 900)(rng);
    int every = 0;
    for (int f = 15; f >= 8 && every == 0; --f) {
      const auto s = text(f);
      if (s[0] <= w && s[1] <= h) every = f;
    }
    int calls = 0;
    std::array<int, 2> size{0, 0};
    const int found = fitting_font(
        [&](int f) {
          ++calls;
          return text(f);
        },
        15, 8, w, h, size);
    ASSERT_EQ(found, every) << "trial " << trial << ": " << chars << " x " << lines << " in " << w << " x " << h;
    if (found > 0) {
      EXPECT_EQ(size, text(found)) << "trial " << trial;
    }
    if (pad == 0) {
      EXPECT_LE(calls, 4) << "trial " << trial;
    }
  }
}

TEST(OverlayLayout, OverlapAndUnitedAreOnAreaNotEdges) {
  EXPECT_FALSE(overlap({0, 0, 10, 10}, {10, 0, 5, 5})) << "touching along an edge";
  EXPECT_TRUE(overlap({0, 0, 10, 10}, {9, 9, 5, 5}));
  EXPECT_FALSE(overlap({0, 0, 0, 10}, {0, 0, 5, 5})) << "an empty box covers nothing";
  const Box u = united({0, 0, 10, 10}, {20, 5, 5, 10});
  EXPECT_EQ(u.x, 0);
  EXPECT_EQ(u.w, 25);
  EXPECT_EQ(u.h, 15);
  EXPECT_EQ(united({}, {3, 4, 5, 6}).x, 3);
}

}  // namespace
}  // namespace terravol::app::viewer
