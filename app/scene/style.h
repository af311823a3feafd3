// The options of `terravol render`, and the parsers of its compound values. The parsers throw
// std::invalid_argument with a one-line message that names the option and the text.
#pragma once

#include <CLI/CLI.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "app/camera.h"
#include "app/scene_file.h"
#include "app/volume_layer.h"
#include "app/terrain_colors.h"
#include "app/terrain_renderer.h"
#include "mrbsp/terrain_tree.h"

namespace terravol::app {

struct RenderOptions {
  std::vector<std::filesystem::path> dems;  // files or folders, one mosaic
  CameraPose pose;
  bool agl = false;                // pose.alt is above the ground under the camera
  std::filesystem::path output;    // PNG
  double fov_y_deg = 45.0;         // vertical, (0, 180)
  RenderSettings render;           // size, order, wireframe, lod colours, background
  mrbsp::TraversalOptions traversal;
  int levels = 0;                  // 0: default_levels(window)
  int max_window = 1024;           // cells, a power of two >= 2
  ShadingOptions shading;
  double haze_km = 60.0;           // RenderSettings::haze_distance, km; 0: none
  bool force = false;              // replace existing outputs
  std::filesystem::path stats;     // JSON, optional
  std::filesystem::path export_vtp;  // optional
  std::vector<VolumeSpec> volumes;   // RF volumes and their styles
  bool legend = true;                // a colour legend when volumes are drawn
  std::size_t surface_triangles = kDefaultSurfaceTriangles;  // per isosurface or slice; 0: all
};

// The scene options `render` and `view` share: --scene, --volume, --field, --volume-frame,
// --iso, --slice, --no-legend.
struct SceneArgs {
  std::filesystem::path scene;
  std::vector<std::filesystem::path> volumes;
  std::vector<std::string> isos, slices;
  std::string volume_frame, field;
  bool no_legend = false;
};
void add_scene_options(CLI::App& cmd, SceneArgs& args);

// The scene the command line describes: the --scene file (empty without one), its DEMs
// replaced by `dems` when not empty (else `dems` gets the file's; none at all is an error),
// and its volumes joined with the --volume files: each --volume FILE (read as --field, placed
// by --volume-frame) gets the --iso and --slice styles; with no --volume, non-empty --iso or
// --slice lists replace the styles of every volume of the file. Throws std::invalid_argument
// for a bad file or bad --iso, --slice or --volume-frame text.
SceneSpec read_scene_args(const SceneArgs& args, std::vector<std::filesystem::path>& dems);

// The camera `render` and `view` start from: --camera TEXT when given (camera_text not null),
// else the scene file's camera, whose agl is or-ed into `agl` and whose field of view replaces
// `fov_y_deg` unless --fov was given; nothing when neither has one. Throws what
// parse_camera_pose throws.
std::optional<CameraPose> resolve_camera(const SceneSpec& file, const std::string* camera_text, bool fov_given,
                                         bool& agl, double& fov_y_deg);

// The LOD threshold: --threshold when given, else the scene file's, else the metric's default.
// Throws std::invalid_argument unless it is a positive finite number of pixels.
float resolve_threshold(bool given, double option, const std::optional<double>& file, mrbsp::LodMetric metric);

// Throws std::invalid_argument naming --fov, --window, --haze or --levels when the field of
// view is not within (0, 180) degrees, the window not a power of two >= 2, the haze distance
// not >= 0 km, or levels (when given) < 1.
void check_view_options(double fov_y_deg, int max_window, double haze_km, bool levels_given, int levels);

// "WxH", each 1..16384.
void parse_size(std::string_view text, int& width, int& height);
// "R,G,B", each 0..255.
Rgb parse_rgb(std::string_view option, std::string_view text);
mrbsp::LodMetric parse_metric(std::string_view text);  // error | area
DrawOrder parse_order(std::string_view text);          // bsp | zbuffer | peel | vtk | sort
const char* order_name(DrawOrder order);               // the inverse of parse_order
Tint parse_tint(std::string_view text);                // atlas | relative | grey

}  // namespace terravol::app
