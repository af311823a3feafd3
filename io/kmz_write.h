// Writing a coverage map as KMZ: a zipped KML 2.2 document (OGC 07-147r2) with one
// GroundOverlay image over its LatLonBox and a ScreenOverlay legend, as Google Earth and
// QGIS open it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace terravol::io {

struct KmzMap {
  std::string name;         // the document's and the ground overlay's name
  std::string description;  // the ground overlay's description (plain text)
  // The image's outer edges, degrees (WGS84): north > south; west and east are written in
  // [-180, 180] (KML's range), so a box across the antimeridian has west > east.
  double north = 0.0, south = 0.0, east = 0.0, west = 0.0;
  std::vector<std::uint8_t> overlay_png;  // draped over the box, row 0 north
  std::vector<std::uint8_t> legend_png;   // shown at the screen's lower left; empty: no legend
};

// doc.kml: a Document with the GroundOverlay (Icon files/overlay.png, altitudeMode
// clampToGround, the LatLonBox) and, with a legend, a ScreenOverlay (Icon files/legend.png,
// its lower left 10 pixels from the screen's, at its own size). Names and description are
// XML-escaped. Coordinates with 10 decimals (about 10 micrometres).
std::string kml_document(const KmzMap& map);

// The KMZ bytes: doc.kml first (the entry KML readers open), then files/overlay.png and
// files/legend.png, deflated by libzip. Throws std::invalid_argument when north <= south or
// a coordinate is not finite, std::runtime_error when libzip fails.
std::vector<std::uint8_t> encode_kmz(const KmzMap& map);

}  // namespace terravol::io
