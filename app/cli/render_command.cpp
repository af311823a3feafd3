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
#include "app/scene_file.h"
#include "app/scene_renderer.h"
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

void run_render(const RenderOptions& o) {
  // Fail before the expensive work when an output would be replaced or nothing can be drawn.
  for (const auto* p : {&o.output, &o.stats, &o.export_vtp}) {
    if (!p->empty() && !o.force && std::filesystem::exists(*p)) {
      throw std::runtime_error(p->string() + ": exists (use --force to overwrite)");
    }
  }
  const auto t_start = Clock::now();
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

  SceneSpec scene;
  scene.dems = o.dems;
  scene.volumes = o.volumes;
  scene.camera = SceneCamera{o.pose, o.agl, o.fov_y_deg};
  const auto t_scene = Clock::now();
  SceneRenderer view(scene, settings, o.max_window, o.levels, o.shading, o.legend, o.surface_triangles);
  const double scene_ms = ms_since(t_scene);

  // Two frames: the first pays for the upload of the vertices and the shaders; the second is
  // what every later frame of a flythrough costs.
  const FrameStats first = view.render(o.pose, o.agl, o.fov_y_deg, o.traversal);
  const FrameStats f = view.render(o.pose, o.agl, o.fov_y_deg, o.traversal);

  write_png(o.output, view.png(), o.force);
  std::printf("wrote %s\n", o.output.string().c_str());
  const MergeFigures& merge = view.merge_figures();
  if (view.volume_count() > 0) {
    std::printf("volumes: %zu triangles extracted in %.0f ms, %zu in the tree after a %.0f ms merge; %zu of %zu drawn\n",
                merge.input_triangles, merge.geometry_ms, merge.tree_triangles, merge.merge_ms, f.merged_triangles,
                f.triangles);
  }
  if (!o.export_vtp.empty()) {
    TerrainRenderer& r = view.renderer();
    export_vtp(o.export_vtp, r.scene(), r.camera(), r.settings(), o.force);
    std::printf("wrote %s\n", o.export_vtp.string().c_str());
  }
  if (!o.stats.empty()) {
    const TerrainScene& terrain = view.terrain();
    const mrbsp::TerrainTree& tree = terrain.tree();
    const WindowChoice& window = terrain.window();
    const WindowBounds b = terrain.bounds();
    const mrbsp::Camera& camera = view.camera();
    ordered_json j;
    j["output"] = o.output.string();
    j["width"] = o.render.width;
    j["height"] = o.render.height;
    j["order"] = order_name(o.render.order);
    j["lod_metric"] = o.traversal.metric == mrbsp::LodMetric::kError ? "error" : "area";
    j["threshold_px"] = o.traversal.threshold_px;
    j["full_res"] = o.traversal.full_res;
    j["window"] = {{"cells", window.cells},   {"row0", window.row0},   {"col0", window.col0},
                   {"south", b.south},        {"north", b.north},      {"west", b.west},
                   {"east", b.east},          {"origin_lat", terrain.frame().lat0()},
                   {"origin_lon", terrain.frame().lon0()}, {"filled_samples", terrain.filled_samples()}};
    j["levels"] = tree.levels();
    j["vertices"] = tree.positions().size();
    j["triangles"] = f.triangles;
    j["merged_triangles"] = f.merged_triangles;
    j["skirt_triangles"] = view.last_frame().skirt_triangles;
    j["nodes_visited"] = f.nodes_visited;
    j["leaves"] = view.last_frame().leaves;
    j["lod_histogram"] = view.last_frame().lod_histogram;
    j["volumes"] = {{"count", view.volume_count()},
                    {"input_triangles", merge.input_triangles},
                    {"tree_triangles", merge.tree_triangles},
                    {"geometry_ms", merge.geometry_ms},
                    {"merge_ms", merge.merge_ms}};
    j["camera"] = {{"lat", o.pose.lat},
                   {"lon", o.pose.lon},
                   {"eye_height", f.eye_height},
                   {"ground_height", f.ground_height},
                   {"heading", o.pose.heading_deg},
                   {"pitch", o.pose.pitch_deg},
                   {"fov_y", o.fov_y_deg},
                   {"eye", {camera.eye.x, camera.eye.y, camera.eye.z}},
                   {"near", camera.near_plane},
                   {"far", terrain.far_plane(camera.eye)}};
    j["build_ms"] = terrain.build_ms();
    j["scene_ms"] = scene_ms;  // read, fill, frame, build, volumes, merge, renderer
    j["first_traversal_ms"] = first.traversal_ms;
    j["first_draw_ms"] = first.draw_ms;
    j["traversal_ms"] = f.traversal_ms;
    j["upload_ms"] = f.upload_ms;
    j["draw_ms"] = f.draw_ms;
    j["total_ms"] = ms_since(t_start);
    const std::string text = j.dump(2) + "\n";
    write_file_atomically(o.stats, std::vector<std::uint8_t>(text.begin(), text.end()), o.force);
    std::printf("wrote %s\n", o.stats.string().c_str());
  }
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("render", "Render the terrain of DEM files, and RF volumes over it, to a PNG image "
                                           "(needs an X display)");
  struct Raw {
    RenderOptions o;
    std::string camera, size = "1280x720", metric = "error", order = "bsp", background, tint = "atlas";
    double threshold = 0.0;  // when --threshold is not given: the metric's default
    SceneArgs scene;
  };
  auto raw = std::make_shared<Raw>();
  RenderOptions& o = raw->o;
  cmd->add_option("dems", o.dems, "DEM files or folders of tiles (one mosaic); default: the scene file's");
  add_scene_options(*cmd, raw->scene);
  auto* camera = cmd->add_option("--camera", raw->camera,
                  "LAT,LON,ALT,HEADING,PITCH: degrees, metres (in the DEM's datum; above ground with --agl), "
                  "heading clockwise from north, pitch above the horizon");
  cmd->add_option("-o,--output", o.output, "PNG file to write")->required();
  auto* fov = cmd->add_option("--fov", o.fov_y_deg, "Vertical field of view, degrees")->capture_default_str();
  auto* size = cmd->add_option("--size", raw->size, "Image size WIDTHxHEIGHT, pixels")->capture_default_str();
  auto* metric = cmd->add_option("--lod-metric", raw->metric, "LOD metric: error (screen-space error) or area (the paper's)")
      ->capture_default_str();
  auto* threshold = cmd->add_option("--threshold", raw->threshold,
                  "LOD threshold: pixels of screen-space error (default 2) or, with --lod-metric area, "
                  "projected box area in square pixels (default 500)");
  auto* levels = cmd->add_option("--levels", o.levels, "LOD levels (default: coarsest level 8x8 cells)");
  auto* window = cmd->add_option("--window", o.max_window, "Largest window side, cells (a power of two)")->capture_default_str();
  cmd->add_option("--background", raw->background, "Uniform background R,G,B (0-255) instead of the sky");
  cmd->add_flag("--wireframe", o.render.wireframe, "Draw triangle edges only");
  cmd->add_flag("--lod-colors", o.render.lod_colors, "Colour each LOD level (skirts grey)");
  cmd->add_flag("--full-res", o.traversal.full_res, "Every region at full resolution");
  auto* order = cmd->add_option("--order", raw->order,
                  "bsp (tree order, no depth test), zbuffer (the same order, depth-tested), and for translucent "
                  "volumes the references: peel (VTK depth peeling, unlimited peels: exact), vtk (VTK's default "
                  "alpha blending, unsorted), sort (vtkDepthSortPolyData)")
      ->capture_default_str();
  cmd->add_flag("--agl", o.agl, "ALT is metres above the ground under the camera");
  cmd->add_flag("--force", o.force, "Replace existing output files");
  cmd->add_option("--stats", o.stats, "Write figures of the render (JSON)");
  cmd->add_option("--export-vtp", o.export_vtp, "Write the triangles drawn, in draw order (VTK XML PolyData)");
  auto* sun_azimuth = cmd->add_option("--sun-azimuth", o.shading.sun_azimuth_deg, "Sun direction, degrees clockwise from north")
      ->capture_default_str();
  auto* sun_elevation = cmd->add_option("--sun-elevation", o.shading.sun_elevation_deg, "Sun elevation, degrees")->capture_default_str();
  auto* haze = cmd->add_option("--haze", o.haze_km, "Aerial perspective: distance (km) at which 63% of the colour fades to the sky; 0: none")
      ->capture_default_str();
  auto* tint = cmd->add_option("--tint", raw->tint, "Terrain tint: atlas, relative (stretched to the window) or grey")
      ->capture_default_str();
  auto* surface = cmd->add_option("--surface-triangles", o.surface_triangles,
                  "Decimate each isosurface and slice to at most this many triangles before merging (0: keep all)")
      ->capture_default_str();
  cmd->callback([=] {
    RenderOptions& opt = raw->o;
    // The scene file first; whatever the command line gave wins.
    const SceneSpec file = read_scene_args(raw->scene, opt.dems);
    const SceneStyle& st = file.style;
    const auto pose = resolve_camera(file, camera->count() > 0 ? &raw->camera : nullptr, fov->count() > 0, opt.agl,
                                     opt.fov_y_deg);
    if (!pose) throw std::invalid_argument("--camera is required (or a \"camera\" in the scene file)");
    opt.pose = *pose;
    if (size->count() == 0 && st.width) raw->size = std::to_string(*st.width) + "x" + std::to_string(*st.height);
    if (metric->count() == 0 && st.lod_metric) raw->metric = *st.lod_metric;
    if (order->count() == 0 && st.order) raw->order = *st.order;
    if (tint->count() == 0 && st.tint) raw->tint = *st.tint;
    if (window->count() == 0 && st.window) opt.max_window = *st.window;
    if (haze->count() == 0 && st.haze_km) opt.haze_km = *st.haze_km;
    if (sun_azimuth->count() == 0 && st.sun_azimuth) opt.shading.sun_azimuth_deg = *st.sun_azimuth;
    if (sun_elevation->count() == 0 && st.sun_elevation) opt.shading.sun_elevation_deg = *st.sun_elevation;
    opt.legend = !raw->scene.no_legend && st.legend.value_or(true);
    if (surface->count() == 0 && st.surface_triangles) opt.surface_triangles = *st.surface_triangles;
    opt.volumes = file.volumes;

    parse_size(raw->size, opt.render.width, opt.render.height);
    opt.traversal.metric = parse_metric(raw->metric);
    opt.render.order = parse_order(raw->order);
    opt.shading.tint = parse_tint(raw->tint);
    if (!raw->background.empty()) {
      opt.render.background = parse_rgb("--background", raw->background);
      opt.render.gradient = false;
    }
    opt.traversal.threshold_px = resolve_threshold(threshold->count() > 0, raw->threshold, st.threshold, opt.traversal.metric);
    opt.traversal.skirts = !opt.render.wireframe;  // skirts patch cracks in filled drawing only
    check_view_options(opt.fov_y_deg, opt.max_window, opt.haze_km, levels->count() > 0, opt.levels);
    if (!(opt.shading.sun_elevation_deg > 0.0 && opt.shading.sun_elevation_deg <= 90.0)) {
      throw std::invalid_argument("--sun-elevation: must be within (0, 90] degrees");
    }
    run_render(opt);
  });
}

}  // namespace terravol::app
