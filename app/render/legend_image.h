// Legend cards drawn on the CPU (FreeType text through vtkFreeTypeTools, no display needed):
// the colour bar of a slice's map and a swatch per isosurface level. The viewer and render
// show them as an image in the window (TerrainRenderer::set_legend); export-map puts one in
// its KMZ (app/output/map_images.h).
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "volume/colormap.h"

namespace terravol::app::render {

// One isosurface level in the legend: a swatch of its colour and its label, and a mark in
// that colour beside the bar where `value` lies in [min(lo, hi), max(lo, hi)].
struct LegendEntry {
  std::string label;  // e.g. "110 dB"
  glm::u8vec3 color;
  double value = 0.0;
};

struct LegendCard {
  std::string title;     // first line, bold, e.g. "path_loss_db (dB)"
  std::string subtitle;  // second line, e.g. "slice 300 m above ground: viridis"; empty: none
  std::optional<volume::Colormap> colormap;  // the bar, lo at the bottom, hi at the top; none: no bar
  double lo = 0.0, hi = 1.0;
  std::string entries_title;  // heading over the swatches, e.g. "isosurfaces"
  std::vector<LegendEntry> entries;
};

// RGBA, row 0 at the top.
struct RgbaImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
};

// The card: the title lines, the bar (22 px wide, labelled at legend_ticks with the ticks'
// decimals, 200 px tall at most, each entry's value marked left of it, 3 px tall) and the
// entries' swatches (opaque, 14 px; marks and swatches outlined in the text's colour) with their labels,
// dark text on white at 85% opacity (alpha 217), as wide as the longest text needs.
// max_height > 0: the bar shrinks (to 40 px at least) and then the text (from 15/12 px down to
// 9/8 px) until the card is at most that tall; a card that cannot fit comes out at its
// smallest. Throws std::runtime_error when FreeType cannot draw the text.
RgbaImage legend_image(const LegendCard& card, int max_height = 0);

// A line of text as RGBA (row 0 at the top, transparent around the glyphs): FreeType through
// vtkFreeTypeTools, `size` px, bold or not, in `color`; with `shadow`, under it the same in
// black one pixel right and down (vtkTextProperty's shadow). For the tiler's marker labels.
// Throws std::runtime_error when FreeType cannot draw the text.
RgbaImage text_image(const std::string& text, int size, bool bold, glm::u8vec3 color, bool shadow);

// The round values the bar is labelled at in [min(lo, hi), max(lo, hi)], ascending: the
// largest step of 1, 2 or 5 times a power of ten that gives at least 3 labels. {lo} when
// lo == hi.
std::vector<double> legend_ticks(double lo, double hi);

// The colour of value v over [lo, hi]: t = (v - lo) / (hi - lo) (0.5 when lo == hi; lo > hi
// reverses the map) through the map, as slices colour (volume/geometry.h).
glm::u8vec3 map_color(const volume::Colormap& colormap, double lo, double hi, double v);

}  // namespace terravol::app::render
