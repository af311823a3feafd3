// Where the viewer's overlay goes so that no two of its parts overlap, at any window size: the
// LOD slider's panel in the lower right, the legend card above it on the right, the overlay
// text in the upper left and the key list in the lower left, each text at the largest font
// size that fits the room the others leave. No VTK: the viewer measures text and cards and
// passes the measures in.
#pragma once

#include <array>
#include <functional>

namespace terravol::app::viewer {

// A rectangle in window pixels, x to the right and y down from the window's top left corner.
// w == 0 or h == 0: nothing.
struct Box {
  int x = 0, y = 0, w = 0, h = 0;
  int right() const { return x + w; }
  int bottom() const { return y + h; }
  bool empty() const { return w <= 0 || h <= 0; }
};

// True when a and b share some area (boxes that only touch along an edge do not).
bool overlap(const Box& a, const Box& b);
// The smallest box holding both (the other one when either is empty).
Box united(const Box& a, const Box& b);

constexpr int kOverlayMargin = 8;  // pixels between the parts and from the window's edges

struct OverlayInput {
  int width = 0, height = 0;  // the window, pixels
  int slider_height = 0;      // the slider's panel (title, knob, end labels), pixels
  // Width and height in pixels of the overlay text / the key list at a font size in pixels.
  std::function<std::array<int, 2>(int font_px)> text, keys;
  bool keys_shown = false;
  // Width and height of the legend card when it may be at most max_height tall ({0, 0}: no
  // legend); the card may come out taller when it cannot shrink further.
  std::function<std::array<int, 2>(int max_height)> legend;
};

struct OverlayLayout {
  Box slider;   // the panel: width clamp(0.36 * window width, 240, 460) px, less when the window is narrower
  Box legend;   // right-aligned above the slider; empty without a legend or when it does not fit
  int legend_max_height = 0;
  Box text;     // top left; empty when even kMinFont does not fit
  int text_font = 0;
  Box keys;     // bottom left; empty when not shown or when even kMinFont does not fit
  int keys_font = 0;
};

constexpr int kTextFonts[2] = {15, 8};  // the overlay text's largest and smallest font sizes
constexpr int kKeyFonts[2] = {14, 7};   // the key list's

// The largest font in [smallest, largest] at which measure(font) fits w x h (size: that
// measure), or 0 when none does. The measure must grow with the font (each is some
// milliseconds of FreeType layout in the viewer, so not every size is tried): after the largest,
// the size that the largest's overshoot says fits, then one step at a time up or down from it;
// at most 4 measures (of the 8 sizes the viewer tries) when the text's size is proportional to
// the font, as the rounding of whole pixels allows.
int fitting_font(const std::function<std::array<int, 2>(int)>& measure, int largest, int smallest, int w, int h,
                 std::array<int, 2>& size);

// The layout: the slider's panel kOverlayMargin from the lower right corner; the legend above
// it against the right edge (at most the height left above the slider); the text in the upper
// left, left of the legend and above the slider; the key list in the lower left, left of the
// slider and the legend and below the text. Fonts step down from the largest size until the
// text fits; a part that cannot fit at the smallest is left out (empty box). The boxes it
// returns are inside the window and pairwise disjoint.
OverlayLayout lay_out_overlay(const OverlayInput& in);

}  // namespace terravol::app::viewer
