#include "io/geotiff_write.h"

#include <geovalues.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "io/bytes.h"
#include "io/tiff_memory.h"

namespace terravol::io {

namespace {

constexpr std::uint32_t kRowsPerStrip = 16;

// GDAL's metadata XML with the band's description and unit, as GDAL's GTiff driver writes
// and reads them back (items with role "description" and "unittype").
std::string gdal_metadata(const GeoTiffText& text) {
  std::string xml = "<GDALMetadata>\n";
  if (!text.description.empty()) {
    xml += "  <Item name=\"DESCRIPTION\" sample=\"0\" role=\"description\">" + xml_escaped(text.description) + "</Item>\n";
  }
  if (!text.units.empty()) {
    xml += "  <Item name=\"UNITTYPE\" sample=\"0\" role=\"unittype\">" + xml_escaped(text.units) + "</Item>\n";
  }
  return xml + "</GDALMetadata>\n";
}

}  // namespace

std::vector<std::uint8_t> encode_geotiff(const GeoRaster& raster, const GeoTiffText& text) {
  if (raster.rows < 1 || raster.cols < 1 ||
      raster.values.size() != static_cast<std::size_t>(raster.rows) * static_cast<std::size_t>(raster.cols)) {
    throw std::invalid_argument("encode_geotiff: " + std::to_string(raster.values.size()) + " values for " +
                                std::to_string(raster.rows) + " x " + std::to_string(raster.cols) + " pixels");
  }
  if (!(std::isfinite(raster.dlon) && raster.dlon > 0 && std::isfinite(raster.dlat) && raster.dlat > 0) ||
      !std::isfinite(raster.west) || !std::isfinite(raster.north)) {
    throw std::invalid_argument("encode_geotiff: the raster's corner and spacing must be finite, spacing > 0");
  }
  std::vector<std::uint8_t> out;
  tiff::MemoryFile file{{}, &out};
  tiff::Diagnostics diag;
  auto failed = [&](const std::string& what) {
    return std::runtime_error("GeoTIFF: " + what + (diag.last_error.empty() ? "" : " (" + diag.last_error + ")"));
  };
  {
    const tiff::TiffPtr tif = tiff::open(file, "w", "map.tif", diag, tmsize_t{256} << 20);
    if (!tif) throw failed("libtiff cannot start the file");
    TIFF* t = tif.get();
    const auto width = static_cast<std::uint32_t>(raster.cols), height = static_cast<std::uint32_t>(raster.rows);
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, width);
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, height);
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, 32);
    TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_IEEEFP);
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1);
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
    TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
    TIFFSetField(t, TIFFTAG_PREDICTOR, PREDICTOR_FLOATINGPOINT);
    TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, kRowsPerStrip);
    TIFFSetField(t, TIFFTAG_SOFTWARE, "terravol");
    if (!text.description.empty()) TIFFSetField(t, TIFFTAG_IMAGEDESCRIPTION, text.description.c_str());
    if (!text.description.empty() || !text.units.empty()) {
      TIFFSetField(t, tiff::kGdalMetadata, gdal_metadata(text).c_str());
    }
    TIFFSetField(t, TIFFTAG_GDAL_NODATA, "nan");
    const double tiepoint[6] = {0.0, 0.0, 0.0, raster.west, raster.north, 0.0};
    const double scale[3] = {raster.dlon, raster.dlat, 0.0};
    TIFFSetField(t, TIFFTAG_GEOTIEPOINTS, 6, tiepoint);
    TIFFSetField(t, TIFFTAG_GEOPIXELSCALE, 3, scale);
    {
      const tiff::GtifPtr keys = tiff::open_keys(t, diag);
      if (!keys) throw failed("libgeotiff cannot start the keys");
      GTIFKeySet(keys.get(), GTModelTypeGeoKey, TYPE_SHORT, 1, ModelTypeGeographic);
      GTIFKeySet(keys.get(), GTRasterTypeGeoKey, TYPE_SHORT, 1, RasterPixelIsArea);
      GTIFKeySet(keys.get(), GeographicTypeGeoKey, TYPE_SHORT, 1, GCS_WGS_84);
      GTIFKeySet(keys.get(), GeogAngularUnitsGeoKey, TYPE_SHORT, 1, Angular_Degree);
      GTIFKeySet(keys.get(), GTCitationGeoKey, TYPE_ASCII, 0, "WGS 84");
      if (!GTIFWriteKeys(keys.get())) throw failed("libgeotiff cannot write the keys");
    }
    // libtiff's predictor works in place, so each strip is copied first.
    std::vector<float> strip;
    for (std::uint32_t y = 0, s = 0; y < height; y += kRowsPerStrip, ++s) {
      const std::uint32_t n = std::min(kRowsPerStrip, height - y);
      const auto first = raster.values.begin() + static_cast<std::ptrdiff_t>(std::size_t{y} * width);
      strip.assign(first, first + static_cast<std::ptrdiff_t>(std::size_t{n} * width));
      if (TIFFWriteEncodedStrip(t, s, strip.data(), static_cast<tmsize_t>(strip.size() * sizeof(float))) < 0) {
        throw failed("libtiff cannot write strip " + std::to_string(s));
      }
    }
    if (!TIFFWriteDirectory(t)) throw failed("libtiff cannot write the directory");
  }  // TIFFClose
  return out;
}

}  // namespace terravol::io
