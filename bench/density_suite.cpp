// Suite 12, densities (issue 15): the colour-cube octree (density/octree.h) drawn in the tree's
// order, against drawing every voxel cell, at 1.75 to 14 volume radii, on a lattice refined 2x
// and 4x per axis; the default RF volume over the bundled DEM at 1280x720 (its frame, alone
// and with the default scene's isosurfaces and slice, and a transfer-function change to the
// next frame); and the image against the independent ray marcher (reference/density.h) and
// against VTK's exact depth peeling of the same polygons (bench/suites.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "app/render/scene_renderer.h"
#include "bench/image_metrics.h"
#include "bench/stats.h"
#include "bench/suite_common.h"
#include "bench/suites.h"
#include "density/transfer.h"
#include "io/mosaic.h"
#include "reference/density.h"
#include "reference/dem.h"
#include "reference/frame.h"
#include "volume/propagation.h"
#include "volume/readers.h"
#include "volume/vdb_write.h"

namespace terravol::bench {

namespace {

using nlohmann::json;

// The transfer function of the suite: path loss 80..150 dB in viridis, densest where the
// signal is strongest, clear at 150 dB.
constexpr char kTransfer[] = "range=80:150,colormap=viridis,opacity=0.5,ramp=down";

// An RF path-loss volume of the bundled DEM's default transmitter (scripts/setup-and-run.sh:
// 45.5 N, 6.5 E, 30 m), `radius_km` around it, heights 0..top every step, at `spacing_arcsec`
// (0: the default), written to `file` unless it is there.
void default_rf(const Terrain& terrain, double radius_km, double top, double step, double spacing_arcsec,
                const std::filesystem::path& file, const BenchConfig& c) {
  if (std::filesystem::exists(file)) return;
  say(c, "density: computing " + file.string());
  const io::Mosaic mosaic = io::Mosaic::open(terrain.dems);
  volume::RfGrid grid;
  grid.radius_km = radius_km;
  grid.spacing_arcsec = spacing_arcsec;
  for (double h = 0; h <= top + 1e-9; h += step) grid.heights_agl.push_back(h);
  volume::Transmitter tx = transmitter(45.5, 6.5, 30.0);
  const volume::RfResult r = volume::compute_rf(mosaic, tx, grid);
  std::filesystem::create_directories(file.parent_path());
  volume::write_vdb(file, {&r.path_loss}, false);
}

// `from` refined `factor` times per axis ((n - 1) factor + 1 points, trilinear; NaN where a
// weight falls on a NaN point), written to `file` unless it is there.
void refined_volume(const std::filesystem::path& from, int factor, const std::filesystem::path& file, const BenchConfig& c) {
  if (std::filesystem::exists(file)) return;
  say(c, "density: refining " + from.string() + " " + std::to_string(factor) + "x per axis");
  const volume::Volume v = volume::read_volume(from, {});
  volume::Volume r = v;
  const auto& d = v.lattice.dims;
  for (std::size_t a = 0; a < 3; ++a) {
    r.lattice.dims[a] = (d[a] - 1) * factor + 1;
    r.lattice.spacing[a] = v.lattice.spacing[a] / factor;
  }
  r.values.assign(r.lattice.size(), 0.0f);
  for (int k = 0; k < r.lattice.dims[2]; ++k)
    for (int j = 0; j < r.lattice.dims[1]; ++j)
      for (int i = 0; i < r.lattice.dims[0]; ++i) {
        const int idx[3] = {i, j, k};
        int i0[3];
        double w[3];
        for (std::size_t a = 0; a < 3; ++a) {
          i0[a] = std::min(idx[a] / factor, d[a] - 2);
          w[a] = static_cast<double>(idx[a]) / factor - i0[a];
        }
        double sum = 0.0;
        for (int cc = 0; cc < 8; ++cc) {
          double weight = 1.0;
          for (std::size_t a = 0; a < 3; ++a) weight *= ((cc >> a) & 1) ? w[a] : 1.0 - w[a];
          if (weight > 0.0) sum += weight * v.at(i0[0] + (cc & 1), i0[1] + ((cc >> 1) & 1), i0[2] + (cc >> 2));
        }
        r.values[r.lattice.index(i, j, k)] = static_cast<float>(sum);
      }
  r.active_points = r.values.size();
  volume::write_vdb(file, {&r}, false);
}

// The pose of an eye `radii` volume radii from the centre of the density's box, from the
// south-west and above (direction (-0.5, -0.7, 0.5) in the scene frame), looking at the centre.
app::scene::CameraPose view_of(const app::render::SceneRenderer& scene, const density::BoxGrid& g, double radii) {
  const glm::dvec3 extent = g.size * glm::dvec3(g.boxes[0], g.boxes[1], g.boxes[2]);
  const glm::dvec3 centre = g.origin + 0.5 * extent;
  const double radius = 0.5 * glm::length(extent);
  const glm::dvec3 dir = glm::normalize(glm::dvec3(-0.5, -0.7, 0.5));
  const glm::dvec3 eye = centre + radii * radius * dir;
  const io::Geodetic at = scene.frame().to_geodetic({eye.x, eye.y, eye.z});
  app::scene::CameraPose pose;
  pose.lat = at.lat;
  pose.lon = at.lon;
  pose.alt = at.h;
  pose.heading_deg = std::atan2(dir.x, dir.y) * 180.0 / M_PI + 180.0;
  pose.pitch_deg = -std::asin(dir.z) * 180.0 / M_PI;
  return pose;
}

double density_frame_ms(const app::render::FrameStats& s) { return s.density_ms + frame_ms(s); }

// One frame of `scene`, its wall time appended to `wall`.
app::render::FrameStats timed_render(app::render::SceneRenderer& scene, const app::scene::CameraPose& pose,
                                     const mrbsp::TraversalOptions& traversal, std::vector<double>& wall) {
  const auto t0 = Clock::now();
  const app::render::FrameStats s = scene.render(pose, false, 45.0, traversal);
  wall.push_back(ms_since(t0));
  return s;
}

// The cells a refinement with `options` draws from `pose` (the eye at pose.alt above the
// datum), counted without drawing them: views whose frames would take too long or too much
// memory are left out (kMaxOctreeCells, kMaxEveryCells).
std::size_t cells_from(app::render::SceneRenderer& scene, const app::scene::CameraPose& pose, const density::RefineOptions& options,
                       const BenchConfig& c) {
  const mrbsp::Camera camera = app::scene::make_scene_camera(scene.frame(), pose, pose.alt, 45.0, c.width, c.height, 1.0);
  std::vector<mrbsp::ColorBox> boxes;
  density::RefineStats stats;
  scene.volumes().density_boxes(camera, options, boxes, stats);
  return stats.boxes;
}

// The series: one lattice (factor 1, 2 or 4), the octree and every voxel cell at each distance.
// Views where the octree itself draws over kMaxOctreeCells are left out (7.6M cells: 16-21 s a
// frame); every cell is drawn up to kMaxEveryCells (7.6M cells: 15 s a frame, a peak of 12.9 GB
// for the whole suite), so that the 4x lattice at 14 radii, whose leaves are under a pixel
// (the paper's case), has its ratio.
constexpr std::size_t kMaxOctreeCells = 3000000, kMaxEveryCells = 8000000;
json lattice_series(const BenchConfig& c, const Terrain& terrain, const std::filesystem::path& file, int factor) {
  app::scene::SceneSpec spec = terrain_spec(terrain, 45.5, 6.5);
  app::scene::VolumeSpec v;
  v.file = file;
  v.density = density::parse_density(kTransfer);
  spec.volumes.push_back(v);
  app::render::SceneRenderer scene(spec, plain_settings(c), bench_scene_options());
  scene.set_auto_slide(false);  // the window stays on the volume, however far the eye
  const app::scene::DensityFigures fig = scene.volumes().density_figures();
  const mrbsp::TraversalOptions traversal;
  // The octree as the commands refine it (epsilon and the error tolerance), every voxel cell,
  // and the papers' criterion alone (projected size; counted, not drawn).
  const density::RefineOptions octree = app::render::default_density_refinement();
  density::RefineOptions every, size_only;
  every.leaves_only = true;
  json views = json::array();
  for (const double radii : {1.75, 3.5, 7.0, 14.0}) {
    const app::scene::CameraPose pose = view_of(scene, fig.grid, radii);
    const std::size_t octree_cells = cells_from(scene, pose, octree, c);
    if (octree_cells > kMaxOctreeCells) {
      say(c, "density " + std::to_string(factor) + "x: " + std::to_string(radii) + " radii: the octree draws " +
                 std::to_string(octree_cells) + " cells: not drawn");
      views.push_back({{"radii", radii}, {"octree_cells", octree_cells}, {"every_cells", cells_from(scene, pose, every, c)}});
      continue;
    }
    scene.set_density_options(octree);
    scene.render(pose, false, 45.0, traversal);  // warm-up
    // Every voxel cell: left out when there are too many for this machine's memory and time.
    const std::size_t every_cells = cells_from(scene, pose, every, c);
    const bool draw_every = every_cells <= kMaxEveryCells;
    if (draw_every) {
      scene.set_density_options(every);
      scene.render(pose, false, 45.0, traversal);  // warm-up
    }
    std::vector<double> a, b, wall_a, wall_b;
    app::render::FrameStats sa, sb;
    for (int r = 0; r < c.repeats; ++r) {
      scene.set_density_options(octree);
      sa = timed_render(scene, pose, traversal, wall_a);
      a.push_back(density_frame_ms(sa));
      if (draw_every) {
        scene.set_density_options(every);
        sb = timed_render(scene, pose, traversal, wall_b);
        b.push_back(density_frame_ms(sb));
      }
    }
    scene.set_density_options(octree);
    json view = {{"radii", radii},
                 {"octree_ms", median(a)},
                 {"octree_wall_ms", median(wall_a)},
                 {"octree_cells", sa.density.boxes},
                 {"size_only_cells", cells_from(scene, pose, size_only, c)},
                 {"octree_cells_per_level", sa.density.per_level},
                 {"octree_faces", sa.boxes.faces},
                 {"octree_refine_ms", sa.density_ms},
                 {"octree_order_ms", sa.boxes.distribute_ms},
                 {"octree_draw_ms", sa.draw_ms},
                 {"every_cells", every_cells}};
    if (draw_every) {
      view["every_ms"] = median(b);
      view["every_faces"] = sb.boxes.faces;
      view["every_over_octree"] = median(b) / median(a);
      view["every_wall_ms"] = median(wall_b);
      view["every_over_octree_wall"] = median(wall_b) / median(wall_a);
    }
    char line[256];
    std::snprintf(line, sizeof line, "density %dx: %.2f radii: octree %.1f ms (%zu cells), every cell %s (%zu cells)", factor,
                  radii, median(a), sa.density.boxes, draw_every ? (std::to_string(median(b)) + " ms").c_str() : "not drawn",
                  every_cells);
    say(c, line);
    views.push_back(view);
  }
  return {{"factor", factor},
          {"leaves", fig.grid.boxes},
          {"levels", fig.levels},
          {"octree_bytes", fig.bytes},
          {"build_ms", fig.build_ms},
          {"resample_ms", fig.resample_ms},
          {"views", views}};
}

}  // namespace

json density_suite(const BenchConfig& c, const Terrain& terrain) {
  json out;
  out["terrain"] = terrain.name;
  out["transfer"] = kTransfer;
  std::filesystem::create_directories(c.cache);
  // 1. The series: a 6 km volume at 6" and 100 m (so that 14 radii stay within 200 km of the
  // DEM), refined 2x and 4x per axis.
  const auto base = c.cache / (terrain.name + "-density-6km.vdb");
  default_rf(terrain, 6.0, 2000.0, 100.0, 6.0, base, c);
  const auto x2 = c.cache / (terrain.name + "-density-6km-x2.vdb"), x4 = c.cache / (terrain.name + "-density-6km-x4.vdb");
  refined_volume(base, 2, x2, c);
  refined_volume(base, 4, x4, c);
  out["series"] = json::array();
  out["series"].push_back(lattice_series(c, terrain, base, 1));
  out["series"].push_back(lattice_series(c, terrain, x2, 2));
  out["series"].push_back(lattice_series(c, terrain, x4, 4));

  // 2. The default RF volume of scripts/setup-and-run.sh at 1280x720 from the default scene's
  // camera: the density alone, then with the default scene's isosurfaces and slice.
  const auto rf = c.cache / (terrain.name + "-default-rf.vdb");
  default_rf(terrain, 20.0, 2000.0, 50.0, 0.0, rf, c);
  app::scene::CameraPose pose;
  pose.lat = 45.22;
  pose.lon = 6.28;
  pose.alt = 9000;
  pose.heading_deg = 38;
  pose.pitch_deg = -24;
  app::scene::SceneSpec spec = terrain_spec(terrain, pose.lat, pose.lon);
  app::scene::VolumeSpec v;
  v.file = rf;
  v.density = density::parse_density(kTransfer);
  spec.volumes.push_back(v);
  app::scene::SceneSpec with = spec;
  {
    volume::IsoSpec a, b;
    a.value = 110;
    a.opacity = 0.45;
    a.color = volume::default_isosurface_color(0);
    b.value = 130;
    b.opacity = 0.3;
    b.color = volume::default_isosurface_color(1);
    volume::SliceSpec s;
    s.kind = volume::SliceKind::kAgl;
    s.value = 300;
    s.opacity = 0.45;
    s.lo = 80.0f;
    s.hi = 160.0f;
    with.volumes.front().isosurfaces = {a, b};
    with.volumes.front().slices = {s};
  }
  const mrbsp::TraversalOptions traversal;
  json defaults = json::array();
  for (const bool surfaces : {false, true}) {
    say(c, std::string("density: the default RF volume") + (surfaces ? " with its isosurfaces and slice" : ""));
    app::render::SceneRenderer scene(surfaces ? with : spec, plain_settings(c), bench_scene_options());
    scene.render(pose, false, 45.0, traversal);
    std::vector<double> t, wall, change;
    app::render::FrameStats s;
    for (int r = 0; r < c.repeats; ++r) {
      s = timed_render(scene, pose, traversal, wall);
      t.push_back(density_frame_ms(s));
    }
    // A transfer-function change (the opacity, alternately up and back) to the finished frame.
    density::DensitySpec d = *scene.volumes().spec(0).density;
    std::vector<double> set_ms, after_ms;
    for (int r = 0; r < c.repeats; ++r) {
      d.sigma_per_km = r % 2 == 0 ? 0.75 : 0.5;
      const auto t0 = Clock::now();
      scene.volumes().set_density(0, d);
      set_ms.push_back(ms_since(t0));
      const app::render::FrameStats after = scene.render(pose, false, 45.0, traversal);
      change.push_back(ms_since(t0));
      after_ms.push_back(density_frame_ms(after));
    }
    // The transfer function the rest compares with (an odd number of repeats ends on the other).
    scene.volumes().set_density(0, density::parse_density(kTransfer));
    const app::scene::DensityFigures fig = scene.volumes().density_figures();
    json j = {{"surfaces", surfaces},
              {"frame_ms", to_json(summarize(t))},
              {"frame_wall_ms", to_json(summarize(wall))},
              {"transfer_change_to_frame_ms", to_json(summarize(change))},
              {"transfer_change_set_ms", to_json(summarize(set_ms))},
              {"transfer_change_frame_ms", to_json(summarize(after_ms))},
              {"build_ms", fig.build_ms},
              {"leaves", fig.grid.boxes},
              {"octree_bytes", fig.bytes},
              {"cells", s.density.boxes},
              {"faces", s.boxes.faces},
              {"bsp_faces", s.boxes.bsp_faces},
              {"triangles", s.triangles},
              {"box_triangles", s.box_triangles},
              {"refine_ms", s.density_ms},
              {"traversal_ms", s.traversal_ms},
              {"order_ms", s.boxes.distribute_ms},
              {"upload_ms", s.upload_ms},
              {"draw_ms", s.draw_ms}};
    char line[200];
    std::snprintf(line, sizeof line,
                  "density: default volume%s: frame %.0f ms (wall %.0f ms; %zu cells, %zu faces), transfer change to frame %.0f ms",
                  surfaces ? " with surfaces" : "", median(t), median(wall), s.density.boxes, s.boxes.faces, median(change));
    say(c, line);
    if (surfaces) {
      // Exactness: bsp against VTK's depth peeling (no peel limit) of the same polygons, with
      // cubes of up to kPeelThreshold px: at 1 px a peeled frame takes many minutes on llvmpipe.
      constexpr double kPeelThreshold = 64.0;
      density::RefineOptions coarse = scene.density_options();
      coarse.threshold_px = kPeelThreshold;
      scene.set_density_options(coarse);
      j["peel_threshold_px"] = kPeelThreshold;
      app::render::RenderSettings ps = plain_settings(c);
      ps.order = app::scene::DrawOrder::kPeel;
      ps.peels = 0;
      auto peel = scene.make_renderer(ps);
      scene.render(pose, false, 45.0, traversal);
      scene.sync_vertices(*peel);
      peel->set_camera(scene.camera(), scene.terrain().far_plane(scene.camera().eye));
      peel->set_frame(scene.last_frame());
      peel->render();
      const std::vector<std::uint8_t> bsp = scene.rgb(), peeled = app::render::window_rgb(peel->window());
      j["bsp_vs_peel_within_3"] = 1.0 - share_differing(bsp, peeled, c.width, c.height, 3);
      j["bsp_vs_peel_within_8"] = 1.0 - share_differing(bsp, peeled, c.width, c.height, 8);
      say(c, "density: bsp against exact peeling: " + std::to_string(100.0 * j["bsp_vs_peel_within_3"].get<double>()) +
                 "% of pixels within 3/255");
    } else {
      // Against the ray marcher: the same view drawn at full resolution, the terrain alone as
      // the background, the marcher's fog over it up to the DEM's ground.
      mrbsp::TraversalOptions full;
      full.full_res = true;
      scene.render(pose, false, 45.0, full);
      const std::vector<std::uint8_t> ours = scene.rgb();
      scene.volumes().set_visible(0, false);
      scene.render(pose, false, 45.0, full);
      const std::vector<std::uint8_t> terrain_only = scene.rgb();
      scene.volumes().set_visible(0, true);
      say(c, "density: marching the reference");
      const auto m0 = Clock::now();
      const volume::Volume vol = volume::read_volume(rf, {});
      const reference::Frame frame(scene.frame().lat0(), scene.frame().lon0());
      const reference::Dem dem = reference::Dem::read(terrain.dems, {44.9, 46.1, 5.9, 7.1});
      const auto ground = [&](double lat, double lon) { return dem.height(lat, lon); };
      const reference::DensityField field(vol, frame, ground);
      const density::DensitySpec ds = density::parse_density(kTransfer);
      const reference::DensityTransfer tf{ds.lo, ds.hi, ds.colormap, ds.sigma_per_km, std::string(density::ramp_name(ds.ramp))};
      const mrbsp::Camera& cam = scene.camera();
      const reference::MarchCamera mc{cam.eye, cam.forward, cam.up, cam.fov_y_deg, cam.width, cam.height};
      const reference::MarchedImage marched = reference::march_density(field, tf, mc, 25.0, [&](double x, double y) {
        try {
          const double lat = frame.lat_of(y), lon = frame.lon_of(x);
          return frame.to_scene(lat, lon, dem.height(lat, lon)).z;
        } catch (const std::exception&) {
          return -std::numeric_limits<double>::infinity();
        }
      });
      const std::vector<unsigned char> expected = reference::composite_over(marched, terrain_only);
      const reference::FootprintError e = reference::footprint_error(marched, ours, expected);
      j["reference_mean_error"] = e.mean;
      j["reference_p99_error"] = e.p99;
      j["reference_pixels"] = e.pixels;
      j["reference_ms"] = ms_since(m0);
      char l2[160];
      std::snprintf(l2, sizeof l2, "density: against the ray marcher: mean %.2f/255, 99th percentile %.0f/255 over %zu pixels", e.mean,
                    e.p99, e.pixels);
      say(c, l2);
    }
    defaults.push_back(j);
  }
  out["default_volume"] = defaults;
  return out;
}

}  // namespace terravol::bench
