#include "app/render/tiled_renderer.h"

#include <algorithm>
#include <cstring>

#include "app/render/terrain_renderer.h"

namespace terravol::app::render {

mrbsp::TraversalOptions tiled_traversal(const mrbsp::TraversalOptions& options, int aa) {
  mrbsp::TraversalOptions o = options;
  o.front_to_back = true;
  if (o.occlusion) {
    const float scale = static_cast<float>(o.metric == mrbsp::LodMetric::kError ? aa : aa * aa);
    o.threshold_px *= scale;
  }
  return o;
}

mrbsp::Camera tiled_traversal_camera(const mrbsp::Camera& camera, const mrbsp::TraversalOptions& options, int aa) {
  mrbsp::Camera c = camera;
  if (options.occlusion) {
    c.width *= aa;
    c.height *= aa;
  }
  return c;
}

TiledRenderer::TiledRenderer(const tiler::Settings& settings) : tiler_(settings) {}

void TiledRenderer::set_legend(const scene::Legend& legend) {
  legend_.reset();
  const std::optional<LegendCard> card = legend_card(legend);
  if (!card) return;
  // As TerrainRenderer places it by default: at most the image's height less 20 px.
  legend_ = legend_image(*card, std::max(1, tiler_.settings().height - 20));
}

double TiledRenderer::draw(const mrbsp::TerrainTree& tree, const scene::TerrainShading& lattice, const mrbsp::Frame& frame,
                           const mrbsp::Camera& camera, double far_plane, const scene::Rgb& sky_bottom,
                           const scene::Rgb& sky_top, double haze_distance, const scene::Rgb& haze_color) {
  tiler::SceneColors colors;
  colors.positions = tree.positions();
  colors.lattice_side = tree.cells() + 1;
  // Rgba is four bytes (std::array<std::uint8_t, 4>): the lattice's colours are read as bytes.
  static_assert(sizeof(scene::Rgba) == 4);
  colors.texture = std::span(reinterpret_cast<const std::uint8_t*>(lattice.rgba.data()), lattice.rgba.size() * 4);
  colors.merged_base = tree.merged_base();
  colors.wall_color = glm::u8vec4(scene::kWallColor[0], scene::kWallColor[1], scene::kWallColor[2], 255);
  colors.merged_colors = tree.merged_colors();
  tiler::Look look;
  look.sky_bottom = glm::dvec3(sky_bottom[0], sky_bottom[1], sky_bottom[2]);
  look.sky_top = glm::dvec3(sky_top[0], sky_top[1], sky_top[2]);
  look.haze_distance = haze_distance;
  look.haze_color = glm::dvec3(haze_color[0], haze_color[1], haze_color[2]);
  stats_ = tiler_.render(colors, look, camera, far_plane, frame.indices);
  rgb_ = tiler_.rgb();
  if (legend_) {
    // The card's RGBA over the picture, its right edge 10 px from the image's and its top 10 px
    // down (vtkImageMapper's blend: source alpha over).
    const int w = tiler_.settings().width, h = tiler_.settings().height;
    const int x0 = w - 10 - legend_->width, y0 = 10;
    for (int y = 0; y < legend_->height; ++y) {
      const int iy = y0 + y;
      if (iy < 0 || iy >= h) continue;
      for (int x = 0; x < legend_->width; ++x) {
        const int ix = x0 + x;
        if (ix < 0 || ix >= w) continue;
        const std::uint8_t* s = &legend_->rgba[4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(legend_->width) + static_cast<std::size_t>(x))];
        std::uint8_t* d = &rgb_[3 * (static_cast<std::size_t>(iy) * static_cast<std::size_t>(w) + static_cast<std::size_t>(ix))];
        const int a = s[3];
        for (int k = 0; k < 3; ++k) d[k] = static_cast<std::uint8_t>((s[k] * a + d[k] * (255 - a) + 127) / 255);
      }
    }
  }
  return stats_.total_ms;
}

}  // namespace terravol::app::render
