// A scene drawn by the coverage-mask tiler (tiler/renderer.h, Greene 1996) instead of VTK:
// `terravol render --renderer tiler`, `fly --renderer tiler` and the antialiasing benchmark.
// It takes the tree's front-to-back frame and the same colours as the VTK path (the lattice
// texture, walls, merged polygons' RGBA, per-vertex haze, the sky gradient), and lays the
// legend card and the markers' labels over the image as the VTK path does (the labels' glyphs
// are FreeType's in both, placed alike, but not pixel for pixel VTK's billboards). Needs no X
// display and no OpenGL.
#pragma once

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "app/render/legend_image.h"
#include "app/scene/terrain_colors.h"
#include "app/scene/volume_layer.h"
#include "mrbsp/terrain_tree.h"
#include "tiler/renderer.h"

namespace terravol::app::render {

// The traversal the tiler draws: front to back, nearest first. With occlusion culling
// (Greene's section 5.2, the tree's pass) the pass must judge samples, not pixels, or it would
// cull nodes that show in some sample of a pixel whose centre is covered: the camera's
// viewport is then aa times larger and the LOD threshold scaled to match (aa times for the
// error metric, aa^2 for the area metric: powers of two, so the LOD choice is bit for bit the
// one at the output size). Without occlusion the camera is the output's.
mrbsp::TraversalOptions tiled_traversal(const mrbsp::TraversalOptions& options, int aa);
mrbsp::Camera tiled_traversal_camera(const mrbsp::Camera& camera, const mrbsp::TraversalOptions& options, int aa);

class TiledRenderer {
 public:
  // Throws what tiler::Renderer throws for bad settings.
  explicit TiledRenderer(const tiler::Settings& settings);

  const tiler::Settings& settings() const { return tiler_.settings(); }

  // Draws `frame` (a front-to-back traversal of `tree`, tiled_traversal) for `camera` (the
  // output's size) with the lattice colours `lattice` (shade_terrain: one RGBA per sample,
  // the texture), the sky gradient (bottom, top; equal for a uniform background) and the haze
  // (distance in metres, 0: none), then lays the legend over it. The frame's colour-box faces
  // (a density: Frame::transient_positions and transient_colors from transient_base) are
  // drawn as merged polygons, composited in float like every translucent polygon. Returns
  // wall milliseconds. Throws std::invalid_argument when the frame's transient_base is not
  // the tree's vertex count.
  double draw(const mrbsp::TerrainTree& tree, const scene::TerrainShading& lattice, const mrbsp::Frame& frame,
              const mrbsp::Camera& camera, double far_plane, const scene::Rgb& sky_bottom, const scene::Rgb& sky_top,
              double haze_distance, const scene::Rgb& haze_color);

  // The legend card over the image (top right, 10 px in, at most the image's height less
  // 20 px), as TerrainRenderer draws it; an empty legend: none.
  void set_legend(const scene::Legend& legend);
  // The markers' names over the image (after the legend): white 18 px bold text with a shadow,
  // centred above each anchor's projection, the bottom of the text on it; anchors behind the
  // near plane are not drawn. Replaces the last labels.
  void set_labels(const std::vector<scene::MarkerLabel>& labels);

  // The last image: width * height * 3 bytes, RGB, top row first.
  const std::vector<std::uint8_t>& rgb() const { return rgb_; }
  const tiler::Stats& stats() const { return stats_; }
  const tiler::Renderer& tiler() const { return tiler_; }

 private:
  tiler::Renderer tiler_;
  tiler::Stats stats_;
  std::vector<std::uint8_t> rgb_;
  std::vector<glm::vec3> positions_;        // the tree's vertices and a frame's own, when it has some
  std::vector<glm::u8vec4> merged_colors_;  // the tree's merged colours and the frame's own
  std::optional<RgbaImage> legend_;
  std::vector<std::pair<glm::dvec3, RgbaImage>> labels_;  // anchor (scene frame), text
};

}  // namespace terravol::app::render
