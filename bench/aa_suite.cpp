// 11. Antialiasing (issue 14): the coverage-mask tiler (tiler/, Greene 1996) against VTK's
// box-filtered supersampling (`fly --samples`: the frame drawn n times larger and averaged down),
// side by side, with a 16 x 16-sample reference drawn by VTK in tiles.
#include <vtkCamera.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkRenderer.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "app/output/frame_sink.h"
#include "app/output/png_output.h"
#include "app/output/write_file.h"
#include "app/render/scene_renderer.h"
#include "app/render/tiled_renderer.h"
#include "app/scene/style.h"
#include "bench/image_metrics.h"
#include "bench/stats.h"
#include "bench/suite_common.h"
#include "bench/suites.h"

namespace terravol::bench {

namespace {

using nlohmann::json;
using app::render::SceneRenderer;
using app::render::TerrainRenderer;
using app::render::TiledRenderer;

// Output pixels per side of a reference tile: the largest divisor of `pixels` whose tile of
// `factor` times as many samples stays within `limit` (llvmpipe's GL limit is 16384; smaller
// tiles keep the read-back buffers small).
int tile_pixels(int pixels, int factor, int limit) {
  for (int parts = 1; parts <= pixels; ++parts)
    if (pixels % parts == 0 && pixels / parts * factor <= limit) return pixels / parts;
  return 1;
}

// The view's sky and look as `terravol render` draws it: the gradient for the pitch, 60 km haze.
struct Look {
  std::array<app::scene::Rgb, 2> sky;
  double haze_m = 0;
  app::scene::Rgb haze_color{};
};

// A VTK renderer drawing the scene's last (back-to-front) frame at `factor` times the size.
struct VtkConfig {
  std::string name;
  int factor = 1;
  std::unique_ptr<TerrainRenderer> renderer;
};

// Draws `scene`'s last frame with VTK at `factor` times width x height and box-filters it down:
// `fly --samples factor^2` (its upload, draw, read-back and filter). Returns the image; `ms` gets
// the time.
std::vector<std::uint8_t> draw_vtk(const SceneRenderer& scene, TerrainRenderer& r, int factor, int width, int height,
                                   const Look& look, double& ms) {
  scene.sync_vertices(r);
  r.set_camera(scene.camera(), scene.terrain().far_plane(scene.camera().eye));
  r.set_background(look.sky[0], look.sky[1]);
  const auto t0 = Clock::now();
  r.set_frame(scene.last_frame());
  r.render();
  std::vector<std::uint8_t> rgb = app::render::window_rgb(r.window());
  if (factor > 1) rgb = app::output::downsample_box(rgb, width, height, factor);
  ms = ms_since(t0);
  return rgb;
}

// The reference: the same frame drawn by VTK at `factor` times the size in tiles (each through
// an off-centre projection: the full view's projection scaled and shifted onto the tile, the sky
// gradient cut to the tile's rows), the samples averaged per output pixel.
std::vector<std::uint8_t> draw_reference(const SceneRenderer& scene, TerrainRenderer& r, int tile_w, int tile_h,
                                         int factor, int width, int height, const Look& look) {
  scene.sync_vertices(r);
  r.set_camera(scene.camera(), scene.terrain().far_plane(scene.camera().eye));
  r.set_frame(scene.last_frame());
  vtkCamera* cam = r.camera();
  cam->SetUseExplicitProjectionTransformMatrix(false);
  vtkNew<vtkMatrix4x4> full;
  full->DeepCopy(cam->GetProjectionTransformMatrix(static_cast<double>(width) / height, -1, 1));
  const double big_w = static_cast<double>(width) * factor, big_h = static_cast<double>(height) * factor;
  const double tw = static_cast<double>(tile_w) * factor, th = static_cast<double>(tile_h) * factor;
  std::vector<double> sum(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3, 0.0);
  for (int ty = 0; ty < height / tile_h; ++ty) {
    for (int tx = 0; tx < width / tile_w; ++tx) {
      const double x0 = tx * tw, y0 = ty * th;  // the tile's lower-left sample, from the bottom-left
      vtkNew<vtkMatrix4x4> shift;
      shift->SetElement(0, 0, big_w / tw);
      shift->SetElement(0, 3, (big_w - 2.0 * x0 - tw) / tw);
      shift->SetElement(1, 1, big_h / th);
      shift->SetElement(1, 3, (big_h - 2.0 * y0 - th) / th);
      vtkNew<vtkMatrix4x4> m;
      vtkMatrix4x4::Multiply4x4(shift, full, m);
      cam->SetExplicitProjectionTransformMatrix(m);
      cam->SetUseExplicitProjectionTransformMatrix(true);
      double bottom[3], top[3];
      for (int k = 0; k < 3; ++k) {
        const double b = look.sky[0][static_cast<std::size_t>(k)], t = look.sky[1][static_cast<std::size_t>(k)];
        bottom[k] = (b + (t - b) * y0 / big_h) / 255.0;
        top[k] = (b + (t - b) * (y0 + th) / big_h) / 255.0;
      }
      r.renderer()->SetBackground(bottom);
      r.renderer()->SetBackground2(top);
      r.render();
      const std::vector<std::uint8_t> rgb = app::render::window_rgb(r.window());
      // Tile row k (from its top) is output row (height - (ty + 1) tile_h) + k / factor.
      const int row0 = height - (ty + 1) * tile_h;
      for (int y = 0; y < static_cast<int>(th); ++y) {
        const std::size_t out_row = static_cast<std::size_t>(row0 + y / factor) * static_cast<std::size_t>(width);
        for (int x = 0; x < static_cast<int>(tw); ++x) {
          const std::size_t o = 3 * (out_row + static_cast<std::size_t>(tx * tile_w + x / factor));
          const std::size_t i = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(tw) + static_cast<std::size_t>(x));
          for (std::size_t k = 0; k < 3; ++k) sum[o + k] += rgb[i + k];
        }
      }
    }
  }
  cam->SetUseExplicitProjectionTransformMatrix(false);
  std::vector<std::uint8_t> out(sum.size());
  const double n = static_cast<double>(factor) * factor;
  for (std::size_t i = 0; i < sum.size(); ++i) out[i] = static_cast<std::uint8_t>(std::lround(sum[i] / n));
  return out;
}

void save_png(const std::filesystem::path& dir, const std::string& name, const std::vector<std::uint8_t>& rgb, int w, int h) {
  std::filesystem::create_directories(dir);
  const std::vector<std::uint8_t> png = app::output::encode_png(rgb, w, h);
  app::output::write_file_atomically(dir / (name + ".png"), png, true);
}

// One part of the suite: a scene at one size, its views, the configurations side by side.
struct Part {
  std::string name;
  int width = 1280, height = 720;
  std::vector<int> vtk_factors;   // VTK supersampling: 1, 2, 4, 8 (samples 1, 4, 16, 64)
  std::vector<int> tiler_aa;      // the tiler: 1, 2, 4, 8
  bool tiler_occlusion = false;   // also the tiler at 8 x 8 with the tree's occlusion pass at sample resolution
};

json run_part(const BenchConfig& c, const Part& part, const app::scene::SceneSpec& spec,
              const std::function<std::vector<View>(const SceneRenderer&)>& views_of) {
  const int W = part.width, H = part.height;
  const app::scene::Style style = app::scene::resolve_style({});
  app::render::RenderSettings settings = app::render::render_settings(style);
  settings.width = W;
  settings.height = H;
  app::render::SceneOptions options = bench_scene_options();
  SceneRenderer scene(spec, settings, options);
  const std::vector<View> views = views_of(scene);
  const double fov = 45.0;
  mrbsp::TraversalOptions traversal = style.traversal;

  std::vector<VtkConfig> vtk;
  for (int f : part.vtk_factors) {
    app::render::RenderSettings s = settings;
    s.width = W * f;
    s.height = H * f;
    vtk.push_back({"vtk_" + std::to_string(f * f), f, scene.make_renderer(s)});
  }
  std::map<int, std::unique_ptr<TiledRenderer>> tiled;
  for (int aa : part.tiler_aa) {
    tiler::Settings t;
    t.width = W;
    t.height = H;
    t.aa = aa;
    tiled[aa] = std::make_unique<TiledRenderer>(t);
  }
  // The reference's tiles: at most 4096 samples a side.
  constexpr int kRefFactor = 16;
  const int tile_w = tile_pixels(W, kRefFactor, 4096), tile_h = tile_pixels(H, kRefFactor, 4096);
  app::render::RenderSettings ref_settings = settings;
  ref_settings.width = tile_w * kRefFactor;
  ref_settings.height = tile_h * kRefFactor;
  std::unique_ptr<TerrainRenderer> ref_renderer = scene.make_renderer(ref_settings);

  std::map<std::string, std::vector<double>> frame_ms, psnr_db, traversal_ms;
  std::vector<double> ref_ms, occlusion_identical, occlusion_culled, tiler8_vs_vtk16, triangles;
  std::map<std::string, std::vector<double>> tiler_figures;
  mrbsp::Frame f2b, f2b_occ;
  tiler::Stats finest;  // the finest tiler's last draw without occlusion
  for (std::size_t v = 0; v < views.size(); ++v) {
    const app::scene::CameraPose& pose = views[v].pose;
    Look look;
    look.sky = app::scene::sky_gradient(pose.pitch_deg, fov);
    look.haze_m = settings.haze_distance;
    look.haze_color = settings.haze_color;
    std::map<std::string, std::vector<double>> t;  // this view's repeats
    std::map<std::string, std::vector<std::uint8_t>> images;
    const auto draw_tiler = [&](int aa, bool occlusion, mrbsp::Frame& frame) {
      mrbsp::TraversalOptions o = traversal;
      o.occlusion = occlusion;
      o.occlusion_adaptive = false;  // the pass in every frame: its cost and its culling, measured
      const auto t0 = Clock::now();
      scene.terrain().tree().traverse(app::render::tiled_traversal_camera(scene.camera(), o, aa),
                                      app::render::tiled_traversal(o, aa), frame);
      const double trav = ms_since(t0);
      tiled[aa]->draw(scene.terrain().tree(), scene.lattice_shading(), frame, scene.camera(),
                      scene.terrain().far_plane(scene.camera().eye), look.sky[0], look.sky[1], look.haze_m, look.haze_color);
      return std::pair<double, double>(trav, ms_since(t0));
    };
    for (int r = -1; r < c.repeats; ++r) {  // r = -1: the untimed warm-up
      const app::render::FrameStats s = scene.prepare(pose, true, fov, traversal);
      if (s.slides > 0) throw std::runtime_error("aa " + part.name + ": the window slid; views must stay inside");
      for (VtkConfig& k : vtk) {
        double ms = 0;
        images[k.name] = draw_vtk(scene, *k.renderer, k.factor, W, H, look, ms);
        if (r >= 0) t[k.name].push_back(s.traversal_ms + ms);
      }
      if (r >= 0) t["traversal_back_to_front"].push_back(s.traversal_ms);
      for (int aa : part.tiler_aa) {
        const auto [trav, ms] = draw_tiler(aa, false, f2b);
        const std::string name = "tiler_" + std::to_string(aa * aa);
        images[name] = tiled[aa]->rgb();
        if (r >= 0) {
          t[name].push_back(ms);
          if (aa == part.tiler_aa.back()) t["traversal_front_to_back"].push_back(trav);
        }
        if (aa == part.tiler_aa.back()) finest = tiled[aa]->stats();
      }
      if (part.tiler_occlusion) {
        const int aa = part.tiler_aa.back();
        const auto [trav, ms] = draw_tiler(aa, true, f2b_occ);
        images["tiler_occlusion"] = tiled[aa]->rgb();
        if (r >= 0) {
          t["tiler_" + std::to_string(aa * aa) + "_occlusion"].push_back(ms);
          t["traversal_occlusion"].push_back(trav);
        }
      }
    }
    triangles.push_back(static_cast<double>(scene.last_frame().indices.size() / 3));
    const tiler::Stats& ts = finest;
    const double pixels = static_cast<double>(W) * H;
    tiler_figures["cells_visited_per_pixel"].push_back(static_cast<double>(ts.cells_visited) / pixels);
    tiler_figures["fragments_per_pixel"].push_back(static_cast<double>(ts.fragments) / pixels);
    tiler_figures["shading_points_per_pixel"].push_back(static_cast<double>(ts.shading_points) / pixels);
    tiler_figures["translucent_triangles"].push_back(static_cast<double>(ts.translucent));
    if (part.tiler_occlusion) {
      const std::string plain = "tiler_" + std::to_string(part.tiler_aa.back() * part.tiler_aa.back());
      occlusion_identical.push_back(share_differing(images["tiler_occlusion"], images[plain], W, H, 0) == 0.0 ? 1.0 : 0.0);
      occlusion_culled.push_back(static_cast<double>(f2b_occ.occlusion.culled_leaves));
    }
    const auto r0 = Clock::now();
    const std::vector<std::uint8_t> ref = draw_reference(scene, *ref_renderer, tile_w, tile_h, kRefFactor, W, H, look);
    ref_ms.push_back(ms_since(r0));
    for (auto& [name, ms] : t) frame_ms[name].push_back(median(ms));
    for (const auto& [name, image] : images) {
      if (name == "tiler_occlusion") continue;
      psnr_db[name].push_back(std::min(99.0, psnr(image, ref, W, H)));
    }
    if (images.count("tiler_64") && images.count("vtk_16")) {
      tiler8_vs_vtk16.push_back(std::min(99.0, psnr(images["tiler_64"], images["vtk_16"], W, H)));
    }
    if (v == 0) {
      const std::filesystem::path dir = c.out / "aa";
      save_png(dir, part.name + "-reference", ref, W, H);
      for (const auto& [name, image] : images) save_png(dir, part.name + "-" + name, image, W, H);
    }
    char line[240];
    std::snprintf(line, sizeof line, "aa %s: view %zu/%zu  vtk_1 %.0f ms, vtk_16 %.0f ms, tiler_16 %.0f ms, tiler_64 %.0f ms",
                  part.name.c_str(), v + 1, views.size(), frame_ms["vtk_1"].back(),
                  frame_ms.count("vtk_16") ? frame_ms["vtk_16"].back() : 0.0,
                  frame_ms.count("tiler_16") ? frame_ms["tiler_16"].back() : 0.0, frame_ms["tiler_64"].back());
    say(c, line);
  }

  json out;
  out["part"] = part.name;
  out["width"] = W;
  out["height"] = H;
  out["views"] = views.size();
  out["reference"] = {{"samples_per_pixel", kRefFactor * kRefFactor},
                      {"tile_samples", {tile_w * kRefFactor, tile_h * kRefFactor}},
                      {"tiles", (W / tile_w) * (H / tile_h)},
                      {"ms", to_json(summarize(ref_ms))}};
  out["triangles"] = to_json(summarize(triangles));
  for (const auto& [name, v] : frame_ms) out["frame_ms"][name] = to_json(summarize(v));
  for (const auto& [name, v] : psnr_db) out["psnr_db"][name] = to_json(summarize(v));
  for (const auto& [name, v] : tiler_figures) out["tiler_64_figures"][name] = to_json(summarize(v));
  // Ratios per view, then summarised (the table).
  const auto ratio = [&](const std::string& a, const std::string& b) {
    std::vector<double> r;
    if (!frame_ms.count(a) || !frame_ms.count(b)) return json();
    for (std::size_t v = 0; v < frame_ms[a].size(); ++v) r.push_back(frame_ms[a][v] / frame_ms[b][v]);
    return to_json(summarize(r));
  };
  out["ratios"]["vtk_16_over_tiler_16"] = ratio("vtk_16", "tiler_16");
  out["ratios"]["tiler_64_over_vtk_16"] = ratio("tiler_64", "vtk_16");
  out["ratios"]["tiler_64_over_vtk_1"] = ratio("tiler_64", "vtk_1");
  out["ratios"]["vtk_64_over_tiler_64"] = ratio("vtk_64", "tiler_64");
  if (!tiler8_vs_vtk16.empty()) out["psnr_db_tiler_64_vs_vtk_16"] = to_json(summarize(tiler8_vs_vtk16));
  if (part.tiler_occlusion) {
    out["occlusion"] = {{"images_identical", summarize(occlusion_identical).median},
                        {"images_identical_min", summarize(occlusion_identical).min},
                        {"culled_leaves", to_json(summarize(occlusion_culled))},
                        {"tiler_64_over_tiler_64_occlusion", ratio("tiler_64", "tiler_64_occlusion")}};
  }
  return out;
}

}  // namespace

json aa_suite(const BenchConfig& c, const Terrain& terrain, const std::vector<volume::Transmitter>& transmitters) {
  json out;
  out["terrain"] = terrain.name;
  {
    say(c, "aa " + terrain.name + ": the terrain at " + std::to_string(c.width) + "x" + std::to_string(c.height));
    const app::scene::SceneSpec spec = terrain_spec(terrain);
    Part part;
    part.name = terrain.name + "-terrain";
    part.width = c.width;
    part.height = c.height;
    part.vtk_factors = {1, 2, 4, 8};
    part.tiler_aa = {1, 2, 4, 8};
    part.tiler_occlusion = true;
    out["terrain_views"] =
        run_part(c, part, spec, [&](const SceneRenderer& s) { return flythrough(s.terrain().bounds(), c.volume_views); });
  }
  if (!transmitters.empty()) {
    say(c, "aa " + terrain.name + ": the benchmark volumes at 1920x1080");
    const VolumeScene vs = three_volume_scene(terrain, transmitters, c.cache, c.log);
    app::scene::SceneSpec spec = vs.spec;
    spec.camera = terrain_spec(terrain, vs.lat, vs.lon).camera;  // the window centred on the volumes
    Part part;
    part.name = terrain.name + "-volumes";
    part.width = 1920;
    part.height = 1080;
    part.vtk_factors = {1, 4};
    part.tiler_aa = {4, 8};
    out["volume_views"] = run_part(c, part, spec, [&](const SceneRenderer& s) {
      return orbit(vs.lat, vs.lon, volume_orbit_km(s.terrain().bounds(), vs.lat), 2500.0, -22.0,
                   std::max(1, c.volume_views / 2));
    });
  }
  return out;
}

}  // namespace terravol::bench
