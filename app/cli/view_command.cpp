// `terravol view DEM... [--camera LAT,LON,ALT,HEADING,PITCH]`: the interactive viewer
// (app/viewer/viewer.h) on an X display.
#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "app/cli/commands.h"
#include "app/cli/scene_options.h"
#include "app/render/terrain_renderer.h"
#include "app/scene/scene_file.h"
#include "app/scene/style.h"
#include "app/viewer/viewer.h"

namespace terravol::app::cli {

void add_view_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("view", "Fly over the terrain of DEM files in a window (needs an X display)");
  cmd->footer(std::string("Keys:\n") + viewer::kViewKeys);
  struct Raw {
    viewer::ViewOptions o;
    std::string camera;
    bool no_slide = false;
    std::string profile_agl = "30,10";
    SceneArgs scene;
  };
  auto raw = std::make_shared<Raw>();
  viewer::ViewOptions& o = raw->o;
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
  auto* fov = cmd->add_option("--fov", o.fov_y_deg, "Vertical field of view, degrees")->capture_default_str();
  auto* levels = cmd->add_option("--levels", o.levels, "LOD levels (default: coarsest level 8x8 cells)");
  cmd->add_option("--speed", o.flight.speed_factor,
                  "Flight speed: metres per second for each metre above the ground")
      ->capture_default_str();
  cmd->add_flag("--lod-colors", o.lod_colors, "Start with each LOD level in its own colour (key L)");
  cmd->add_flag("--wireframe", o.wireframe, "Start in wireframe (key T)");
  cmd->add_flag("--no-slide", raw->no_slide, "Start with automatic sliding of the window off (key G)");
  cmd->add_option("--status", o.status, "After every frame, write the viewer's state to this JSON file");
  cmd->add_option("--screenshot", o.screenshot,
                  "Where key P writes the view (PNG, replaced each time; default terravol-view-NNN.png here)");
  cmd->add_option("--profile-plot", o.profile_plot,
                  "Where two Shift-clicks write their link profile's plot (PNG, replaced each time; default "
                  "terravol-profile-NNN.png here)");
  cmd->add_option("--profile-agl", raw->profile_agl,
                  "TX,RX: the profile's antennas, metres above the ground at the first and second click")
      ->capture_default_str();
  cmd->add_option("--profile-freq", o.profile_freq_mhz, "The profile's frequency, MHz")->capture_default_str();
  cmd->callback([=] {
    viewer::ViewOptions& opt = raw->o;
    // The scene file first; whatever the command line gave wins.
    const scene::SceneSpec file = read_scene_args(raw->scene, opt.dems);
    opt.scene_file = raw->scene.scene;
    opt.pose = scene::resolve_camera(file, camera->count() > 0 ? &raw->camera : nullptr, fov->count() > 0, opt.agl,
                                     opt.fov_y_deg);
    opt.style = scene::resolve_style(file.style);
    opt.volumes = file.volumes;
    opt.objects = file.objects;
    opt.auto_slide = !raw->no_slide;
    scene::check_view_options(opt.fov_y_deg, opt.style, levels->count() > 0, opt.levels);
    if (!(opt.flight.speed_factor > 0.0) || !std::isfinite(opt.flight.speed_factor)) {
      throw std::invalid_argument("--speed: must be a positive number");
    }
    if (opt.agl && !opt.pose) throw std::invalid_argument("--agl needs --camera");
    {
      char comma = 0, extra = 0;
      std::istringstream in(raw->profile_agl);
      in >> opt.profile_tx_agl >> comma >> opt.profile_rx_agl;
      const bool ok = in && comma == ',' && !(in >> extra);
      const auto height = [](double h) { return h >= 0.0 && h <= 100000.0; };
      if (!ok || !height(opt.profile_tx_agl) || !height(opt.profile_rx_agl)) {
        throw std::invalid_argument("--profile-agl " + raw->profile_agl +
                                    ": expected TX,RX, metres above ground within [0, 100000]");
      }
    }
    if (!(opt.profile_freq_mhz > 0.0 && opt.profile_freq_mhz <= 100000.0)) {
      throw std::invalid_argument("--profile-freq: must be within (0, 100000] MHz");
    }
    if (!opt.profile_plot.empty()) {
      const std::filesystem::path folder = opt.profile_plot.parent_path();
      if (!folder.empty() && !std::filesystem::is_directory(folder)) {
        throw std::invalid_argument("--profile-plot " + opt.profile_plot.string() + ": folder " + folder.string() +
                                    " does not exist");
      }
    }
    render::require_x_display("view");
    viewer::run_viewer(opt);
  });
}

}  // namespace terravol::app::cli
