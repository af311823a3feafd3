// `terravol view`: the interactive viewer. An on-screen VTK window over the terrain of a DEM
// mosaic, drawn by the scene pipeline (app/render/scene_renderer.h) through the MRBSP tree in
// back-to-front order, with flight controls, an LOD threshold slider, a text overlay, and a
// window that slides over the mosaic with the camera, read ahead on a worker thread (Wiley et
// al. 1997, section 4.3). Key bindings: kViewKeys.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "app/scene/camera.h"
#include "app/scene/flight.h"
#include "app/scene/scene_file.h"
#include "app/scene/style.h"

namespace terravol::app::viewer {

struct ViewOptions {
  std::vector<std::filesystem::path> dems;  // files or folders, one mosaic
  std::optional<scene::CameraPose> pose;    // none: scene::default_pose (above the mosaic's centre)
  bool agl = false;                         // pose->alt is above the ground under the camera
  double fov_y_deg = 45.0;                  // vertical, (0, 180)
  // The scene file's style overridden by the options: the window's size, the LOD metric and
  // threshold at the start, the draw order, shading, window, haze, legend and the volumes'
  // triangle budget.
  scene::Style style;
  int levels = 0;                           // 0: default_levels(window)
  scene::FlightSettings flight;             // speed_factor from --speed
  bool lod_colors = false, wireframe = false;
  bool auto_slide = true;
  // After every rendered frame, a small JSON of the viewer's state (written to a temporary
  // name and renamed); empty: none.
  std::filesystem::path status;
  std::vector<scene::VolumeSpec> volumes;  // RF volumes and their styles
  std::vector<scene::ObjectSpec> objects;  // models placed on the terrain (--object, the scene file's)
  std::filesystem::path scene_file;  // the --scene file, if any (a recorded path refers to it)
  // Where the save-path key writes the recorded keyframes (a camera path for terravol fly,
  // atomically, replaced each time); empty: terravol-path.json in the current folder.
  std::filesystem::path record;
  // Where the screenshot key writes (replaced each time, atomically); empty: the next free
  // terravol-view-NNN.png in the current folder.
  std::filesystem::path screenshot;
  // The profile path (two Shift-clicks): its plot (terravol profile's, PNG, atomically, replaced
  // each time); empty: the next free terravol-profile-NNN.png in the current folder. The link
  // goes from an antenna profile_tx_agl metres above the first point to one profile_rx_agl
  // above the second, at profile_freq_mhz, through the built-in model (Deygout, k = 4/3).
  std::filesystem::path profile_plot;
  double profile_tx_agl = 30.0, profile_rx_agl = 10.0;  // [0, 100000] m
  double profile_freq_mhz = 900.0;                      // (0, 100000]
};

// The key bindings, one per line, for --help and the overlay's help panel.
extern const char* const kViewKeys;

// Opens the window and runs until the quit key (or the window is closed). Prints a timing
// summary on stdout at the end. Throws std::runtime_error (one line) for a camera outside the
// mosaic or under the ground, or without an X display; io::FormatError from the DEMs.
void run_viewer(const ViewOptions& options);

}  // namespace terravol::app::viewer
