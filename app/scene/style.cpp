#include "app/render_options.h"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>

namespace terravol::app {

namespace {

// A whole decimal integer in [lo, hi], or nullopt-like failure through `ok`.
bool parse_int(std::string_view text, int lo, int hi, int& out) {
  int v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) return false;
  if (v < lo || v > hi) return false;
  out = v;
  return true;
}

std::string quote(std::string_view option, std::string_view text) {
  return std::string(option) + " " + std::string(text) + ": ";
}

}  // namespace

std::optional<CameraPose> resolve_camera(const SceneSpec& file, const std::string* camera_text, bool fov_given,
                                         bool& agl, double& fov_y_deg) {
  if (camera_text != nullptr) return parse_camera_pose(*camera_text);
  if (!file.camera) return std::nullopt;
  agl = agl || file.camera->agl;
  if (!fov_given) fov_y_deg = file.camera->fov_y_deg;
  return file.camera->pose;
}

float resolve_threshold(bool given, double option, const std::optional<double>& file, mrbsp::LodMetric metric) {
  const double t = given ? option : file ? *file : mrbsp::default_threshold(metric);
  if (!(t > 0.0) || !std::isfinite(t)) {
    throw std::invalid_argument("--threshold " + std::to_string(t) + ": must be a positive number of pixels");
  }
  return static_cast<float>(t);
}

void check_view_options(double fov_y_deg, int max_window, double haze_km, bool levels_given, int levels) {
  if (!(fov_y_deg > 0.0 && fov_y_deg < 180.0)) {
    throw std::invalid_argument("--fov " + std::to_string(fov_y_deg) + ": must be within (0, 180) degrees");
  }
  if (max_window < 2 || (max_window & (max_window - 1)) != 0) {
    throw std::invalid_argument("--window " + std::to_string(max_window) + ": must be a power of two >= 2");
  }
  if (!(haze_km >= 0.0) || !std::isfinite(haze_km)) throw std::invalid_argument("--haze: must be a distance >= 0 km");
  if (levels_given && levels < 1) throw std::invalid_argument("--levels " + std::to_string(levels) + ": must be >= 1");
}

void parse_size(std::string_view text, int& width, int& height) {
  const std::size_t x = text.find('x');
  int w = 0, h = 0;
  if (x == std::string_view::npos || !parse_int(text.substr(0, x), 1, 16384, w) ||
      !parse_int(text.substr(x + 1), 1, 16384, h)) {
    throw std::invalid_argument(quote("--size", text) + "expected WIDTHxHEIGHT in pixels, each 1..16384, e.g. 1280x720");
  }
  width = w;
  height = h;
}

Rgb parse_rgb(std::string_view option, std::string_view text) {
  Rgb c{};
  std::size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const std::size_t comma = k < 2 ? text.find(',', start) : text.size();
    int v = 0;
    if (comma == std::string_view::npos || !parse_int(text.substr(start, comma - start), 0, 255, v)) {
      throw std::invalid_argument(quote(option, text) + "expected R,G,B with each 0..255, e.g. 255,0,255");
    }
    c[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(v);
    start = comma + 1;
  }
  return c;
}

mrbsp::LodMetric parse_metric(std::string_view text) {
  if (text == "error") return mrbsp::LodMetric::kError;
  if (text == "area") return mrbsp::LodMetric::kArea;
  throw std::invalid_argument(quote("--lod-metric", text) + "unknown metric (expected error or area)");
}

DrawOrder parse_order(std::string_view text) {
  if (text == "bsp") return DrawOrder::kBsp;
  if (text == "zbuffer") return DrawOrder::kZBuffer;
  if (text == "peel") return DrawOrder::kPeel;
  if (text == "vtk") return DrawOrder::kVtk;
  if (text == "sort") return DrawOrder::kSort;
  throw std::invalid_argument(quote("--order", text) + "unknown order (expected bsp, zbuffer, peel, vtk or sort)");
}

const char* order_name(DrawOrder order) {
  switch (order) {
    case DrawOrder::kBsp: return "bsp";
    case DrawOrder::kZBuffer: return "zbuffer";
    case DrawOrder::kPeel: return "peel";
    case DrawOrder::kVtk: return "vtk";
    case DrawOrder::kSort: return "sort";
  }
  return "?";
}

void add_scene_options(CLI::App& cmd, SceneArgs& args) {
  cmd.add_option("--scene", args.scene,
                 "Scene file (JSON: dem, volumes, camera, render; docs/scene-file.md); options given here override it");
  cmd.add_option("--volume", args.volumes, "RF volume (.vdb, .vti, .vtk) to draw over the terrain; repeatable");
  cmd.add_option("--field", args.field, "The --volume files' grid or array (default: the first)");
  cmd.add_option("--volume-frame", args.volume_frame,
                 "Where the --volume files lie when they do not say: geographic, geographic-agl or enu:LAT,LON,H");
  cmd.add_option("--iso", args.isos,
                 "Isosurface VALUE[,color=R:G:B][,opacity=A] of every --volume (of the scene file's volumes when "
                 "no --volume is given); repeatable");
  cmd.add_option("--slice", args.slices,
                 "Slice lat|lon|alt|agl=VALUE[,colormap=NAME][,opacity=A][,range=LO:HI] of every --volume (as --iso); "
                 "repeatable");
  cmd.add_flag("--no-legend", args.no_legend, "No colour legend for the volumes");
}

SceneSpec read_scene_args(const SceneArgs& args, std::vector<std::filesystem::path>& dems) {
  SceneSpec scene;
  if (!args.scene.empty()) scene = load_scene_file(args.scene);
  if (dems.empty()) dems = scene.dems;
  if (dems.empty()) throw std::invalid_argument("no DEM: give DEM files or a scene file with \"dem\"");
  scene.dems = dems;
  const std::string& frame = args.volume_frame;
  if (!frame.empty()) {
    try {
      volume::parse_frame(frame);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(quote("--volume-frame", frame) + e.what());
    }
  }
  std::vector<volume::IsoSpec> iso_specs;
  for (std::size_t k = 0; k < args.isos.size(); ++k) iso_specs.push_back(volume::parse_isosurface(args.isos[k], k));
  std::vector<volume::SliceSpec> slice_specs;
  for (const auto& text : args.slices) slice_specs.push_back(volume::parse_slice(text));
  if (args.volumes.empty()) {
    for (VolumeSpec& v : scene.volumes) {
      if (!iso_specs.empty()) v.isosurfaces = iso_specs;
      if (!slice_specs.empty()) v.slices = slice_specs;
    }
    return scene;
  }
  for (const auto& f : args.volumes) {
    VolumeSpec v;
    v.file = f;
    v.field = args.field;
    v.frame = frame;
    v.isosurfaces = iso_specs;
    v.slices = slice_specs;
    scene.volumes.push_back(std::move(v));
  }
  return scene;
}

Tint parse_tint(std::string_view text) {
  if (text == "atlas") return Tint::kAtlas;
  if (text == "relative") return Tint::kRelative;
  if (text == "grey" || text == "gray") return Tint::kGrey;
  throw std::invalid_argument(quote("--tint", text) + "unknown tint (expected atlas, relative or grey)");
}

}  // namespace terravol::app
