// The independent reference of a Terravol render (issue 11): the check that translucent RF
// isosurfaces and slices over terrain are composited exactly.
//
// A render is run by the real command (run_render): `terravol render --scene S --full-res
// --surface-triangles 0 --haze 0 --export-vtp drawn.vtp --stats stats.json -o ours.png`. Its
// image is then compared with one built without the tree, the volume layer or the renderer
// (reference_image):
// - terrain: the exported triangles whose level is >= -1 (terrain and crack fills), opaque and
//   depth-tested, their exported colours sampled as the renderer samples them: from a bilinear
//   texture of the lattice (draw.h, texture_terrain; at --full-res the vertices are the lattice
//   samples). Gouraud-interpolated vertex colours would differ inside each cell, by more than
//   8/255 on 0.16% of one view's pixels over rough terrain, more than the target allows;
// - volumes: each visible volume of the scene file read again (volume::read_volume: reading is
//   not under test), its isosurfaces extracted again and its slices cut again
//   (reference/geometry.h), placed by this folder's own scene frame (reference/frame.h) with
//   the frame's origin from the stats' window.origin_lat/origin_lon, the ground from the DEM's
//   own samples (reference/dem.h);
// - objects (the scene file's "objects"): each model read again with assimp and placed by this
//   folder's own code (reference/objects.h), at full resolution as --full-res draws them;
// - drawn by VTK depth peeling with no limit (reference/draw.h), with the exported camera and
//   background, at the stats' size.
// Nothing here includes app/, mrbsp/, objects/, volume/'s geometry or volume::LatticeMapper.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "reference/draw.h"

namespace terravol::reference {

// What the reference takes from a render's --stats file.
struct RenderStats {
  int width = 0, height = 0;
  double origin_lat = 0, origin_lon = 0;  // the scene frame's origin (window.origin_*)
  WindowLattice window;                   // window.cells, south, north, west, east
};
// Throws std::runtime_error("PATH: ...") when unreadable or a key is missing.
RenderStats read_stats(const std::filesystem::path& stats);

struct Reference {
  Image image;
  Drawn drawn;
  std::size_t volume_triangles = 0;
  std::size_t object_triangles = 0;  // the scene's objects, placed by reference/objects.h
  double geometry_ms = 0, draw_ms = 0;  // wall time: reading and rebuilding, then drawing
};

// The reference image of the render that wrote `vtp` and `stats` from `scene`. Throws
// std::runtime_error (one line, naming the file) for unreadable inputs, and what draw() throws.
Reference reference_image(const std::filesystem::path& scene, const std::filesystem::path& vtp,
                          const std::filesystem::path& stats);

// A PNG as RGB, top row first (vtkPNGReader; grey and RGBA files are converted). Throws
// std::runtime_error("PATH: ...").
Image read_png(const std::filesystem::path& png);
// Writes `image` as a PNG (replacing the file). Throws std::runtime_error when writing fails.
void write_png(const std::filesystem::path& png, const Image& image);

// The share of pixels (0..1) whose three channels each differ by at most `tolerance` levels.
// Throws std::invalid_argument when the sizes differ or tolerance < 0.
double share_within(const Image& a, const Image& b, int tolerance);
// An image of where a and b differ by more than `tolerance`: b's pixels, greyed, with the
// differing ones red. Same preconditions as share_within.
Image difference_image(const Image& a, const Image& b, int tolerance);

// The outputs of one run of the real command.
struct RenderRun {
  std::filesystem::path png, vtp, stats, log;  // log: its stdout and stderr
  double seconds = 0;
};

// Runs `exe render --scene SCENE --full-res --surface-triangles 0 --haze 0 --export-vtp
// DIR/NAME.vtp --stats DIR/NAME.json -o DIR/NAME.png --force EXTRA...` (EXTRA: e.g. --camera,
// --agl, --fov, --size, --background, --no-legend, --order) and waits for it, at most
// timeout_s seconds. Throws std::runtime_error naming the command's last line of output when it
// cannot start, fails or times out.
RenderRun run_render(const std::filesystem::path& exe, const std::filesystem::path& scene,
                     const std::filesystem::path& dir, const std::string& name,
                     const std::vector<std::string>& extra, int timeout_s = 600);

}  // namespace terravol::reference
