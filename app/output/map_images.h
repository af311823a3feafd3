// The pictures of a coverage map in a KMZ (io/kmz_write.h): the colour-mapped overlay and its
// legend (app/render/legend_image.h), drawn on the CPU, so no display is needed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/geo_raster.h"
#include "volume/colormap.h"

namespace terravol::app::output {

// The raster's pixels, RGBA, row 0 north: render::map_color of each value, opaque; NaN
// transparent (0, 0, 0, 0). PNG (app/output/png_output.h).
std::vector<std::uint8_t> overlay_png(const io::GeoRaster& raster, const volume::Colormap& colormap, double lo,
                                      double hi);

// A categorical map (best_server, volume::is_categorical): each value rounded to its category
// k, coloured volume::category_color(k), opaque; NaN transparent. PNG.
std::vector<std::uint8_t> category_overlay_png(const io::GeoRaster& raster);

// A swatch per category (value k, its label), in the legend card, no bar. Throws as legend_png.
struct MapCategory {
  std::int64_t k = 0;
  std::string label;
};
std::vector<std::uint8_t> category_legend_png(const std::string& title, const std::string& subtitle,
                                              const std::string& entries_title, const std::vector<MapCategory>& categories);

struct MapLegend {
  std::string title;     // first line, bold, e.g. "path_loss_db (dB)"
  std::string subtitle;  // second line, e.g. "10 m above ground"; empty: none
  double lo = 0.0, hi = 1.0;
};

// The legend card of render::legend_image (the map's bar from lo at the bottom to hi at the
// top, no isosurface entries) as an RGBA PNG. Throws std::runtime_error when FreeType cannot
// draw the text.
std::vector<std::uint8_t> legend_png(const volume::Colormap& colormap, const MapLegend& legend);

}  // namespace terravol::app::output
