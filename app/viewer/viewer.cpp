// The interactive viewer (`terravol view`; docs/architecture.md, "The viewer"). One timer
// drives everything: key and mouse events only change state and mark the view dirty; every
// tick of a repeating timer moves the camera by the keys held (for the real time elapsed) and,
// if anything changed, draws one frame: finish a slide whose window was read ahead, start one
// if the camera nears the window's edge, traverse the tree, replace the triangle list, draw,
// write the status file. Nothing is drawn while nothing changes. The interactor's own
// rendering is switched off so that widgets and expose events only ask for a frame.
#include "app/viewer/viewer.h"

#include <nlohmann/json.hpp>

#include <vtkActor2D.h>
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkCoordinate.h>
#include <vtkInteractorStyle.h>
#include <vtkObjectFactory.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSliderRepresentation2D.h>
#include <vtkSliderWidget.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkXRenderWindowInteractor.h>

#include <X11/XKBlib.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <future>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "app/output/png_output.h"
#include "app/output/write_file.h"
#include "app/render/terrain_renderer.h"
#include "app/scene/camera_path.h"
#include "app/scene/terrain_scene.h"
#include "app/scene/volume_layer.h"
#include "io/error.h"
#include "io/mosaic.h"

namespace terravol::app::viewer {

const char* const kViewKeys =
    "W / S        forward / back, along the view\n"
    "A / D        strafe left / right\n"
    "R / F        up / down (also PageUp / PageDown)\n"
    "arrows       turn left / right, look up / down\n"
    "left drag    look around\n"
    "Shift        4x faster; mouse wheel: speed x1.25 or /1.25\n"
    "+ / -        finer / coarser LOD (threshold / or x sqrt 2); or drag the slider\n"
    "M            LOD metric: screen-space error / projected area\n"
    "L            LOD colours\n"
    "T            wireframe (triangle edges)\n"
    "G            automatic sliding of the window\n"
    "1 .. 9       show or hide volume N (and select it)\n"
    "[ / ]        move the selected volume's first slice down / up (50 m; 0.01 deg)\n"
    ", / .        lower / raise its first isosurface's level by 2 units\n"
    "P            screenshot (PNG)\n"
    "K / J        record a keyframe of the camera / save the keyframes as a camera path\n"
    "Home         back to the starting pose\n"
    "H            show or hide this list\n"
    "Esc or Q     quit";

namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::ordered_json;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

std::string degrees(double v, char positive, char negative) {
  char b[32];
  std::snprintf(b, sizeof b, "%.5f %c", std::abs(v), v < 0 ? negative : positive);
  return b;
}

// The slider's range per metric, log2 of the threshold: screen-space error 0.25..16 px,
// projected area 32..32768 square px.
struct SliderRange {
  double lo, hi;
};
SliderRange slider_range(mrbsp::LodMetric m) {
  return m == mrbsp::LodMetric::kError ? SliderRange{-2.0, 4.0} : SliderRange{5.0, 15.0};
}

std::string threshold_text(mrbsp::LodMetric m, double t) {
  char b[64];
  if (m == mrbsp::LodMetric::kError) {
    std::snprintf(b, sizeof b, "%.2f px", t);
  } else {
    std::snprintf(b, sizeof b, "%.0f px^2", t);
  }
  return b;
}

// Slider geometry, in the slider representation's units (lengths along the slider in units of
// the window width, widths in units of its height; vtkSliderRepresentation2D).
constexpr double kSliderX0 = 0.62, kSliderX1 = 0.96, kSliderY = 0.1;  // normalized display
constexpr double kEndCapLength = 0.008, kSliderLength = 0.014;

constexpr auto kOverlayPeriod = std::chrono::milliseconds(250);

class ViewerStyle;

// A moved window read from the mosaic and shaded, ready to slide to.
struct PreparedSlide {
  scene::SceneWindow window;
  scene::TerrainShading lattice, vertices;
  double read_ms = 0, shade_ms = 0;
};

class Viewer {
 public:
  explicit Viewer(const ViewOptions& options);
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  void run();

  // Events, from ViewerStyle and the slider.
  void key_press(const std::string& key);
  void key_release(const std::string& key);
  void button(bool down, int x, int y);
  void mouse_move(int x, int y);
  void wheel(int clicks);
  void leave();
  void tick();
  void slider_moved();
  void request_frame() { dirty_ = true; }

 private:
  void draw_frame();
  void start_slide();
  bool slide_ready() const;
  void finish_slide();
  void set_metric(mrbsp::LodMetric m);
  void set_threshold(double t);
  void sync_slider();
  void update_overlay(double agl, double speed);
  void write_status(double agl, double speed, const mrbsp::Camera& camera);
  void save_screenshot();
  scene::FlightInput input() const;
  // Held now, or pressed since the last tick (so that a tap shorter than a tick still moves).
  bool held(const char* key) const { return held_.count(key) > 0 || tapped_.count(key) > 0; }
  double& threshold() { return threshold_[metric_ == mrbsp::LodMetric::kError ? 1 : 0]; }
  void clamp_to_mosaic(scene::CameraPose& p) const;
  void volume_key(const std::string& key);
  void record_key();
  void save_path();
  void upload_vertices();

  ViewOptions o_;
  io::Mosaic mosaic_;
  std::unique_ptr<scene::TerrainScene> scene_;
  scene::TerrainShading lattice_;    // the window's lattice shading (its colours are the texture)
  scene::VolumeLayer volumes_;
  std::size_t selected_volume_ = 0;
  std::vector<scene::PathKey> keys_;  // recorded keyframes (K), saved by J
  Clock::time_point first_key_time_;
  double last_merge_ms_ = 0;  // the last interactive change of a volume, extraction to upload
  std::future<PreparedSlide> pending_slide_;  // destroyed (waited for) before the mosaic
  std::unique_ptr<render::TerrainRenderer> renderer_;
  mrbsp::Frame frame_;
  scene::CameraPose pose_, start_pose_;
  scene::FlightSettings flight_;
  mrbsp::LodMetric metric_;
  double threshold_[2];  // per metric, [0] area, [1] error: each keeps its own
  bool lod_colors_, wireframe_, auto_slide_, help_ = false;
  bool dirty_ = true, screenshot_pending_ = false;
  bool dragging_ = false;
  int drag_x_ = 0, drag_y_ = 0;
  std::set<std::string> held_, tapped_;
  Clock::time_point start_, last_tick_;

  // Figures.
  std::size_t frames_ = 0, slides_ = 0, screenshots_ = 0;
  double frame_ms_ = 0, traversal_ms_ = 0, upload_ms_ = 0, draw_ms_ = 0, last_slide_ms_ = 0;
  // The last slide: reading the window and shading it (worker thread), sliding the tree and
  // replacing the vertices (this thread; last_slide_ms_ is their sum).
  std::array<double, 4> slide_parts_{};
  std::vector<double> frame_log_, traversal_log_, draw_log_, slide_log_;
  std::filesystem::path last_screenshot_;
  std::string message_;  // shown in the overlay (e.g. where a screenshot went)
  std::string overlay_settings_;  // the overlay's settings lines as last drawn
  Clock::time_point overlay_time_;
  bool overlay_stale_ = false;

  // VTK.
  vtkNew<vtkXRenderWindowInteractor> interactor_;
  vtkSmartPointer<ViewerStyle> style_;
  vtkNew<vtkSliderRepresentation2D> slider_rep_;
  vtkNew<vtkSliderWidget> slider_;
  vtkNew<vtkCallbackCommand> slider_callback_;
  vtkNew<vtkCallbackCommand> render_callback_;
  vtkNew<vtkTextActor> overlay_, help_text_, slider_min_, slider_max_;
  vtkNew<vtkActor2D> slider_panel_;
};

// Key and mouse events to the viewer, and nothing else: VTK's default bindings of
// vtkInteractorStyle::OnChar (w wireframe, 3 stereo, e and q exit, f fly-to, p pick, r reset,
// s surface, u user, j/t joystick/trackball) are switched off by an empty OnChar.
class ViewerStyle : public vtkInteractorStyle {
 public:
  static ViewerStyle* New();
  vtkTypeMacro(ViewerStyle, vtkInteractorStyle);
  ViewerStyle(const ViewerStyle&) = delete;
  ViewerStyle& operator=(const ViewerStyle&) = delete;

  void set_viewer(Viewer* v) { viewer_ = v; }

  void OnChar() override {}
  void OnKeyPress() override { viewer_->key_press(key()); }
  void OnKeyRelease() override { viewer_->key_release(key()); }
  void OnLeftButtonDown() override { viewer_->button(true, pos()[0], pos()[1]); }
  void OnLeftButtonUp() override { viewer_->button(false, pos()[0], pos()[1]); }
  void OnMouseMove() override { viewer_->mouse_move(pos()[0], pos()[1]); }
  void OnMouseWheelForward() override { viewer_->wheel(1); }
  void OnMouseWheelBackward() override { viewer_->wheel(-1); }
  void OnLeave() override { viewer_->leave(); }
  void OnExpose() override { viewer_->request_frame(); }
  void OnConfigure() override { viewer_->request_frame(); }
  void OnTimer() override { viewer_->tick(); }

 protected:
  ViewerStyle() = default;
  ~ViewerStyle() override = default;

 private:
  // The key's X keysym name, letters in lower case (with Shift held X names them in upper).
  std::string key() {
    const char* k = this->Interactor->GetKeySym();
    std::string s = k != nullptr ? k : "";
    if (s.size() == 1) s[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(s[0])));
    return s;
  }
  int* pos() { return this->Interactor->GetEventPosition(); }
  Viewer* viewer_ = nullptr;
};

vtkStandardNewMacro(ViewerStyle);

scene::CameraPose default_pose(const io::Mosaic& m) {
  const io::Georef& g = m.georef();
  scene::CameraPose p;
  p.lat = g.y0 - (m.rows() - 1) * g.dy / 2.0;
  p.lon = std::remainder(g.x0 + (m.cols() - 1) * g.dx / 2.0, 360.0);
  p.alt = 1500.0;  // above the ground
  p.heading_deg = 0.0;
  p.pitch_deg = -15.0;
  return p;
}

// Fractional lattice row and column of a geographic point (row 0 north).
void lattice_position(const io::Mosaic& m, double lat, double lon, double& row, double& col) {
  const io::Georef& g = m.georef();
  row = (g.y0 - lat) / g.dy;
  col = (std::remainder(lon - g.x0 - 180.0, 360.0) + 180.0) / g.dx;
}

void style_text(vtkTextProperty* t, int size) {
  t->SetFontFamilyToCourier();
  t->SetFontSize(size);
  t->SetColor(1.0, 1.0, 1.0);
  t->BoldOn();
  t->ShadowOn();
  t->SetBackgroundColor(0.05, 0.08, 0.12);
  t->SetBackgroundOpacity(0.55);
}

Viewer::Viewer(const ViewOptions& options)
    : o_(options),
      mosaic_(io::Mosaic::open(options.dems)),
      flight_(options.flight),
      metric_(options.style.traversal.metric),
      lod_colors_(options.lod_colors),
      wireframe_(options.wireframe),
      auto_slide_(options.auto_slide) {
  threshold_[0] = mrbsp::default_threshold(mrbsp::LodMetric::kArea);
  threshold_[1] = mrbsp::default_threshold(mrbsp::LodMetric::kError);
  threshold() = options.style.traversal.threshold_px;

  // The camera, inside the mosaic and above its ground.
  const bool given = options.pose.has_value();
  pose_ = given ? *options.pose : default_pose(mosaic_);
  const bool agl = given ? options.agl : true;
  double row = 0, col = 0;
  lattice_position(mosaic_, pose_.lat, pose_.lon, row, col);
  if (row < 0 || row > mosaic_.rows() - 1 || col < 0 || col > mosaic_.cols() - 1) {
    const io::Georef& g = mosaic_.georef();
    const double south = g.y0 - (mosaic_.rows() - 1) * g.dy, east = g.x0 + (mosaic_.cols() - 1) * g.dx;
    throw std::runtime_error("camera " + degrees(pose_.lat, 'N', 'S') + ", " + degrees(pose_.lon, 'E', 'W') +
                             " is outside the DEM (" + degrees(south, 'N', 'S') + " .. " + degrees(g.y0, 'N', 'S') +
                             ", " + degrees(g.x0, 'E', 'W') + " .. " + degrees(east, 'E', 'W') + ")");
  }
  render::require_x_display();
  const scene::WindowChoice window = scene::choose_window(mosaic_.rows(), mosaic_.cols(), row, col, o_.style.window);
  scene_ = std::make_unique<scene::TerrainScene>(mosaic_, window, o_.levels > 0 ? o_.levels : scene::default_levels(window.cells));
  const double ground = scene_->ground_height(pose_.lat, pose_.lon);
  if (agl) pose_.alt += ground;
  if (pose_.alt <= ground) {
    char b[160];
    std::snprintf(b, sizeof b, "camera at %.1f m is not above the ground (%.1f m there)%s", pose_.alt, ground,
                  agl ? "" : "; use --agl for heights above ground");
    throw std::runtime_error(b);
  }
  start_pose_ = pose_;

  // The renderer, on screen.
  render::RenderSettings settings;
  settings.width = o_.style.width;
  settings.height = o_.style.height;
  settings.order = o_.style.order;
  settings.lod_colors = lod_colors_;
  settings.wireframe = wireframe_;
  settings.gradient = true;
  settings.haze_color = scene::kHorizon;
  settings.haze_distance = o_.style.haze_km * 1000.0;
  settings.offscreen = false;
  volumes_ = scene::VolumeLayer(o_.volumes, mosaic_, scene_->frame(), o_.style.surface_triangles);
  volumes_.merge_into(*scene_);
  lattice_ = scene::shade_terrain(scene_->cells(), scene_->xs(), scene_->ys(), scene_->z(), scene_->heights(), o_.style.shading);
  const mrbsp::TerrainTree& tree = scene_->tree();
  renderer_ = std::make_unique<render::TerrainRenderer>(tree.positions(),
                                                scene::vertex_shading(lattice_, tree.merged_base(), tree.merged_colors()),
                                                settings, render::ColorTexture{scene_->cells() + 1, lattice_.rgba});
  if (o_.style.legend) renderer_->set_legend(volumes_.legend());
  vtkRenderWindow* win = renderer_->window();
  std::string title = "Terravol view - " + o_.dems.front().filename().string();
  if (o_.dems.size() > 1) title += " + " + std::to_string(o_.dems.size() - 1) + " more";
  win->SetWindowName(title.c_str());

  // Interaction: our style only; the interactor asks for frames instead of rendering.
  style_ = vtkSmartPointer<ViewerStyle>::New();
  style_->set_viewer(this);
  interactor_->SetRenderWindow(win);
  interactor_->SetInteractorStyle(style_);
  interactor_->EnableRenderOff();
  render_callback_->SetClientData(this);
  render_callback_->SetCallback([](vtkObject*, unsigned long, void* self, void*) {
    static_cast<Viewer*>(self)->request_frame();
  });
  interactor_->AddObserver(vtkCommand::RenderEvent, render_callback_);
  interactor_->Initialize();
  // Held keys: without this X repeats a held key as release-press pairs, and a tick that
  // falls between them would stop the camera.
  Bool supported = False;
  XkbSetDetectableAutoRepeat(static_cast<Display*>(win->GetGenericDisplayId()), True, &supported);

  // The threshold slider, bottom right, on a log2 scale, its value in the title, on a dark
  // translucent panel so that it reads over sky and snow alike.
  {
    vtkNew<vtkPoints> corners;
    const double x0 = kSliderX0 - 0.025, x1 = kSliderX1 + 0.025, y0 = kSliderY - 0.085, y1 = kSliderY + 0.075;
    for (const auto& [x, y] : {std::pair{x0, y0}, std::pair{x1, y0}, std::pair{x1, y1}, std::pair{x0, y1}}) {
      corners->InsertNextPoint(x, y, 0.0);
    }
    vtkNew<vtkCellArray> quad;
    const vtkIdType ids[4] = {0, 1, 2, 3};
    quad->InsertNextCell(4, ids);
    vtkNew<vtkPolyData> rect;
    rect->SetPoints(corners);
    rect->SetPolys(quad);
    vtkNew<vtkCoordinate> normalized;
    normalized->SetCoordinateSystemToNormalizedViewport();
    vtkNew<vtkPolyDataMapper2D> mapper;
    mapper->SetInputData(rect);
    mapper->SetTransformCoordinate(normalized);
    slider_panel_->SetMapper(mapper);
    slider_panel_->GetProperty()->SetColor(0.05, 0.08, 0.12);
    slider_panel_->GetProperty()->SetOpacity(0.55);
    renderer_->renderer()->AddActor2D(slider_panel_);
  }
  slider_rep_->GetPoint1Coordinate()->SetCoordinateSystemToNormalizedDisplay();
  slider_rep_->GetPoint1Coordinate()->SetValue(kSliderX0, kSliderY);
  slider_rep_->GetPoint2Coordinate()->SetCoordinateSystemToNormalizedDisplay();
  slider_rep_->GetPoint2Coordinate()->SetValue(kSliderX1, kSliderY);
  slider_rep_->SetEndCapLength(kEndCapLength);
  slider_rep_->SetSliderLength(kSliderLength);
  slider_rep_->SetSliderWidth(0.045);
  slider_rep_->SetTubeWidth(0.012);
  slider_rep_->SetEndCapWidth(0.035);
  slider_rep_->SetTitleHeight(0.026);
  slider_rep_->ShowSliderLabelOff();
  slider_rep_->GetTubeProperty()->SetColor(0.92, 0.92, 0.92);
  slider_rep_->GetCapProperty()->SetColor(0.92, 0.92, 0.92);
  slider_rep_->GetSliderProperty()->SetColor(1.0, 0.62, 0.15);
  slider_rep_->GetSelectedProperty()->SetColor(1.0, 0.85, 0.3);
  style_text(slider_rep_->GetTitleProperty(), 16);
  slider_rep_->GetTitleProperty()->SetBackgroundOpacity(0.0);  // the panel is behind it
  slider_->SetInteractor(interactor_);
  slider_->SetRepresentation(slider_rep_);
  slider_->SetAnimationModeToJump();
  slider_callback_->SetClientData(this);
  slider_callback_->SetCallback([](vtkObject*, unsigned long, void* self, void*) {
    static_cast<Viewer*>(self)->slider_moved();
  });
  slider_->AddObserver(vtkCommand::InteractionEvent, slider_callback_);
  slider_->EnabledOn();
  for (vtkTextActor* end : {slider_min_.GetPointer(), slider_max_.GetPointer()}) {
    style_text(end->GetTextProperty(), 13);
    end->GetTextProperty()->BoldOff();
    end->GetTextProperty()->SetBackgroundOpacity(0.0);
    end->GetTextProperty()->SetVerticalJustificationToBottom();
    end->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    renderer_->renderer()->AddActor2D(end);
  }
  slider_min_->GetTextProperty()->SetJustificationToLeft();
  slider_min_->SetPosition(kSliderX0, kSliderY + 0.032);
  slider_max_->GetTextProperty()->SetJustificationToRight();
  slider_max_->SetPosition(kSliderX1, kSliderY + 0.032);
  sync_slider();

  // The overlay, top left, and the key list, bottom left.
  style_text(overlay_->GetTextProperty(), 15);
  overlay_->GetTextProperty()->SetVerticalJustificationToTop();
  overlay_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  overlay_->SetPosition(0.008, 0.988);
  renderer_->renderer()->AddActor2D(overlay_);
  style_text(help_text_->GetTextProperty(), 14);
  help_text_->GetTextProperty()->SetVerticalJustificationToBottom();
  help_text_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  help_text_->SetPosition(0.008, 0.015);
  help_text_->SetInput(kViewKeys);
  help_text_->SetVisibility(help_);
  renderer_->renderer()->AddActor2D(help_text_);
}

Viewer::~Viewer() {
  slider_->EnabledOff();
  slider_->SetInteractor(nullptr);
  interactor_->SetInteractorStyle(nullptr);
}

void Viewer::run() {
  start_ = last_tick_ = Clock::now();
  draw_frame();
  interactor_->CreateRepeatingTimer(15);
  interactor_->Start();
  std::printf("frames %zu: median %.1f ms (traversal %.1f ms, draw %.1f ms); slides %zu", frames_,
              median(frame_log_), median(traversal_log_), median(draw_log_), slides_);
  if (slides_ > 0) std::printf(": median %.0f ms", median(slide_log_));
  std::printf("\n");
  std::fflush(stdout);
}

scene::FlightInput Viewer::input() const {
  scene::FlightInput in;
  in.forward = int(held("w")) - int(held("s"));
  in.right = int(held("d")) - int(held("a"));
  in.up = int(held("r") || held("Prior")) - int(held("f") || held("Next"));
  in.turn = int(held("Right")) - int(held("Left"));
  in.tilt = int(held("Up")) - int(held("Down"));
  in.boost = held("Shift_L") || held("Shift_R");
  return in;
}

void Viewer::key_press(const std::string& key) {
  static const std::set<std::string> kMotion{"w",  "s",    "a",    "d",     "r",       "f",      "Prior",
                                             "Next", "Up", "Down", "Left", "Right", "Shift_L", "Shift_R"};
  if (kMotion.count(key) > 0) {
    held_.insert(key);
    tapped_.insert(key);
    return;  // the next tick moves
  }
  if (key == "Escape" || key == "q") {
    interactor_->TerminateApp();
    return;
  }
  if (key == "l") {
    lod_colors_ = !lod_colors_;
    renderer_->set_lod_colors(lod_colors_);
  } else if (key == "t") {
    wireframe_ = !wireframe_;
    renderer_->set_wireframe(wireframe_);
  } else if (key == "m") {
    set_metric(metric_ == mrbsp::LodMetric::kError ? mrbsp::LodMetric::kArea : mrbsp::LodMetric::kError);
  } else if (key == "g") {
    auto_slide_ = !auto_slide_;
  } else if (key == "p") {
    screenshot_pending_ = true;
  } else if (key == "k") {
    record_key();
  } else if (key == "j") {
    save_path();
  } else if (key == "h") {
    help_ = !help_;
    help_text_->SetVisibility(help_);
  } else if (key == "Home") {
    pose_ = start_pose_;
  } else if ((key.size() == 1 && key[0] >= '1' && key[0] <= '9') || key == "bracketleft" ||
             key == "bracketright" || key == "comma" || key == "period") {
    volume_key(key);
  } else if (key == "equal" || key == "plus" || key == "KP_Add") {
    set_threshold(threshold() / std::sqrt(2.0));
  } else if (key == "minus" || key == "KP_Subtract") {
    set_threshold(threshold() * std::sqrt(2.0));
  } else {
    return;
  }
  dirty_ = true;
}

void Viewer::key_release(const std::string& key) {
  if (held_.erase(key) > 0) dirty_ = true;  // one more frame, so the status shows the key up
}

void Viewer::button(bool down, int x, int y) {
  dragging_ = down;
  drag_x_ = x;
  drag_y_ = y;
}

void Viewer::mouse_move(int x, int y) {
  if (!dragging_) return;
  pose_ = scene::look(pose_, x - drag_x_, y - drag_y_, flight_);
  drag_x_ = x;
  drag_y_ = y;
  dirty_ = true;
}

void Viewer::wheel(int clicks) {
  flight_.speed_factor = std::clamp(flight_.speed_factor * std::pow(1.25, clicks), 0.01, 100.0);
  dirty_ = true;  // the overlay shows the speed
}

// The pointer left the window: under X the keyboard focus goes with it here, so the releases of
// keys held now would go elsewhere; stop rather than fly on.
void Viewer::leave() { held_.clear(); }

void Viewer::clamp_to_mosaic(scene::CameraPose& p) const {
  const io::Georef& g = mosaic_.georef();
  const double south = g.y0 - (mosaic_.rows() - 1) * g.dy, west = g.x0;
  p.lat = std::clamp(p.lat, south, g.y0);
  const double east_of_west = std::remainder(p.lon - west - 180.0, 360.0) + 180.0;
  p.lon = std::remainder(west + std::clamp(east_of_west, 0.0, (mosaic_.cols() - 1) * g.dx), 360.0);
}

void Viewer::tick() {
  // VTK's X event loop handles one event between timer checks, and a frame takes longer than
  // the timer's period: without this, events (a held key's repeats first) would queue up
  // faster than they are handled, and a key's release would come seconds late.
  Display* display = static_cast<Display*>(renderer_->window()->GetGenericDisplayId());
  while (XPending(display) > 0) {
    XEvent event;
    XNextEvent(display, &event);
    interactor_->DispatchEvent(&event);
  }
  const Clock::time_point now = Clock::now();
  // At most a quarter second per tick, so a stall (a slide, a busy machine) is no leap.
  const double dt = std::min(std::chrono::duration<double>(now - last_tick_).count(), 0.25);
  last_tick_ = now;
  const scene::FlightInput in = input();
  if (in.moving()) {
    const scene::TerrainScene& scene = *scene_;
    pose_ = scene::fly(pose_, in, dt, scene.frame(),
                [&scene](double lat, double lon) { return scene.ground_height(lat, lon); }, flight_);
    clamp_to_mosaic(pose_);
    dirty_ = true;
  }
  tapped_.clear();
  if (slide_ready()) dirty_ = true;
  if (overlay_stale_ && now - overlay_time_ >= kOverlayPeriod) dirty_ = true;
  if (dirty_ || screenshot_pending_) {
    dirty_ = false;
    draw_frame();
  }
}

// Number keys toggle (and select) a volume; [ ] move its first slice, , . its first
// isosurface. Each change re-extracts that one piece of geometry, merges all visible geometry
// into the tree again and uploads the vertices; the overlay and the status say how long it took.
void Viewer::volume_key(const std::string& key) {
  if (volumes_.size() == 0) {
    message_ = "no volumes (give --volume or --scene)";
    return;
  }
  const auto t0 = Clock::now();
  std::string what;
  try {
    if (key[0] >= '1' && key[0] <= '9') {
      const std::size_t v = static_cast<std::size_t>(key[0] - '1');
      if (v >= volumes_.size()) {
        message_ = "there is no volume " + key;
        return;
      }
      selected_volume_ = v;
      volumes_.set_visible(v, !volumes_.spec(v).visible);
      what = "volume " + key + (volumes_.spec(v).visible ? " shown" : " hidden");
    } else if (key == "bracketleft" || key == "bracketright") {
      const scene::VolumeSpec& spec = volumes_.spec(selected_volume_);
      if (spec.slices.empty()) {
        message_ = "volume " + std::to_string(selected_volume_ + 1) + " has no slice";
        return;
      }
      volume::SliceSpec s = spec.slices.front();
      const bool degrees = s.kind == volume::SliceKind::kLat || s.kind == volume::SliceKind::kLon;
      s.value += (key == "bracketright" ? 1.0 : -1.0) * (degrees ? 0.01 : 50.0);
      volumes_.set_slice(selected_volume_, 0, s);
      char b[96];
      std::snprintf(b, sizeof b, "slice %s %g%s", std::string(volume::slice_kind_name(s.kind)).c_str(), s.value,
                    degrees ? " deg" : " m");
      what = b;
    } else {
      const scene::VolumeSpec& spec = volumes_.spec(selected_volume_);
      if (spec.isosurfaces.empty()) {
        message_ = "volume " + std::to_string(selected_volume_ + 1) + " has no isosurface";
        return;
      }
      volume::IsoSpec iso = spec.isosurfaces.front();
      iso.value += key == "period" ? 2.0f : -2.0f;
      volumes_.set_isosurface(selected_volume_, 0, iso);
      char b[64];
      std::snprintf(b, sizeof b, "isosurface %g", static_cast<double>(iso.value));
      what = b;
    }
  } catch (const std::invalid_argument& e) {
    message_ = e.what();  // e.g. a slice moved out of its volume: nothing changed
    return;
  }
  const double geometry_ms = volumes_.figures().geometry_ms;
  volumes_.merge_into(*scene_);
  upload_vertices();
  if (o_.style.legend) renderer_->set_legend(volumes_.legend());
  last_merge_ms_ = ms_between(t0, Clock::now());
  char b[160];
  std::snprintf(b, sizeof b, "%s: %.0f ms (geometry %.0f, merge %.0f)", what.c_str(), last_merge_ms_, geometry_ms,
                volumes_.figures().merge_ms);
  message_ = b;
}

// Keyframes at the times they were recorded, so that the path replays the flight's pace.
void Viewer::record_key() {
  const Clock::time_point now = Clock::now();
  if (keys_.empty()) first_key_time_ = now;
  scene::PathKey k;
  k.t = std::chrono::duration<double>(now - first_key_time_).count();
  if (!keys_.empty()) k.t = std::max(k.t, keys_.back().t + scene::kMinKeyGap);
  k.lat = pose_.lat;
  k.lon = pose_.lon;
  k.alt = pose_.alt;  // above the datum
  k.heading_deg = pose_.heading_deg;
  k.pitch_deg = pose_.pitch_deg;
  k.fov_y_deg = o_.fov_y_deg;
  k.threshold = threshold();
  keys_.push_back(k);
  char b[96];
  std::snprintf(b, sizeof b, "keyframe %zu at %.1f s (J saves the path)", keys_.size(), k.t);
  message_ = b;
}

void Viewer::save_path() {
  if (keys_.size() < 2) {
    message_ = "record at least two keyframes (K) before saving";
    return;
  }
  // The scene: the --scene file (absolute), else the DEMs.
  nlohmann::json scene;
  if (!o_.scene_file.empty()) {
    scene = std::filesystem::absolute(o_.scene_file).string();
  } else {
    scene = nlohmann::json::object();
    scene["dem"] = nlohmann::json::array();
    for (const auto& d : o_.dems) scene["dem"].push_back(std::filesystem::absolute(d).string());
  }
  const std::filesystem::path out = o_.record.empty() ? std::filesystem::path("terravol-path.json") : o_.record;
  try {
    const std::string text = scene::path_to_json(scene, keys_).dump(2) + "\n";
    output::write_file_atomically(out, std::vector<std::uint8_t>(text.begin(), text.end()), true);
    message_ = "saved " + std::to_string(keys_.size()) + " keyframes to " + out.string();
  } catch (const std::exception& e) {
    message_ = std::string("saving the path failed: ") + e.what();
  }
}

void Viewer::upload_vertices() {
  const mrbsp::TerrainTree& tree = scene_->tree();
  renderer_->replace_vertices(tree.positions(), scene::vertex_shading(lattice_, tree.merged_base(), tree.merged_colors()),
                              render::ColorTexture{scene_->cells() + 1, lattice_.rgba});
}

void Viewer::slider_moved() {
  const double t = std::exp2(slider_rep_->GetValue());
  threshold() = t;
  sync_slider();
  dirty_ = true;
}

void Viewer::set_metric(mrbsp::LodMetric m) {
  metric_ = m;
  sync_slider();
}

void Viewer::set_threshold(double t) {
  const SliderRange r = slider_range(metric_);
  threshold() = std::clamp(t, std::exp2(r.lo), std::exp2(r.hi));
  sync_slider();
}

void Viewer::sync_slider() {
  const SliderRange r = slider_range(metric_);
  const double t = threshold();
  slider_rep_->SetMinimumValue(r.lo);
  slider_rep_->SetMaximumValue(r.hi);
  slider_rep_->SetValue(std::log2(t));
  const bool error = metric_ == mrbsp::LodMetric::kError;
  const std::string title = std::string("LOD threshold ") + threshold_text(metric_, t) +
                            (error ? " (screen-space error)" : " (projected area)");
  slider_rep_->SetTitleText(title.c_str());
  slider_min_->SetInput(error ? "0.25 px  finer" : "32 px^2  finer");
  slider_max_->SetInput(error ? "coarser  16 px" : "coarser  32768 px^2");
}

// Sliding runs in two halves. start_slide(), when the camera is within a quarter of the window
// of its edge, reads the moved window from the mosaic and shades it on a worker thread (the
// camera still has a quarter of the window ahead meanwhile); finish_slide(), at the first frame
// after it is ready, slides the tree and replaces the renderer's vertices on this thread.
void Viewer::start_slide() {
  if (pending_slide_.valid()) return;
  double row = 0, col = 0;
  lattice_position(mosaic_, pose_.lat, pose_.lon, row, col);
  const scene::WindowChoice& now = scene_->window();
  const int step = 1 << (scene_->tree().levels() - 1);  // samples across one coarsest-level cell
  const scene::WindowChoice next = scene::plan_slide(now, mosaic_.rows(), mosaic_.cols(), row, col, step);
  if (next.row0 == now.row0 && next.col0 == now.col0) return;
  const mrbsp::TerrainTree& tree = scene_->tree();
  pending_slide_ = std::async(std::launch::async, [mosaic = &mosaic_, next, frame = scene_->frame(),
                                                   shading = o_.style.shading, base = tree.merged_base(),
                                                   merged = tree.merged_colors()] {
    PreparedSlide p;
    const auto t0 = Clock::now();
    p.window = scene::read_scene_window(*mosaic, next, frame);
    const auto t1 = Clock::now();
    p.lattice = scene::shade_terrain(next.cells, p.window.xs, p.window.ys, p.window.z, p.window.heights, shading);
    p.vertices = scene::vertex_shading(p.lattice, base, merged);
    p.read_ms = ms_between(t0, t1);
    p.shade_ms = ms_between(t1, Clock::now());
    return p;
  });
}

bool Viewer::slide_ready() const {
  return pending_slide_.valid() &&
         pending_slide_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

void Viewer::finish_slide() {
  if (!slide_ready()) return;
  PreparedSlide p;
  try {
    p = pending_slide_.get();
  } catch (const io::FormatError& e) {
    std::fprintf(stderr, "terravol: %s (automatic sliding turned off)\n", e.what());
    auto_slide_ = false;
    return;
  }
  const auto t0 = Clock::now();
  scene_->slide(std::move(p.window));  // merges the volumes again into the moved window
  lattice_ = std::move(p.lattice);
  const auto t1 = Clock::now();
  if (volumes_.size() > 0) {
    // The merged vertices were made anew by the slide: their count and colours changed.
    p.vertices = scene::vertex_shading(lattice_, scene_->tree().merged_base(), scene_->tree().merged_colors());
  }
  renderer_->replace_vertices(scene_->tree().positions(), p.vertices, render::ColorTexture{scene_->cells() + 1, lattice_.rgba});
  const auto t2 = Clock::now();
  slide_parts_ = {p.read_ms, p.shade_ms, ms_between(t0, t1), ms_between(t1, t2)};
  last_slide_ms_ = ms_between(t0, t2);
  slide_log_.push_back(last_slide_ms_);
  ++slides_;
}

void Viewer::draw_frame() {
  const auto t0 = Clock::now();
  finish_slide();
  if (auto_slide_) start_slide();
  const int* size = renderer_->window()->GetSize();
  const int width = std::max(size[0], 1), height = std::max(size[1], 1);
  const double ground = scene_->ground_height(pose_.lat, pose_.lon);
  const double agl = pose_.alt - ground;
  const double speed = scene::flight_speed(agl, flight_, held("Shift_L") || held("Shift_R"));
  const mrbsp::Camera camera =
      scene::make_scene_camera(scene_->frame(), pose_, pose_.alt, o_.fov_y_deg, width, height, scene::near_plane_for(agl));
  renderer_->set_camera(camera, scene_->far_plane(camera.eye));
  const auto sky = scene::sky_gradient(pose_.pitch_deg, o_.fov_y_deg);
  renderer_->renderer()->SetBackground(sky[0][0] / 255.0, sky[0][1] / 255.0, sky[0][2] / 255.0);
  renderer_->renderer()->SetBackground2(sky[1][0] / 255.0, sky[1][1] / 255.0, sky[1][2] / 255.0);

  mrbsp::TraversalOptions traversal = o_.style.traversal;
  traversal.metric = metric_;
  traversal.threshold_px = static_cast<float>(threshold());
  const auto t1 = Clock::now();
  scene_->tree().traverse(camera, traversal, frame_);
  const auto t2 = Clock::now();
  renderer_->set_frame(frame_);
  const auto t3 = Clock::now();
  traversal_ms_ = ms_between(t1, t2);
  upload_ms_ = ms_between(t2, t3);
  update_overlay(agl, speed);
  draw_ms_ = renderer_->render();
  frame_ms_ = ms_between(t0, Clock::now());
  if (frames_ > 0) {  // the first frame compiles shaders and uploads every vertex
    frame_log_.push_back(frame_ms_);
    traversal_log_.push_back(traversal_ms_);
    draw_log_.push_back(draw_ms_);
  }
  ++frames_;
  if (screenshot_pending_) {
    screenshot_pending_ = false;
    save_screenshot();
  }
  write_status(agl, speed, camera);
}

// The text is drawn again (FreeType, then a texture) only when a setting in it changes or a
// quarter second has passed: redrawing it every frame cost about 7 ms per frame. tick() brings
// a last frame when the camera stops, so the figures do not stay stale.
void Viewer::update_overlay(double agl, double speed) {
  const scene::WindowChoice& w = scene_->window();
  const bool error = metric_ == mrbsp::LodMetric::kError;
  char settings[512];
  std::snprintf(settings, sizeof settings,
                "LOD %s %s   colours %s   wireframe %s\n"
                "window %d cells at row %d, col %d   slides %zu (last %.0f ms)   auto-slide %s\n%s",
                error ? "error" : "area", threshold_text(metric_, threshold()).c_str(), lod_colors_ ? "on" : "off",
                wireframe_ ? "on" : "off", w.cells, w.row0, w.col0, slides_, last_slide_ms_,
                auto_slide_ ? "on" : "off", message_.empty() ? "H: keys" : message_.c_str());
  const auto now = Clock::now();
  if (settings == overlay_settings_ && now - overlay_time_ < kOverlayPeriod) {
    overlay_stale_ = true;  // it shows older figures: tick() refreshes it once the camera stops
    return;
  }
  overlay_stale_ = false;
  overlay_settings_ = settings;
  overlay_time_ = now;
  char b[1024];
  std::snprintf(b, sizeof b,
                "%zu triangles, %zu nodes   frame %.0f ms (traversal %.1f, draw %.0f)\n"
                "%s %s   alt %.0f m   AGL %.0f m   heading %.0f   pitch %.0f   speed %.0f m/s\n",
                frame_.indices.size() / 3, frame_.nodes_visited, frame_ms_, traversal_ms_, draw_ms_,
                degrees(pose_.lat, 'N', 'S').c_str(), degrees(pose_.lon, 'E', 'W').c_str(), pose_.alt, agl,
                pose_.heading_deg, pose_.pitch_deg, speed);
  overlay_->SetInput((b + overlay_settings_).c_str());
}

void Viewer::save_screenshot() {
  std::filesystem::path path = o_.screenshot;
  if (path.empty()) {
    for (int k = 1; path.empty() || std::filesystem::exists(path); ++k) {
      char name[64];
      std::snprintf(name, sizeof name, "terravol-view-%03d.png", k);
      path = name;
    }
  }
  try {
    output::write_png(path, output::window_png(renderer_->window()), true);
    ++screenshots_;
    last_screenshot_ = path;
    message_ = "wrote " + path.string();
  } catch (const std::exception& e) {
    message_ = std::string("screenshot failed: ") + e.what();
    std::fprintf(stderr, "terravol: %s\n", message_.c_str());
  }
  dirty_ = true;  // show the message
}

void Viewer::write_status(double agl, double speed, const mrbsp::Camera& camera) {
  if (o_.status.empty()) return;
  const scene::WindowChoice& w = scene_->window();
  const scene::WindowBounds b = scene_->bounds();
  const int* size = renderer_->window()->GetSize();
  // The slider's knob centre at the range's ends, in window pixels from the top left
  // (vtkSliderRepresentation2D: caps at both ends, the knob slides between them).
  const double x0 = kSliderX0 * size[0], x1 = kSliderX1 * size[0];
  const double knob_lo = x0 + (kEndCapLength + kSliderLength / 2.0) * size[0];
  const double knob_hi = x1 - (kEndCapLength + kSliderLength / 2.0) * size[0];
  const SliderRange r = slider_range(metric_);
  ordered_json j;
  j["frame"] = frames_;
  j["time_s"] = std::chrono::duration<double>(Clock::now() - start_).count();
  j["triangles"] = frame_.indices.size() / 3;
  j["nodes_visited"] = frame_.nodes_visited;
  j["threshold"] = threshold();
  j["metric"] = metric_ == mrbsp::LodMetric::kError ? "error" : "area";
  j["lod_colors"] = lod_colors_;
  j["wireframe"] = wireframe_;
  j["auto_slide"] = auto_slide_;
  j["camera"] = {{"lat", pose_.lat},
                 {"lon", pose_.lon},
                 {"alt", pose_.alt},
                 {"agl", agl},
                 {"heading", pose_.heading_deg},
                 {"pitch", pose_.pitch_deg},
                 {"eye", {camera.eye.x, camera.eye.y, camera.eye.z}}};
  j["speed_mps"] = speed;
  j["keys_held"] = held_;
  j["frame_ms"] = frame_ms_;
  j["traversal_ms"] = traversal_ms_;
  j["upload_ms"] = upload_ms_;
  j["draw_ms"] = draw_ms_;
  j["slides"] = slides_;
  j["last_slide_ms"] = last_slide_ms_;
  j["last_slide_parts_ms"] = {{"read_window", slide_parts_[0]},
                              {"shading", slide_parts_[1]},
                              {"tree", slide_parts_[2]},
                              {"vertices", slide_parts_[3]}};
  j["slide_pending"] = pending_slide_.valid();
  j["volumes"] = ordered_json::array();
  for (std::size_t v = 0; v < volumes_.size(); ++v) {
    const scene::VolumeSpec& spec = volumes_.spec(v);
    ordered_json jv;
    jv["visible"] = spec.visible;
    jv["isovalues"] = ordered_json::array();
    for (const auto& iso : spec.isosurfaces) jv["isovalues"].push_back(iso.value);
    jv["slices"] = ordered_json::array();
    for (const auto& s : spec.slices) jv["slices"].push_back({{"kind", volume::slice_kind_name(s.kind)}, {"value", s.value}});
    j["volumes"].push_back(jv);
  }
  j["merged_triangles"] = volumes_.figures().tree_triangles;
  j["last_merge_ms"] = last_merge_ms_;
  j["message"] = message_;
  // Nothing will draw another frame until something happens: no key held, no slide read
  // ahead, no overlay refresh or screenshot due.
  j["idle"] = held_.empty() && !pending_slide_.valid() && !overlay_stale_ && !screenshot_pending_ && !dirty_;
  j["window"] = {{"cells", w.cells},
                 {"row0", w.row0},
                 {"col0", w.col0},
                 {"south", b.south},
                 {"north", b.north},
                 {"west", b.west},
                 {"east", b.east},
                 {"origin_lat", scene_->frame().lat0()},
                 {"origin_lon", scene_->frame().lon0()}};
  j["size"] = {size[0], size[1]};
  j["slider"] = {{"x_min", knob_lo},
                 {"x_max", knob_hi},
                 {"y", (1.0 - kSliderY) * size[1]},
                 {"value", slider_rep_->GetValue()},
                 {"value_min", r.lo},
                 {"value_max", r.hi}};
  j["screenshots"] = screenshots_;
  j["screenshot"] = last_screenshot_.string();
  const std::string text = j.dump(2) + "\n";
  try {
    output::write_file_atomically(o_.status, std::vector<std::uint8_t>(text.begin(), text.end()), true);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "terravol: %s\n", e.what());
  }
}

}  // namespace

void run_viewer(const ViewOptions& options) {
  Viewer viewer(options);
  viewer.run();
}

}  // namespace terravol::app::viewer
