#include "bench/suites.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <memory>

#include "app/output/png_output.h"
#include "app/render/scene_renderer.h"
#include "app/scene/volume_layer.h"
#include "bench/image_metrics.h"
#include "bench/plain_vtk.h"
#include "bench/suite_common.h"
#include "bench/stats.h"
#include "io/mosaic.h"
#include "volume/splat.h"

#include <sys/resource.h>

namespace terravol::bench {

namespace {

using nlohmann::json;

// The full-resolution lattice of the scene's window drawn by plain VTK, with a translucent
// overlay (empty: none).
std::unique_ptr<PlainVtkScene> plain_scene(const app::render::SceneRenderer& scene, const volume::Mesh& overlay,
                                           Translucency translucency, const BenchConfig& c) {
  const int n = scene.terrain().cells();
  const auto& positions = scene.terrain().tree().positions();
  const std::size_t lattice = static_cast<std::size_t>(n + 1) * static_cast<std::size_t>(n + 1);
  const std::vector<std::uint32_t> triangles = lattice_triangles(n);
  PlainVtkOptions o;
  o.width = c.width;
  o.height = c.height;
  o.translucency = translucency;
  o.background = plain_settings(c).background;
  return std::make_unique<PlainVtkScene>(std::span(positions.data(), lattice), scene.lattice_shading().rgba,
                                         triangles, overlay.vertices, overlay.colors, overlay.triangles, o);
}

double far_plane(const app::render::SceneRenderer& scene) { return scene.terrain().far_plane(scene.camera().eye); }

}  // namespace

json terrain_suite(const BenchConfig& c, const Terrain& terrain) {
  say(c, "terrain " + terrain.name + ": building the 1024-cell window");
  app::render::SceneRenderer scene(terrain_spec(terrain), plain_settings(c), bench_scene_options());
  auto plain = plain_scene(scene, {}, Translucency::kPeel4, c);
  const std::vector<View> views = flythrough(scene.terrain().bounds(), c.views);

  struct Config {
    mrbsp::LodMetric metric = mrbsp::LodMetric::kError;
    double t = 1.0;
    bool occlusion = false;  // then compared with the configuration of index `off`
    std::size_t off = 0;
    std::vector<double> traversal, upload, draw, frame, triangles, psnr, ssim, share8, ratio;
    std::vector<double> identical, occlusion_ms, tested;  // occlusion on: per view
    std::vector<std::uint8_t> image;                      // the last view's
  };
  std::vector<Config> configs;
  for (auto metric : {mrbsp::LodMetric::kError, mrbsp::LodMetric::kArea})
    for (double t : {0.5, 1.0, 2.0, 4.0}) {
      Config k;
      k.metric = metric;
      k.t = t;
      configs.push_back(std::move(k));
    }
  // Occlusion culling (Greene 1996) side by side with the same thresholds without it.
  for (std::size_t off : {std::size_t{1}, std::size_t{2}}) {
    Config k;
    k.metric = mrbsp::LodMetric::kError;
    k.t = configs[off].t;
    k.occlusion = true;
    k.off = off;
    configs.push_back(std::move(k));
  }
  std::vector<double> plain_ms, full_triangles, plain_psnr;
  mrbsp::TraversalOptions full;
  full.full_res = true;

  for (std::size_t v = 0; v < views.size(); ++v) {
    const app::scene::CameraPose& pose = views[v].pose;
    // The reference image: every triangle of the window at the finest level, in tree order.
    const app::render::FrameStats ref = scene.render(pose, true, 45.0, full);
    const std::vector<std::uint8_t> reference = scene.rgb();
    full_triangles.push_back(static_cast<double>(ref.triangles));
    plain->set_camera(scene.camera(), far_plane(scene));
    if (v == 0) plain->render();  // warm-up: the first draw uploads the geometry
    std::vector<double> p;
    for (int r = 0; r < c.repeats; ++r) p.push_back(plain->render());
    plain_ms.push_back(median(p));
    plain_psnr.push_back(psnr(plain->rgb(), reference, c.width, c.height));

    for (Config& k : configs) {
      mrbsp::TraversalOptions o = lod(k.metric, k.t);
      o.occlusion = k.occlusion;
      if (v == 0) scene.render(pose, true, 45.0, o);  // warm-up
      std::vector<double> tr, up, dr, fr;
      app::render::FrameStats s;
      for (int r = 0; r < c.repeats; ++r) {
        s = scene.render(pose, true, 45.0, o);
        tr.push_back(s.traversal_ms);
        up.push_back(s.upload_ms);
        dr.push_back(s.draw_ms);
        fr.push_back(frame_ms(s));
      }
      std::vector<std::uint8_t> image = scene.rgb();
      if (k.occlusion) {
        k.identical.push_back(image == configs[k.off].image ? 1.0 : 0.0);
        k.occlusion_ms.push_back(scene.last_frame().occlusion.pass_ms);
        k.tested.push_back(static_cast<double>(scene.last_frame().occlusion.tested_nodes));
      }
      k.traversal.push_back(median(tr));
      k.upload.push_back(median(up));
      k.draw.push_back(median(dr));
      k.frame.push_back(median(fr));
      k.triangles.push_back(static_cast<double>(s.triangles));
      k.psnr.push_back(std::min(99.0, psnr(image, reference, c.width, c.height)));
      k.ssim.push_back(ssim(image, reference, c.width, c.height));
      k.share8.push_back(share_differing(image, reference, c.width, c.height, 8));
      k.ratio.push_back(plain_ms.back() / k.frame.back());
      k.image = std::move(image);
    }
    char b[160];
    std::snprintf(b, sizeof b, "terrain %s: view %zu/%zu  plain VTK %.0f ms, MRBSP 1 px %.1f ms", terrain.name.c_str(),
                  v + 1, views.size(), plain_ms.back(), configs[1].frame.back());
    say(c, b);
  }

  json out;
  out["terrain"] = terrain.name;
  out["window_cells"] = scene.terrain().cells();
  out["levels"] = scene.terrain().tree().levels();
  out["views"] = views.size();
  out["repeats"] = c.repeats;
  out["plain_vtk"] = {{"frame_ms", to_json(summarize(plain_ms))},
                      {"triangles", plain->triangles()},
                      {"full_res_in_view", to_json(summarize(full_triangles))},
                      {"psnr_against_reference", to_json(summarize(plain_psnr))},
                      {"per_view_ms", plain_ms}};
  json list = json::array();
  for (const Config& k : configs) {
    json j;
    j["metric"] = k.metric == mrbsp::LodMetric::kError ? "error" : "area";
    j["threshold"] = k.t;
    j["threshold_px_or_px2"] = lod(k.metric, k.t).threshold_px;
    j["occlusion"] = k.occlusion;
    if (k.occlusion) {
      j["images_identical_to_off"] =
          std::accumulate(k.identical.begin(), k.identical.end(), 0.0) / static_cast<double>(k.identical.size());
      j["occlusion_pass_ms"] = to_json(summarize(k.occlusion_ms));
      j["occlusion_tested_nodes"] = to_json(summarize(k.tested));
      j["frame_off_over_on"] = summarize(configs[k.off].frame).median / summarize(k.frame).median;
    }
    j["traversal_ms"] = to_json(summarize(k.traversal));
    j["upload_ms"] = to_json(summarize(k.upload));
    j["draw_ms"] = to_json(summarize(k.draw));
    j["frame_ms"] = to_json(summarize(k.frame));
    j["triangles"] = to_json(summarize(k.triangles));
    j["psnr_db"] = to_json(summarize(k.psnr));
    j["ssim"] = to_json(summarize(k.ssim));
    j["share_over_8"] = to_json(summarize(k.share8));
    j["plain_over_mrbsp"] = to_json(summarize(k.ratio));
    j["per_view_ms"] = k.frame;
    j["per_view_triangles"] = k.triangles;
    list.push_back(j);
  }
  out["mrbsp"] = list;
  out["headline_ratio_1px"] = summarize(configs[1].ratio).median;
  return out;
}

json translucency_suite(const BenchConfig& c, const Terrain& terrain, const std::vector<volume::Transmitter>& transmitters) {
  const VolumeScene vs = three_volume_scene(terrain, transmitters, c.cache, c.log);
  app::scene::SceneSpec spec = vs.spec;
  spec.camera = terrain_spec(terrain, vs.lat, vs.lon).camera;  // the window centred on the volumes
  say(c, "translucency " + terrain.name + ": reading the volumes and merging them into the tree");
  app::render::SceneRenderer scene(spec, plain_settings(c), bench_scene_options());
  const app::scene::MergeFigures merged = scene.merge_figures();
  const mrbsp::MemoryStats memory = scene.terrain().tree().memory();

  // The same traversal in VTK's orders.
  auto order = [&](app::scene::DrawOrder o, int peels) {
    app::render::RenderSettings s = plain_settings(c);
    s.order = o;
    s.peels = peels;
    return scene.make_renderer(s);
  };
  auto peel_exact = order(app::scene::DrawOrder::kPeel, 0);
  auto peel4 = order(app::scene::DrawOrder::kPeel, 4);
  auto oit = order(app::scene::DrawOrder::kVtk, 0);

  // What a ParaView user would draw: the full lattice and undecimated geometry.
  say(c, "translucency " + terrain.name + ": the plain VTK pipeline (undecimated geometry)");
  const io::Mosaic mosaic = io::Mosaic::open(spec.dems);
  const auto t0 = Clock::now();
  const app::scene::VolumeLayer raw(spec.volumes, mosaic, scene.frame(), 0);
  const volume::Mesh raw_mesh = raw.visible_mesh();
  const double raw_geometry_ms = ms_since(t0);
  auto plain4 = plain_scene(scene, raw_mesh, Translucency::kPeel4, c);
  auto plain_exact = plain_scene(scene, raw_mesh, Translucency::kPeelExact, c);

  // Views around the volumes, within the central half of the window (no slides).
  const double range_km = volume_orbit_km(scene.terrain().bounds(), vs.lat);
  const std::vector<View> views = orbit(vs.lat, vs.lon, range_km, 2500.0, -22.0, c.volume_views);
  const mrbsp::TraversalOptions lod_default;

  std::map<std::string, std::vector<double>> ms, err3, psnr_db, ratio;
  std::vector<double> triangles, merged_triangles, plain_triangles;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const app::scene::CameraPose& pose = views[v].pose;
    if (v == 0) scene.render(pose, true, 45.0, lod_default);  // warm-up
    std::vector<double> t_bsp;
    app::render::FrameStats s;
    for (int r = 0; r < c.repeats; ++r) {
      s = scene.render(pose, true, 45.0, lod_default);
      t_bsp.push_back(frame_ms(s));
    }
    if (s.slides > 0) throw std::runtime_error("translucency " + terrain.name + ": the window slid; views must stay inside");
    triangles.push_back(static_cast<double>(s.triangles));
    merged_triangles.push_back(static_cast<double>(s.merged_triangles));
    const std::vector<std::uint8_t> bsp = scene.rgb();
    ms["bsp"].push_back(median(t_bsp));
    const double far = far_plane(scene);

    std::map<std::string, std::vector<std::uint8_t>> images;
    auto time_order = [&](const std::string& name, app::render::TerrainRenderer& r) {
      scene.sync_vertices(r);  // the low alternatives this view's traversal built
      r.set_camera(scene.camera(), far);
      if (v == 0) {
        r.set_frame(scene.last_frame());
        r.render();
      }
      std::vector<double> t;
      for (int k = 0; k < c.repeats; ++k) {
        const auto u0 = Clock::now();
        r.set_frame(scene.last_frame());  // what a frame costs in this order: the upload and the draw
        const double upload = ms_since(u0);
        t.push_back(upload + r.render());
      }
      ms[name].push_back(median(t) + s.traversal_ms);  // the traversal is shared
      images[name] = app::render::window_rgb(r.window());
    };
    time_order("peel_exact", *peel_exact);
    time_order("peel4", *peel4);
    time_order("vtk_default", *oit);
    auto time_plain = [&](const std::string& name, PlainVtkScene& p) {
      p.set_camera(scene.camera(), far);
      if (v == 0) p.render();
      std::vector<double> t;
      for (int k = 0; k < c.repeats; ++k) t.push_back(p.render());
      ms[name].push_back(median(t));
      images[name] = p.rgb();
    };
    time_plain("plain_peel4", *plain4);
    time_plain("plain_peel_exact", *plain_exact);
    plain_triangles.push_back(static_cast<double>(plain4->triangles()));

    const auto& exact = images["peel_exact"];
    for (const auto& [name, image] : std::vector<std::pair<std::string, const std::vector<std::uint8_t>*>>{
             {"bsp", &bsp}, {"peel4", &images["peel4"]}, {"vtk_default", &images["vtk_default"]}}) {
      err3[name].push_back(share_differing(*image, exact, c.width, c.height, 3));
      psnr_db[name].push_back(std::min(99.0, psnr(*image, exact, c.width, c.height)));
    }
    // The plain pipeline against its own exact image (same geometry).
    err3["plain_peel4"].push_back(
        share_differing(images["plain_peel4"], images["plain_peel_exact"], c.width, c.height, 3));
    psnr_db["plain_peel4"].push_back(std::min(99.0, psnr(images["plain_peel4"], images["plain_peel_exact"], c.width, c.height)));
    for (const char* name : {"peel_exact", "peel4", "vtk_default", "plain_peel4", "plain_peel_exact"})
      ratio[name].push_back(ms[name].back() / ms["bsp"].back());
    char b2[200];
    std::snprintf(b2, sizeof b2, "translucency %s: view %zu/%zu  bsp %.0f ms, peel %.0f ms, plain peel4 %.0f ms",
                  terrain.name.c_str(), v + 1, views.size(), ms["bsp"].back(), ms["peel_exact"].back(),
                  ms["plain_peel4"].back());
    say(c, b2);
  }

  json out;
  out["terrain"] = terrain.name;
  out["views"] = views.size();
  out["orbit_km"] = range_km;
  out["merge"] = json{{"input_triangles", merged.input_triangles},
                  {"tree_polygons", merged.tree_triangles},
                  {"geometry_ms", merged.geometry_ms},
                  {"merge_ms", merged.merge_ms},
                  {"merged_bytes", memory.merged},
                  {"undecimated_triangles", raw_mesh.triangle_count()},
                  {"undecimated_geometry_ms", raw_geometry_ms}};
  out["triangles"] = to_json(summarize(triangles));
  out["merged_triangles"] = to_json(summarize(merged_triangles));
  out["plain_triangles"] = to_json(summarize(plain_triangles));
  for (const auto& [name, v] : ms) out["frame_ms"][name] = to_json(summarize(v));
  for (const auto& [name, v] : ratio) out["ratio_over_bsp"][name] = to_json(summarize(v));
  for (const auto& [name, v] : err3) out["share_over_3"][name] = to_json(summarize(v));
  for (const auto& [name, v] : psnr_db) out["psnr_db"][name] = to_json(summarize(v));

  // 5. Responsiveness: from the change to the next finished frame, as the viewer sees it.
  say(c, "translucency " + terrain.name + ": responsiveness");
  const app::scene::CameraPose pose = views.front().pose;
  std::vector<double> threshold_ms, slice_ms, slice_merge_ms;
  for (int r = 0; r < std::max(3, c.repeats); ++r) {
    const auto u0 = Clock::now();
    scene.render(pose, true, 45.0, lod(mrbsp::LodMetric::kError, r % 2 ? 2.0 : 1.0));
    threshold_ms.push_back(ms_since(u0));
  }
  // An edit of one surface, then the re-merge and the next finished frame (total, of it merge).
  const auto time_edit = [&](const std::function<void(int)>& edit, std::vector<double>& total,
                             std::vector<double>& merge) {
    for (int r = 0; r < std::max(2, c.repeats - 1); ++r) {
      const auto u0 = Clock::now();
      edit(r);
      merge.push_back(scene.remerge().merge_ms);
      scene.render(pose, true, 45.0, lod_default);
      total.push_back(ms_since(u0));
    }
  };
  time_edit(
      [&](int r) {
        volume::SliceSpec slice = spec.volumes[0].slices.at(0);
        slice.value += r % 2 ? 0.0 : 50.0;
        scene.volumes().set_slice(0, 0, slice);
      },
      slice_ms, slice_merge_ms);
  std::vector<double> iso_ms, iso_merge_ms;
  time_edit(
      [&](int r) {
        volume::IsoSpec iso = spec.volumes[0].isosurfaces.at(0);
        iso.value += r % 2 ? 0.0f : 3.0f;
        scene.volumes().set_isosurface(0, 0, iso);
      },
      iso_ms, iso_merge_ms);
  out["responsiveness"] = {{"threshold_change_ms", to_json(summarize(threshold_ms))},
                           {"slice_move_ms", to_json(summarize(slice_ms))},
                           {"slice_move_merge_ms", to_json(summarize(slice_merge_ms))},
                           {"isovalue_change_ms", to_json(summarize(iso_ms))},
                           {"isovalue_change_merge_ms", to_json(summarize(iso_merge_ms))}};
  return out;
}

json scaling_suite(const BenchConfig& c, const std::vector<Terrain>& terrains) {
  json list = json::array();
  for (std::size_t k = 0; k < terrains.size(); ++k) {
    const Terrain& t = terrains[k];
    say(c, "scaling " + t.name + ": building its largest window");
    const auto t0 = Clock::now();
    app::render::SceneRenderer scene(terrain_spec(t), plain_settings(c), bench_scene_options(4096));
    const double build_ms = ms_since(t0);
    const app::scene::WindowBounds b = scene.terrain().bounds();
    View view;
    view.pose.lat = 0.5 * (b.south + b.north);
    view.pose.lon = 0.5 * (b.west + b.east);
    view.pose.alt = 2500.0;
    view.pose.heading_deg = 30.0;
    view.pose.pitch_deg = -20.0;
    const mrbsp::TraversalOptions one = lod(mrbsp::LodMetric::kError, 1.0);
    scene.render(view.pose, true, 45.0, one);  // warm-up
    std::vector<double> fr, tr;
    app::render::FrameStats s;
    for (int r = 0; r < std::max(3, c.repeats); ++r) {
      s = scene.render(view.pose, true, 45.0, one);
      fr.push_back(frame_ms(s));
      tr.push_back(s.traversal_ms);
    }
    const std::size_t n = static_cast<std::size_t>(scene.terrain().cells());
    json j;
    j["terrain"] = t.name;
    j["tiles"] = t.tiles;
    j["window_cells"] = n;
    j["samples"] = (n + 1) * (n + 1);
    j["scene_build_ms"] = build_ms;
    j["tree_bytes"] = scene.terrain().tree().memory().total();
    j["mrbsp_frame_ms"] = to_json(summarize(fr));
    j["mrbsp_traversal_ms"] = to_json(summarize(tr));
    j["mrbsp_triangles"] = s.triangles;
    j["mrbsp_nodes_visited"] = s.nodes_visited;
    const bool largest = k + 1 == terrains.size();
    if (c.plain_largest || !largest) {
      say(c, "scaling " + t.name + ": plain VTK at full resolution");
      auto plain = plain_scene(scene, {}, Translucency::kPeel4, c);
      plain->set_camera(scene.camera(), far_plane(scene));
      plain->render();  // warm-up (uploads the geometry)
      std::vector<double> p;
      for (int r = 0; r < std::max(2, c.repeats - 1); ++r) p.push_back(plain->render());
      j["plain_frame_ms"] = to_json(summarize(p));
      j["plain_triangles"] = plain->triangles();
    }
    char b2[200];
    std::snprintf(b2, sizeof b2, "scaling %s: %zu samples, MRBSP %.1f ms, %zu triangles", t.name.c_str(),
                  (n + 1) * (n + 1), summarize(fr).median, s.triangles);
    say(c, b2);
    list.push_back(j);
  }
  return list;
}

json build_suite(const BenchConfig& c, const Terrain& terrain) {
  say(c, "build " + terrain.name + ": build and slide of a 1024-cell window");
  const io::Mosaic mosaic = io::Mosaic::open(terrain.dems);
  const app::scene::WindowChoice w0 = app::scene::choose_window(mosaic.rows(), mosaic.cols(),
                                                                (mosaic.rows() - 1) / 2.0, (mosaic.cols() - 1) / 2.0, 1024);
  const int levels = app::scene::default_levels(w0.cells);
  app::scene::WindowChoice w1 = w0;
  w1.col0 += 1 << (levels - 1);  // one coarsest cell east
  if (w1.col0 + w1.cells > mosaic.cols() - 1) w1.col0 = w0.col0 - (1 << (levels - 1));
  const io::SceneFrame frame = app::scene::centre_frame(mosaic, w0);
  const app::scene::SceneWindow a = app::scene::read_scene_window(mosaic, w0, frame);
  const app::scene::SceneWindow b = app::scene::read_scene_window(mosaic, w1, frame);
  auto view = [](const app::scene::SceneWindow& s) { return mrbsp::TerrainWindow{s.window.cells, s.xs, s.ys, s.z}; };

  std::vector<double> build, slide;
  std::unique_ptr<mrbsp::TerrainTree> tree;
  const int reps = std::max(3, c.repeats);
  for (int r = 0; r <= reps; ++r) {  // the first is a warm-up
    const auto t0 = Clock::now();
    tree = std::make_unique<mrbsp::TerrainTree>(view(a), levels);
    if (r > 0) build.push_back(ms_since(t0));
  }
  for (int r = 0; r <= 2 * reps; ++r) {
    const auto t0 = Clock::now();
    tree->slide(view(r % 2 ? a : b));
    if (r > 0) slide.push_back(ms_since(t0));
  }
  const mrbsp::MemoryStats m = tree->memory();
  const double samples = static_cast<double>(m.samples);
  json out;
  out["terrain"] = terrain.name;
  out["window_cells"] = w0.cells;
  out["levels"] = levels;
  out["samples"] = m.samples;
  out["build_ms"] = to_json(summarize(build));
  out["slide_ms"] = to_json(summarize(slide));
  out["build_over_slide"] = summarize(build).median / summarize(slide).median;
  out["build_samples_per_s"] = samples / (summarize(build).median / 1000.0);
  out["bytes_per_sample"] = json{{"nodes", static_cast<double>(m.nodes) / samples},
                             {"vertices", static_cast<double>(m.vertices) / samples},
                             {"total", static_cast<double>(m.total()) / samples}};
  return out;
}

namespace {

// CPU seconds of this process (all threads) or of its waited-for children.
double cpu_seconds(int who) {
  rusage u{};
  getrusage(who, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

}  // namespace

json rf_suite(const BenchConfig& c, const std::filesystem::path& sdf, const volume::Transmitter& tx, int splat_heights) {
  volume::RfGrid grid;
  grid.radius_km = 20.0;
  grid.spacing_arcsec = 3.0;
  for (int k = 0; k < 31; ++k) grid.heights_agl.push_back(10.0 + 10.0 * k);
  const bool splat = std::filesystem::exists("/usr/bin/splat");
  if (!splat) say(c, "rf: /usr/bin/splat not found: SPLAT! is not timed");
  std::map<std::string, std::vector<double>> wall, cpu;
  std::size_t points = 0;
  for (int r = 0; r < c.repeats; ++r) {
    // The box, and the disc SPLAT! computes (the same points as SPLAT!'s, RfGrid::disc).
    for (const std::string name : {"itm", "itm_disc", "deygout"}) {
      const double c0 = cpu_seconds(RUSAGE_SELF);
      const auto t0 = Clock::now();
      const io::Mosaic mosaic = io::Mosaic::open({sdf});
      volume::RfOptions options;
      options.model = name == "deygout" ? volume::RfModel::kDeygout : volume::RfModel::kItm;
      volume::RfGrid run_grid = grid;
      run_grid.disc = name == "itm_disc";
      const volume::RfResult result = volume::compute_rf(mosaic, tx, run_grid, options);
      wall[name].push_back(ms_since(t0) / 1000.0);
      cpu[name].push_back(cpu_seconds(RUSAGE_SELF) - c0);
      points = result.path_loss.values.size();
      say(c, "rf " + name + ": " + std::to_string(wall[name].back()) + " s");
    }
    if (!splat) continue;
    volume::SplatRunOptions run;
    run.sdf_folder = sdf;
    run.site = volume::SplatSite{"bench", tx.lat, tx.lon, tx.height_agl};
    run.lrp.frequency_mhz = tx.frequency_mhz;
    run.radius_km = grid.radius_km;
    run.olditm = true;
    run.heights_agl.assign(grid.heights_agl.begin(), grid.heights_agl.begin() + splat_heights);
    const double c0 = cpu_seconds(RUSAGE_CHILDREN);
    const auto t0 = Clock::now();
    const volume::SplatRunResult result = volume::run_splat(run);
    const double total = ms_since(t0) / 1000.0;
    wall["splat_per_height"].push_back(result.seconds / splat_heights);
    wall["splat_preparation"].push_back(total - result.seconds);
    cpu["splat_per_height"].push_back((cpu_seconds(RUSAGE_CHILDREN) - c0) / splat_heights);
    say(c, "rf splat -olditm: " + std::to_string(result.seconds / splat_heights) + " s per height");
  }
  json out;
  out["terrain"] = sdf.filename().string();
  out["tx"] = {tx.lat, tx.lon, tx.height_agl, tx.frequency_mhz};
  out["points"] = points;
  out["heights"] = grid.heights_agl.size();
  out["splat_heights"] = splat ? splat_heights : 0;
  for (const auto& [name, v] : wall) out["wall_s"][name] = to_json(summarize(v));
  for (const auto& [name, v] : cpu) out["cpu_s"][name] = to_json(summarize(v));
  if (splat) {
    const double n = static_cast<double>(grid.heights_agl.size());
    const double splat_wall = median(wall["splat_preparation"]) + n * median(wall["splat_per_height"]);
    const double splat_cpu = n * median(cpu["splat_per_height"]);
    out["splat_volume_wall_s"] = splat_wall;
    out["splat_volume_cpu_s"] = splat_cpu;
    out["splat_over_itm_wall"] = splat_wall / median(wall["itm"]);
    out["splat_over_itm_cpu"] = splat_cpu / median(cpu["itm"]);
    out["splat_over_itm_disc_wall"] = splat_wall / median(wall["itm_disc"]);
    out["splat_over_itm_disc_cpu"] = splat_cpu / median(cpu["itm_disc"]);
  }
  return out;
}

}  // namespace terravol::bench
