// Legend cards: a canvas, FreeType glyphs blended onto it, the bar and the swatches.
#include "app/render/legend_image.h"

#include <vtkFreeTypeTools.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkSmartPointer.h>
#include <vtkStdString.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace terravol::app::render {

namespace {

// An RGBA canvas, row 0 at the top.
struct Canvas {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;

  Canvas(int w, int h) : width(w), height(h), rgba(static_cast<std::size_t>(w) * h * 4, 0) {}
  std::uint8_t* at(int x, int y) { return rgba.data() + (static_cast<std::size_t>(y) * width + x) * 4; }
  void fill(int x0, int y0, int x1, int y1, glm::u8vec3 rgb, std::uint8_t alpha) {
    for (int y = std::max(y0, 0); y < std::min(y1, height); ++y)
      for (int x = std::max(x0, 0); x < std::min(x1, width); ++x) {
        std::uint8_t* p = at(x, y);
        p[0] = rgb.r;
        p[1] = rgb.g;
        p[2] = rgb.b;
        p[3] = alpha;
      }
  }
  // Source-over of a colour with coverage a (0..255) onto an opaque or translucent pixel.
  void blend(int x, int y, glm::u8vec3 rgb, int a) {
    if (x < 0 || y < 0 || x >= width || y >= height || a <= 0) return;
    std::uint8_t* p = at(x, y);
    const double sa = a / 255.0, da = p[3] / 255.0, oa = sa + da * (1.0 - sa);
    for (int c = 0; c < 3; ++c) {
      const double v = (rgb[c] * sa + p[c] * da * (1.0 - sa)) / oa;
      p[c] = static_cast<std::uint8_t>(std::lround(v));
    }
    p[3] = static_cast<std::uint8_t>(std::lround(oa * 255.0));
  }
};

constexpr glm::u8vec3 kInk{30, 30, 30};
constexpr int kDpi = 72;

vtkSmartPointer<vtkTextProperty> text_style(int size, bool bold) {
  auto p = vtkSmartPointer<vtkTextProperty>::New();
  p->SetFontFamilyToArial();
  p->SetFontSize(size);
  p->SetBold(bold);
  p->SetColor(kInk.r / 255.0, kInk.g / 255.0, kInk.b / 255.0);
  p->SetJustificationToLeft();
  p->SetVerticalJustificationToBottom();
  return p;
}

// Width and height in pixels that `text` takes.
std::array<int, 2> text_size(vtkTextProperty* style, const std::string& text) {
  int box[4] = {0, 0, 0, 0};
  if (!vtkFreeTypeTools::GetInstance()->GetBoundingBox(style, vtkStdString(text), kDpi, box)) {
    throw std::runtime_error("legend: FreeType cannot measure '" + text + "'");
  }
  return {box[1] - box[0] + 1, box[3] - box[2] + 1};
}

// Draws `text` in `ink` with its top-left corner at (x, y) of the canvas (row 0 at the top).
void draw_text(Canvas& canvas, vtkTextProperty* style, const std::string& text, int x, int y, glm::u8vec3 ink = kInk) {
  vtkNew<vtkImageData> image;
  int dims[2] = {0, 0};
  if (!vtkFreeTypeTools::GetInstance()->RenderString(style, vtkStdString(text), kDpi, image.GetPointer(), dims)) {
    throw std::runtime_error("legend: FreeType cannot draw '" + text + "'");
  }
  // The image's rows go up; its alpha is the glyphs' coverage.
  int extent[6];
  image->GetExtent(extent);
  const int comps = image->GetNumberOfScalarComponents();
  for (int iy = 0; iy < dims[1]; ++iy) {
    for (int ix = 0; ix < dims[0]; ++ix) {
      const auto* p = static_cast<const unsigned char*>(image->GetScalarPointer(extent[0] + ix, extent[2] + iy, 0));
      const int a = comps == 4 ? p[3] : p[0];
      canvas.blend(x + ix, y + dims[1] - 1 - iy, ink, a);
    }
  }
}

std::string label(double v, double step) {
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  char b[48];
  std::snprintf(b, sizeof b, "%.*f", std::clamp(decimals, 0, 9), v == 0.0 ? 0.0 : v);
  return b;
}


// The card at one text size and bar height.
RgbaImage draw_card(const LegendCard& card, int title_px, int body_px, int bar_height) {
  const auto title_style = text_style(title_px, true), body_style = text_style(body_px, false);
  const int pad = std::max(6, body_px * 10 / 12), gap = std::max(4, body_px / 2);
  constexpr int kBarWidth = 22, kTickLength = 5, kMarkLength = 7;
  const int swatch = body_px + 2;
  const auto size_of = [&](vtkTextProperty* style, const std::string& s) {
    return s.empty() ? std::array<int, 2>{0, 0} : text_size(style, s);
  };
  const auto title = size_of(title_style, card.title);
  const auto subtitle = size_of(body_style, card.subtitle);
  int width = std::max(2 * pad + title[0], 2 * pad + subtitle[0]);
  int y = pad + title[1] + (subtitle[1] ? gap / 2 + subtitle[1] : 0);
  // The bar's labels.
  std::vector<double> ticks;
  std::vector<std::string> labels;
  int label_width = 0, label_height = 0, bar_top = 0;
  if (card.colormap) {
    ticks = legend_ticks(card.lo, card.hi);
    const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
    for (const double t : ticks) {
      labels.push_back(label(t, step));
      const auto s = text_size(body_style, labels.back());
      label_width = std::max(label_width, s[0]);
      label_height = std::max(label_height, s[1]);
    }
    bar_top = y + gap + label_height / 2;
    width = std::max(width, 2 * pad + kMarkLength + kBarWidth + kTickLength + gap / 2 + label_width);
    y = bar_top + bar_height + label_height / 2;
  }
  // The entries.
  const auto entries_title = size_of(title_style, card.entries.empty() ? std::string() : card.entries_title);
  int entries_top = 0, row = swatch;
  if (!card.entries.empty()) {
    entries_top = y + gap + (entries_title[1] ? entries_title[1] + gap / 2 : 0);
    width = std::max(width, 2 * pad + entries_title[0]);
    for (const LegendEntry& e : card.entries) {
      const auto s = text_size(body_style, e.label);
      row = std::max(row, s[1]);
      width = std::max(width, 2 * pad + swatch + gap + s[0]);
    }
    y = entries_top + static_cast<int>(card.entries.size()) * (row + gap / 2) - gap / 2;
  }
  const int height = y + pad;
  Canvas canvas(width, height);
  canvas.fill(0, 0, width, height, {255, 255, 255}, 217);
  draw_text(canvas, title_style, card.title, pad, pad);
  if (!card.subtitle.empty()) draw_text(canvas, body_style, card.subtitle, pad, pad + title[1] + gap / 2);
  if (card.colormap) {
    const int x0 = pad + kMarkLength;
    const auto row_of = [&](double v) {
      const double f = card.hi == card.lo ? 0.5 : (v - card.lo) / (card.hi - card.lo);
      return bar_top + static_cast<int>(std::lround((1.0 - f) * (bar_height - 1)));
    };
    // Row y shows the value at its centre, hi at the top.
    for (int r = 0; r < bar_height; ++r) {
      const double f = 1.0 - (r + 0.5) / bar_height;
      const glm::u8vec3 c = map_color(*card.colormap, card.lo, card.hi, card.lo + f * (card.hi - card.lo));
      canvas.fill(x0, bar_top + r, x0 + kBarWidth, bar_top + r + 1, c, 255);
    }
    for (std::size_t k = 0; k < ticks.size(); ++k) {
      const int ty = row_of(ticks[k]);
      canvas.fill(x0 + kBarWidth, ty, x0 + kBarWidth + kTickLength, ty + 1, kInk, 255);
      draw_text(canvas, body_style, labels[k], x0 + kBarWidth + kTickLength + gap / 2, ty - label_height / 2);
    }
    // Each isosurface level marked left of the bar, in its colour, 3 px tall.
    for (const LegendEntry& e : card.entries) {
      if (!(e.value >= std::min(card.lo, card.hi) && e.value <= std::max(card.lo, card.hi))) continue;
      const int my = row_of(e.value);
      canvas.fill(pad - 1, my - 2, x0, my + 3, kInk, 255);  // an outline, so that pale colours show on white
      canvas.fill(pad, my - 1, x0, my + 2, e.color, 255);
    }
  }
  if (!card.entries.empty()) {
    if (entries_title[1]) draw_text(canvas, title_style, card.entries_title, pad, entries_top - gap / 2 - entries_title[1]);
    for (std::size_t k = 0; k < card.entries.size(); ++k) {
      const int ry = entries_top + static_cast<int>(k) * (row + gap / 2);
      const int sy = ry + (row - swatch) / 2;
      canvas.fill(pad - 1, sy - 1, pad + swatch + 1, sy + swatch + 1, kInk, 255);
      canvas.fill(pad, sy, pad + swatch, sy + swatch, card.entries[k].color, 255);
      draw_text(canvas, body_style, card.entries[k].label, pad + swatch + gap, ry);
    }
  }
  return {width, height, std::move(canvas.rgba)};
}

}  // namespace

RgbaImage text_image(const std::string& text, int size, bool bold, glm::u8vec3 color, bool shadow) {
  const auto style = text_style(size, bold);
  const auto [w, h] = text_size(style, text);
  const int pad = shadow ? 1 : 0;
  Canvas canvas(w + pad, h + pad);
  if (shadow) draw_text(canvas, style, text, 1, 1, glm::u8vec3(0, 0, 0));
  draw_text(canvas, style, text, 0, 0, color);
  return {canvas.width, canvas.height, std::move(canvas.rgba)};
}

glm::u8vec3 map_color(const volume::Colormap& colormap, double lo, double hi, double v) {
  return colormap.map(hi == lo ? 0.5 : (v - lo) / (hi - lo));
}

std::vector<double> legend_ticks(double lo, double hi) {
  const double a = std::min(lo, hi), b = std::max(lo, hi);
  if (!(b > a)) return {a};
  double best = 0.0;
  for (double p = std::pow(10.0, std::floor(std::log10(b - a))) * 10.0; best == 0.0; p /= 10.0) {
    for (const double m : {5.0, 2.0, 1.0}) {
      const double step = m * p;
      if (std::floor(b / step + 1e-9) - std::ceil(a / step - 1e-9) + 1 >= 3) {
        best = step;
        break;
      }
    }
  }
  std::vector<double> ticks;
  for (double k = std::ceil(a / best - 1e-9); k * best <= b + 1e-9 * best; k += 1.0) ticks.push_back(k * best);
  return ticks;
}

RgbaImage legend_image(const LegendCard& card, int max_height) {
  constexpr int kBarMax = 200, kBarMin = 40;
  constexpr std::array<std::array<int, 2>, 4> kText{{{15, 12}, {13, 11}, {11, 9}, {9, 8}}};
  RgbaImage img;
  for (const auto& [title_px, body_px] : kText) {
    img = draw_card(card, title_px, body_px, kBarMax);
    if (max_height <= 0 || img.height <= max_height) return img;
    if (!card.colormap) continue;
    // The bar takes what the rest leaves.
    const int bar = kBarMax - (img.height - max_height);
    img = draw_card(card, title_px, body_px, std::max(bar, kBarMin));
    if (img.height <= max_height) return img;
  }
  return img;
}

}  // namespace terravol::app::render
