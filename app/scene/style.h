// How a scene is drawn, as a scene file's "render" object and the command line both name it:
// the draw orders, the parsers of the options' compound values, and the one table of which
// source wins (an option given on the command line, else the scene file, else the default),
// shared by every command that reads a scene (render, view, fly). No VTK and no CLI11 here.
// The parsers throw std::invalid_argument with a one-line message that names the option and
// the text.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "app/scene/camera.h"
#include "app/scene/terrain_colors.h"
#include "mrbsp/terrain_tree.h"

namespace terravol::app::scene {

struct SceneSpec;

enum class DrawOrder : std::uint8_t {
  kBsp,      // the tree's back-to-front order, depth test off (OrderedPolyDataMapper)
  kZBuffer,  // the same triangles in the same order, vtkPolyDataMapper with the depth test on
  // The references for translucency, all with the terrain opaque and depth-tested and the
  // merged triangles of the same frame in a second, translucent actor:
  kPeel,  // VTK's depth peeling, occlusion ratio 0; with no limit on peels (the default): exact
  kVtk,   // VTK 9.1's default translucent pass: weighted blended order-independent
          // translucency (McGuire and Bavoil 2013), depth test on
  kSort,  // vtkDepthSortPolyData (cells by centre, back to front), then plain alpha blending
};

// What draws an export (render, fly --renderer): VTK, or the coverage-mask tiler (tiler/,
// Greene 1996: the tree's front-to-back order tiled in software with aa x aa samples a pixel).
enum class Engine : std::uint8_t { kVtk, kTiler };

// Isosurfaces are reduced to this many triangles each before merging (0: all); slices never.
inline constexpr std::size_t kDefaultSurfaceTriangles = 12000;

// Densities (density/octree.h): a colour cube is drawn as its faces when its largest side spans
// fewer than this many pixels (epsilon; Chamberlain et al.'s cubes "project to no more than a
// pixel"); the range the options, the scene file and the viewer's keys accept.
inline constexpr double kDefaultDensityThreshold = 1.0;
inline constexpr double kMinDensityThreshold = 0.25, kMaxDensityThreshold = 64.0;
// Densities: a colour cube whose faces stand for its contents within this many 1/255 levels
// (premultiplied; density::RefineOptions::error_tolerance) is also drawn whole while it spans
// fewer than 32 pixels (density::RefineOptions::max_size_px); 0 turns that off (Chamberlain's
// projected size alone).
inline constexpr double kDefaultDensityError = 1.0;
inline constexpr double kMaxDensityError = 64.0;

// The "render" object of a scene file (docs/scene-file.md), or what a command line gave: every
// key optional; what is absent is decided by the next source (overlay) or the default
// (resolve_style). Names (metric, order, tint) as the options spell them.
struct SceneStyle {
  std::optional<int> width, height;
  std::optional<double> threshold;
  std::optional<std::string> lod_metric, order, tint;
  std::optional<int> window;
  std::optional<double> haze_km, sun_azimuth, sun_elevation;
  std::optional<bool> legend, markers;
  std::optional<std::size_t> surface_triangles;
  std::optional<std::string> occlusion, coherence;
  std::optional<double> density_threshold, density_error;
};

// A style with every key decided.
struct Style {
  int width = 1280, height = 720;   // pixels
  mrbsp::TraversalOptions traversal;  // metric and threshold (pixels, or square pixels for area)
  DrawOrder order = DrawOrder::kBsp;
  ShadingOptions shading;           // tint and sun
  int window = 1024;                // largest window side, cells, a power of two
  double haze_km = 60.0;            // 0: none
  bool legend = true;               // a colour legend when volumes are drawn
  bool markers = true;              // a marker at each transmitter a volume records
  std::size_t surface_triangles = kDefaultSurfaceTriangles;  // per isosurface; 0: all
  double density_threshold = kDefaultDensityThreshold;        // pixels (epsilon)
  double density_error = kDefaultDensityError;                // 1/255 levels, premultiplied; 0: off
  // traversal.occlusion and traversal.coherence come from "occlusion" (on | off, default off)
  // and "coherence" (off | update | conservative, default off).
};

// The precedence table, in one place: every key set in `given` (the command line) wins over the
// same key of `file` (the scene file); a key set in neither stays unset.
SceneStyle overlay(const SceneStyle& file, const SceneStyle& given);

// Every key of `style` decided: its value, else Style's default (the threshold's default is
// the metric's, mrbsp::default_threshold). Throws std::invalid_argument naming the option for a
// name that does not parse or a threshold that is not a positive finite number of pixels.
Style resolve_style(const SceneStyle& style);

// The camera a command starts from: --camera TEXT when given (camera_text not null), else the
// scene file's camera, whose agl is or-ed into `agl` and whose field of view replaces
// `fov_y_deg` unless --fov was given; nothing when neither has one. Throws what
// parse_camera_pose throws.
std::optional<CameraPose> resolve_camera(const SceneSpec& file, const std::string* camera_text, bool fov_given,
                                         bool& agl, double& fov_y_deg);

// The LOD threshold: --threshold when given, else the scene file's, else the metric's default.
// Throws std::invalid_argument unless it is a positive finite number of pixels.
float resolve_threshold(bool given, double option, const std::optional<double>& file, mrbsp::LodMetric metric);

// Throws std::invalid_argument naming --fov, --window, --haze, --levels or --sun-elevation
// when the field of view is not within (0, 180) degrees, the window not a power of two >= 2,
// the haze distance not >= 0 km, levels (when given) < 1, or the sun's elevation not within
// (0, 90] degrees.
void check_view_options(double fov_y_deg, const Style& style, bool levels_given, int levels);

// "WxH", each 1..16384.
void parse_size(std::string_view text, int& width, int& height);
// "R,G,B", each 0..255.
Rgb parse_rgb(std::string_view option, std::string_view text);
mrbsp::LodMetric parse_metric(std::string_view text);  // error | area
const char* metric_name(mrbsp::LodMetric metric);      // the inverse of parse_metric
DrawOrder parse_order(std::string_view text);          // bsp | zbuffer | peel | vtk | sort
const char* order_name(DrawOrder order);               // the inverse of parse_order
Tint parse_tint(std::string_view text);                // atlas | relative | grey
const char* tint_name(Tint tint);                      // the inverse of parse_tint ("grey")
bool parse_on_off(std::string_view option, std::string_view text);  // on | off
mrbsp::Coherence parse_coherence(std::string_view text);             // off | update | conservative
const char* coherence_name(mrbsp::Coherence coherence);              // the inverse of parse_coherence
Engine parse_engine(std::string_view text);            // --renderer: vtk | tiler
const char* engine_name(Engine engine);                // the inverse of parse_engine
int parse_aa(std::string_view text);                   // --aa: 1 | 2 | 4 | 8 (samples per pixel per axis)

}  // namespace terravol::app::scene
