// An antialiased software renderer for the MRBSP tree's exact front-to-back order: Greene,
// "Hierarchical Polygon Tiling with Coverage Masks", SIGGRAPH 1996 (sections 3.1, 4.1, 4.3,
// 4.4; the algorithm and where this departs from the paper are in tiler/renderer.cpp). Each
// triangle is tiled, nearest first, into a coverage pyramid of aa x aa sub-samples per pixel
// (coverage::Pyramid: triage masks above the finest level, one-bit masks at it); only the
// samples it newly covers are shaded, and they are box-filtered into their pixel. Translucent
// triangles are composited under what lies in front of them ("under" operator), sample by
// sample, in the same order, which is exact because the order is. No depth buffer, no VTK.
//
// The colours are those of the VTK path (app/render/terrain_renderer.h), so that the two
// images agree away from edges: terrain from the lattice texture (bilinear between texel
// centres, clamped at the edges), walls in one colour, merged polygons in their vertices'
// RGBA, every colour attribute interpolated perspective-correctly as GL interpolates
// varyings; haze per vertex from its depth, mixed in after the colour; a sky that is linear
// in window y.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "mrbsp/terrain_tree.h"

namespace terravol::tiler {

struct Settings {
  int width = 1280, height = 720;  // output pixels; width * aa and height * aa at most 16384
  int aa = 8;                      // sub-samples per pixel per axis: 1, 2, 4 or 8 (aa^2 per pixel)
  // Shading points of textured (terrain) triangles per texel of the texture, per axis. A
  // terrain fragment (the samples a triangle newly covers in one pixel) is shaded at the
  // centroid of its samples when the pixel spans less than 1 / texel_rate texels along both
  // screen axes; otherwise its pixel's aa x aa samples are cut into kx x ky blocks (kx, ky the
  // powers of two at least texel_rate times the texels spanned along x and y, at most aa) and
  // each block's newly covered samples are shaded at their centroid. 0: every sample on its
  // own (exact supersampling of the texture). Untextured triangles (walls, merged polygons)
  // have colours linear across them and are shaded at each fragment's centroid.
  // The default, 0.25 (blocks once a pixel spans 4 texels or more), against 1.0: the bench's
  // quick aa suite over N44W072 (3 views) at 1280x720 and 8 x 8 drew its terrain views 1.2x
  // faster against VTK (1.33 shading points a pixel down to 0.80) at 54.6 dB against the
  // 16 x 16 supersampled reference instead of 54.9 dB; shading once per fragment (0.01) gave
  // 54.4 dB.
  double texel_rate = 0.25;
  int band_rows = 64;  // output pixel rows per band; bands are tiled in parallel, each with its own pyramid
  int threads = 0;     // worker threads, 0: TBB's default
};

// What the triangles are drawn in, borrowed for one render(). The vertex layout is
// mrbsp::TerrainTree's (positions()): the lattice samples, then the walls' vertices, then from
// merged_base the merged vertices. A triangle's kind is that of its first vertex.
struct SceneColors {
  std::span<const glm::vec3> positions;  // scene frame, metres
  int lattice_side = 0;                  // n + 1: vertices [0, side^2) are lattice samples j * side + i
  // The lattice colours as a side x side texture of RGBA bytes, texel j * side + i the colour
  // of sample (i, j) (the texture's alpha is not used: terrain is opaque).
  std::span<const std::uint8_t> texture;
  std::uint32_t merged_base = 0;          // vertices [side^2, merged_base) are walls'
  glm::u8vec4 wall_color{112, 96, 78, 255};
  std::span<const glm::u8vec4> merged_colors;  // vertex merged_base + k has merged_colors[k]
};

struct Look {
  // The background: linear in window y, sky_bottom at the image's bottom edge and sky_top at
  // its top edge (equal for a uniform background), as VTK's gradient background.
  glm::dvec3 sky_bottom{205, 222, 240}, sky_top{95, 145, 210};  // 0..255
  // Aerial perspective: each vertex fades toward haze_color by 0.85 (1 - exp(-d / haze_distance)),
  // d its depth along the view axis in metres, interpolated across the triangle; 0: none.
  double haze_distance = 0.0;
  glm::dvec3 haze_color{214, 226, 238};
};

// What one render() did.
struct Stats {
  std::size_t triangles = 0;            // given
  std::size_t translucent = 0;          // of those, drawn translucent (a merged vertex with alpha < 255)
  std::size_t clipped = 0;              // clipped at the near or far plane or the guard band
  std::size_t tiled = 0;                // triangle-band pairs tiled into a pyramid
  std::size_t fragments = 0;            // (triangle, pixel) pairs with newly covered or shown samples
  std::size_t shading_points = 0;       // colours evaluated
  std::uint64_t samples_covered = 0;    // samples newly covered by opaque triangles
  std::uint64_t samples_background = 0; // samples left to the sky
  std::uint64_t cells_visited = 0;      // pyramid cells and tiles composited (Greene, section 9)
  std::size_t class_splits = 0;         // translucent transmittance classes split (partly covered pixels)
  double setup_ms = 0, tile_ms = 0, total_ms = 0;  // wall: projection and binning; bands; all
  double tile_cpu_ms = 0;               // CPU time of the bands, over every thread
};

class Renderer {
 public:
  // Throws std::invalid_argument for a size outside 1..16384 / aa, aa not 1, 2, 4 or 8, a
  // negative or non-finite texel_rate, or band_rows < 1.
  explicit Renderer(const Settings& settings);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  const Settings& settings() const { return settings_; }

  // Draws triangles (three indices each into colors.positions) given nearest first, as
  // mrbsp::TerrainTree::traverse() emits them with TraversalOptions::front_to_back: every
  // triangle must come before every triangle it can hide. camera: its width and height must be
  // the settings'; the near plane is camera.near_plane and the far plane far_plane (metres,
  // > near), as VTK's clipping range; both sides of every triangle are drawn. Opaque triangles
  // (terrain, walls, merged ones whose three vertices have alpha 255) cover their samples;
  // translucent ones add their colour times alpha times the transmittance of what lies in
  // front, sample by sample, and scale that transmittance by 1 - alpha. Throws
  // std::invalid_argument when an index is out of range, the camera's size differs, the
  // vertex layout is inconsistent (texture size, merged colours) or the planes are bad.
  Stats render(const SceneColors& colors, const Look& look, const mrbsp::Camera& camera, double far_plane,
               std::span<const std::uint32_t> indices);

  // The last image: width * height * 3 bytes, RGB, top row first.
  const std::vector<std::uint8_t>& rgb() const { return rgb_; }
  // Per pixel of the last image (top row first): how many of its aa^2 samples were shaded by
  // an opaque triangle or the background, each counted once per time it was shaded (so aa^2
  // everywhere unless a sample was shaded twice or never).
  const std::vector<std::uint8_t>& sample_counts() const { return counts_; }

 private:
  struct Impl;
  Settings settings_;
  std::vector<std::uint8_t> rgb_, counts_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace terravol::tiler
