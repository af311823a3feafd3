// The interactive viewer (`terravol view`; docs/architecture.md, "The viewer"): input, overlay
// and status around the scene pipeline (app/render/scene_renderer.h), which slides the window
// on a worker thread here. One timer drives everything: key and mouse events only change state
// and mark the view dirty; every tick of a repeating timer moves the camera by the keys held
// (for the real time elapsed) and, if anything changed, draws one frame: the pipeline finishes
// a slide whose window was read ahead, starts one if the camera nears the window's edge,
// traverses the tree and replaces the triangle list; then the overlay, the draw and the status
// file. Nothing is drawn while nothing changes. The interactor's own rendering is switched off
// so that widgets and expose events only ask for a frame.
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
#include <vtkTextRenderer.h>
#include <vtkTransformPolyDataFilter.h>
#include <vtkXRenderWindowInteractor.h>

#include <X11/XKBlib.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "app/output/png_output.h"
#include "app/output/profile_plot.h"
#include "app/output/write_file.h"
#include "app/render/scene_renderer.h"
#include "app/render/terrain_renderer.h"
#include "app/scene/camera_path.h"
#include "app/scene/mosaic_lattice.h"
#include "app/scene/object_layer.h"
#include "app/scene/profile_path.h"
#include "app/scene/terrain_scene.h"
#include "app/scene/timing.h"
#include "app/scene/volume_layer.h"
#include "app/viewer/overlay_layout.h"
#include "density/transfer.h"
#include "io/mosaic.h"

namespace terravol::app::viewer {

const char* const kViewKeys =
    "W / S        forward / back, along the view\n"
    "A / D        strafe left / right\n"
    "R / F        up / down (also PageUp / PageDown)\n"
    "arrows       turn left / right, look up / down\n"
    "left drag    look around\n"
    "Ctrl+click   the point under the cursor: lat, lon, ground, each volume's value\n"
    "Shift+click  twice: the link profile between the two points, drawn and plotted\n"
    "Shift        4x faster; mouse wheel: speed x1.25 or /1.25\n"
    "+ / -        finer / coarser LOD (threshold / or x sqrt 2); or drag the slider\n"
    "M            LOD metric: screen-space error / projected area\n"
    "L            LOD colours\n"
    "T            wireframe (triangle edges)\n"
    "G            automatic sliding of the window\n"
    "1 .. 9       show or hide volume N (and select it)\n"
    "X            transmitter markers on / off\n"
    "B            objects (3D models) on / off\n"
    "[ / ]        move the selected volume's first slice down / up (50 m; 0.01 deg)\n"
    ", / .        lower / raise its first isosurface's level by 2 units\n"
    "E / Shift+E  density: finer / coarser colour cubes (epsilon / or x sqrt 2)\n"
    "O / Shift+O  density: the selected volume's opacity x sqrt 2 / or / sqrt 2 (cubes built again)\n"
    "P            screenshot (PNG)\n"
    "K / J        record a keyframe of the camera / save the keyframes as a camera path\n"
    "Home         back to the starting pose\n"
    "H            show or hide this list\n"
    "Esc or Q     quit";

namespace {

using nlohmann::ordered_json;
using scene::Clock;
using scene::degrees;
using scene::ms_between;
using scene::ms_since;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
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

// The slider's panel (overlay_layout.h): its height, and inside it, from the top, the title
// (16 px text), the tube and knob, the end labels (13 px text), in pixels.
constexpr int kSliderPanelHeight = 92;
constexpr int kSliderPad = 8, kSliderTubeY = 48, kSliderInset = 16;

// vtkSliderRepresentation2D with the extent of what it draws (tube, end caps, knob) in window
// pixels, read back from the geometry it built (VTK 9.1 puts all three in one vtkPoints: end
// caps 0-3 and 12-15, tube 4-7, knob 8-11, then the label's and title's anchors; lengths are
// fractions of the window's width, thicknesses of its height) rather than predicted.
class MeasuredSlider : public vtkSliderRepresentation2D {
 public:
  static MeasuredSlider* New();
  vtkTypeMacro(MeasuredSlider, vtkSliderRepresentation2D);
  MeasuredSlider(const MeasuredSlider&) = delete;
  MeasuredSlider& operator=(const MeasuredSlider&) = delete;

  // Builds the representation and returns the box of its tube, caps and knob (y down from the
  // top of a window `height` pixels tall).
  Box drawn_box(int height) { return box_of(0, 16, height); }
  // The knob's box.
  Box knob_box(int height) { return box_of(8, 12, height); }

 protected:
  MeasuredSlider() = default;
  ~MeasuredSlider() override = default;

 private:
  Box box_of(int first, int end, int height) {
    BuildRepresentation();
    SliderXForm->Update();
    vtkPoints* points = SliderXForm->GetOutput()->GetPoints();
    if (points == nullptr || points->GetNumberOfPoints() < end) return {};
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (int i = first; i < end; ++i) {
      double p[3];
      points->GetPoint(i, p);
      x0 = std::min(x0, p[0]);
      x1 = std::max(x1, p[0]);
      y0 = std::min(y0, p[1]);
      y1 = std::max(y1, p[1]);
    }
    const int left = static_cast<int>(std::floor(x0)), right = static_cast<int>(std::ceil(x1));
    const int top = height - static_cast<int>(std::ceil(y1)), bottom = height - static_cast<int>(std::floor(y0));
    return {left, top, right - left, bottom - top};
  }
};

vtkStandardNewMacro(MeasuredSlider);

// A text actor's box in window pixels (y down), as VTK's text renderer measures it.
Box text_box(vtkTextActor* actor, vtkViewport* viewport, int height) {
  if (!actor->GetVisibility() || actor->GetInput() == nullptr || actor->GetInput()[0] == '\0') return {};
  // vtkTextActor::GetBoundingBox: relative to the actor's position (viewport pixels here).
  double b[4];
  actor->GetBoundingBox(viewport, b);
  const double* at = actor->GetPosition();
  b[0] += at[0];
  b[1] += at[0];
  b[2] += at[1];
  b[3] += at[1];
  const int x0 = static_cast<int>(std::floor(b[0])), x1 = static_cast<int>(std::ceil(b[1]));
  const int y0 = height - static_cast<int>(std::ceil(b[3])), y1 = height - static_cast<int>(std::floor(b[2]));
  return {x0, y0, x1 - x0, y1 - y0};
}

ordered_json box_json(const Box& b) {
  if (b.empty()) return nullptr;
  return {{"x", b.x}, {"y", b.y}, {"w", b.w}, {"h", b.h}};
}

constexpr auto kOverlayPeriod = std::chrono::milliseconds(250);
// Quiet this long after the last key (a held key repeats faster), the viewer tidies the tree:
// the small BSPs edits wore are built anew (TerrainTree::tidy).
constexpr auto kTidyAfter = std::chrono::milliseconds(400);

// `given`, or when it is empty the first STEM-NNN.png (NNN from 001) not in the current folder.
std::filesystem::path given_or_next_free(const std::filesystem::path& given, const char* stem) {
  std::filesystem::path path = given;
  for (int k = 1; path.empty() || (given.empty() && std::filesystem::exists(path)); ++k) {
    char name[96];
    std::snprintf(name, sizeof name, "%s-%03d.png", stem, k);
    path = name;
  }
  return path;
}

class ViewerStyle;

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
  // Ctrl-click: the pick, and at once the frame that shows it in the overlay (not at the next
  // tick of the 15 ms timer: that wait was a third of the time from the click to the overlay).
  void pick(int x, int y);
  void pick_message();  // message_ from pick_ (there is one)
  void profile_pick(int x, int y);
  void mouse_move(int x, int y);
  void wheel(int clicks);
  void leave();
  void tick();
  void slider_moved();
  void request_frame() { dirty_ = true; }

 private:
  void draw_frame();
  void set_metric(mrbsp::LodMetric m);
  void set_threshold(double t);
  void sync_slider();
  void update_overlay(double agl, double speed);
  // Places the slider, legend, overlay text and key list (lay_out_overlay) for the window's
  // size and their current text, when either changed.
  void lay_out();
  void write_status(double agl, double speed, const mrbsp::Camera& camera);
  void save_screenshot();
  scene::FlightInput input() const;
  // Held now, or pressed since the last tick (so that a tap shorter than a tick still moves).
  bool held(const char* key) const { return held_.count(key) > 0 || tapped_.count(key) > 0; }
  double& threshold() { return threshold_[metric_ == mrbsp::LodMetric::kError ? 1 : 0]; }
  void volume_key(const std::string& key);
  void markers_key();
  void objects_key();
  void density_key(const std::string& key);
  void write_profile(const io::Geodetic& from, const io::Geodetic& to);
  void record_key();
  void save_path();

  ViewOptions o_;
  std::unique_ptr<render::SceneRenderer> pipeline_;  // the scene: window, tree, volumes, slides, renderer
  std::size_t selected_volume_ = 0;
  std::vector<scene::PathKey> keys_;  // recorded keyframes (K), saved by J
  Clock::time_point first_key_time_;
  double last_merge_ms_ = 0;  // the last interactive change of a volume, extraction to upload
  scene::CameraPose pose_, start_pose_;
  scene::FlightSettings flight_;
  mrbsp::LodMetric metric_;
  double threshold_[2];  // per metric, [0] area, [1] error: each keeps its own
  bool lod_colors_, wireframe_, help_ = false;
  bool dirty_ = true, screenshot_pending_ = false;
  bool dragging_ = false;
  int drag_x_ = 0, drag_y_ = 0;
  std::set<std::string> held_, tapped_;
  Clock::time_point start_, last_tick_;
  Clock::time_point last_key_;  // the last key pressed
  std::size_t tidied_slots_ = 0;  // small BSPs tidy() built anew so far

  // Figures.
  std::size_t frames_ = 0, screenshots_ = 0, key_presses_ = 0;
  double frame_ms_ = 0, traversal_ms_ = 0, upload_ms_ = 0, draw_ms_ = 0;
  double overlay_ms_ = 0;  // of the frame: the overlay's text and its layout (update_overlay, lay_out)
  std::vector<double> frame_log_, traversal_log_, draw_log_, slide_log_;  // slide_log_: this thread's part
  std::filesystem::path last_screenshot_;
  std::string message_;  // shown in the overlay (e.g. where a screenshot went)
  std::optional<render::Pick> pick_;  // the last Ctrl-click's point (status file)
  Clock::time_point pick_time_;          // when it was handled
  std::optional<double> pick_shown_ms_;  // from then to the end of the draw that first showed it
  std::optional<io::Geodetic> profile_from_;  // the first Shift-click's point, until the second
  nlohmann::ordered_json profile_status_;     // the last profile path (status file); null: none
  std::string overlay_settings_;  // the overlay's settings lines as last drawn
  bool layout_dirty_ = true;  // the text, the key list or the legend changed since lay_out()
  bool slider_dirty_ = true;  // the slider's texts changed since lay_out() placed them
  int layout_size_[2] = {0, 0};
  OverlayLayout layout_;
  double knob_lo_ = 0, knob_hi_ = 0;  // the knob's centre at the range's ends, window pixels
  Clock::time_point overlay_time_;
  bool overlay_stale_ = false;

  // VTK.
  vtkNew<vtkXRenderWindowInteractor> interactor_;
  vtkSmartPointer<ViewerStyle> style_;
  vtkNew<MeasuredSlider> slider_rep_;
  vtkNew<vtkSliderWidget> slider_;
  vtkNew<vtkCallbackCommand> slider_callback_;
  vtkNew<vtkCallbackCommand> render_callback_;
  vtkNew<vtkTextActor> overlay_, help_text_, slider_title_, slider_min_, slider_max_;
  vtkNew<vtkActor2D> slider_panel_;
  vtkNew<vtkPoints> slider_corners_;  // the panel's, normalized viewport
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
  void OnLeftButtonDown() override {
    if (this->Interactor->GetControlKey() != 0) {
      viewer_->pick(pos()[0], pos()[1]);
    } else if (this->Interactor->GetShiftKey() != 0) {
      viewer_->profile_pick(pos()[0], pos()[1]);
    } else {
      viewer_->button(true, pos()[0], pos()[1]);
    }
  }
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
      flight_(options.flight),
      metric_(options.style.traversal.metric),
      lod_colors_(options.lod_colors),
      wireframe_(options.wireframe) {
  threshold_[0] = mrbsp::default_threshold(mrbsp::LodMetric::kArea);
  threshold_[1] = mrbsp::default_threshold(mrbsp::LodMetric::kError);
  threshold() = options.style.traversal.threshold_px;

  // The scene around the camera, on screen; the camera inside the mosaic and above its ground.
  io::Mosaic mosaic = io::Mosaic::open(options.dems);
  const bool given = options.pose.has_value();
  pose_ = given ? *options.pose : scene::default_pose(mosaic);
  const bool agl = given ? options.agl : true;
  scene::SceneSpec spec;
  spec.dems = o_.dems;
  spec.volumes = o_.volumes;
  spec.objects = o_.objects;
  spec.camera = scene::SceneCamera{pose_, agl, o_.fov_y_deg};
  render::RenderSettings settings = render::render_settings(o_.style);
  settings.lod_colors = lod_colors_;
  settings.wireframe = wireframe_;
  settings.offscreen = false;
  const render::SceneOptions scene_options = render::scene_options(o_.style, o_.levels, render::Sliding::kAsynchronous);
  pipeline_ = std::make_unique<render::SceneRenderer>(std::move(mosaic), spec, settings, scene_options);
  pipeline_->set_auto_slide(options.auto_slide);
  pose_.alt = pipeline_->eye_height(pose_, agl);  // in the datum from here on
  start_pose_ = pose_;

  render::TerrainRenderer& renderer = pipeline_->renderer();
  vtkRenderWindow* win = renderer.window();
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
  // translucent panel so that it reads over sky and snow alike. lay_out() places them.
  {
    for (int k = 0; k < 4; ++k) slider_corners_->InsertNextPoint(0.0, 0.0, 0.0);
    vtkNew<vtkCellArray> quad;
    const vtkIdType ids[4] = {0, 1, 2, 3};
    quad->InsertNextCell(4, ids);
    vtkNew<vtkPolyData> rect;
    rect->SetPoints(slider_corners_);
    rect->SetPolys(quad);
    vtkNew<vtkCoordinate> normalized;
    normalized->SetCoordinateSystemToNormalizedViewport();
    vtkNew<vtkPolyDataMapper2D> mapper;
    mapper->SetInputData(rect);
    mapper->SetTransformCoordinate(normalized);
    slider_panel_->SetMapper(mapper);
    slider_panel_->GetProperty()->SetColor(0.05, 0.08, 0.12);
    slider_panel_->GetProperty()->SetOpacity(0.55);
    renderer.renderer()->AddActor2D(slider_panel_);
  }
  slider_rep_->GetPoint1Coordinate()->SetCoordinateSystemToDisplay();
  slider_rep_->GetPoint2Coordinate()->SetCoordinateSystemToDisplay();
  slider_rep_->SetTitleText("");  // slider_title_ instead, measured with the others
  slider_rep_->ShowSliderLabelOff();
  slider_rep_->GetTubeProperty()->SetColor(0.92, 0.92, 0.92);
  slider_rep_->GetCapProperty()->SetColor(0.92, 0.92, 0.92);
  slider_rep_->GetSliderProperty()->SetColor(1.0, 0.62, 0.15);
  slider_rep_->GetSelectedProperty()->SetColor(1.0, 0.85, 0.3);
  slider_->SetInteractor(interactor_);
  slider_->SetRepresentation(slider_rep_);
  slider_->SetAnimationModeToJump();
  slider_callback_->SetClientData(this);
  slider_callback_->SetCallback([](vtkObject*, unsigned long, void* self, void*) {
    static_cast<Viewer*>(self)->slider_moved();
  });
  slider_->AddObserver(vtkCommand::InteractionEvent, slider_callback_);
  slider_->EnabledOn();
  style_text(slider_title_->GetTextProperty(), 16);
  slider_title_->GetTextProperty()->SetBackgroundOpacity(0.0);  // the panel is behind it
  slider_title_->GetTextProperty()->SetVerticalJustificationToTop();
  renderer.renderer()->AddActor2D(slider_title_);
  for (vtkTextActor* end : {slider_min_.GetPointer(), slider_max_.GetPointer()}) {
    style_text(end->GetTextProperty(), 13);
    end->GetTextProperty()->BoldOff();
    end->GetTextProperty()->SetBackgroundOpacity(0.0);
    end->GetTextProperty()->SetVerticalJustificationToBottom();
    renderer.renderer()->AddActor2D(end);
  }
  slider_min_->GetTextProperty()->SetJustificationToLeft();
  slider_max_->GetTextProperty()->SetJustificationToRight();
  sync_slider();

  // The overlay, top left, and the key list, bottom left.
  style_text(overlay_->GetTextProperty(), kTextFonts[0]);
  overlay_->GetTextProperty()->SetVerticalJustificationToTop();
  renderer.renderer()->AddActor2D(overlay_);
  style_text(help_text_->GetTextProperty(), kKeyFonts[0]);
  help_text_->GetTextProperty()->SetVerticalJustificationToBottom();
  help_text_->SetInput(kViewKeys);
  help_text_->SetVisibility(help_);
  renderer.renderer()->AddActor2D(help_text_);
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
  std::printf("frames %zu: median %.1f ms (traversal %.1f ms, draw %.1f ms); slides %d", frames_,
              median(frame_log_), median(traversal_log_), median(draw_log_), pipeline_->slides());
  if (pipeline_->slides() > 0) std::printf(": median %.0f ms", median(slide_log_));
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
  ++key_presses_;
  last_key_ = Clock::now();
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
    pipeline_->renderer().set_lod_colors(lod_colors_);
  } else if (key == "t") {
    wireframe_ = !wireframe_;
    pipeline_->renderer().set_wireframe(wireframe_);
  } else if (key == "m") {
    set_metric(metric_ == mrbsp::LodMetric::kError ? mrbsp::LodMetric::kArea : mrbsp::LodMetric::kError);
  } else if (key == "g") {
    pipeline_->set_auto_slide(!pipeline_->auto_slide());
  } else if (key == "x") {
    markers_key();
  } else if (key == "b") {
    objects_key();
  } else if (key == "e" || key == "E" || key == "o" || key == "O") {
    density_key(key);
  } else if (key == "p") {
    screenshot_pending_ = true;
  } else if (key == "k") {
    record_key();
  } else if (key == "j") {
    save_path();
  } else if (key == "h") {
    help_ = !help_;
    help_text_->SetVisibility(help_);
    layout_dirty_ = true;
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

// The point under the cursor, in the overlay: where, the ground, and each visible volume's value.
void Viewer::pick(int x, int y) {
  pick_time_ = Clock::now();
  pick_shown_ms_.reset();
  pick_ = pipeline_->pick(x, y);
  if (!pick_) {
    message_ = "pick: nothing under the cursor (sky, or beyond the window)";
  } else {
    pick_message();
  }
  dirty_ = false;
  draw_frame();
}

void Viewer::pick_message() {
  const io::Geodetic& g = pick_->point.where;
  char b[256];
  std::snprintf(b, sizeof b, "pick %.5f, %.5f on the %s: ground %.1f m, %.1f m above it (%.1f ms)", g.lat, g.lon,
                pick_->point.on_surface ? "surface" : "terrain", pick_->ground, g.h - pick_->ground, pick_->ms);
  message_ = b;
  for (const scene::PointValue& v : pick_->values) {
    std::snprintf(b, sizeof b, "\n  %s: %.2f %s", v.volume.c_str(), v.value, v.units.c_str());
    message_ += b;
  }
}

// Two Shift-clicks: the first end, then the second, and the link profile between them drawn
// over the terrain and plotted (write_profile). A third starts a new path.
void Viewer::profile_pick(int x, int y) {
  dirty_ = true;
  const std::optional<render::Pick> p = pipeline_->pick(x, y);
  if (!p) {
    message_ = "profile: nothing under the cursor (sky, or beyond the window)";
    return;
  }
  const io::Geodetic at{p->point.where.lat, p->point.where.lon, p->ground};
  if (!profile_from_) {
    profile_from_ = at;
    char b[160];
    std::snprintf(b, sizeof b, "profile from %.5f, %.5f: Shift+click its other end", at.lat, at.lon);
    message_ = b;
    profile_status_ = {{"from", {{"lat", at.lat}, {"lon", at.lon}, {"ground", at.h}}}, {"to", nullptr}};
    return;
  }
  const io::Geodetic from = *std::exchange(profile_from_, std::nullopt);
  write_profile(from, at);
}

// The link from an antenna above `from` to one above `to` (ViewOptions' heights and
// frequency), as terravol profile computes it (volume::link_profile over the mosaic's samples),
// its path merged into the tree (scene::profile_path_mesh) and its plot written atomically.
void Viewer::write_profile(const io::Geodetic& from, const io::Geodetic& to) {
  const auto t0 = Clock::now();
  volume::Transmitter tx;
  tx.lat = from.lat;
  tx.lon = from.lon;
  tx.height_agl = o_.profile_tx_agl;
  tx.frequency_mhz = o_.profile_freq_mhz;
  const std::filesystem::path path = given_or_next_free(o_.profile_plot, "terravol-profile");
  try {
    const volume::LinkProfile l = pipeline_->link_profile(tx, to.lat, to.lon, o_.profile_rx_agl);
    const double profile_ms = ms_since(t0);
    const render::SceneRenderer& pipeline = *pipeline_;
    const volume::Mesh wall = scene::profile_path_mesh(
        l, from.lat, from.lon, to.lat, to.lon, pipeline.frame(),
        [&pipeline](double lat, double lon) { return pipeline.ground_height(lat, lon); });
    const double merge_ms = pipeline_->set_path(wall);
    const std::string verdict = volume::verdict(l);
    const auto t1 = Clock::now();
    output::write_png(path, output::profile_png(l, verdict, 1200, 600), true);
    const double plot_ms = ms_since(t1);
    const volume::FresnelAnalysis& f = l.fresnel;
    profile_status_ = {{"from", {{"lat", from.lat}, {"lon", from.lon}, {"ground", from.h}}},
                       {"to", {{"lat", to.lat}, {"lon", to.lon}, {"ground", to.h}}},
                       {"tx_agl", o_.profile_tx_agl},
                       {"rx_agl", o_.profile_rx_agl},
                       {"freq_mhz", o_.profile_freq_mhz},
                       {"distance_km", l.path.profile.distance_m / 1000.0},
                       {"path_loss_db", l.path.path_loss_db},
                       {"worst_clearance_m", f.worst < f.clearance_m.size() ? ordered_json(f.worst_clearance_m) : ordered_json(nullptr)},
                       {"worst_clearance_f1", f.worst < f.clearance_m.size() ? ordered_json(f.worst_clearance_f1) : ordered_json(nullptr)},
                       {"verdict", verdict},
                       {"file", path.string()},
                       {"path_triangles", wall.triangle_count()},
                       {"tree_pieces", pipeline_->terrain().tree().merge_stats().stored_polygons},
                       {"profile_ms", profile_ms},
                       {"merge_ms", merge_ms},
                       {"plot_ms", plot_ms}};
    std::string shown = verdict;
    if (const std::size_t at = shown.find("; path loss"); at != std::string::npos) shown.replace(at, 2, "\n  ");
    char b[160];
    std::snprintf(b, sizeof b, "profile %.2f km (%.0f ms): ", l.path.profile.distance_m / 1000.0, ms_since(t0));
    message_ = b + shown + "\n  wrote " + path.string();
  } catch (const std::exception& e) {
    message_ = std::string("profile failed: ") + e.what();
    profile_status_ = {{"error", e.what()}};
    std::fprintf(stderr, "terravol: %s\n", message_.c_str());
  }
}

// X: every volume's transmitter markers on or off; only their surfaces are merged again.
void Viewer::markers_key() {
  scene::VolumeLayer& volumes = pipeline_->volumes();
  const auto t0 = Clock::now();
  volumes.set_markers(!volumes.markers_shown());
  const scene::MergeFigures& merge = pipeline_->remerge();
  last_merge_ms_ = ms_since(t0);
  char b[128];
  std::snprintf(b, sizeof b, "transmitter markers %s: %.0f ms (%zu surfaces merged)", volumes.markers_shown() ? "on" : "off",
                last_merge_ms_, merge.merged_surfaces);
  message_ = b;
}

// B: the objects on or off; the next frame takes them out of the tree or merges them again.
void Viewer::objects_key() {
  scene::ObjectLayer& objects = pipeline_->objects();
  if (objects.size() == 0) {
    message_ = "no objects (give --object or a scene file's \"objects\")";
    return;
  }
  objects.set_visible(!objects.visible());
  message_ = std::string("objects ") + (objects.visible() ? "on" : "off");
}

// E, Shift+E: epsilon of the colour cubes (the next frame refines with it); O, Shift+O: the
// selected volume's density opacity, a new transfer function (its cubes built again).
void Viewer::density_key(const std::string& key) {
  scene::VolumeLayer& volumes = pipeline_->volumes();
  char b[160];
  if (key == "e" || key == "E") {
    density::RefineOptions d = pipeline_->density_options();
    d.threshold_px = std::clamp(key == "e" ? d.threshold_px / std::sqrt(2.0) : d.threshold_px * std::sqrt(2.0),
                                scene::kMinDensityThreshold, scene::kMaxDensityThreshold);
    pipeline_->set_density_options(d);
    std::snprintf(b, sizeof b, "density threshold %.2f px", d.threshold_px);
    message_ = b;
    return;
  }
  if (selected_volume_ >= volumes.size() || !volumes.spec(selected_volume_).density) {
    message_ = "volume " + std::to_string(selected_volume_ + 1) + " has no density (give --density)";
    return;
  }
  density::DensitySpec d = *volumes.spec(selected_volume_).density;
  d.sigma_per_km *= key == "o" ? std::sqrt(2.0) : 1.0 / std::sqrt(2.0);
  const auto t0 = Clock::now();
  volumes.set_density(selected_volume_, d);
  if (o_.style.legend) pipeline_->renderer().set_legend(volumes.legend());
  last_merge_ms_ = ms_since(t0);
  std::snprintf(b, sizeof b, "density opacity %.3g per km: cubes built in %.0f ms", d.sigma_per_km, last_merge_ms_);
  message_ = b;
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

void Viewer::tick() {
  // VTK's X event loop handles one event between timer checks, and a frame takes longer than
  // the timer's period: without this, events (a held key's repeats first) would queue up
  // faster than they are handled, and a key's release would come seconds late.
  Display* display = static_cast<Display*>(pipeline_->renderer().window()->GetGenericDisplayId());
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
    const render::SceneRenderer& pipeline = *pipeline_;
    pose_ = scene::fly(pose_, in, dt, pipeline.frame(),
                       [&pipeline](double lat, double lon) { return pipeline.ground_height(lat, lon); }, flight_);
    scene::clamp_near_mosaic(pipeline.mosaic(), pose_.lat, pose_.lon);
    dirty_ = true;
  }
  tapped_.clear();
  if (pipeline_->slide_ready()) dirty_ = true;
  if (overlay_stale_ && now - overlay_time_ >= kOverlayPeriod) dirty_ = true;
  if (dirty_ || screenshot_pending_) {
    dirty_ = false;
    draw_frame();
  } else if (held_.empty() && now - last_key_ >= kTidyAfter && !pipeline_->slide_pending() &&
             pipeline_->terrain().tree().merge_stats().worn_slots > 0) {
    tidied_slots_ += pipeline_->tidy().rebuilt_slots;
    dirty_ = true;  // the same image, from fewer pieces
  } else if (held_.empty() && now - last_key_ >= kTidyAfter && pipeline_->memory_to_return()) {
    pipeline_->return_memory();  // the pages slides freed, given back at rest
  }
}

// Number keys toggle (and select) a volume; [ ] move its first slice, , . its first
// isosurface. Each change re-extracts that one piece of geometry, merges all visible geometry
// into the tree again and uploads the vertices; the overlay and the status say how long it took.
void Viewer::volume_key(const std::string& key) {
  scene::VolumeLayer& volumes = pipeline_->volumes();
  if (volumes.size() == 0) {
    message_ = "no volumes (give --volume or --scene)";
    return;
  }
  const auto t0 = Clock::now();
  std::string what;
  try {
    if (key[0] >= '1' && key[0] <= '9') {
      const std::size_t v = static_cast<std::size_t>(key[0] - '1');
      if (v >= volumes.size()) {
        message_ = "there is no volume " + key;
        return;
      }
      selected_volume_ = v;
      volumes.set_visible(v, !volumes.spec(v).visible);
      what = "volume " + key + (volumes.spec(v).visible ? " shown" : " hidden");
    } else if (key == "bracketleft" || key == "bracketright") {
      const scene::VolumeSpec& spec = volumes.spec(selected_volume_);
      if (spec.slices.empty()) {
        message_ = "volume " + std::to_string(selected_volume_ + 1) + " has no slice";
        return;
      }
      volume::SliceSpec s = spec.slices.front();
      const bool degrees = s.kind == volume::SliceKind::kLat || s.kind == volume::SliceKind::kLon;
      s.value += (key == "bracketright" ? 1.0 : -1.0) * (degrees ? 0.01 : 50.0);
      volumes.set_slice(selected_volume_, 0, s);
      char b[96];
      std::snprintf(b, sizeof b, "slice %s %g%s", std::string(volume::slice_kind_name(s.kind)).c_str(), s.value,
                    degrees ? " deg" : " m");
      what = b;
    } else {
      const scene::VolumeSpec& spec = volumes.spec(selected_volume_);
      if (spec.isosurfaces.empty()) {
        message_ = "volume " + std::to_string(selected_volume_ + 1) + " has no isosurface";
        return;
      }
      volume::IsoSpec iso = spec.isosurfaces.front();
      iso.value += key == "period" ? 2.0f : -2.0f;
      volumes.set_isosurface(selected_volume_, 0, iso);
      char b[64];
      std::snprintf(b, sizeof b, "isosurface %g", static_cast<double>(iso.value));
      what = b;
    }
  } catch (const std::invalid_argument& e) {
    message_ = e.what();  // e.g. a slice moved out of its volume: nothing changed
    return;
  }
  const double geometry_ms = volumes.figures().geometry_ms;
  const scene::MergeFigures& merge = pipeline_->remerge();
  last_merge_ms_ = ms_since(t0);
  char b[160];
  std::snprintf(b, sizeof b, "%s: %.0f ms (geometry %.0f, merge %.0f)", what.c_str(), last_merge_ms_, geometry_ms,
                merge.merge_ms);
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
  slider_title_->SetInput(title.c_str());
  slider_min_->SetInput(error ? "0.25 px  finer" : "32 px^2  finer");
  slider_max_->SetInput(error ? "coarser  16 px" : "coarser  32768 px^2");
  layout_dirty_ = slider_dirty_ = true;  // the title's width changed
}

void Viewer::draw_frame() {
  const auto t0 = Clock::now();
  mrbsp::TraversalOptions traversal = o_.style.traversal;
  traversal.metric = metric_;
  traversal.threshold_px = static_cast<float>(threshold());
  const int slides = pipeline_->slides();
  // Finishes a slide read ahead, starts reading the next when the camera nears the window's
  // edge, then the camera (at the window's current size), the sky, the traversal.
  const render::FrameStats f = pipeline_->prepare(pose_, false, o_.fov_y_deg, traversal);
  if (const auto error = pipeline_->take_slide_error()) {
    std::fprintf(stderr, "terravol: %s (automatic sliding turned off)\n", error->c_str());
  }
  if (f.slides > slides) slide_log_.push_back(f.slide_ms);
  const double agl = f.eye_height - f.ground_height;
  const double speed = scene::flight_speed(agl, flight_, held("Shift_L") || held("Shift_R"));
  traversal_ms_ = f.traversal_ms;
  upload_ms_ = f.upload_ms;
  const auto overlay_t0 = Clock::now();
  update_overlay(agl, speed);
  lay_out();
  overlay_ms_ = ms_since(overlay_t0);
  draw_ms_ = pipeline_->draw();
  frame_ms_ = ms_since(t0);
  if (pick_ && !pick_shown_ms_) pick_shown_ms_ = ms_since(pick_time_);
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
  write_status(agl, speed, pipeline_->camera());
}

// The text is drawn again (FreeType, then a texture) only when a setting in it changes or a
// quarter second has passed: redrawing it every frame cost about 7 ms per frame. tick() brings
// a last frame when the camera stops, so the figures do not stay stale.
void Viewer::update_overlay(double agl, double speed) {
  const scene::WindowChoice& w = pipeline_->terrain().window();
  const render::SlideFigures& slide = pipeline_->last_slide();
  const bool error = metric_ == mrbsp::LodMetric::kError;
  char settings[512];
  std::snprintf(settings, sizeof settings,
                "LOD %s %s   colours %s   wireframe %s\n"
                "window %d cells at row %d, col %d   slides %d (last %.0f ms)   auto-slide %s\n%s",
                error ? "error" : "area", threshold_text(metric_, threshold()).c_str(), lod_colors_ ? "on" : "off",
                wireframe_ ? "on" : "off", w.cells, w.row0, w.col0, pipeline_->slides(),
                slide.tree_ms + slide.vertices_ms, pipeline_->auto_slide() ? "on" : "off",
                message_.empty() ? "H: keys" : message_.c_str());
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
                pipeline_->last_frame().indices.size() / 3, pipeline_->last_frame().nodes_visited, frame_ms_,
                traversal_ms_, draw_ms_,
                degrees(pose_.lat, 'N', 'S').c_str(), degrees(pose_.lon, 'E', 'W').c_str(), pose_.alt, agl,
                pose_.heading_deg, pose_.pitch_deg, speed);
  overlay_->SetInput((b + overlay_settings_).c_str());
  layout_dirty_ = true;
}

void Viewer::lay_out() {
  vtkRenderWindow* win = pipeline_->renderer().window();
  const int* size = win->GetSize();
  const int W = size[0], H = size[1];
  const bool resized = W != layout_size_[0] || H != layout_size_[1];
  if (!layout_dirty_ && !resized) return;
  layout_dirty_ = false;
  layout_size_[0] = W;
  layout_size_[1] = H;
  const int dpi = win->GetDPI();
  // Text measured as VTK will draw it: the actor's property at the font size tried.
  const auto measure = [dpi](vtkTextActor* actor) {
    return [actor, dpi](int font) {
      vtkNew<vtkTextProperty> p;
      p->ShallowCopy(actor->GetTextProperty());
      p->SetFontSize(font);
      int b[4] = {0, 0, 0, 0};
      vtkTextRenderer::GetInstance()->GetBoundingBox(p, actor->GetInput() ? actor->GetInput() : "", b, dpi);
      // vtkTextActor draws its background 2 px beyond the glyphs' box on every side.
      return std::array<int, 2>{b[1] - b[0] + 1 + 4, b[3] - b[2] + 1 + 4};
    };
  };
  OverlayInput in;
  in.width = W;
  in.height = H;
  in.slider_height = kSliderPanelHeight;
  in.text = measure(overlay_);
  in.keys = measure(help_text_);
  in.keys_shown = help_;
  render::TerrainRenderer& renderer = pipeline_->renderer();
  in.legend = [&renderer](int max_height) { return renderer.legend_size(max_height); };
  layout_ = lay_out_overlay(in);

  // The slider: the panel, the title at its top, the tube across its middle, the end labels
  // at its bottom; placed again only when the window's size or its texts changed (its box
  // depends on nothing else), since measuring its texts and building its representation cost
  // milliseconds that a changed overlay message need not pay.
  if (resized || slider_dirty_) {
    slider_dirty_ = false;
    const Box& sb = layout_.slider;
    const double nx0 = double(sb.x) / W, nx1 = double(sb.right()) / W;
    const double ny0 = 1.0 - double(sb.bottom()) / H, ny1 = 1.0 - double(sb.y) / H;
    slider_corners_->SetPoint(0, nx0, ny0, 0.0);
    slider_corners_->SetPoint(1, nx1, ny0, 0.0);
    slider_corners_->SetPoint(2, nx1, ny1, 0.0);
    slider_corners_->SetPoint(3, nx0, ny1, 0.0);
    slider_corners_->Modified();
    const double tube_y = H - (sb.y + kSliderTubeY);
    slider_rep_->GetPoint1Coordinate()->SetValue(sb.x + kSliderInset, tube_y);
    slider_rep_->GetPoint2Coordinate()->SetValue(sb.right() - kSliderInset, tube_y);
    // VTK sizes the slider's parts as fractions of the window: lengths of its width, widths of
    // its height (9.1), so that these are pixels.
    slider_rep_->SetEndCapLength(8.0 / W);
    slider_rep_->SetSliderLength(14.0 / W);
    slider_rep_->SetSliderWidth(28.0 / H);
    slider_rep_->SetTubeWidth(8.0 / H);
    slider_rep_->SetEndCapWidth(22.0 / H);
    // The title and the end labels at the largest size that fits the panel's width.
    const int inner = sb.w - 2 * kSliderPad;
    int title_font = 16;
    while (title_font > 7 && measure(slider_title_)(title_font)[0] > inner) --title_font;
    slider_title_->GetTextProperty()->SetFontSize(title_font);
    int end_font = 13;
    while (end_font > 6 && measure(slider_min_)(end_font)[0] + measure(slider_max_)(end_font)[0] + 12 > inner) --end_font;
    slider_min_->GetTextProperty()->SetFontSize(end_font);
    slider_max_->GetTextProperty()->SetFontSize(end_font);
    slider_title_->SetPosition(sb.x + kSliderPad, H - (sb.y + kSliderPad));
    slider_min_->SetPosition(sb.x + kSliderPad, H - (sb.bottom() - kSliderPad));
    slider_max_->SetPosition(sb.right() - kSliderPad, H - (sb.bottom() - kSliderPad));
    const double value = slider_rep_->GetValue();
    slider_rep_->SetValue(slider_rep_->GetMinimumValue());
    const auto knob_x = [&] {
      const Box k = slider_rep_->knob_box(H);
      return k.x + 0.5 * k.w;
    };
    knob_lo_ = knob_x();
    slider_rep_->SetValue(slider_rep_->GetMaximumValue());
    knob_hi_ = knob_x();
    slider_rep_->SetValue(value);
    slider_rep_->BuildRepresentation();
  }

  // The legend, the text and the key list.
  const bool legend = !layout_.legend.empty();
  renderer.place_legend(layout_.legend.right(), layout_.legend.y, legend ? layout_.legend_max_height : 0);
  overlay_->SetVisibility(!layout_.text.empty());
  overlay_->GetTextProperty()->SetFontSize(std::max(layout_.text_font, kTextFonts[1]));
  overlay_->SetPosition(layout_.text.x + 2, H - layout_.text.y - 2);
  help_text_->SetVisibility(help_ && !layout_.keys.empty());
  help_text_->GetTextProperty()->SetFontSize(std::max(layout_.keys_font, kKeyFonts[1]));
  help_text_->SetPosition(layout_.keys.x + 2, H - layout_.keys.bottom() + 2);
}

void Viewer::save_screenshot() {
  const std::filesystem::path path = given_or_next_free(o_.screenshot, "terravol-view");
  try {
    output::write_png(path, output::window_png(pipeline_->renderer().window()), true);
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
  const scene::TerrainScene& terrain = pipeline_->terrain();
  const scene::WindowChoice& w = terrain.window();
  const scene::WindowBounds b = terrain.bounds();
  const int* size = pipeline_->renderer().window()->GetSize();
  const mrbsp::Frame& frame = pipeline_->last_frame();
  const render::SlideFigures& slide = pipeline_->last_slide();
  const SliderRange r = slider_range(metric_);
  ordered_json j;
  j["frame"] = frames_;
  j["time_s"] = std::chrono::duration<double>(Clock::now() - start_).count();
  j["triangles"] = frame.indices.size() / 3;
  j["nodes_visited"] = frame.nodes_visited;
  j["threshold"] = threshold();
  j["metric"] = metric_ == mrbsp::LodMetric::kError ? "error" : "area";
  j["lod_colors"] = lod_colors_;
  j["wireframe"] = wireframe_;
  j["auto_slide"] = pipeline_->auto_slide();
  j["camera"] = {{"lat", pose_.lat},
                 {"lon", pose_.lon},
                 {"alt", pose_.alt},
                 {"agl", agl},
                 {"heading", pose_.heading_deg},
                 {"pitch", pose_.pitch_deg},
                 {"eye", {camera.eye.x, camera.eye.y, camera.eye.z}}};
  j["speed_mps"] = speed;
  j["keys_held"] = held_;
  j["key_presses"] = key_presses_;  // handled so far, bound or not
  j["frame_ms"] = frame_ms_;
  j["traversal_ms"] = traversal_ms_;
  j["upload_ms"] = upload_ms_;
  j["draw_ms"] = draw_ms_;
  j["overlay_ms"] = overlay_ms_;
  j["slides"] = pipeline_->slides();
  j["last_slide_ms"] = slide.tree_ms + slide.vertices_ms;  // this thread's part
  j["last_slide_parts_ms"] = {{"read_window", slide.read_ms},
                              {"shading", slide.shade_ms},
                              {"tree", slide.tree_ms},
                              {"vertices", slide.vertices_ms}};
  j["slide_pending"] = pipeline_->slide_pending();
  scene::VolumeLayer& volumes = pipeline_->volumes();
  j["volumes"] = ordered_json::array();
  for (std::size_t v = 0; v < volumes.size(); ++v) {
    const scene::VolumeSpec& spec = volumes.spec(v);
    ordered_json jv;
    jv["visible"] = spec.visible;
    jv["isovalues"] = ordered_json::array();
    for (const auto& iso : spec.isosurfaces) jv["isovalues"].push_back(iso.value);
    jv["slices"] = ordered_json::array();
    for (const auto& s : spec.slices) jv["slices"].push_back({{"kind", volume::slice_kind_name(s.kind)}, {"value", s.value}});
    if (spec.density) jv["density"] = density::format_density(*spec.density);
    j["volumes"].push_back(jv);
  }
  j["density_threshold"] = pipeline_->density_options().threshold_px;
  j["density_error"] = pipeline_->density_options().error_tolerance * 255.0;
  const scene::MergeFigures& merge = pipeline_->merge_figures();
  j["merged_triangles"] = merge.tree_triangles;
  j["merge"] = {{"input_triangles", merge.input_triangles},
                {"tree_triangles", merge.tree_triangles},
                {"surface_triangles", o_.style.surface_triangles},
                {"geometry_ms", merge.geometry_ms},
                {"merge_ms", merge.merge_ms},
                {"merged_surfaces", merge.merged_surfaces}};
  j["markers"] = volumes.markers_shown();
  j["objects"] = pipeline_->objects().visible();
  j["last_merge_ms"] = last_merge_ms_;
  // Small BSPs edits wore and the viewer has not yet tidied, and those it has tidied so far.
  j["worn_slots"] = pipeline_->terrain().tree().merge_stats().worn_slots;
  j["tidied_slots"] = tidied_slots_;
  j["message"] = message_;
  if (pick_) {
    const io::Geodetic& g = pick_->point.where;
    ordered_json values = ordered_json::array();
    for (const scene::PointValue& v : pick_->values) {
      values.push_back({{"volume", v.volume}, {"value", std::isfinite(v.value) ? ordered_json(v.value) : ordered_json(nullptr)}});
    }
    j["pick"] = {{"lat", g.lat},       {"lon", g.lon},       {"height", g.h},
                 {"ground", pick_->ground}, {"on_surface", pick_->point.on_surface}, {"ms", pick_->ms},
                 {"to_overlay_ms", pick_shown_ms_ ? ordered_json(*pick_shown_ms_) : ordered_json(nullptr)},
                 {"values", values}};
  }
  if (!profile_status_.is_null()) j["profile"] = profile_status_;
  // Nothing will draw another frame until something happens: no key held, no slide read
  // ahead, no overlay refresh or screenshot due, no worn small BSP left to tidy.
  j["idle"] = held_.empty() && !pipeline_->slide_pending() && !overlay_stale_ && !screenshot_pending_ && !dirty_ &&
              pipeline_->terrain().tree().merge_stats().worn_slots == 0;
  j["window"] = {{"cells", w.cells},
                 {"row0", w.row0},
                 {"col0", w.col0},
                 {"south", b.south},
                 {"north", b.north},
                 {"west", b.west},
                 {"east", b.east},
                 {"origin_lat", terrain.frame().lat0()},
                 {"origin_lon", terrain.frame().lon0()}};
  j["size"] = {size[0], size[1]};
  // The knob's centre at the range's ends and the tube's height, in window pixels from the
  // top left, as the slider's representation built them.
  j["slider"] = {{"x_min", knob_lo_},
                 {"x_max", knob_hi_},
                 {"y", layout_.slider.y + kSliderTubeY},
                 {"value", slider_rep_->GetValue()},
                 {"value_min", r.lo},
                 {"value_max", r.hi}};
  // What the overlay's parts cover as drawn, window pixels from the top left ({x, y, w, h};
  // null: not drawn): the slider is its panel with the tube, caps, knob and texts as VTK built
  // and measured them, the texts as VTK's text renderer measures them, the legend the card's
  // image where the renderer put it.
  vtkRenderer* ren = pipeline_->renderer().renderer();
  Box slider = layout_.slider;
  slider = united(slider, slider_rep_->drawn_box(size[1]));
  for (vtkTextActor* t : {slider_title_.GetPointer(), slider_min_.GetPointer(), slider_max_.GetPointer()}) {
    slider = united(slider, text_box(t, ren, size[1]));
  }
  const auto& legend_box = pipeline_->renderer().legend_box();
  j["overlay"] = {{"slider", box_json(slider)},
                  {"legend", legend_box ? box_json({(*legend_box)[0], (*legend_box)[1], (*legend_box)[2], (*legend_box)[3]})
                                        : ordered_json(nullptr)},
                  {"text", box_json(text_box(overlay_, ren, size[1]))},
                  {"keys", box_json(text_box(help_text_, ren, size[1]))},
                  {"keys_shown", help_},
                  {"text_font", layout_.text_font},
                  {"keys_font", layout_.keys_font}};
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
