#include "app/render/tiled_renderer.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

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

namespace {

// Blends an RGBA image (row 0 at the top) over RGB pixels (w x h, top row first) with its
// top-left corner at (x0, y0), clipped to the picture (vtkImageMapper's blend: source alpha over).
void blend(std::vector<std::uint8_t>& rgb, int w, int h, const RgbaImage& image, int x0, int y0) {
  for (int y = std::max(0, -y0); y < image.height && y0 + y < h; ++y) {
    for (int x = std::max(0, -x0); x < image.width && x0 + x < w; ++x) {
      const std::uint8_t* s = &image.rgba[4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(x))];
      std::uint8_t* d = &rgb[3 * (static_cast<std::size_t>(y0 + y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x0 + x))];
      const int a = s[3];
      for (int k = 0; k < 3; ++k) d[k] = static_cast<std::uint8_t>((s[k] * a + d[k] * (255 - a) + 127) / 255);
    }
  }
}

}  // namespace

TiledRenderer::TiledRenderer(const tiler::Settings& settings) : tiler_(settings) {}

void TiledRenderer::set_labels(const std::vector<scene::MarkerLabel>& labels) {
  labels_.clear();
  for (const scene::MarkerLabel& l : labels) labels_.emplace_back(l.at, text_image(l.text, 18, true, glm::u8vec3(255), true));
}

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
  colors.merged_colors = tree.merged_colors();
  if (!frame.transient_positions.empty()) {
    // The frame's own vertices (colour-box faces, from transient_base = positions().size()) go
    // after the tree's as more merged vertices: a copy of the tree's per frame (12 and 4 bytes
    // a vertex), which an export renderer can afford.
    if (frame.transient_base != tree.positions().size()) {
      throw std::invalid_argument("TiledRenderer::draw: the frame's own vertices start at " + std::to_string(frame.transient_base) +
                                  ", after " + std::to_string(tree.positions().size()) + " vertices of the tree");
    }
    positions_.assign(tree.positions().begin(), tree.positions().end());
    positions_.insert(positions_.end(), frame.transient_positions.begin(), frame.transient_positions.end());
    merged_colors_.assign(tree.merged_colors().begin(), tree.merged_colors().end());
    merged_colors_.insert(merged_colors_.end(), frame.transient_colors.begin(), frame.transient_colors.end());
    colors.positions = positions_;
    colors.merged_colors = merged_colors_;
  }
  colors.lattice_side = tree.cells() + 1;
  // Rgba is four bytes (std::array<std::uint8_t, 4>): the lattice's colours are read as bytes.
  static_assert(sizeof(scene::Rgba) == 4);
  colors.texture = std::span(reinterpret_cast<const std::uint8_t*>(lattice.rgba.data()), lattice.rgba.size() * 4);
  colors.merged_base = tree.merged_base();
  colors.wall_color = glm::u8vec4(scene::kWallColor[0], scene::kWallColor[1], scene::kWallColor[2], 255);
  tiler::Look look;
  look.sky_bottom = glm::dvec3(sky_bottom[0], sky_bottom[1], sky_bottom[2]);
  look.sky_top = glm::dvec3(sky_top[0], sky_top[1], sky_top[2]);
  look.haze_distance = haze_distance;
  look.haze_color = glm::dvec3(haze_color[0], haze_color[1], haze_color[2]);
  stats_ = tiler_.render(colors, look, camera, far_plane, frame.indices);
  rgb_ = tiler_.rgb();
  const int w = tiler_.settings().width, h = tiler_.settings().height;
  // The card: its right edge 10 px from the image's, its top 10 px down.
  if (legend_) blend(rgb_, w, h, *legend_, w - 10 - legend_->width, 10);
  // The labels: each centred above its anchor's projection.
  const glm::dvec3 f = glm::normalize(camera.forward), r = glm::normalize(glm::cross(f, camera.up)), u = glm::cross(r, f);
  const double focal = h * 0.5 / std::tan(glm::radians(camera.fov_y_deg) * 0.5);
  for (const auto& [at, image] : labels_) {
    const glm::dvec3 d = at - camera.eye;
    const double depth = glm::dot(d, f);
    if (!(depth > camera.near_plane)) continue;
    const double x = 0.5 * w + focal * glm::dot(d, r) / depth, y_up = 0.5 * h + focal * glm::dot(d, u) / depth;
    if (!(std::abs(x) < 1e6) || !(std::abs(y_up) < 1e6)) continue;
    // Centred on the text and its bottom on the anchor, as VTK justifies it: the shadow's extra
    // column and row (text_image) lie beyond.
    blend(rgb_, w, h, image, static_cast<int>(std::lround(x - 0.5 * (image.width - 1))),
          static_cast<int>(std::floor(h - y_up)) - (image.height - 2));
  }
  return stats_.total_ms;
}

}  // namespace terravol::app::render
