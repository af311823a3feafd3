#include "app/output/map_images.h"

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

#include "app/output/png_output.h"

namespace terravol::app::output {

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

// Draws `text` with its top-left corner at (x, y) of the canvas (row 0 at the top).
void draw_text(Canvas& canvas, vtkTextProperty* style, const std::string& text, int x, int y) {
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
      canvas.blend(x + ix, y + dims[1] - 1 - iy, kInk, a);
    }
  }
}

std::string label(double v, double step) {
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  char b[48];
  std::snprintf(b, sizeof b, "%.*f", std::clamp(decimals, 0, 9), v == 0.0 ? 0.0 : v);
  return b;
}

}  // namespace

glm::u8vec3 map_color(const volume::Colormap& colormap, double lo, double hi, double v) {
  return colormap.map(hi == lo ? 0.5 : (v - lo) / (hi - lo));
}

std::vector<std::uint8_t> overlay_png(const io::GeoRaster& raster, const volume::Colormap& colormap, double lo,
                                      double hi) {
  std::vector<std::uint8_t> rgba(raster.values.size() * 4, 0);
  for (std::size_t i = 0; i < raster.values.size(); ++i) {
    const float v = raster.values[i];
    if (std::isnan(v)) continue;
    const glm::u8vec3 c = map_color(colormap, lo, hi, v);
    rgba[4 * i] = c.r;
    rgba[4 * i + 1] = c.g;
    rgba[4 * i + 2] = c.b;
    rgba[4 * i + 3] = 255;
  }
  return encode_png(rgba, raster.cols, raster.rows, 4);
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

std::vector<std::uint8_t> legend_png(const volume::Colormap& colormap, const MapLegend& legend) {
  const auto title_style = text_style(15, true), body_style = text_style(12, false);
  const std::vector<double> ticks = legend_ticks(legend.lo, legend.hi);
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  constexpr int kPad = 10, kBarWidth = 22, kBarHeight = 200, kTickLength = 5, kGap = 6;
  const auto title = text_size(title_style, legend.title);
  const auto subtitle = legend.subtitle.empty() ? std::array<int, 2>{0, 0} : text_size(body_style, legend.subtitle);
  int label_width = 0, label_height = 0;
  std::vector<std::string> labels;
  for (const double t : ticks) {
    labels.push_back(label(t, step));
    const auto s = text_size(body_style, labels.back());
    label_width = std::max(label_width, s[0]);
    label_height = std::max(label_height, s[1]);
  }
  const int bar_top = kPad + title[1] + (subtitle[1] ? kGap / 2 + subtitle[1] : 0) + kGap + label_height / 2;
  const int width = std::max({2 * kPad + title[0], 2 * kPad + subtitle[0],
                              2 * kPad + kBarWidth + kTickLength + kGap / 2 + label_width});
  const int height = bar_top + kBarHeight + label_height / 2 + kPad;
  Canvas canvas(width, height);
  canvas.fill(0, 0, width, height, {255, 255, 255}, 217);
  draw_text(canvas, title_style, legend.title, kPad, kPad);
  if (!legend.subtitle.empty()) draw_text(canvas, body_style, legend.subtitle, kPad, kPad + title[1] + kGap / 2);
  // The bar: row y shows the value at its centre, hi at the top.
  for (int y = 0; y < kBarHeight; ++y) {
    const double f = 1.0 - (y + 0.5) / kBarHeight;
    const glm::u8vec3 c = map_color(colormap, legend.lo, legend.hi, legend.lo + f * (legend.hi - legend.lo));
    canvas.fill(kPad, bar_top + y, kPad + kBarWidth, bar_top + y + 1, c, 255);
  }
  for (std::size_t k = 0; k < ticks.size(); ++k) {
    const double f = legend.hi == legend.lo ? 0.5 : (ticks[k] - legend.lo) / (legend.hi - legend.lo);
    const int y = bar_top + static_cast<int>(std::lround((1.0 - f) * (kBarHeight - 1)));
    canvas.fill(kPad + kBarWidth, y, kPad + kBarWidth + kTickLength, y + 1, kInk, 255);
    draw_text(canvas, body_style, labels[k], kPad + kBarWidth + kTickLength + kGap / 2, y - label_height / 2);
  }
  return encode_png(canvas.rgba, width, height, 4);
}

}  // namespace terravol::app::output
