// `terravol render DEM... --camera LAT,LON,ALT,HEADING,PITCH -o out.png`: one offscreen image
// of the terrain, drawn in the MRBSP tree's back-to-front order with no depth buffer (or, with
// --order zbuffer, the same triangles with VTK's depth test, as the reference); or, with
// --renderer tiler, its front-to-back order tiled in software with --aa x --aa samples a pixel
// (tiler/, Greene 1996).
#include <nlohmann/json.hpp>

#include <vtkCamera.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "app/cli/commands.h"
#include "app/cli/scene_options.h"
#include "app/output/png_output.h"
#include "app/output/vtp_export.h"
#include "app/output/write_file.h"
#include "app/render/scene_renderer.h"
#include "app/render/terrain_renderer.h"
#include "app/render/tiled_renderer.h"
#include "app/scene/camera.h"
#include "app/scene/scene_file.h"
#include "app/scene/style.h"
#include "app/scene/terrain_colors.h"
#include "app/scene/terrain_scene.h"
#include "app/scene/timing.h"

namespace terravol::app::cli {

namespace {

using nlohmann::ordered_json;
using scene::Clock;
using scene::ms_since;

struct RenderOptions {
  std::vector<std::filesystem::path> dems;  // files or folders, one mosaic
  scene::CameraPose pose;
  bool agl = false;                // pose.alt is above the ground under the camera
  std::filesystem::path output;    // PNG
  double fov_y_deg = 45.0;         // vertical, (0, 180)
  scene::Style style;              // the scene file's, overridden by the style options
  bool wireframe = false, lod_colors = false;
  std::optional<scene::Rgb> background;  // uniform, instead of the sky
  bool full_res = false;           // every region at full resolution
  int levels = 0;                  // 0: default_levels(window)
  bool force = false;              // replace existing outputs
  std::filesystem::path stats;     // JSON, optional
  std::filesystem::path export_vtp;  // optional
  std::vector<scene::VolumeSpec> volumes;  // RF volumes and their styles
  std::vector<scene::ObjectSpec> objects;  // models placed on the terrain
  scene::Engine engine = scene::Engine::kVtk;  // --renderer
  int aa = 8;                                  // --aa (the tiler's samples per pixel per axis)
  double texel_rate = tiler::Settings{}.texel_rate;  // --texel-rate (the tiler's texture shading)
  double near_plane = 0;                       // --near-plane, metres; 0: from the eye's height
};

void run_render(const RenderOptions& o) {
  // Fail before the expensive work when an output would be replaced or nothing can be drawn.
  output::check_output_path(o.output, "-o", ".png", o.force);
  for (const auto* p : {&o.stats, &o.export_vtp}) {
    if (!p->empty() && !o.force && std::filesystem::exists(*p)) {
      throw std::runtime_error(p->string() + ": exists (use --force to overwrite)");
    }
  }
  const auto t_start = Clock::now();
  const scene::Style& st = o.style;
  render::RenderSettings settings = render::render_settings(st);
  settings.wireframe = o.wireframe;
  settings.lod_colors = o.lod_colors;
  if (o.background) {
    settings.background = *o.background;
    settings.gradient = false;
  }
  if (settings.gradient) {
    const auto sky = scene::sky_gradient(o.pose.pitch_deg, o.fov_y_deg);
    settings.background = sky[0];
    settings.background_top = sky[1];
    settings.haze_color = scene::kHorizon;
  } else {
    settings.haze_color = settings.background;  // fade into the uniform background
  }
  // Haze is for pictures; the LOD colours are a diagnostic and stay exact.
  settings.haze_distance = settings.lod_colors ? 0.0 : st.haze_km * 1000.0;
  mrbsp::TraversalOptions traversal = st.traversal;
  traversal.full_res = o.full_res;
  traversal.crack_fills = !settings.wireframe;  // crack fills matter in filled drawing only

  scene::SceneSpec scene;
  scene.dems = o.dems;
  scene.volumes = o.volumes;
  scene.objects = o.objects;
  scene.camera = scene::SceneCamera{o.pose, o.agl, o.fov_y_deg};
  const auto t_scene = Clock::now();
  render::SceneOptions options = render::scene_options(st, o.levels);
  options.near_plane = o.near_plane;
  options.engine = o.engine;
  options.tiler.aa = o.aa;
  options.tiler.texel_rate = o.texel_rate;
  render::SceneRenderer view(scene, settings, options);
  const double scene_ms = ms_since(t_scene);
  const bool tiled = o.engine == scene::Engine::kTiler;

  // Two frames: the first pays for the upload of the vertices and the shaders; the second is
  // what every later frame of a flythrough costs.
  const render::FrameStats first = view.render(o.pose, o.agl, o.fov_y_deg, traversal);
  const render::FrameStats f = view.render(o.pose, o.agl, o.fov_y_deg, traversal);

  output::write_png(o.output,
                    tiled ? output::encode_png(view.rgb(), settings.width, settings.height)
                          : output::window_png(view.renderer().window()),
                    o.force);
  std::printf("wrote %s\n", o.output.string().c_str());
  const scene::MergeFigures& merge = view.merge_figures();
  if (view.volume_count() > 0) {
    std::printf("volumes: %zu triangles extracted in %.0f ms, %zu in the tree after a %.0f ms merge; %zu of %zu drawn\n",
                merge.input_triangles, merge.geometry_ms, merge.tree_triangles, merge.merge_ms, f.merged_triangles,
                f.triangles);
  }
  const scene::DensityFigures density = view.volumes().density_figures();
  if (density.drawn) {
    std::printf("density: %d x %d x %d leaves, %d levels, built in %.0f ms (%.0f MB); %zu cells drawn as %zu faces "
                "(%zu triangles), refined in %.1f ms, ordered in %.1f ms\n",
                density.grid.boxes[0], density.grid.boxes[1], density.grid.boxes[2], density.levels, density.build_ms,
                static_cast<double>(density.bytes) / 1048576.0, f.density.boxes, f.boxes.faces, f.box_triangles, f.density_ms,
                f.boxes.distribute_ms);
  }
  const scene::ObjectFigures& objects = view.objects().figures();
  if (objects.instances > 0) {
    std::printf("objects: %zu instances of %zu models read in %.0f ms, levels made in %.0f ms; %zu of %zu triangles "
                "chosen (%zu colour cubes)\n",
                objects.instances, objects.models, objects.read_ms, objects.lod_ms, objects.chosen_triangles,
                objects.full_triangles, objects.cubes);
  }
  if (!o.export_vtp.empty()) {
    render::TerrainRenderer& r = view.renderer();
    output::export_vtp(o.export_vtp, r.scene(), view.terrain().tree().cells(), r.camera(), r.settings(), o.force);
    std::printf("wrote %s\n", o.export_vtp.string().c_str());
  }
  if (!o.stats.empty()) {
    const scene::TerrainScene& terrain = view.terrain();
    const mrbsp::TerrainTree& tree = terrain.tree();
    const scene::WindowChoice& window = terrain.window();
    const scene::WindowBounds b = terrain.bounds();
    const mrbsp::Camera& camera = view.camera();
    ordered_json j;
    j["output"] = o.output.string();
    j["width"] = settings.width;
    j["height"] = settings.height;
    j["renderer"] = scene::engine_name(o.engine);
    j["order"] = scene::order_name(settings.order);
    if (tiled) {
      const tiler::Stats& t = view.tiled().stats();
      const double pixels = static_cast<double>(settings.width) * settings.height;
      j["tiler"] = {{"aa", o.aa},
                    {"texel_rate", view.tiled().settings().texel_rate},
                    {"triangles", t.triangles},
                    {"translucent", t.translucent},
                    {"clipped", t.clipped},
                    {"fragments", t.fragments},
                    {"shading_points", t.shading_points},
                    {"samples_covered", t.samples_covered},
                    {"samples_background", t.samples_background},
                    {"cells_visited_per_pixel", static_cast<double>(t.cells_visited) / pixels},
                    {"class_splits", t.class_splits},
                    {"setup_ms", t.setup_ms},
                    {"tile_ms", t.tile_ms},
                    {"tile_cpu_ms", t.tile_cpu_ms}};
    }
    j["lod_metric"] = scene::metric_name(traversal.metric);
    j["threshold_px"] = traversal.threshold_px;
    j["full_res"] = traversal.full_res;
    j["window"] = {{"cells", window.cells},   {"row0", window.row0},   {"col0", window.col0},
                   {"south", b.south},        {"north", b.north},      {"west", b.west},
                   {"east", b.east},          {"origin_lat", terrain.frame().lat0()},
                   {"origin_lon", terrain.frame().lon0()}, {"filled_samples", terrain.filled_samples()}};
    j["levels"] = tree.levels();
    j["vertices"] = tree.positions().size();
    j["triangles"] = f.triangles;
    j["merged_triangles"] = f.merged_triangles;
    j["crack_triangles"] = view.last_frame().crack_triangles;
    j["nodes_visited"] = f.nodes_visited;
    j["leaves"] = view.last_frame().leaves;
    j["lod_histogram"] = view.last_frame().lod_histogram;
    const mrbsp::OcclusionStats& occ = view.last_frame().occlusion;
    j["occlusion"] = {{"on", traversal.occlusion},          {"coherence", scene::coherence_name(traversal.coherence)},
                      {"tested_nodes", occ.tested_nodes},   {"skipped_tests", occ.skipped_tests},
                      {"culled_nodes", occ.culled_nodes},   {"sampled_visible", occ.sampled_visible},
                      {"culled_leaves", occ.culled_leaves}, {"tiled_triangles", occ.tiled_triangles},
                      {"ran", occ.ran},                     {"left_out", occ.left_out},
                      {"pass_ms", occ.pass_ms}};
    j["volumes"] = {{"count", view.volume_count()},
                    {"input_triangles", merge.input_triangles},
                    {"tree_triangles", merge.tree_triangles},
                    {"pieces_per_triangle", merge.input_triangles > 0 ? static_cast<double>(merge.tree_triangles) /
                                                                            static_cast<double>(merge.input_triangles)
                                                                      : 0.0},
                    {"merged_bytes", tree.memory().merged},
                    {"geometry_ms", merge.geometry_ms},
                    {"merge_ms", merge.merge_ms},
                    {"merge_distribute_ms", tree.merge_stats().distribute_ms},
                    {"merge_build_ms", tree.merge_stats().build_ms}};
    j["objects"] = {{"models", objects.models},
                    {"instances", objects.instances},
                    {"full_triangles", objects.full_triangles},
                    {"chosen_triangles", objects.chosen_triangles},
                    {"lod_triangles", objects.lod_triangles},
                    {"colour_cubes", objects.cubes},
                    {"read_ms", objects.read_ms},
                    {"lod_ms", objects.lod_ms},
                    {"first_merge_ms", first.objects_ms}};
    j["density"] = {{"drawn", density.drawn},
                    {"threshold_px", view.density_options().threshold_px},
                    {"leaves", density.grid.boxes},
                    {"levels", density.levels},
                    {"bytes", density.bytes},
                    {"resample_ms", density.resample_ms},
                    {"build_ms", density.build_ms},
                    {"cells", f.density.boxes},
                    {"cells_per_level", f.density.per_level},
                    {"faces", f.boxes.faces},
                    {"triangles", f.box_triangles},
                    {"bsp_faces", f.boxes.bsp_faces},
                    {"refine_ms", f.density_ms},
                    {"order_ms", f.boxes.distribute_ms}};
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
    output::write_file_atomically(o.stats, std::vector<std::uint8_t>(text.begin(), text.end()), o.force);
    std::printf("wrote %s\n", o.stats.string().c_str());
  }
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("render", "Render the terrain of DEM files, and RF volumes over it, to a PNG image "
                                           "(VTK needs an X display; --renderer tiler does not)");
  struct Raw {
    RenderOptions o;
    std::string camera, background;
    RendererArgs renderer;
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
  cmd->add_option("--near-plane", o.near_plane,
                  "Near clipping distance, metres (default: a twentieth of the eye's height above the ground). "
                  "The tree's order needs no depth buffer; depth-tested orders (--order peel, zbuffer, vtk, sort) "
                  "resolve depth better with a larger one");
  auto* levels = cmd->add_option("--levels", o.levels, "LOD levels (default: coarsest level 8x8 cells)");
  cmd->add_option("--background", raw->background, "Uniform background R,G,B (0-255) instead of the sky");
  cmd->add_flag("--wireframe", o.wireframe, "Draw triangle edges only");
  cmd->add_flag("--lod-colors", o.lod_colors, "Colour each LOD level (crack fills grey)");
  cmd->add_flag("--full-res", o.full_res, "Every region at full resolution");
  cmd->add_flag("--agl", o.agl, "ALT is metres above the ground under the camera");
  cmd->add_flag("--force", o.force, "Replace existing output files");
  cmd->add_option("--stats", o.stats, "Write figures of the render (JSON)");
  cmd->add_option("--export-vtp", o.export_vtp, "Write the triangles drawn, in draw order (VTK XML PolyData)");
  add_renderer_options(*cmd, raw->renderer);
  cmd->callback([=] {
    RenderOptions& opt = raw->o;
    if (opt.near_plane != 0.0 && !(opt.near_plane >= 0.01 && opt.near_plane <= 10000.0)) {
      throw std::invalid_argument("--near-plane: metres from 0.01 to 10000");
    }
    const RendererChoice drawn = resolve_renderer(raw->renderer);
    opt.engine = drawn.engine;
    opt.aa = drawn.aa;
    opt.texel_rate = drawn.texel_rate;
    if (opt.engine == scene::Engine::kTiler) {
      if (opt.wireframe || opt.lod_colors) {
        throw std::invalid_argument(std::string("--renderer tiler: draws filled triangles only (no ") +
                                    (opt.wireframe ? "--wireframe" : "--lod-colors") + ")");
      }
      if (!opt.export_vtp.empty()) throw std::invalid_argument("--export-vtp: needs --renderer vtk (the VTK polydata it writes)");
    }
    // The scene file first; whatever the command line gave wins.
    const scene::SceneSpec file = read_scene_args(raw->scene, opt.dems);
    const auto pose = scene::resolve_camera(file, camera->count() > 0 ? &raw->camera : nullptr, fov->count() > 0,
                                            opt.agl, opt.fov_y_deg);
    if (!pose) throw std::invalid_argument("--camera is required (or a \"camera\" in the scene file)");
    opt.pose = *pose;
    opt.style = scene::resolve_style(file.style);
    opt.volumes = file.volumes;
    opt.objects = file.objects;
    if (!raw->background.empty()) opt.background = scene::parse_rgb("--background", raw->background);
    scene::check_view_options(opt.fov_y_deg, opt.style, levels->count() > 0, opt.levels);
    if (opt.engine == scene::Engine::kTiler && opt.style.order != scene::DrawOrder::kBsp) {
      throw std::invalid_argument(std::string("--renderer tiler: draws in the tree's own order (--order bsp), not --order ") +
                                  scene::order_name(opt.style.order));
    }
    check_tiler_size(drawn, opt.style.width, opt.style.height);
    run_render(opt);
  });
}

}  // namespace terravol::app::cli
