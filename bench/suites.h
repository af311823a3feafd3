// The benchmark suites of `terravol bench` (docs/benchmarks.md). Each draws its scenes at
// 1280x720 offscreen, warms up, repeats every timed frame, and measures the configurations it
// compares side by side in one run (per view, one after the other), so that its ratios hold on
// a noisy machine. Each returns its figures as JSON (medians and spreads: bench/stats.h).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/scenes.h"

namespace terravol::bench {

struct BenchConfig {
  int width = 1280, height = 720;
  int views = 60;          // views of each terrain flythrough (suite 1)
  int volume_views = 8;    // views of each translucency orbit (suites 2, 5, 6)
  int repeats = 3;         // timed repetitions of each frame, after one untimed warm-up
  int flight_frames = 1000;  // frames of the low-altitude suite's flight (suite 9)
  bool plain_largest = true;  // scaling: draw the largest terrain with plain VTK too (33 M triangles)
  bool quick = false;         // exactness: the two fixed cameras only (plus the orbit)
  std::filesystem::path cache;  // RF volumes and generated tiles, kept between runs
  std::filesystem::path out;    // the report's folder (exactness keeps its images in exactness/)
  std::filesystem::path under_test;  // exactness: the terravol whose render is measured; empty: this one
  std::string exactness_views;       // exactness: comma-separated VIEW or TERRAIN-VIEW; empty: all
  std::function<void(const std::string&)> log;  // progress, one line at a time
};

// 1. Terrain: a flythrough (scenes.h, flythrough) over the terrain's 1024-cell window. Per view:
// Terravol's full-resolution image (the quality reference), the full-resolution lattice drawn by
// plain VTK (bench/plain_vtk.h: ordinary mapper, depth test, geometry uploaded once), and the
// MRBSP at thresholds 0.5, 1, 2, 4 of both metrics (the area metric's threshold is 250 t square
// pixels, so that t = 2 is its default of 500): traversal, upload and draw times, triangles,
// PSNR, SSIM and the share of pixels off by more than 8/255 against the reference.
nlohmann::json terrain_suite(const BenchConfig& config, const Terrain& terrain);

// 2, 5 and 6 on one three-volume scene (scenes.h): per view of an orbit around the volumes,
// the same traversal drawn in the tree's order (bsp), by VTK's depth peeling with 4 peels and
// with no limit (exact: the reference), and by VTK's default translucency; then the pipeline a
// ParaView user would build: the full-resolution lattice and the undecimated isosurfaces and
// slice drawn by plain VTK with 4 peels and with no limit. Then the responsiveness: time from
// a threshold change, and from a slice move, to the next finished frame. And the merge figures.
nlohmann::json translucency_suite(const BenchConfig& config, const Terrain& terrain,
                                  const std::vector<volume::Transmitter>& transmitters);

// Part of 2 (issue 11's closed surface): hydrogen.vtk's isosurface at 0.02 (`volume`, 64 m
// across, --volume-frame enu:45.5,6.5,1900) over the bundled DEM (`dem`, N45E006) from five
// cameras around it, each with its own window, as `terravol render --stats` draws one frame:
// the pieces the tree stores per input triangle after that frame (low alternatives included)
// and the merge time, summarised over the cameras. Throws what SceneRenderer throws.
nlohmann::json hydrogen_pieces(const BenchConfig& config, const std::filesystem::path& dem,
                               const std::filesystem::path& volume);

// 3. Scaling: one view (2500 m above the window's centre, pitch -20) of each terrain in its
// largest window (at most 4096 cells): MRBSP at 1 px and plain VTK at full resolution.
nlohmann::json scaling_suite(const BenchConfig& config, const std::vector<Terrain>& terrains);

// 4. Build and slide of the tree of a 1024-cell window (no rendering): build time, slide time
// (by one coarsest cell east and back), their ratio, samples per second, bytes per sample.
nlohmann::json build_suite(const BenchConfig& config, const Terrain& terrain);

// 7. Exactness (issue 11): the real `terravol render --full-res --surface-triangles 0 --haze 0`
// (run as a child process: `under_test`, or this executable) against the independent reference
// (reference/check.h: the exported terrain, the volumes extracted again from their files and
// placed by the reference's own code, VTK depth peeling with no peel limit). Scenes over the
// terrain: the two 8 km RF volumes (0-1500 m every 100 m, isosurfaces at 110 and 125 dB
// and at 112 and 122 dB), in render's default window and in a 256-cell one; and the translucency
// suite's three volumes and slice (three_volume_scene). Views: inside the second volume (the
// issue's 44.16,-71.40,1800,40,-12 over N44W072), outside (44.05,-71.60,4500,35,-18), beside it,
// near the ground (beside and inside), far above, two at the edges of the 256-cell window,
// `volume_views` views of an 8 km orbit at 2500 m (fov 50), and the translucency suite's orbit
// poses about its three volumes (fov 45; render centres its window on each camera, that suite
// on the volumes). A uniform background, no legend. Per view: the share of pixels within 8/255
// (and its complement, over_8) and 3/255 of the reference (issue 11's target: >= 99.9% within
// 8/255 for every view), of the same render with --order peel within 8/255 of the reference
// and within 3/255 of bsp (target: >= 99.9%); the images of each view go to out/exactness/.
// `exactness_views` selects views. Terrains with a scene: "n44w072" and "utah"
// (has_exactness_scene). Throws for another terrain or no view selected, and what the render and
// the reference throw.
bool has_exactness_scene(const std::string& terrain);
// The names of the views the suite draws over the terrain with this configuration (empty for a
// terrain without a scene).
std::vector<std::string> exactness_views(const BenchConfig& config, const std::string& terrain);
nlohmann::json exactness_suite(const BenchConfig& config, const Terrain& terrain);

// 8. RF volumes: a 20 km box at 3" with 31 receiver heights (10..310 m) over SDF tiles, the
// built-in ITM (compute_rf, both cores, tiles read afresh) against SPLAT!'s own ITM
// (`splat -olditm`) run once per height as `terravol splat-volume` runs it, and the built-in
// Deygout model on the same lattice. Per repetition, one after the other: the ITM volume, the
// Deygout volume, and SPLAT! at `splat_heights` of the heights; SPLAT!'s volume time is its
// preparation (the tiles given to it) plus 31 times its median time per height. Wall and CPU
// seconds (getrusage; SPLAT!'s CPU is its children's). SPLAT! is skipped without
// /usr/bin/splat.
nlohmann::json rf_suite(const BenchConfig& config, const std::filesystem::path& sdf_folder,
                        const volume::Transmitter& transmitter, int splat_heights);

// 9. Objects on the terrain (issue 16; Wiley et al. 1997, section 7.2): eight milk trucks
// (`truck`, assimp-testmodels' glTF CesiumMilkTruck, 3,624 triangles) seen from 40 to 600 m, and
// 200 instances of the truck and of `wuson` (PLY, 3,732 triangles) scattered over 4 x 4 km of
// the terrain, seen from 0.3 to 3 km, in a 512-cell window. Per view, side by side: the
// pipeline with each instance's level chosen per frame (2 px of screen-space error, colour cubes
// below a pixel), the same pipeline with every instance at full resolution (its own tree, so
// neither re-merges between the timed frames), and plain VTK drawing the window's
// full-resolution lattice with every instance at full resolution (4 peels); frame times (the
// level choice included), their ratios, PSNR of the chosen levels' image against the full
// resolution one, the object triangles drawn, the cost of the first frame of a view (the
// re-merge of the instances whose level changed), the tree's bytes for the merged objects over
// the chosen levels' own, and each model's levels (triangles, Hausdorff errors).
nlohmann::json object_suite(const BenchConfig& config, const Terrain& terrain, const std::filesystem::path& truck,
                            const std::filesystem::path& wuson);

// 10. Low altitude (issue 12): low views (100, 250 and 500 m above the ground, pitch 0 to -6) in
// valleys and toward ridges (Utah: the Salt Lake valley toward the Wasatch and up its canyons;
// N44W072: the White Mountains' notches; any other terrain: the lowest points of its window's
// central half looking toward the highest), min(views, 20) of them (quick: 4), and 6 high views
// (3000-8000 m, pitch -25 to -45; quick: 2), in one 1024-cell window centred on the place. Per
// view, at 1 and 2 px, occlusion culling off then on: frame, traversal and draw times,
// triangles, whether the images are identical, the pass's time and tests; and from an item
// buffer of the off frame (bench/item_buffer.h): the triangles drawn that show in no pixel
// (hidden), the share of them the occlusion pass culls when it runs (a traversal with
// occlusion_adaptive off, whose image is compared too), visible triangles culled (0 when
// conservative), and the crack fills' share of the terrain's pixels; with the share of timed
// frames the pass ran in and its time in the warm-up (the probe). Then a low flight of
// `flight_frames` frames (100 to 500 m above the ground, along a valley): per frame the unculled
// draw, and occlusion at 1 px testing every node, with hierarchy updating and with conservative
// updating (p_skip 0.5), each from its own Frame: node tests, skipped tests, pass time, and
// whether each image equals the unculled one. Throws what SceneRenderer throws.
nlohmann::json lowalt_suite(const BenchConfig& config, const Terrain& terrain);

// 11. Antialiasing (issue 14): the coverage-mask tiler (tiler/, app/render/tiled_renderer.h)
// against VTK's box-filtered supersampling (`fly --samples`: the frame drawn f times larger and
// averaged down), each image against a 16 x 16-sample reference (the same frame drawn by VTK 16
// times larger, in tiles of at most 4096 samples a side through off-centre projections, and
// averaged down). Side by side per view (after an untimed warm-up, `repeats` times, medians):
// first the terrain at the configured size over `volume_views` views of the terrain
// flythrough, drawn as `terravol render` draws (sky gradient, 60 km haze): VTK at 1, 4, 16 and 64
// samples, the tiler at aa 1, 2, 4 and 8 (its front-to-back traversal included), and the tiler
// at 8 with the tree's occlusion pass at sample resolution (tiled_traversal; its image must be
// the same); then, given transmitters, the three-volume scene (three_volume_scene) at 1920x1080
// over max(1, volume_views / 2) views of its orbit: VTK at 1 and 16 samples, the tiler at 4 and 8.
// A VTK frame's time is the back-to-front traversal, the upload of the triangle list, the draw,
// the read-back and the filter (what `fly --samples` does per frame), all from one traversal
// (the LOD choice at f times the size and f times the threshold is the same). Per view: frame
// times, PSNR against the reference, the tiler at 8 against VTK at 16 samples, the issue's
// ratios, the tiler's work per pixel (pyramid cells visited, fragments, shading points). The
// first view's images go to out/aa/. Throws what SceneRenderer throws.
nlohmann::json aa_suite(const BenchConfig& config, const Terrain& terrain, const std::vector<volume::Transmitter>& transmitters);

// 12. Densities (issue 15; bench/density_suite.cpp), over the bundled DEM (N45E006, made by
// `terravol sample-dem`; its default transmitter at 45.5 N, 6.5 E, 30 m): a 6 km path-loss
// volume (6", 0-2000 m every 100 m) and the same refined 2x and 4x per axis, each seen from
// 1.75, 3.5, 7 and 14 volume radii (from the south-west, 30 degrees up): per view, side by side,
// the colour-cube octree at epsilon 1 px and every voxel cell (left out above 3 million
// cells), frame times (the refinement, the traversal that orders the cells, upload and draw),
// cells and faces. Then the default RF volume of scripts/setup-and-run.sh (20 km, 0-2000 m
// every 50 m) from the default scene's camera: the density alone and with the default scene's
// two isosurfaces and agl slice: frame time, a transfer-function change to the finished frame;
// the density alone against the independent ray marcher over the terrain-only image (mean and
// 99th percentile of the largest channel difference inside the volume's box); with the
// surfaces, bsp against VTK's exact depth peeling of the same polygons. Transfer function:
// range 80:150 dB, viridis, 0.5 per km, ramp down. Throws what SceneRenderer throws.
nlohmann::json density_suite(const BenchConfig& config, const Terrain& terrain);

}  // namespace terravol::bench
