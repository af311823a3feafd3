// The link profile's chart (profile_plot.h).
#include "app/output/profile_plot.h"

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotArea.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <stdexcept>

#include "app/output/png_output.h"
#include "app/render/terrain_renderer.h"

namespace terravol::app::output {

namespace {

using Rgb = std::array<unsigned char, 3>;

// A table of columns (x first) that a plot reads; the plot keeps a reference to it.
vtkSmartPointer<vtkTable> make_table(std::initializer_list<const std::vector<double>*> columns) {
  auto table = vtkSmartPointer<vtkTable>::New();
  int n = 0;
  for (const std::vector<double>* c : columns) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(("c" + std::to_string(n++)).c_str());
    a->SetNumberOfValues(static_cast<vtkIdType>(c->size()));
    for (std::size_t i = 0; i < c->size(); ++i) a->SetValue(static_cast<vtkIdType>(i), (*c)[i]);
    table->AddColumn(a);
  }
  return table;
}

vtkPlot* add_line(vtkChartXY* chart, const std::string& label, const std::vector<double>& x,
                  const std::vector<double>& y, Rgb c, float width, int line_type = vtkPen::SOLID_LINE) {
  vtkPlot* plot = chart->AddPlot(vtkChart::LINE);
  plot->SetInputData(make_table({&x, &y}), 0, 1);
  plot->SetLabel(label);
  plot->SetColor(c[0], c[1], c[2], 255);
  plot->SetWidth(width);
  plot->GetPen()->SetLineType(line_type);
  return plot;
}

void add_points(vtkChartXY* chart, const std::string& label, const std::vector<double>& x, const std::vector<double>& y,
                Rgb c, int marker) {
  auto* points = vtkPlotPoints::SafeDownCast(chart->AddPlot(vtkChart::POINTS));
  points->SetInputData(make_table({&x, &y}), 0, 1);
  points->SetLabel(label);
  points->SetColor(c[0], c[1], c[2], 255);
  points->SetMarkerStyle(marker);
  points->SetMarkerSize(12.0f);
}

void style_axis(vtkAxis* axis, const char* title) {
  axis->SetTitle(title);
  axis->GetTitleProperties()->SetFontSize(14);
  axis->GetTitleProperties()->SetColor(0, 0, 0);
  axis->GetLabelProperties()->SetFontSize(12);
  axis->GetLabelProperties()->SetColor(0, 0, 0);
}

}  // namespace

std::vector<std::uint8_t> profile_png(const volume::LinkProfile& l, const std::string& title, int width, int height) {
  if (width < 200 || width > 8000 || height < 200 || height > 8000) {
    throw std::invalid_argument("profile plot: size " + std::to_string(width) + "x" + std::to_string(height) +
                                " is outside [200, 8000] pixels");
  }
  const volume::PathProfile& p = l.path.profile;
  const volume::FresnelAnalysis& f = l.fresnel;

  // The samples with both ends; the ends' ground is the DEM under the antennas.
  const std::size_t n = p.d_m.size() + 2;
  std::vector<double> km(n), terrain(n), floor(n), los(n), upper(n), lower(n), lower60(n);
  double lowest = std::min(l.tx_ground_m, l.rx_ground_m);
  for (const double z : p.z_m) lowest = std::min(lowest, z);
  lowest = std::floor(lowest / 10.0) * 10.0;
  for (std::size_t i = 0; i < n; ++i) {
    const bool end = i == 0 || i == n - 1;
    const std::size_t s = i - 1;  // sample index when not an end
    const double d = i == 0 ? 0.0 : i == n - 1 ? p.distance_m : p.d_m[s];
    km[i] = d / 1000.0;
    const double bulge = end ? 0.0 : f.bulge_m[s];
    terrain[i] = (i == 0 ? l.tx_ground_m : i == n - 1 ? l.rx_ground_m : p.z_m[s]) + bulge;
    floor[i] = lowest + bulge;
    los[i] = i == 0 ? p.tx_height_m : i == n - 1 ? p.rx_height_m : f.los_m[s];
    const double f1 = end ? 0.0 : f.f1_m[s];
    upper[i] = los[i] + f1;
    lower[i] = los[i] - f1;
    lower60[i] = los[i] - 0.6 * f1;
  }

  // A plain render window with the chart's scene on a vtkContextActor, not a vtkContextView:
  // the view makes a render window interactor, and making or freeing one while `terravol view`
  // runs its X event loop corrupts the loop's list of interactors (VTK 9.1 crashed there).
  vtkNew<vtkRenderWindow> window;
  render::use_shared_display(window, "the profile plot");
  window->SetOffScreenRendering(1);
  window->SetSize(width, height);
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1.0, 1.0, 1.0);
  window->AddRenderer(renderer);
  vtkNew<vtkContextActor> actor;
  actor->GetScene()->SetRenderer(renderer);
  renderer->AddActor(actor);
  vtkNew<vtkChartXY> chart;
  actor->GetScene()->AddItem(chart);
  chart->SetTitle(title);
  chart->GetTitleProperties()->SetFontSize(13);
  chart->GetTitleProperties()->SetColor(0, 0, 0);
  style_axis(chart->GetAxis(vtkAxis::BOTTOM), "distance (km)");
  style_axis(chart->GetAxis(vtkAxis::LEFT), "height above the datum (m), terrain raised by the Earth's bulge");

  auto* area = vtkPlotArea::SafeDownCast(chart->AddPlot(vtkChart::AREA));
  area->SetInputData(make_table({&km, &floor, &terrain}));
  area->SetInputArray(0, "c0");
  area->SetInputArray(1, "c1");
  area->SetInputArray(2, "c2");
  area->SetLabel("terrain + bulge");
  area->SetColor(166, 134, 96, 255);  // vtkPlotArea fills with the plot's colour
  add_line(chart, "line of sight", km, los, {200, 30, 30}, 2.0f);
  add_line(chart, "first Fresnel zone", km, upper, {40, 90, 200}, 1.5f);
  add_line(chart, "", km, lower, {40, 90, 200}, 1.5f)->SetLegendVisibility(false);
  add_line(chart, "60% of F1", km, lower60, {40, 90, 200}, 1.5f, vtkPen::DASH_LINE);
  const std::vector<double> tx_x{0.0, 0.0}, tx_y{l.tx_ground_m, p.tx_height_m};
  const std::vector<double> rx_x{km.back(), km.back()}, rx_y{l.rx_ground_m, p.rx_height_m};
  add_line(chart, "antennas", tx_x, tx_y, {0, 0, 0}, 3.0f);
  add_line(chart, "", rx_x, rx_y, {0, 0, 0}, 3.0f)->SetLegendVisibility(false);
  if (!l.path.edges.empty()) {
    std::vector<double> ex, ey;
    std::string label = "knife edges (J =";
    for (const volume::KnifeEdge& e : l.path.edges) {
      ex.push_back(p.d_m[e.sample] / 1000.0);
      ey.push_back(p.z_m[e.sample] + f.bulge_m[e.sample]);
      char b[32];
      std::snprintf(b, sizeof b, " %.1f", e.loss_db);
      label += b;
    }
    add_points(chart, label + " dB)", ex, ey, {230, 120, 0}, vtkPlotPoints::DIAMOND);
  }
  if (f.worst < p.d_m.size()) {
    const std::vector<double> wx{p.d_m[f.worst] / 1000.0}, wy{p.z_m[f.worst] + f.bulge_m[f.worst]};
    add_points(chart, "worst obstruction", wx, wy, {150, 0, 150}, vtkPlotPoints::CROSS);
  }
  // Axes fitted to everything drawn, with a margin; the legend outside the plot area, so that it
  // hides nothing.
  double top = -1e300;
  for (const auto* v : {&terrain, &upper}) top = std::max(top, *std::max_element(v->begin(), v->end()));
  const double bottom = *std::min_element(floor.begin(), floor.end());
  const double margin = 0.05 * std::max(1.0, top - bottom);
  vtkAxis* y = chart->GetAxis(vtkAxis::LEFT);
  y->SetBehavior(vtkAxis::FIXED);
  y->SetRange(bottom, top + margin);
  vtkAxis* x = chart->GetAxis(vtkAxis::BOTTOM);
  x->SetBehavior(vtkAxis::FIXED);
  x->SetRange(0.0, km.back());
  chart->SetShowLegend(true);
  vtkChartLegend* legend = chart->GetLegend();
  legend->SetLabelSize(12);
  legend->SetInline(false);
  legend->SetHorizontalAlignment(vtkChartLegend::RIGHT);
  legend->SetVerticalAlignment(vtkChartLegend::CENTER);

  window->Render();
  std::vector<std::uint8_t> png = window_png(window);
  window->Finalize();
  return png;
}

}  // namespace terravol::app::output
