// What the benchmark suites share (bench/suites.cpp, bench/lowalt_suite.cpp): the pipeline's
// settings and options for a benchmark scene, and the frame time they report.
#pragma once

#include <cmath>
#include <string>

#include "app/render/scene_renderer.h"
#include "bench/scenes.h"
#include "bench/suites.h"

namespace terravol::bench {

// A line of progress, to the configuration's log if any.
inline void say(const BenchConfig& c, const std::string& line) {
  if (c.log) c.log(line);
}

// The renderer's settings of every suite: the configured size, one uniform background colour
// (so that images of different pipelines compare), no haze.
inline app::render::RenderSettings plain_settings(const BenchConfig& c) {
  app::render::RenderSettings s;
  s.width = c.width;
  s.height = c.height;
  s.gradient = false;  // one background colour in every pipeline, so images compare
  s.haze_distance = 0.0;
  return s;
}

// The pipeline's options for a benchmark's scene: no legend, windows of at most `max_window` cells.
inline app::render::SceneOptions bench_scene_options(int max_window = 1024) {
  app::render::SceneOptions o;
  o.max_window = max_window;
  o.legend = false;
  return o;
}

// The scene of a terrain with its window centred on (lat, lon) (the mosaic's centre when both
// are NaN) at most `max_window` cells wide.
inline app::scene::SceneSpec terrain_spec(const Terrain& t, double lat = std::nan(""), double lon = std::nan("")) {
  app::scene::SceneSpec spec;
  spec.dems = t.dems;
  if (!std::isnan(lat)) {
    app::scene::SceneCamera cam;
    cam.pose.lat = lat;
    cam.pose.lon = lon;
    cam.pose.alt = 1000;
    cam.agl = true;
    spec.camera = cam;
  }
  return spec;
}

// Frame time of the MRBSP: traversal, the upload of its triangle list, and the draw.
inline double frame_ms(const app::render::FrameStats& s) { return s.traversal_ms + s.upload_ms + s.draw_ms; }

// The LOD options at threshold t of a metric (the area metric's threshold is 250 t square
// pixels, so that t = 2 is its default of 500).
inline mrbsp::TraversalOptions lod(mrbsp::LodMetric metric, double t) {
  mrbsp::TraversalOptions o;
  o.metric = metric;
  o.threshold_px = static_cast<float>(metric == mrbsp::LodMetric::kError ? t : 250.0 * t);
  return o;
}

}  // namespace terravol::bench
