#include "app/output/map_images.h"

#include <cmath>

#include "app/output/png_output.h"
#include "app/render/legend_image.h"

namespace terravol::app::output {

std::vector<std::uint8_t> overlay_png(const io::GeoRaster& raster, const volume::Colormap& colormap, double lo,
                                      double hi) {
  std::vector<std::uint8_t> rgba(raster.values.size() * 4, 0);
  for (std::size_t i = 0; i < raster.values.size(); ++i) {
    const float v = raster.values[i];
    if (std::isnan(v)) continue;
    const glm::u8vec3 c = render::map_color(colormap, lo, hi, v);
    rgba[4 * i] = c.r;
    rgba[4 * i + 1] = c.g;
    rgba[4 * i + 2] = c.b;
    rgba[4 * i + 3] = 255;
  }
  return encode_png(rgba, raster.cols, raster.rows, 4);
}

std::vector<std::uint8_t> category_overlay_png(const io::GeoRaster& raster) {
  std::vector<std::uint8_t> rgba(raster.values.size() * 4, 0);
  for (std::size_t i = 0; i < raster.values.size(); ++i) {
    const float v = raster.values[i];
    if (!std::isfinite(v)) continue;
    const glm::u8vec3 c = volume::category_color(std::llround(v));
    rgba[4 * i] = c.r;
    rgba[4 * i + 1] = c.g;
    rgba[4 * i + 2] = c.b;
    rgba[4 * i + 3] = 255;
  }
  return encode_png(rgba, raster.cols, raster.rows, 4);
}

std::vector<std::uint8_t> category_legend_png(const std::string& title, const std::string& subtitle,
                                              const std::string& entries_title, const std::vector<MapCategory>& categories) {
  render::LegendCard card;
  card.title = title;
  card.subtitle = subtitle;
  card.entries_title = entries_title;
  for (const MapCategory& c : categories)
    card.entries.push_back({c.label, volume::category_color(c.k), static_cast<double>(c.k)});
  const render::RgbaImage img = render::legend_image(card);
  return encode_png(img.rgba, img.width, img.height, 4);
}

std::vector<std::uint8_t> legend_png(const volume::Colormap& colormap, const MapLegend& legend) {
  render::LegendCard card;
  card.title = legend.title;
  card.subtitle = legend.subtitle;
  card.colormap = colormap;
  card.lo = legend.lo;
  card.hi = legend.hi;
  const render::RgbaImage img = render::legend_image(card);
  return encode_png(img.rgba, img.width, img.height, 4);
}

}  // namespace terravol::app::output
