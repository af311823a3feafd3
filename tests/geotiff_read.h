// Reading a GeoTIFF back in tests with libtiff and libgeotiff directly (tags and GeoKeys as
// stored), independently of io/geotiff.cpp.
#pragma once

#include <geotiff.h>
#include <geovalues.h>
#include <tiffio.h>
#include <xtiffio.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace terravol::test {

struct GeoTiffContents {
  bool opened = false;
  std::uint32_t width = 0, height = 0;
  std::uint16_t bits = 0, sample_format = 0, samples_per_pixel = 0;
  std::vector<double> tiepoint, scale;  // as stored (6 and 3 values)
  int model_type = 0, raster_type = 0, geographic_type = 0, angular_units = 0;
  std::string nodata;       // GDAL_NODATA, "" when absent
  std::string description;  // ImageDescription
  std::string gdal_metadata;  // GDAL_METADATA (XML), "" when absent
  std::vector<float> values;  // row-major, row 0 first
};

// GDAL's two tags, registered before a directory is read (a tag merged later stays anonymous).
inline TIFFExtendProc& parent_tag_extender() {
  static TIFFExtendProc parent = nullptr;
  return parent;
}
inline void gdal_tag_extender(TIFF* tif) {
  static const TIFFFieldInfo kFields[] = {
      {TIFFTAG_GDAL_NODATA, TIFF_VARIABLE, TIFF_VARIABLE, TIFF_ASCII, FIELD_CUSTOM, 1, 0,
       const_cast<char*>("GDALNoDataValue")},
      {42112, TIFF_VARIABLE, TIFF_VARIABLE, TIFF_ASCII, FIELD_CUSTOM, 1, 0, const_cast<char*>("GDALMetadata")}};
  TIFFMergeFieldInfo(tif, kFields, 2);
  if (parent_tag_extender()) parent_tag_extender()(tif);
}

inline GeoTiffContents read_geotiff_file(const std::filesystem::path& path) {
  static const bool registered = [] {
    XTIFFInitialize();
    parent_tag_extender() = TIFFSetTagExtender(gdal_tag_extender);
    return true;
  }();
  (void)registered;
  GeoTiffContents c;
  TIFF* tif = XTIFFOpen(path.c_str(), "r");
  if (tif == nullptr) return c;
  c.opened = true;
  TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &c.width);
  TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &c.height);
  TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &c.bits);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &c.sample_format);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &c.samples_per_pixel);
  std::uint16_t n = 0;
  double* v = nullptr;
  if (TIFFGetField(tif, TIFFTAG_GEOTIEPOINTS, &n, &v)) c.tiepoint.assign(v, v + n);
  if (TIFFGetField(tif, TIFFTAG_GEOPIXELSCALE, &n, &v)) c.scale.assign(v, v + n);
  char* text = nullptr;
  if (TIFFGetField(tif, TIFFTAG_GDAL_NODATA, &text) && text) c.nodata = text;
  if (TIFFGetField(tif, TIFFTAG_IMAGEDESCRIPTION, &text) && text) c.description = text;
  if (TIFFGetField(tif, 42112, &text) && text) c.gdal_metadata = text;
  if (GTIF* gt = GTIFNew(tif)) {
    unsigned short s = 0;
    if (GTIFKeyGet(gt, GTModelTypeGeoKey, &s, 0, 1) == 1) c.model_type = s;
    if (GTIFKeyGet(gt, GTRasterTypeGeoKey, &s, 0, 1) == 1) c.raster_type = s;
    if (GTIFKeyGet(gt, GeographicTypeGeoKey, &s, 0, 1) == 1) c.geographic_type = s;
    if (GTIFKeyGet(gt, GeogAngularUnitsGeoKey, &s, 0, 1) == 1) c.angular_units = s;
    GTIFFree(gt);
  }
  if (c.bits == 32 && c.sample_format == SAMPLEFORMAT_IEEEFP && c.samples_per_pixel == 1) {
    c.values.resize(std::size_t{c.width} * c.height);
    for (std::uint32_t row = 0; row < c.height; ++row) {
      if (TIFFReadScanline(tif, c.values.data() + std::size_t{row} * c.width, row, 0) < 0) c.values.clear();
      if (c.values.empty()) break;
    }
  }
  XTIFFClose(tif);
  return c;
}

}  // namespace terravol::test
