#include "app/viewer/overlay_layout.h"

#include <algorithm>
#include <cmath>

namespace terravol::app::viewer {

bool overlap(const Box& a, const Box& b) {
  if (a.empty() || b.empty()) return false;
  return a.x < b.right() && b.x < a.right() && a.y < b.bottom() && b.y < a.bottom();
}

Box united(const Box& a, const Box& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  const int x = std::min(a.x, b.x), y = std::min(a.y, b.y);
  return {x, y, std::max(a.right(), b.right()) - x, std::max(a.bottom(), b.bottom()) - y};
}

int fitting_font(const std::function<std::array<int, 2>(int)>& measure, int largest, int smallest, int w, int h,
                 std::array<int, 2>& size) {
  const auto fits = [&](const std::array<int, 2>& s) { return s[0] <= w && s[1] <= h; };
  size = measure(largest);
  if (fits(size)) return largest;
  if (size[0] <= 0 || size[1] <= 0 || w <= 0 || h <= 0) return 0;
  // Text grows about in proportion to the font: start where that says it fits, then step up
  // while the next size fits too, or down until one does.
  const double scale = std::min(static_cast<double>(w) / size[0], static_cast<double>(h) / size[1]);
  int f = std::clamp(static_cast<int>(std::floor(largest * scale)), smallest, largest - 1);
  size = measure(f);
  if (fits(size)) {
    while (f + 1 < largest) {
      const std::array<int, 2> next = measure(f + 1);
      if (!fits(next)) break;
      ++f;
      size = next;
    }
    return f;
  }
  while (f > smallest) {
    size = measure(--f);
    if (fits(size)) return f;
  }
  return 0;
}

OverlayLayout lay_out_overlay(const OverlayInput& in) {
  constexpr int m = kOverlayMargin;
  OverlayLayout out;
  const int W = in.width, H = in.height;
  // The slider's panel, lower right.
  const int sw = std::min(std::clamp(static_cast<int>(0.36 * W), 240, 460), W - 2 * m);
  const int sh = std::min(in.slider_height, H - 2 * m);
  if (sw > 0 && sh > 0) out.slider = {W - m - sw, H - m - sh, sw, sh};
  const int above_slider = out.slider.empty() ? H - m : out.slider.y - m;  // y the others stay above
  // The legend, right, above the slider.
  if (in.legend) {
    out.legend_max_height = above_slider - m;
    const auto [lw, lh] = in.legend(std::max(out.legend_max_height, 1));
    if (lw > 0 && lh > 0 && lh <= out.legend_max_height && lw <= W - 2 * m) out.legend = {W - m - lw, m, lw, lh};
  }
  // The text, upper left: left of the legend, above the slider.
  const int text_right = out.legend.empty() ? W - m : out.legend.x - m;
  std::array<int, 2> size{0, 0};
  if (in.text) {
    out.text_font = fitting_font(in.text, kTextFonts[0], kTextFonts[1], text_right - m, above_slider - m, size);
    if (out.text_font > 0) out.text = {m, m, size[0], size[1]};
  }
  // The key list, lower left: left of the slider and the legend, below the text.
  if (in.keys_shown && in.keys) {
    int keys_right = out.slider.empty() ? W - m : out.slider.x - m;
    if (!out.legend.empty()) keys_right = std::min(keys_right, out.legend.x - m);
    const int top = out.text.empty() ? m : out.text.bottom() + m;
    out.keys_font = fitting_font(in.keys, kKeyFonts[0], kKeyFonts[1], keys_right - m, H - m - top, size);
    if (out.keys_font > 0) out.keys = {m, H - m - size[1], size[0], size[1]};
  }
  return out;
}

}  // namespace terravol::app::viewer
