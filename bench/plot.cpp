#include "bench/plot.h"

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <cmath>
#include <stdexcept>

#include "app/output/png_output.h"
#include "app/output/write_file.h"
#include "app/render/terrain_renderer.h"

namespace terravol::bench {

namespace {

constexpr int kTitleFont = 16, kAxisTitleFont = 14, kLabelFont = 12;  // points
constexpr float kLineWidth = 2.0f, kMarkerSize = 8.0f;                // pixels

void check_values(const std::vector<double>& values, bool log_axis, const std::string& series,
                  char axis) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    if (!std::isfinite(v) || (log_axis && v <= 0)) {
      throw std::invalid_argument("write_chart_png: series \"" + series + "\": " + axis + "[" +
                                  std::to_string(i) + "] = " + std::to_string(v) +
                                  (std::isfinite(v) ? " on a log axis" : " is not finite"));
    }
  }
}

void check_spec(const ChartSpec& spec) {
  if (spec.width <= 0 || spec.height <= 0) {
    throw std::invalid_argument("write_chart_png: image size " + std::to_string(spec.width) + "x" +
                                std::to_string(spec.height) + " is empty");
  }
  if (spec.series.empty()) throw std::invalid_argument("write_chart_png: no series");
  for (const Series& s : spec.series) {
    if (s.x.empty() || s.x.size() != s.y.size()) {
      throw std::invalid_argument("write_chart_png: series \"" + s.name + "\" has " +
                                  std::to_string(s.x.size()) + " x and " +
                                  std::to_string(s.y.size()) + " y values");
    }
    check_values(s.x, spec.log_x, s.name, 'x');
    check_values(s.y, spec.log_y, s.name, 'y');
  }
}

// HSV (all in 0..1) to 8-bit RGB.
std::array<std::uint8_t, 3> hsv_rgb(double h, double s, double v) {
  const double sector = h * 6.0;
  const int i = static_cast<int>(sector) % 6;
  const double f = sector - std::floor(sector);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  const double rgb[6][3] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
  std::array<std::uint8_t, 3> out{};
  for (int k = 0; k < 3; ++k) out[k] = static_cast<std::uint8_t>(std::lround(rgb[i][k] * 255.0));
  return out;
}

void style_axis(vtkAxis* axis, const std::string& title, bool log_scale) {
  axis->SetTitle(title);
  axis->GetTitleProperties()->SetFontSize(kAxisTitleFont);
  axis->GetTitleProperties()->SetColor(0, 0, 0);
  axis->GetLabelProperties()->SetFontSize(kLabelFont);
  axis->GetLabelProperties()->SetColor(0, 0, 0);
  axis->SetLogScale(log_scale);
}

}  // namespace

std::array<std::uint8_t, 3> series_color(std::size_t index) {
  // Tableau 10 (matplotlib's tab10).
  using Rgb = std::array<std::uint8_t, 3>;
  static constexpr std::array<Rgb, 10> kPalette = {
      Rgb{31, 119, 180},  Rgb{255, 127, 14}, Rgb{44, 160, 44},   Rgb{214, 39, 40},
      Rgb{148, 103, 189}, Rgb{140, 86, 75},  Rgb{227, 119, 194}, Rgb{127, 127, 127},
      Rgb{188, 189, 34},  Rgb{23, 190, 207}};
  if (index < kPalette.size()) return kPalette[index];
  constexpr double kGolden = 0.6180339887498949;
  return hsv_rgb(std::fmod(static_cast<double>(index - kPalette.size()) * kGolden, 1.0), 0.7, 0.8);
}

void write_chart_png(const std::filesystem::path& path, const ChartSpec& spec) {
  check_spec(spec);
  app::render::require_x_display();

  vtkNew<vtkContextView> view;
  vtkRenderWindow* window = view->GetRenderWindow();
  window->SetOffScreenRendering(1);
  window->SetSize(spec.width, spec.height);
  view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);

  vtkNew<vtkChartXY> chart;
  view->GetScene()->AddItem(chart);
  chart->SetTitle(spec.title);
  chart->GetTitleProperties()->SetFontSize(kTitleFont);
  chart->GetTitleProperties()->SetColor(0, 0, 0);
  style_axis(chart->GetAxis(vtkAxis::BOTTOM), spec.x_label, spec.log_x);
  style_axis(chart->GetAxis(vtkAxis::LEFT), spec.y_label, spec.log_y);

  for (std::size_t i = 0; i < spec.series.size(); ++i) {
    const Series& s = spec.series[i];
    vtkNew<vtkDoubleArray> xs, ys;
    xs->SetName("x");
    ys->SetName(s.name.empty() ? "y" : s.name.c_str());
    xs->SetNumberOfValues(static_cast<vtkIdType>(s.x.size()));
    ys->SetNumberOfValues(static_cast<vtkIdType>(s.y.size()));
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      xs->SetValue(static_cast<vtkIdType>(k), s.x[k]);
      ys->SetValue(static_cast<vtkIdType>(k), s.y[k]);
    }
    vtkNew<vtkTable> table;  // the plot keeps a reference
    table->AddColumn(xs);
    table->AddColumn(ys);

    vtkPlot* plot = chart->AddPlot(s.points_only ? vtkChart::POINTS : vtkChart::LINE);
    plot->SetInputData(table, 0, 1);
    plot->SetLabel(s.name);
    const std::array<std::uint8_t, 3> c = series_color(i);
    plot->SetColor(c[0], c[1], c[2], 255);
    plot->SetWidth(kLineWidth);
    if (s.points_only) {
      auto* points = vtkPlotPoints::SafeDownCast(plot);
      if (points != nullptr) {
        points->SetMarkerStyle(vtkPlotPoints::CIRCLE);
        points->SetMarkerSize(kMarkerSize);
      }
    }
  }
  chart->SetShowLegend(spec.series.size() > 1);
  chart->GetLegend()->SetLabelSize(kLabelFont);

  window->Render();
  // vtkAxis switches to log scaling during a render pass (vtkAxis.h), after the plots have cached
  // their points in linear coordinates, which then fall outside the chart: draw again.
  if (spec.log_x || spec.log_y) window->Render();
  const std::vector<std::uint8_t> png = app::output::window_png(window);
  window->Finalize();
  app::output::write_file_atomically(path, png, /*overwrite=*/true);
}

}  // namespace terravol::bench
