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
