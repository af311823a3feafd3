#include "bench/scenes.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "app/scene/mosaic_lattice.h"
#include "io/mosaic.h"
#include "volume/vdb_write.h"

namespace terravol::bench {

std::vector<View> flythrough(const app::scene::WindowBounds& b, int count) {
  const double clat = 0.5 * (b.south + b.north), clon = 0.5 * (b.west + b.east);
  // Within 0.4 of the half side from the centre: the window slides only within a quarter
  // side of an edge (app/scene/terrain_scene.h, plan_slide).
  const double dlat = 0.4 * 0.5 * (b.north - b.south), dlon = 0.4 * 0.5 * (b.east - b.west);
  std::vector<View> views;
  for (int k = 0; k < count; ++k) {
    const double t = count > 1 ? static_cast<double>(k) / (count - 1) : 0.5;
    View v;
    v.overview = k % 6 == 5;
    v.pose.lat = clat + dlat * (2.0 * t - 1.0);
    v.pose.lon = clon + dlon * std::sin(3.0 * t * std::numbers::pi);
    v.pose.heading_deg = std::fmod(15.0 * k, 360.0);
    v.pose.pitch_deg = v.overview ? -45.0 : -5.0 - 15.0 * std::abs(std::sin(1.7 * k));
    v.pose.alt = v.overview ? 8000.0 : 600.0 + 1900.0 * std::abs(std::cos(1.3 * k));
    views.push_back(v);
  }
  return views;
}

std::vector<View> orbit(double lat, double lon, double range_km, double agl, double pitch_deg, int count) {
  constexpr double kMetresPerDegree = 111320.0;
  std::vector<View> views;
  for (int k = 0; k < count; ++k) {
    const double bearing = 225.0 + 360.0 * k / count;  // from the centre to the eye, degrees
    const double a = bearing * std::numbers::pi / 180.0;
    View v;
    v.pose.lat = lat + range_km * 1000.0 * std::cos(a) / kMetresPerDegree;
    v.pose.lon = lon + range_km * 1000.0 * std::sin(a) / (kMetresPerDegree * std::cos(lat * std::numbers::pi / 180.0));
    v.pose.heading_deg = std::fmod(bearing + 180.0, 360.0);
    v.pose.pitch_deg = pitch_deg;
    v.pose.alt = agl;
    views.push_back(v);
  }
  return views;
}

double volume_orbit_km(const app::scene::WindowBounds& b, double lat) {
  const double half_km = 0.5 * std::min((b.north - b.south) * 111.32,
                                        (b.east - b.west) * 111.32 * std::cos(lat * std::numbers::pi / 180.0));
  return std::min(8.0, 0.4 * half_km);
}

app::scene::WindowBounds centred_window(const Terrain& terrain, double lat, double lon, int max_cells) {
  const io::Mosaic mosaic = io::Mosaic::open(terrain.dems);
  const app::scene::LatticePoint p = app::scene::lattice_point(mosaic, lat, lon);
  const app::scene::WindowChoice w = app::scene::choose_window(mosaic.rows(), mosaic.cols(), p.row, p.col, max_cells);
  const io::Georef& g = mosaic.georef();
  app::scene::WindowBounds b;
  b.north = g.y0 - w.row0 * g.dy;
  b.south = b.north - w.cells * g.dy;
  b.west = g.x0 + w.col0 * g.dx;
  b.east = b.west + w.cells * g.dx;
  return b;
}

volume::Transmitter transmitter(double lat, double lon, double height_agl) {
  volume::Transmitter t;
  t.lat = lat;
  t.lon = lon;
  t.height_agl = height_agl;
  t.frequency_mhz = 900.0;
  return t;
}

std::vector<volume::Transmitter> benchmark_transmitters(const std::string& terrain) {
  if (terrain == "n44w072") return {transmitter(44.27, -71.30, 30), transmitter(44.32, -71.22, 60), transmitter(44.22, -71.20, 20)};
  if (terrain == "utah")
    return {transmitter(40.6589, -112.2019, 30), transmitter(40.76, -111.89, 30), transmitter(40.60, -111.80, 40)};
  return {};
}

void rf_volume(const Terrain& terrain, const volume::Transmitter& transmitter, double radius_km, double top_m,
               double step_m, const std::filesystem::path& file, const std::function<void(const std::string&)>& progress) {
  if (std::filesystem::exists(file)) return;
  if (progress) progress("computing " + file.string());
  const io::Mosaic mosaic = io::Mosaic::open(terrain.dems);
  volume::RfGrid grid;
  grid.radius_km = radius_km;
  for (double h = 0; h <= top_m + 1e-9; h += step_m) grid.heights_agl.push_back(h);
  const volume::RfResult r = volume::compute_rf(mosaic, transmitter, grid);
  volume::write_vdb(file, {&r.path_loss}, false);
}

VolumeScene three_volume_scene(const Terrain& terrain, const std::vector<volume::Transmitter>& transmitters,
                               const std::filesystem::path& cache,
                               const std::function<void(const std::string&)>& progress) {
  std::filesystem::create_directories(cache);
  VolumeScene scene;
  scene.spec.dems = terrain.dems;
  // The styles of scripts/exactness.sh: isosurface values (dB) and opacities per volume.
  const double iso[3][2][2] = {{{105, 0.4}, {125, 0.3}}, {{110, 0.6}, {120, 0.35}}, {{100, 0.5}, {115, 0.45}}};
  for (std::size_t k = 0; k < transmitters.size(); ++k) {
    const auto file = cache / (terrain.name + "-rf" + std::to_string(k) + ".vdb");
    rf_volume(terrain, transmitters[k], 12.0, 2000.0, 100.0, file, progress);
    app::scene::VolumeSpec v;
    v.file = file;
    for (const auto& [value, opacity] : iso[k % 3]) {
      volume::IsoSpec s;
      s.value = value;
      s.opacity = opacity;
      s.color = volume::default_isosurface_color(v.isosurfaces.size() + 2 * k);
      v.isosurfaces.push_back(s);
    }
    if (k == 0) {
      volume::SliceSpec s;
      s.kind = volume::SliceKind::kAgl;
      s.value = 400;
      s.opacity = 0.5;
      s.colormap = "viridis";
      s.lo = 80;
      s.hi = 160;
      v.slices.push_back(s);
    }
    scene.spec.volumes.push_back(v);
    scene.lat += transmitters[k].lat / static_cast<double>(transmitters.size());
    scene.lon += transmitters[k].lon / static_cast<double>(transmitters.size());
  }
  return scene;
}

}  // namespace terravol::bench
