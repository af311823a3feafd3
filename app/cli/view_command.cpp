// `terravol view DEM... [--camera LAT,LON,ALT,HEADING,PITCH]`: the interactive viewer
// (app/viewer.h) on an X display.
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "app/commands.h"
#include "app/scene_file.h"
#include "app/render_options.h"
#include "app/viewer.h"

namespace terravol::app {

void add_view_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("view", "Fly over the terrain of DEM files in a window (needs an X display)");
  cmd->footer(std::string("Keys:\n") + kViewKeys);
  struct Raw {
    ViewOptions o;
    std::string camera, size = "1280x720", metric = "error", tint = "atlas";
    double threshold = 0.0;
    bool no_slide = false;
    SceneArgs scene;
  };
  auto raw = std::make_shared<Raw>();
  ViewOptions& o = raw->o;
  cmd->add_option("dems", o.dems, "DEM files or folders of tiles (one mosaic); default: the scene file's");
  add_scene_options(*cmd, raw->scene);
  cmd->add_option("--record", o.record,
                  "Where key J saves the keyframes recorded with key K, as a camera path for terravol fly "
                  "(default terravol-path.json here; replaced each time)");
  auto* camera = cmd->add_option("--camera", raw->camera,
                  "LAT,LON,ALT,HEADING,PITCH: degrees, metres (in the DEM's datum; above ground with --agl), "
                  "heading clockwise from north, pitch above the horizon (default: 1500 m above the "
                  "mosaic's centre, looking north)");
  cmd->add_flag("--agl", o.agl, "ALT is metres above the ground under the camera");
  auto* size = cmd->add_option("--size", raw->size, "Window size WIDTHxHEIGHT, pixels")->capture_default_str();
  auto* fov = cmd->add_option("--fov", o.fov_y_deg, "Vertical field of view, degrees")->capture_default_str();
  auto* metric = cmd->add_option("--lod-metric", raw->metric, "LOD metric at the start: error or area (key M switches)")
      ->capture_default_str();
  auto* threshold = cmd->add_option("--threshold", raw->threshold,
                                    "LOD threshold at the start: pixels of screen-space error (default 2) or, "
                                    "with --lod-metric area, square pixels (default 500)");
  auto* levels = cmd->add_option("--levels", o.levels, "LOD levels (default: coarsest level 8x8 cells)");
  auto* window = cmd->add_option("--window", o.max_window, "Largest window side, cells (a power of two)")->capture_default_str();
  cmd->add_option("--speed", o.flight.speed_factor,
                  "Flight speed: metres per second for each metre above the ground")
      ->capture_default_str();
  cmd->add_flag("--lod-colors", o.lod_colors, "Start with each LOD level in its own colour (key L)");
  cmd->add_flag("--wireframe", o.wireframe, "Start in wireframe (key T)");
  cmd->add_flag("--no-slide", raw->no_slide, "Start with automatic sliding of the window off (key G)");
  auto* haze = cmd->add_option("--haze", o.haze_km, "Aerial perspective: distance (km) at which 63% of the colour fades; 0: none")
      ->capture_default_str();
  auto* tint = cmd->add_option("--tint", raw->tint, "Terrain tint: atlas, relative (stretched to the window) or grey")
      ->capture_default_str();
  cmd->add_option("--status", o.status, "After every frame, write the viewer's state to this JSON file");
  cmd->add_option("--screenshot", o.screenshot,
                  "Where key P writes the view (PNG, replaced each time; default terravol-view-NNN.png here)");
  cmd->callback([=] {
    ViewOptions& opt = raw->o;
    // The scene file first; whatever the command line gave wins.
    const SceneSpec file = read_scene_args(raw->scene, opt.dems);
    opt.scene_file = raw->scene.scene;
    const SceneStyle& st = file.style;
    opt.pose = resolve_camera(file, camera->count() > 0 ? &raw->camera : nullptr, fov->count() > 0, opt.agl,
                              opt.fov_y_deg);
    if (size->count() == 0 && st.width) raw->size = std::to_string(*st.width) + "x" + std::to_string(*st.height);
    if (metric->count() == 0 && st.lod_metric) raw->metric = *st.lod_metric;
    if (tint->count() == 0 && st.tint) raw->tint = *st.tint;
    if (window->count() == 0 && st.window) opt.max_window = *st.window;
    if (haze->count() == 0 && st.haze_km) opt.haze_km = *st.haze_km;
    opt.legend = !raw->scene.no_legend && st.legend.value_or(true);
    opt.volumes = file.volumes;
    parse_size(raw->size, opt.width, opt.height);
    opt.traversal.metric = parse_metric(raw->metric);
    opt.shading.tint = parse_tint(raw->tint);
    opt.auto_slide = !raw->no_slide;
    opt.traversal.threshold_px = resolve_threshold(threshold->count() > 0, raw->threshold, st.threshold, opt.traversal.metric);
    check_view_options(opt.fov_y_deg, opt.max_window, opt.haze_km, levels->count() > 0, opt.levels);
    if (!(opt.flight.speed_factor > 0.0) || !std::isfinite(opt.flight.speed_factor)) {
      throw std::invalid_argument("--speed: must be a positive number");
    }
    if (opt.agl && !opt.pose) throw std::invalid_argument("--agl needs --camera");
    run_viewer(opt);
  });
}

}  // namespace terravol::app
