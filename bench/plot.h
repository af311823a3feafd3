// Line and scatter charts of benchmark figures, drawn by VTK's 2D charts (vtkChartXY) and
// written as PNG.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace terravol::bench {

// One curve: the points (x[i], y[i]) in the given order, joined by straight lines, or drawn as
// markers only when points_only. x and y have the same, non-zero length; every value is finite.
struct Series {
  std::string name;  // the legend's label (the legend is shown when a chart has 2+ series)
  std::vector<double> x, y;
  bool points_only = false;
};

struct ChartSpec {
  std::string title, x_label, y_label;  // may be empty (then not drawn)
  std::vector<Series> series;           // at least one; drawn in this order, later on top
  // Logarithmic axes (base 10): every x (log_x) or y (log_y) value must then be positive.
  bool log_x = false, log_y = false;
  int width = 900, height = 500;  // of the image, pixels; both positive
};

// The colour (8-bit RGB) that write_chart_png gives to series number `index` (0-based): ten
// distinct colours of a qualitative palette (Tableau 10), then further hues spread by the golden
// ratio, so every chart's series differ in colour.
std::array<std::uint8_t, 3> series_color(std::size_t index);

// Renders the chart offscreen (vtkContextView + vtkChartXY; white background, black text: title
// 16 pt, axis titles 14 pt, tick labels and legend 12 pt; axes fitted to the data) at
// spec.width x spec.height pixels and writes it as an RGB PNG to `path`, replacing any file
// there, through a temporary file in the same folder renamed when complete (so a reader never
// sees half an image). Needs an X display (VTK 9.1 on Debian renders through GLX even offscreen).
// Throws std::invalid_argument when there is no series, a series is empty, its x and y differ in
// length, a value is not finite, a value on a log axis is not positive, or the size is not
// positive; std::runtime_error when no X display can be opened
// (terravol::app::render::require_x_display) or the file cannot be written.
void write_chart_png(const std::filesystem::path& path, const ChartSpec& spec);

}  // namespace terravol::bench
