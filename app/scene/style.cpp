#include "app/scene/style.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <tuple>

#include "app/scene/scene_file.h"

namespace terravol::app::scene {

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

// Every key of SceneStyle, once: what overlay() takes from each source.
constexpr auto kStyleKeys =
    std::make_tuple(&SceneStyle::width, &SceneStyle::height, &SceneStyle::threshold, &SceneStyle::lod_metric,
                    &SceneStyle::order, &SceneStyle::tint, &SceneStyle::window, &SceneStyle::haze_km,
                    &SceneStyle::sun_azimuth, &SceneStyle::sun_elevation, &SceneStyle::legend, &SceneStyle::markers,
                    &SceneStyle::surface_triangles, &SceneStyle::occlusion, &SceneStyle::coherence,
                    &SceneStyle::density_threshold, &SceneStyle::density_error);

}  // namespace

SceneStyle overlay(const SceneStyle& file, const SceneStyle& given) {
  SceneStyle s = file;
  std::apply([&](auto... key) { ((given.*key ? void(s.*key = given.*key) : void()), ...); }, kStyleKeys);
  return s;
}

Style resolve_style(const SceneStyle& s) {
  Style r;
  if (s.width) r.width = *s.width;
  if (s.height) r.height = *s.height;
  if (s.lod_metric) r.traversal.metric = parse_metric(*s.lod_metric);
  r.traversal.threshold_px = resolve_threshold(s.threshold.has_value(), s.threshold.value_or(0.0), std::nullopt,
                                               r.traversal.metric);
  if (s.order) r.order = parse_order(*s.order);
  if (s.tint) r.shading.tint = parse_tint(*s.tint);
  if (s.window) r.window = *s.window;
  if (s.haze_km) r.haze_km = *s.haze_km;
  if (s.sun_azimuth) r.shading.sun_azimuth_deg = *s.sun_azimuth;
  if (s.sun_elevation) r.shading.sun_elevation_deg = *s.sun_elevation;
  if (s.legend) r.legend = *s.legend;
  if (s.markers) r.markers = *s.markers;
  if (s.surface_triangles) r.surface_triangles = *s.surface_triangles;
  if (s.occlusion) r.traversal.occlusion = parse_on_off("--occlusion", *s.occlusion);
  if (s.coherence) r.traversal.coherence = parse_coherence(*s.coherence);
  if (s.density_threshold) {
    const double t = *s.density_threshold;
    if (!(t >= kMinDensityThreshold && t <= kMaxDensityThreshold)) {
      char b[128];
      std::snprintf(b, sizeof b, "--density-threshold %g: expected pixels within [%g, %g]", t, kMinDensityThreshold,
                    kMaxDensityThreshold);
      throw std::invalid_argument(b);
    }
    r.density_threshold = t;
  }
  if (s.density_error) {
    const double e = *s.density_error;
    if (!(e >= 0.0 && e <= kMaxDensityError)) {
      char b[128];
      std::snprintf(b, sizeof b, "--density-error %g: expected levels within [0, %g]", e, kMaxDensityError);
      throw std::invalid_argument(b);
    }
    r.density_error = e;
  }
  return r;
}

bool parse_on_off(std::string_view option, std::string_view text) {
  if (text == "on") return true;
  if (text == "off") return false;
  throw std::invalid_argument(quote(option, text) + "expected on or off");
}

Engine parse_engine(std::string_view text) {
  if (text == "vtk") return Engine::kVtk;
  if (text == "tiler") return Engine::kTiler;
  throw std::invalid_argument(quote("--renderer", text) + "unknown renderer (expected vtk or tiler)");
}

const char* engine_name(Engine engine) { return engine == Engine::kTiler ? "tiler" : "vtk"; }

int parse_aa(std::string_view text) {
  if (text == "1") return 1;
  if (text == "2") return 2;
  if (text == "4") return 4;
  if (text == "8") return 8;
  throw std::invalid_argument(quote("--aa", text) + "expected 1, 2, 4 or 8 (samples per pixel per axis)");
}

mrbsp::Coherence parse_coherence(std::string_view text) {
  if (text == "off") return mrbsp::Coherence::kOff;
  if (text == "update") return mrbsp::Coherence::kUpdate;
  if (text == "conservative") return mrbsp::Coherence::kConservative;
  throw std::invalid_argument(quote("--coherence", text) + "expected off, update or conservative");
}

const char* coherence_name(mrbsp::Coherence coherence) {
  switch (coherence) {
    case mrbsp::Coherence::kUpdate: return "update";
    case mrbsp::Coherence::kConservative: return "conservative";
    case mrbsp::Coherence::kOff: break;
  }
  return "off";
}

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

void check_view_options(double fov_y_deg, const Style& style, bool levels_given, int levels) {
  if (!(fov_y_deg > 0.0 && fov_y_deg < 180.0)) {
    throw std::invalid_argument("--fov " + std::to_string(fov_y_deg) + ": must be within (0, 180) degrees");
  }
  const int window = style.window;
  if (window < 2 || (window & (window - 1)) != 0) {
    throw std::invalid_argument("--window " + std::to_string(window) + ": must be a power of two >= 2");
  }
  if (!(style.haze_km >= 0.0) || !std::isfinite(style.haze_km)) {
    throw std::invalid_argument("--haze: must be a distance >= 0 km");
  }
  if (levels_given && levels < 1) throw std::invalid_argument("--levels " + std::to_string(levels) + ": must be >= 1");
  const double sun = style.shading.sun_elevation_deg;
  if (!(sun > 0.0 && sun <= 90.0)) throw std::invalid_argument("--sun-elevation: must be within (0, 90] degrees");
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

const char* metric_name(mrbsp::LodMetric metric) { return metric == mrbsp::LodMetric::kError ? "error" : "area"; }

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

Tint parse_tint(std::string_view text) {
  if (text == "atlas") return Tint::kAtlas;
  if (text == "relative") return Tint::kRelative;
  if (text == "grey" || text == "gray") return Tint::kGrey;
  throw std::invalid_argument(quote("--tint", text) + "unknown tint (expected atlas, relative or grey)");
}

const char* tint_name(Tint tint) {
  switch (tint) {
    case Tint::kAtlas: return "atlas";
    case Tint::kRelative: return "relative";
    case Tint::kGrey: return "grey";
  }
  return "?";
}

}  // namespace terravol::app::scene
