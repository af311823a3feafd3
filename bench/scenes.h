// The terrains, volumes and camera paths the benchmarks draw (docs/benchmarks.md).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "app/scene/camera.h"
#include "app/scene/scene_file.h"
#include "app/scene/terrain_scene.h"
#include "volume/propagation.h"

namespace terravol::bench {

// A terrain of the shared data (or made by `terravol sample-dem --tiles`).
struct Terrain {
  std::string name;                          // "n44w072", "utah", ...
  std::vector<std::filesystem::path> dems;
  int tiles = 1;                             // DEM tiles in it
};

// One view of a path: a pose with its altitude above the ground.
struct View {
  app::scene::CameraPose pose;  // pose.alt: metres above the ground under the camera
  bool overview = false;
};

// A flythrough of `count` views over the central half of `bounds` (so that the window never
// slides): low oblique views (pitch -5 to -20 degrees, 600 to 2500 m above the ground) turning
// through every heading, and every sixth view a high overview (8000 m, pitch -45).
// Deterministic. Precondition: count >= 1.
std::vector<View> flythrough(const app::scene::WindowBounds& bounds, int count);

// An orbit of `count` views around (lat, lon) at `range_km`, `agl` metres above the ground,
// looking at the centre with pitch `pitch_deg`, starting from the south-west.
std::vector<View> orbit(double lat, double lon, double range_km, double agl, double pitch_deg, int count);

// The range of the translucency suite's orbit (orbit(lat, lon, km, 2500, -22, count)) about a
// point at latitude `lat` in a window with `bounds`: min(8 km, 0.4 of the window's half side),
// so that the window never slides.
double volume_orbit_km(const app::scene::WindowBounds& bounds, double lat);

// The bounds of the window (at most `max_cells` cells) that a scene of the terrain gets when its
// camera is at (lat, lon) (app/scene/terrain_scene.h, choose_window). Throws what
// io::Mosaic::open throws.
app::scene::WindowBounds centred_window(const Terrain& terrain, double lat, double lon, int max_cells);

// A 900 MHz transmitter without ERP (path loss only), as scripts/exactness.sh makes them.
volume::Transmitter transmitter(double lat, double lon, double height_agl);

// `file`, an RF path-loss volume of the transmitter over the terrain by the built-in model (as
// `terravol rf --radius-km R --heights 0:TOP:STEP` writes it), computed and written unless it is
// already there. `progress` is told when it is computed. Throws what compute_rf and write_vdb
// throw.
void rf_volume(const Terrain& terrain, const volume::Transmitter& transmitter, double radius_km, double top_m,
               double step_m, const std::filesystem::path& file, const std::function<void(const std::string&)>& progress);

// The benchmark's three transmitters over a shared terrain ("n44w072", "utah"); empty for any
// other.
std::vector<volume::Transmitter> benchmark_transmitters(const std::string& terrain);

// The three-volume scene of scripts/exactness.sh over a terrain: an RF path-loss volume per
// transmitter
// (three expected; 12 km radius, 0-2000 m, written as `<cache>/<name>-rfK.vdb` by the built-in model unless
// already there), two translucent isosurfaces each and a slice 400 m above the ground on the
// first. `progress` is told when a volume is computed. Throws what compute_rf and write_vdb
// throw.
struct VolumeScene {
  app::scene::SceneSpec spec;
  double lat = 0, lon = 0;  // the centre of the transmitters
};
VolumeScene three_volume_scene(const Terrain& terrain, const std::vector<volume::Transmitter>& transmitters,
                               const std::filesystem::path& cache, const std::function<void(const std::string&)>& progress);

}  // namespace terravol::bench
