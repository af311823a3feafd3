// The pictures of a coverage map in a KMZ (io/kmz_write.h): the colour-mapped overlay and its
// legend, drawn on the CPU (FreeType text through vtkFreeTypeTools), so no display is needed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/geo_raster.h"
#include "volume/colormap.h"

namespace terravol::app::output {

// The colour of value v over [lo, hi]: t = (v - lo) / (hi - lo) (0.5 when lo == hi; lo > hi
// reverses the map) through the map, as slices colour (volume/geometry.h).
glm::u8vec3 map_color(const volume::Colormap& colormap, double lo, double hi, double v);

// The raster's pixels, RGBA, row 0 north: map_color of each value, opaque; NaN transparent
// (0, 0, 0, 0). PNG (app/output/png_output.h).
std::vector<std::uint8_t> overlay_png(const io::GeoRaster& raster, const volume::Colormap& colormap, double lo,
                                      double hi);

struct MapLegend {
  std::string title;     // first line, bold, e.g. "path_loss_db (dB)"
  std::string subtitle;  // second line, e.g. "10 m above ground"; empty: none
  double lo = 0.0, hi = 1.0;
};

// A legend card, RGBA PNG: the title lines over a vertical colour bar from lo (bottom) to hi
// (top), labelled at round values (steps of 1, 2 or 5 times a power of ten, 3 to 6 labels),
// dark text on white at 85% opacity, as wide as the longest text needs. Throws
// std::runtime_error when FreeType cannot draw the text.
std::vector<std::uint8_t> legend_png(const volume::Colormap& colormap, const MapLegend& legend);

// The round values legend_png labels in [min(lo, hi), max(lo, hi)], ascending: the largest
// step of 1, 2 or 5 times a power of ten that gives at least 3 labels. {lo} when lo == hi.
std::vector<double> legend_ticks(double lo, double hi);

}  // namespace terravol::app::output
