// The options of the commands that read a scene (render, view): --scene and the volumes, and
// one option per key of the scene file's "render" object, which overrides that key
// (scene::overlay, app/scene/style.h). The parsers behind them are in app/scene/style.h.
#pragma once

#include <CLI/CLI.hpp>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "app/scene/scene_file.h"
#include "app/scene/style.h"
#include "tiler/renderer.h"

namespace terravol::app::cli {

// The style options as given: --size, --lod-metric, --threshold, --order, --tint, --window,
// --haze, --sun-azimuth, --sun-elevation, --surface-triangles, --occlusion, --coherence, --density-threshold,
// --density-error. The values start at
// scene::Style's defaults (shown in --help); only the options given count (given_style).
struct StyleArgs {
  std::string size, metric, order, tint, occlusion, coherence;
  double threshold = 0.0, haze_km = 0.0, sun_azimuth = 0.0, sun_elevation = 0.0, density_threshold = 0.0, density_error = 0.0;
  int window = 0;
  std::size_t surface_triangles = 0;
  CLI::Option *size_option = nullptr, *metric_option = nullptr, *threshold_option = nullptr,
              *order_option = nullptr, *tint_option = nullptr, *window_option = nullptr, *haze_option = nullptr,
              *sun_azimuth_option = nullptr, *sun_elevation_option = nullptr, *surface_option = nullptr,
              *occlusion_option = nullptr, *coherence_option = nullptr, *density_threshold_option = nullptr, *density_error_option = nullptr;
};

// The scene options: --scene, --volume, --field, --volume-frame, --iso, --slice, --density,
// --object, --no-legend and the style options.
struct SceneArgs {
  std::filesystem::path scene;
  std::vector<std::filesystem::path> volumes;
  std::vector<std::string> isos, slices, objects;
  std::string density;  // --density text; empty: none given
  std::string volume_frame, field;
  bool no_legend = false, no_markers = false;
  StyleArgs style;
};
void add_scene_options(CLI::App& cmd, SceneArgs& args);
// --object FILE@LAT,LON,AGL[,heading=..][,pitch=..][,roll=..][,scale=..][,opacity=..][,up=y|z]
// (render, view and fly share it).
CLI::Option* add_object_option(CLI::App& cmd, std::vector<std::string>& objects);
// --density RANGE...: render, view and fly share its help (docs/scene-file.md, "density").
CLI::Option* add_density_option(CLI::App& cmd, std::string& density);
// --density-threshold PIXELS (epsilon of the colour cubes).
CLI::Option* add_density_threshold_option(CLI::App& cmd, double& threshold);
// --density-error LEVELS (the colour cubes' error tolerance, 1/255 levels).
CLI::Option* add_density_error_option(CLI::App& cmd, double& levels);
// The scene objects of --object texts (scene::parse_object; the files are read later).
std::vector<scene::ObjectSpec> parse_objects(const std::vector<std::string>& texts);

// --renderer vtk|tiler, --aa 1|2|4|8 and --texel-rate, as given (render and fly share them).
struct RendererArgs {
  std::string renderer = "vtk", aa = "8";
  double texel_rate = tiler::Settings{}.texel_rate;
  CLI::Option* aa_option = nullptr;
  CLI::Option* texel_rate_option = nullptr;
};
void add_renderer_options(CLI::App& cmd, RendererArgs& args);
// What they name. Throws std::invalid_argument (one line naming the option and the text) for a
// bad value (a --texel-rate that is negative or not finite), or --aa or --texel-rate given
// without --renderer tiler.
struct RendererChoice {
  scene::Engine engine = scene::Engine::kVtk;
  int aa = 8;
  double texel_rate = tiler::Settings{}.texel_rate;  // tiler::Settings::texel_rate
};
RendererChoice resolve_renderer(const RendererArgs& args);
// With the tiler: throws std::invalid_argument naming --size and --aa unless width * aa and
// height * aa are at most 16384 samples (its pyramid's limit).
void check_tiler_size(const RendererChoice& choice, int width, int height);

// The style keys the command line gave: each style option given, and legend false with
// --no-legend. Throws std::invalid_argument for a bad --size.
scene::SceneStyle given_style(const SceneArgs& args);

// The scene the command line describes: the --scene file (empty without one), its DEMs
// replaced by `dems` when not empty (else `dems` gets the file's; none at all is an error),
// its style overlaid with given_style (the options win), and its volumes joined with the
// --volume files: each --volume FILE (read as --field, placed by --volume-frame) gets the
// --iso, --slice and --density styles; with no --volume, non-empty --iso or --slice lists, or
// a --density, replace the styles of every volume of the file; each --object
// (scene::parse_object) joins the file's objects. A level without a colour takes the palette's
// colour of its place among every volume's (volume v's level k is the (v * levels + k)-th), so
// that the same level of two volumes differs. Throws std::invalid_argument for a bad file
// or bad --iso, --slice, --density, --object, --volume-frame or --size text, and when --iso,
// --slice, --density, --field or --volume-frame is given with no volume to style (no --volume
// and none in the scene file).
scene::SceneSpec read_scene_args(const SceneArgs& args, std::vector<std::filesystem::path>& dems);

}  // namespace terravol::app::cli
