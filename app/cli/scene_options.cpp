#include "app/cli/scene_options.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "density/transfer.h"
#include "volume/geometry.h"
#include "volume/volume.h"

namespace terravol::app::cli {

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
  add_density_option(cmd, args.density);
  add_object_option(cmd, args.objects);
  cmd.add_flag("--no-legend", args.no_legend, "No colour legend for the volumes");
  cmd.add_flag("--no-markers", args.no_markers, "No marker at the transmitters the volumes record");

  StyleArgs& s = args.style;
  const scene::Style defaults;
  s.size = std::to_string(defaults.width) + "x" + std::to_string(defaults.height);
  s.metric = scene::metric_name(defaults.traversal.metric);
  s.order = scene::order_name(defaults.order);
  s.tint = scene::tint_name(defaults.shading.tint);
  s.window = defaults.window;
  s.haze_km = defaults.haze_km;
  s.sun_azimuth = defaults.shading.sun_azimuth_deg;
  s.sun_elevation = defaults.shading.sun_elevation_deg;
  s.surface_triangles = defaults.surface_triangles;
  s.occlusion = defaults.traversal.occlusion ? "on" : "off";
  s.coherence = scene::coherence_name(defaults.traversal.coherence);
  // Each shows its default (the values just set) in --help.
  const auto option = [&cmd](const char* name, auto& value, const char* help) {
    return cmd.add_option(name, value, help)->capture_default_str();
  };
  s.size_option = option("--size", s.size, "Image (view: window) size WIDTHxHEIGHT, pixels");
  s.metric_option = option("--lod-metric", s.metric,
                           "LOD metric: error (screen-space error) or area (the paper's); in view, key M switches");
  s.threshold_option = cmd.add_option("--threshold", s.threshold,
                                      "LOD threshold: pixels of screen-space error (default 2) or, with --lod-metric "
                                      "area, projected box area in square pixels (default 500)");
  s.window_option = option("--window", s.window, "Largest window side, cells (a power of two)");
  s.order_option = option("--order", s.order,
                          "bsp (tree order, no depth test), zbuffer (the same order, depth-tested), and for "
                          "translucent volumes the references: peel (VTK depth peeling, unlimited peels: exact), "
                          "vtk (VTK's default alpha blending, unsorted), sort (vtkDepthSortPolyData)");
  s.sun_azimuth_option = option("--sun-azimuth", s.sun_azimuth, "Sun direction, degrees clockwise from north");
  s.sun_elevation_option = option("--sun-elevation", s.sun_elevation, "Sun elevation, degrees");
  s.haze_option = option("--haze", s.haze_km,
                         "Aerial perspective: distance (km) at which 63% of the colour fades to the sky; 0: none");
  s.tint_option = option("--tint", s.tint, "Terrain tint: atlas, relative (stretched to the window) or grey");
  s.surface_option = option("--surface-triangles", s.surface_triangles,
                            "Reduce each isosurface to at most this many triangles before merging (0: keep all; "
                            "slices are never reduced)");
  s.occlusion_option = option("--occlusion", s.occlusion,
                              "Occlusion culling of hidden terrain and volumes (Greene's coverage masks): on or off; "
                              "the image is the same either way");
  s.density_threshold = defaults.density_threshold;
  s.density_threshold_option = add_density_threshold_option(cmd, s.density_threshold)->capture_default_str();
  s.density_error = defaults.density_error;
  s.density_error_option = add_density_error_option(cmd, s.density_error)->capture_default_str();
  s.coherence_option = option("--coherence", s.coherence,
                              "Occlusion tests reused from frame to frame (Bittner and Havran): off, update or "
                              "conservative; with --occlusion on");
}

CLI::Option* add_object_option(CLI::App& cmd, std::vector<std::string>& objects) {
  return cmd.add_option("--object", objects,
                        "3D model (glTF, OBJ, PLY, STL, FBX, ... read by assimp) placed on the terrain: "
                        "FILE@LAT,LON,AGL[,heading=DEG][,pitch=DEG][,roll=DEG][,scale=S][,opacity=A][,up=y|z] "
                        "(AGL metres above the ground; docs/scene-file.md, \"objects\"); repeatable");
}

CLI::Option* add_density_option(CLI::App& cmd, std::string& density) {
  return cmd.add_option("--density", density,
                        "Draw the volumes as a density of colour cubes: range=LO:HI,colormap=NAME,opacity=SIGMA_PER_KM"
                        "[,ramp=flat|up|down] (values outside LO..HI clear; extinction per km; docs/scene-file.md)");
}

CLI::Option* add_density_threshold_option(CLI::App& cmd, double& threshold) {
  return cmd.add_option("--density-threshold", threshold,
                        "Density: a colour cube is drawn as its faces once its largest side spans fewer pixels than "
                        "this (epsilon; in view, keys E and Shift+E)");
}

CLI::Option* add_density_error_option(CLI::App& cmd, double& levels) {
  return cmd.add_option("--density-error", levels,
                        "Density: a colour cube whose faces stand for its contents within this many 1/255 levels "
                        "(premultiplied colour and opacity) is also drawn whole while it spans fewer than 32 pixels; "
                        "0: off, the projected size alone decides");
}

std::vector<scene::ObjectSpec> parse_objects(const std::vector<std::string>& texts) {
  std::vector<scene::ObjectSpec> out;
  for (const std::string& t : texts) out.push_back(scene::parse_object(t));
  return out;
}

void add_renderer_options(CLI::App& cmd, RendererArgs& args) {
  cmd.add_option("--renderer", args.renderer,
                 "vtk (OpenGL through VTK, needs an X display) or tiler (software: the tree's front-to-back order "
                 "tiled into a coverage pyramid, antialiased by --aa)")
      ->capture_default_str();
  args.aa_option = cmd.add_option("--aa", args.aa, "With --renderer tiler: samples per pixel per axis, 1, 2, 4 or 8")
                       ->capture_default_str();
  args.texel_rate_option =
      cmd.add_option("--texel-rate", args.texel_rate,
                     "With --renderer tiler: texture shading points per texel a pixel spans, per axis, where a pixel "
                     "spans many texels of the terrain (0: every sample shaded, exact supersampling)")
          ->capture_default_str();
}

RendererChoice resolve_renderer(const RendererArgs& args) {
  RendererChoice c{scene::parse_engine(args.renderer), scene::parse_aa(args.aa), args.texel_rate};
  const auto given = [](const CLI::Option* o) { return o != nullptr && o->count() > 0; };
  if (c.engine == scene::Engine::kVtk && given(args.aa_option)) {
    throw std::invalid_argument("--aa: needs --renderer tiler (VTK antialiases by supersampling: fly --samples)");
  }
  if (c.engine == scene::Engine::kVtk && given(args.texel_rate_option)) {
    throw std::invalid_argument("--texel-rate: needs --renderer tiler");
  }
  if (!(c.texel_rate >= 0.0) || !std::isfinite(c.texel_rate)) {
    throw std::invalid_argument("--texel-rate " + std::to_string(c.texel_rate) + ": expected a finite number >= 0");
  }
  return c;
}

void check_tiler_size(const RendererChoice& choice, int width, int height) {
  if (choice.engine != scene::Engine::kTiler) return;
  const int most = 16384 / choice.aa;
  if (width > most || height > most) {
    throw std::invalid_argument("--size " + std::to_string(width) + "x" + std::to_string(height) + " at --aa " +
                                std::to_string(choice.aa) + ": at most 16384 samples per side (" + std::to_string(most) +
                                " pixels)");
  }
}

scene::SceneStyle given_style(const SceneArgs& args) {
  const StyleArgs& s = args.style;
  const auto given = [](const CLI::Option* o) { return o != nullptr && o->count() > 0; };
  scene::SceneStyle g;
  if (given(s.size_option)) {
    int w = 0, h = 0;
    scene::parse_size(s.size, w, h);
    g.width = w;
    g.height = h;
  }
  if (given(s.metric_option)) g.lod_metric = s.metric;
  if (given(s.threshold_option)) g.threshold = s.threshold;
  if (given(s.order_option)) g.order = s.order;
  if (given(s.tint_option)) g.tint = s.tint;
  if (given(s.window_option)) g.window = s.window;
  if (given(s.haze_option)) g.haze_km = s.haze_km;
  if (given(s.sun_azimuth_option)) g.sun_azimuth = s.sun_azimuth;
  if (given(s.sun_elevation_option)) g.sun_elevation = s.sun_elevation;
  if (given(s.surface_option)) g.surface_triangles = s.surface_triangles;
  if (given(s.occlusion_option)) g.occlusion = s.occlusion;
  if (given(s.coherence_option)) g.coherence = s.coherence;
  if (given(s.density_threshold_option)) g.density_threshold = s.density_threshold;
  if (given(s.density_error_option)) g.density_error = s.density_error;
  if (args.no_legend) g.legend = false;
  if (args.no_markers) g.markers = false;
  return g;
}

scene::SceneSpec read_scene_args(const SceneArgs& args, std::vector<std::filesystem::path>& dems) {
  scene::SceneSpec scene;
  if (!args.scene.empty()) scene = scene::load_scene_file(args.scene);
  if (dems.empty()) dems = scene.dems;
  if (dems.empty()) throw std::invalid_argument("no DEM: give DEM files or a scene file with \"dem\"");
  scene.dems = dems;
  scene.style = scene::overlay(scene.style, given_style(args));
  const std::string& frame = args.volume_frame;
  if (!frame.empty()) {
    try {
      volume::parse_frame(frame);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("--volume-frame " + frame + ": " + e.what());
    }
  }
  // Each volume's --iso levels: those without a colour take the palette's by their place among
  // every volume's, as in a scene file (volume v's level k is the (v * levels + k)-th).
  const auto iso_specs = [&](std::size_t volume_index) {
    std::vector<volume::IsoSpec> specs;
    for (std::size_t k = 0; k < args.isos.size(); ++k) {
      specs.push_back(volume::parse_isosurface(args.isos[k], volume_index * args.isos.size() + k));
    }
    return specs;
  };
  const std::vector<volume::IsoSpec> checked = iso_specs(0);  // bad levels fail here, volumes or not
  std::vector<volume::SliceSpec> slice_specs;
  for (const auto& text : args.slices) slice_specs.push_back(volume::parse_slice(text));
  std::optional<density::DensitySpec> density;
  if (!args.density.empty()) density = density::parse_density(args.density);
  for (scene::ObjectSpec& o : parse_objects(args.objects)) scene.objects.push_back(std::move(o));
  if (args.volumes.empty() && scene.volumes.empty()) {
    // Options for volumes, with no volume: an error, not a picture without what they asked for.
    const std::pair<const char*, bool> styling[] = {{"--iso", !args.isos.empty()},
                                                    {"--slice", !args.slices.empty()},
                                                    {"--density", density.has_value()},
                                                    {"--field", !args.field.empty()},
                                                    {"--volume-frame", !frame.empty()}};
    for (const auto& [name, given] : styling) {
      if (given) {
        throw std::invalid_argument(std::string(name) +
                                    " needs a volume: give --volume FILE (or a scene file with \"volumes\")");
      }
    }
  }
  if (args.volumes.empty()) {
    for (std::size_t k = 0; k < scene.volumes.size(); ++k) {
      scene::VolumeSpec& v = scene.volumes[k];
      if (!checked.empty()) v.isosurfaces = iso_specs(k);
      if (!slice_specs.empty()) v.slices = slice_specs;
      if (density) v.density = density;
    }
    return scene;
  }
  for (const auto& f : args.volumes) {
    scene::VolumeSpec v;
    v.file = f;
    v.field = args.field;
    v.frame = frame;
    v.isosurfaces = iso_specs(scene.volumes.size());
    v.slices = slice_specs;
    v.density = density;
    scene.volumes.push_back(std::move(v));
  }
  return scene;
}

}  // namespace terravol::app::cli
