// `terravol render DEM... --camera LAT,LON,ALT,HEADING,PITCH -o out.png`: one offscreen image
// of the terrain, drawn in the MRBSP tree's back-to-front order with no depth buffer (or, with
// --order zbuffer, the same triangles with VTK's depth test, as the reference).
#include <nlohmann/json.hpp>

#include <vtkCamera.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "app/camera.h"
#include "app/commands.h"
#include "app/png_output.h"
#include "app/render_options.h"
#include "app/terrain_colors.h"
#include "app/terrain_renderer.h"
#include "app/terrain_scene.h"
#include "app/vtp_export.h"
#include "app/write_file.h"
#include "io/mosaic.h"

namespace terravol::app {

namespace {

using nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::string degrees(double v, char positive, char negative) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4f %c", std::abs(v), v < 0 ? negative : positive);
  return b;
}

void run_render(const RenderOptions& o) {
  // Fail before the expensive work when an output would be replaced or nothing can be drawn.
  for (const auto* p : {&o.output, &o.stats, &o.export_vtp}) {
    if (!p->empty() && !o.force && std::filesystem::exists(*p)) {
      throw std::runtime_error(p->string() + ": exists (use --force to overwrite)");
    }
  }
  const auto t_start = Clock::now();

  // The mosaic and the window around the camera.
  const io::Mosaic mosaic = io::Mosaic::open(o.dems);
  const io::Georef& g = mosaic.georef();
  const double row = (g.y0 - o.pose.lat) / g.dy;
  const double col = (std::remainder(o.pose.lon - g.x0 - 180.0, 360.0) + 180.0) / g.dx;
  if (row < 0 || row > mosaic.rows() - 1 || col < 0 || col > mosaic.cols() - 1) {
    const double south = g.y0 - (mosaic.rows() - 1) * g.dy, east = g.x0 + (mosaic.cols() - 1) * g.dx;
    throw std::runtime_error("camera " + degrees(o.pose.lat, 'N', 'S') + ", " + degrees(o.pose.lon, 'E', 'W') +
                             " is outside the DEM (" + degrees(south, 'N', 'S') + " .. " + degrees(g.y0, 'N', 'S') +
                             ", " + degrees(g.x0, 'E', 'W') + " .. " + degrees(east, 'E', 'W') + ")");
  }
  require_x_display();
  const WindowChoice window = choose_window(mosaic.rows(), mosaic.cols(), row, col, o.max_window);
  const int levels = o.levels > 0 ? o.levels : default_levels(window.cells);
  const auto t_read = Clock::now();
  const TerrainScene scene(mosaic, window, levels);
  const double scene_ms = ms_since(t_read);
  const mrbsp::TerrainTree& tree = scene.tree();

  // The camera.
  const double ground = scene.ground_height(o.pose.lat, o.pose.lon);
  const double eye_height = o.agl ? ground + o.pose.alt : o.pose.alt;
  const double clearance = eye_height - ground;
  if (clearance <= 0.0) {
    char b[160];
    std::snprintf(b, sizeof b, "camera at %.1f m is not above the ground (%.1f m there)%s", eye_height, ground,
                  o.agl ? "" : "; use --agl for heights above ground");
    throw std::runtime_error(b);
  }
  const mrbsp::Camera camera = make_scene_camera(scene.frame(), o.pose, eye_height, o.fov_y_deg, o.render.width,
                                                 o.render.height, near_plane_for(clearance));
  const double far = scene.far_plane(camera.eye);
  RenderSettings settings = o.render;
  if (settings.gradient) {
    const auto sky = sky_gradient(o.pose.pitch_deg, o.fov_y_deg);
    settings.background = sky[0];
    settings.background_top = sky[1];
    settings.haze_color = kHorizon;
  } else {
    settings.haze_color = settings.background;  // fade into the uniform background
  }
  // Haze is for pictures; the LOD colours are a diagnostic and stay exact.
  settings.haze_distance = settings.lod_colors ? 0.0 : o.haze_km * 1000.0;

  // Colours, the VTK scene, and two frames: the first pays for the upload of the vertices and
  // the shaders; the second is what every later frame of a flythrough costs.
  const auto t_shade = Clock::now();
  const TerrainShading lattice =
      shade_terrain(scene.cells(), scene.xs(), scene.ys(), scene.z(), scene.heights(), o.shading);
  const TerrainShading shading = vertex_shading(lattice, tree.merged_base(), tree.merged_colors());
  const double shade_ms = ms_since(t_shade);
  TerrainRenderer renderer(tree.positions(), shading, settings, ColorTexture{scene.cells() + 1, lattice.rgba});
  renderer.set_camera(camera, far);

  mrbsp::Frame frame;
  auto t0 = Clock::now();
  tree.traverse(camera, o.traversal, frame);
  const double first_traversal_ms = ms_since(t0);
  renderer.set_frame(frame);
  const double first_draw_ms = renderer.render();

  t0 = Clock::now();
  tree.traverse(camera, o.traversal, frame);
  const double traversal_ms = ms_since(t0);
  t0 = Clock::now();
  renderer.set_frame(frame);
  const double upload_ms = ms_since(t0);
  const double draw_ms = renderer.render();

  write_png(o.output, renderer.png(), o.force);
  std::printf("wrote %s\n", o.output.string().c_str());

  const std::size_t triangles = frame.indices.size() / 3;
  if (!o.export_vtp.empty()) {
    export_vtp(o.export_vtp, renderer.scene(), renderer.camera(), settings, o.force);
    std::printf("wrote %s\n", o.export_vtp.string().c_str());
  }
  if (!o.stats.empty()) {
    const WindowBounds b = scene.bounds();
    ordered_json j;
    j["output"] = o.output.string();
    j["width"] = o.render.width;
    j["height"] = o.render.height;
    j["order"] = o.render.order == DrawOrder::kBsp ? "bsp" : "zbuffer";
    j["lod_metric"] = o.traversal.metric == mrbsp::LodMetric::kError ? "error" : "area";
    j["threshold_px"] = o.traversal.threshold_px;
    j["full_res"] = o.traversal.full_res;
    j["window"] = {{"cells", window.cells},   {"row0", window.row0},   {"col0", window.col0},
                   {"south", b.south},        {"north", b.north},      {"west", b.west},
                   {"east", b.east},          {"origin_lat", scene.frame().lat0()},
                   {"origin_lon", scene.frame().lon0()}, {"filled_samples", scene.filled_samples()}};
    j["levels"] = tree.levels();
    j["vertices"] = tree.positions().size();
    j["triangles"] = triangles;
    j["skirt_triangles"] = frame.skirt_triangles;
    j["nodes_visited"] = frame.nodes_visited;
    j["leaves"] = frame.leaves;
    j["lod_histogram"] = frame.lod_histogram;
    j["camera"] = {{"lat", o.pose.lat},
                   {"lon", o.pose.lon},
                   {"eye_height", eye_height},
                   {"ground_height", ground},
                   {"heading", o.pose.heading_deg},
                   {"pitch", o.pose.pitch_deg},
                   {"fov_y", o.fov_y_deg},
                   {"eye", {camera.eye.x, camera.eye.y, camera.eye.z}},
                   {"near", camera.near_plane},
                   {"far", far}};
    j["build_ms"] = scene.build_ms();
    j["scene_ms"] = scene_ms;  // read, fill, frame and build
    j["shade_ms"] = shade_ms;
    j["first_traversal_ms"] = first_traversal_ms;
    j["first_draw_ms"] = first_draw_ms;
    j["traversal_ms"] = traversal_ms;
    j["upload_ms"] = upload_ms;
    j["draw_ms"] = draw_ms;
    j["total_ms"] = ms_since(t_start);
    const std::string text = j.dump(2) + "\n";
    write_file_atomically(o.stats, std::vector<std::uint8_t>(text.begin(), text.end()), o.force);
    std::printf("wrote %s\n", o.stats.string().c_str());
  }
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("render", "Render the terrain of DEM files to a PNG image (needs an X display)");
  struct Raw {
    RenderOptions o;
    std::string camera, size = "1280x720", metric = "error", order = "bsp", background, tint = "atlas";
    double threshold = 0.0;  // when --threshold is not given: the metric's default
  };
  auto raw = std::make_shared<Raw>();
  RenderOptions& o = raw->o;
  cmd->add_option("dems", o.dems, "DEM files or folders of tiles (one mosaic)")->required();
  cmd->add_option("--camera", raw->camera,
                  "LAT,LON,ALT,HEADING,PITCH: degrees, metres (in the DEM's datum; above ground with --agl), "
                  "heading clockwise from north, pitch above the horizon")
      ->required();
  cmd->add_option("-o,--output", o.output, "PNG file to write")->required();
  cmd->add_option("--fov", o.fov_y_deg, "Vertical field of view, degrees")->capture_default_str();
  cmd->add_option("--size", raw->size, "Image size WIDTHxHEIGHT, pixels")->capture_default_str();
  cmd->add_option("--lod-metric", raw->metric, "LOD metric: error (screen-space error) or area (the paper's)")
      ->capture_default_str();
  auto* threshold = cmd->add_option("--threshold", raw->threshold,
                  "LOD threshold: pixels of screen-space error (default 2) or, with --lod-metric area, "
                  "projected box area in square pixels (default 500)");
  auto* levels = cmd->add_option("--levels", o.levels, "LOD levels (default: coarsest level 8x8 cells)");
  cmd->add_option("--window", o.max_window, "Largest window side, cells (a power of two)")->capture_default_str();
  cmd->add_option("--background", raw->background, "Uniform background R,G,B (0-255) instead of the sky");
  cmd->add_flag("--wireframe", o.render.wireframe, "Draw triangle edges only");
  cmd->add_flag("--lod-colors", o.render.lod_colors, "Colour each LOD level (skirts grey)");
  cmd->add_flag("--full-res", o.traversal.full_res, "Every region at full resolution");
  cmd->add_option("--order", raw->order, "bsp (tree order, no depth test) or zbuffer (the reference)")
      ->capture_default_str();
  cmd->add_flag("--agl", o.agl, "ALT is metres above the ground under the camera");
  cmd->add_flag("--force", o.force, "Replace existing output files");
  cmd->add_option("--stats", o.stats, "Write figures of the render (JSON)");
  cmd->add_option("--export-vtp", o.export_vtp, "Write the triangles drawn, in draw order (VTK XML PolyData)");
  cmd->add_option("--sun-azimuth", o.shading.sun_azimuth_deg, "Sun direction, degrees clockwise from north")
      ->capture_default_str();
  cmd->add_option("--sun-elevation", o.shading.sun_elevation_deg, "Sun elevation, degrees")->capture_default_str();
  cmd->add_option("--haze", o.haze_km, "Aerial perspective: distance (km) at which 63% of the colour fades to the sky; 0: none")
      ->capture_default_str();
  cmd->add_option("--tint", raw->tint, "Terrain tint: atlas, relative (stretched to the window) or grey")
      ->capture_default_str();
  cmd->callback([raw, levels, threshold] {
    RenderOptions& opt = raw->o;
    opt.pose = parse_camera_pose(raw->camera);
    parse_size(raw->size, opt.render.width, opt.render.height);
    opt.traversal.metric = parse_metric(raw->metric);
    opt.render.order = parse_order(raw->order);
    opt.shading.tint = parse_tint(raw->tint);
    if (!raw->background.empty()) {
      opt.render.background = parse_rgb("--background", raw->background);
      opt.render.gradient = false;
    }
    if (threshold->count() == 0) raw->threshold = mrbsp::default_threshold(opt.traversal.metric);
    if (!(raw->threshold > 0.0) || !std::isfinite(raw->threshold)) {
      throw std::invalid_argument("--threshold " + std::to_string(raw->threshold) + ": must be a positive number of pixels");
    }
    opt.traversal.threshold_px = static_cast<float>(raw->threshold);
    opt.traversal.skirts = !opt.render.wireframe;  // skirts patch cracks in filled drawing only
    if (!(opt.fov_y_deg > 0.0 && opt.fov_y_deg < 180.0)) {
      throw std::invalid_argument("--fov " + std::to_string(opt.fov_y_deg) + ": must be within (0, 180) degrees");
    }
    if (opt.max_window < 2 || (opt.max_window & (opt.max_window - 1)) != 0) {
      throw std::invalid_argument("--window " + std::to_string(opt.max_window) + ": must be a power of two >= 2");
    }
    if (!(opt.haze_km >= 0.0) || !std::isfinite(opt.haze_km)) {
      throw std::invalid_argument("--haze: must be a distance >= 0 km");
    }
    if (levels->count() > 0 && opt.levels < 1) throw std::invalid_argument("--levels " + std::to_string(opt.levels) + ": must be >= 1");
    if (!(opt.shading.sun_elevation_deg > 0.0 && opt.shading.sun_elevation_deg <= 90.0)) {
      throw std::invalid_argument("--sun-elevation: must be within (0, 90] degrees");
    }
    run_render(opt);
  });
}

}  // namespace terravol::app
