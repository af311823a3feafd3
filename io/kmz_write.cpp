#include "io/kmz_write.h"

#include <zip.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "io/bytes.h"

namespace terravol::io {

namespace {

std::string degrees(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10f", v);
  return b;
}

// A longitude in [-180, 180], 180 kept as 180.
double wrapped(double lon) {
  if (lon >= -180.0 && lon <= 180.0) return lon;
  const double r = std::remainder(lon, 360.0);
  return r == -180.0 ? 180.0 : r;
}

void check_box(const KmzMap& m) {
  for (const double v : {m.north, m.south, m.east, m.west}) {
    if (!std::isfinite(v)) throw std::invalid_argument("KMZ: the overlay's box must be finite");
  }
  if (!(m.north > m.south)) throw std::invalid_argument("KMZ: the overlay's north edge must lie north of its south edge");
}

}  // namespace

std::string kml_document(const KmzMap& m) {
  check_box(m);
  std::string k;
  k += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  k += "<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n";
  k += "<Document>\n";
  k += "  <name>" + xml_escaped(m.name) + "</name>\n";
  k += "  <GroundOverlay>\n";
  k += "    <name>" + xml_escaped(m.name) + "</name>\n";
  if (!m.description.empty()) k += "    <description>" + xml_escaped(m.description) + "</description>\n";
  k += "    <Icon><href>files/overlay.png</href></Icon>\n";
  k += "    <altitudeMode>clampToGround</altitudeMode>\n";
  k += "    <LatLonBox>\n";
  k += "      <north>" + degrees(m.north) + "</north>\n";
  k += "      <south>" + degrees(m.south) + "</south>\n";
  k += "      <east>" + degrees(wrapped(m.east)) + "</east>\n";
  k += "      <west>" + degrees(wrapped(m.west)) + "</west>\n";
  k += "    </LatLonBox>\n";
  k += "  </GroundOverlay>\n";
  if (!m.legend_png.empty()) {
    k += "  <ScreenOverlay>\n";
    k += "    <name>Legend</name>\n";
    k += "    <Icon><href>files/legend.png</href></Icon>\n";
    k += "    <overlayXY x=\"0\" y=\"0\" xunits=\"fraction\" yunits=\"fraction\"/>\n";
    k += "    <screenXY x=\"10\" y=\"10\" xunits=\"pixels\" yunits=\"pixels\"/>\n";
    k += "    <size x=\"-1\" y=\"-1\" xunits=\"pixels\" yunits=\"pixels\"/>\n";
    k += "  </ScreenOverlay>\n";
  }
  k += "</Document>\n";
  k += "</kml>\n";
  return k;
}

std::vector<std::uint8_t> encode_kmz(const KmzMap& m) {
  const std::string kml = kml_document(m);
  zip_error_t err;
  zip_error_init(&err);
  std::unique_ptr<zip_error_t, void (*)(zip_error_t*)> err_guard(&err, zip_error_fini);
  zip_source_t* buffer = zip_source_buffer_create(nullptr, 0, 0, &err);
  if (buffer == nullptr) throw std::runtime_error("KMZ: libzip cannot make a buffer");
  std::unique_ptr<zip_source_t, void (*)(zip_source_t*)> buffer_guard(buffer, zip_source_free);
  zip_source_keep(buffer);  // zip_close must leave it, with the archive in it
  zip_t* archive = zip_open_from_source(buffer, ZIP_TRUNCATE, &err);
  if (archive == nullptr) {
    zip_source_free(buffer);  // the reference zip_open_from_source did not take
    throw std::runtime_error(std::string("KMZ: ") + zip_error_strerror(&err));
  }
  auto add = [&](const char* name, const void* data, std::size_t size) {
    zip_source_t* s = zip_source_buffer(archive, data, size, 0);
    if (s == nullptr || zip_file_add(archive, name, s, ZIP_FL_ENC_UTF_8) < 0) {
      if (s != nullptr) zip_source_free(s);
      const std::string why = zip_strerror(archive);
      zip_discard(archive);
      throw std::runtime_error("KMZ: cannot add " + std::string(name) + " (" + why + ")");
    }
  };
  add("doc.kml", kml.data(), kml.size());
  add("files/overlay.png", m.overlay_png.data(), m.overlay_png.size());
  if (!m.legend_png.empty()) add("files/legend.png", m.legend_png.data(), m.legend_png.size());
  if (zip_close(archive) != 0) {
    const std::string why = zip_strerror(archive);
    zip_discard(archive);
    throw std::runtime_error("KMZ: " + why);
  }
  if (zip_source_open(buffer) != 0 || zip_source_seek(buffer, 0, SEEK_END) != 0) {
    throw std::runtime_error("KMZ: cannot read the archive back");
  }
  const zip_int64_t size = zip_source_tell(buffer);
  std::vector<std::uint8_t> out(size > 0 ? static_cast<std::size_t>(size) : 0);
  zip_source_seek(buffer, 0, SEEK_SET);
  const zip_int64_t got = zip_source_read(buffer, out.data(), out.size());
  zip_source_close(buffer);
  if (got != size) throw std::runtime_error("KMZ: cannot read the archive back");
  return out;
}

}  // namespace terravol::io
