// GeoTIFF DEMs: libtiff decodes the TIFF (strips or tiles, any compression it was built with)
// and libgeotiff parses the GeoKeys. GeoTIFF 1.0 specification (rev. 1.8.2) sections used:
//   2.4      GeoKeyDirectoryTag and the key structure (read by libgeotiff)
//   2.5.2.2  Raster space: PixelIsArea puts raster (0,0) at the outer corner of the first
//            pixel, PixelIsPoint at its centre
//   2.6.1    ModelTiepointTag, ModelPixelScaleTag (y scale positive = rows go south),
//            ModelTransformationTag
//   6.2.1-4  configuration, geographic, projected and vertical CS keys
//   6.3.1.1-3 model type, raster type and linear unit codes; 6.3.2.1-3 geographic CS, datum
//            and ellipsoid codes; 6.3.3.1-2 projected CS (PCS_WGS84_UTM_zone_*) and
//            projection (Proj_UTM_zone_*) codes; 6.3.4.1 vertical CS codes
// Outside the specification: the GDAL_NODATA tag (42113, an ASCII number) written by GDAL.
#include <geotiff.h>
#include <geovalues.h>
#include <tiffio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/error.h"
#include "io/readers.h"
#include "io/tiff_memory.h"

namespace terravol::io {

namespace {

constexpr int kEpsgEgm96 = 5773;
constexpr int kEpsgEgm2008 = 3855;
constexpr int kEpsgEgm84 = 5798;
constexpr int kEpsgNavd88 = 5703;
constexpr int kEpsgMsl = 5714;
constexpr int kEpsgWgs84Ellipsoidal3d = 4979;
constexpr int kSemiMajorWgs84 = 6378137;
constexpr double kInvFlatteningWgs84 = 298.257223563;
constexpr const char* kSupported = "Terravol reads EPSG:4326 and WGS84 UTM 326xx/327xx";

// libtiff may allocate no more than this at once on our behalf (strip offset arrays, codec
// buffers): a header claiming 10^9 strips then fails instead of allocating gigabytes.
constexpr tmsize_t kMaxLibtiffAlloc = tmsize_t{256} << 20;
// Largest tile decoded at once (strips are decoded a row at a time). With the largest grid
// (kMaxSamples floats and mask bytes) this keeps a hostile header under 1.5 GiB.
constexpr std::uint64_t kMaxTileBytes = std::uint64_t{256} << 20;

// ---- tags and keys -------------------------------------------------------------------------

// A DOUBLE array tag registered by libgeotiff (count passed with the value).
std::vector<double> double_array_tag(TIFF* tif, ttag_t tag) {
  const TIFFField* field = TIFFFindField(tif, tag, TIFF_ANY);
  if (field == nullptr || !TIFFFieldPassCount(field) || TIFFFieldDataType(field) != TIFF_DOUBLE)
    return {};
  double* values = nullptr;
  std::uint32_t n = 0;
  if (TIFFFieldReadCount(field) == TIFF_VARIABLE2) {
    std::uint32_t count = 0;
    if (!TIFFGetField(tif, tag, &count, &values)) return {};
    n = count;
  } else {
    std::uint16_t count = 0;
    if (!TIFFGetField(tif, tag, &count, &values)) return {};
    n = count;
  }
  if (values == nullptr) return {};
  return {values, values + n};
}

std::optional<int> short_key(GTIF* gt, geokey_t key) {
  unsigned short v = 0;
  if (GTIFKeyGetSHORT(gt, key, &v, 0, 1) != 1) return std::nullopt;
  return v;
}

std::optional<double> double_key(GTIF* gt, geokey_t key) {
  double v = 0.0;
  if (GTIFKeyGetDOUBLE(gt, key, &v, 0, 1) != 1) return std::nullopt;
  return v;
}

std::string ascii_key(GTIF* gt, geokey_t key) {
  char buf[256] = {};
  if (GTIFKeyGetASCII(gt, key, buf, static_cast<int>(sizeof buf) - 1) <= 0) return {};
  std::string s(buf, strnlen(buf, sizeof buf));
  while (!s.empty() && (s.back() == '|' || s.back() == ' ')) s.pop_back();  // GDAL's separators
  for (char& c : s) {
    if (c == '\n' || c == '\r' || c == '|') c = ' ';
  }
  return s;
}

bool is_user_defined(const std::optional<int>& code) {
  return code && *code == KvUserDefined;
}

std::string epsg(int code) {
  return "EPSG:" + std::to_string(code);
}

// Accepts the geographic CS of the file as WGS84 or throws. `what` names the CS for messages
// ("" for a geographic model, "UTM zone 25S on " for a projected one). Returns a note for the
// user when WGS84 is an assumption rather than what the file says.
std::optional<std::string> check_wgs84(GTIF* gt, const std::string& source,
                                       const std::string& what) {
  const auto gcs = short_key(gt, GeographicTypeGeoKey);
  if (gcs && *gcs == GCS_WGS_84) return std::nullopt;
  if (gcs && !is_user_defined(gcs)) {
    throw FormatError(source,
                      "unsupported " + what + "geographic CRS " + epsg(*gcs) + "; " + kSupported);
  }
  if (const auto pm = short_key(gt, GeogPrimeMeridianGeoKey);
      pm && *pm != PM_Greenwich && !is_user_defined(pm)) {
    throw FormatError(source, "unsupported prime meridian " + epsg(*pm) + "; " + kSupported);
  }
  if (const auto pm_long = double_key(gt, GeogPrimeMeridianLongGeoKey);
      pm_long && *pm_long != 0.0) {
    throw FormatError(source, "prime meridian is not Greenwich; " + std::string(kSupported));
  }
  double towgs84[7] = {};
  const int n_towgs84 = GTIFKeyGetDOUBLE(gt, GeogTOWGS84GeoKey, towgs84, 0, 7);
  for (int i = 0; i < n_towgs84; ++i) {
    if (towgs84[i] != 0.0) {
      throw FormatError(
          source, "datum is shifted from WGS84 (GeogTOWGS84GeoKey); " + std::string(kSupported));
    }
  }
  const auto datum = short_key(gt, GeogGeodeticDatumGeoKey);
  if (datum && *datum == Datum_WGS84) return std::nullopt;
  if (datum && !is_user_defined(datum)) {
    throw FormatError(source,
                      "unsupported " + what + "geodetic datum " + epsg(*datum) + "; " + kSupported);
  }
  // User-defined or unnamed datum: accept a WGS84-sized ellipsoid (GRS 1980 differs from it
  // by 0.1 mm in the semi-minor axis).
  const auto ellipsoid = short_key(gt, GeogEllipsoidGeoKey);
  std::string described;
  if (ellipsoid && (*ellipsoid == Ellipse_WGS_84 || *ellipsoid == Ellipse_GRS_1980)) {
    described = *ellipsoid == Ellipse_WGS_84 ? "the WGS84 ellipsoid" : "the GRS 1980 ellipsoid";
  } else if (ellipsoid && !is_user_defined(ellipsoid)) {
    throw FormatError(source,
                      "unsupported " + what + "ellipsoid " + epsg(*ellipsoid) + "; " + kSupported);
  } else {
    const auto a = double_key(gt, GeogSemiMajorAxisGeoKey);
    const auto inv_f = double_key(gt, GeogInvFlatteningGeoKey);
    if (a && std::fabs(*a - kSemiMajorWgs84) > 0.5) {
      throw FormatError(source, "ellipsoid semi-major axis " + std::to_string(*a) +
                                    " m is not WGS84's; " + kSupported);
    }
    if (inv_f && std::fabs(*inv_f - kInvFlatteningWgs84) > 1e-3) {
      throw FormatError(source, "ellipsoid inverse flattening " + std::to_string(*inv_f) +
                                    " is not WGS84's; " + kSupported);
    }
    described = a ? "a WGS84-sized ellipsoid" : "no ellipsoid either";
  }
  return "horizontal datum not named (GeoTIFF gives " + described + "); taken as WGS84";
}

// The horizontal CRS from the GeoKeys (spec 6.2.1-6.2.3), or a FormatError naming what the
// file uses instead.
Georef read_crs(GTIF* gt, const std::string& source, std::vector<std::string>& notes) {
  Georef ref;
  const auto pcs = short_key(gt, ProjectedCSTypeGeoKey);
  const auto gcs = short_key(gt, GeographicTypeGeoKey);
  auto model = short_key(gt, GTModelTypeGeoKey);
  if (!model) {
    if (pcs)
      model = ModelTypeProjected;
    else if (gcs)
      model = ModelTypeGeographic;
  }
  if (!model) {
    throw FormatError(source,
                      "GeoTIFF keys do not say the coordinate system (no GTModelTypeGeoKey); " +
                          std::string(kSupported));
  }
  if (*model == ModelTypeGeographic) {
    const auto units = short_key(gt, GeogAngularUnitsGeoKey);
    if (units && *units != Angular_Degree && !is_user_defined(units)) {
      throw FormatError(source, "geographic angular units " + epsg(*units) + " are not degrees");
    }
    if (auto note = check_wgs84(gt, source, "")) notes.push_back(*note);
    ref.crs = Crs::kGeographic;
    return ref;
  }
  if (*model != ModelTypeProjected) {
    throw FormatError(source, "unsupported model type " + std::to_string(*model) +
                                  " (only projected and geographic); " + kSupported);
  }
  const auto units = short_key(gt, ProjLinearUnitsGeoKey);
  if (units && *units != Linear_Meter) {
    throw FormatError(source,
                      "projected linear units " + epsg(*units) + " are not metres; " + kSupported);
  }
  ref.crs = Crs::kUtm;
  if (pcs && *pcs >= 32601 && *pcs <= 32660) {  // PCS_WGS84_UTM_zone_1N .. 60N
    ref.utm_zone = *pcs - 32600;
    ref.utm_north = true;
    return ref;
  }
  if (pcs && *pcs >= 32701 && *pcs <= 32760) {  // PCS_WGS84_UTM_zone_1S .. 60S
    ref.utm_zone = *pcs - 32700;
    ref.utm_north = false;
    return ref;
  }
  if (pcs && !is_user_defined(pcs)) {
    throw FormatError(source, "unsupported projection " + epsg(*pcs) + "; " + kSupported);
  }
  // User-defined PCS: a UTM projection code (Proj_UTM_zone_*) on a WGS84-compatible datum.
  const auto projection = short_key(gt, ProjectionGeoKey);
  if (projection && *projection >= Proj_UTM_zone_1N && *projection <= Proj_UTM_zone_1N + 59) {
    ref.utm_zone = *projection - Proj_UTM_zone_1N + 1;
    ref.utm_north = true;
  } else if (projection && *projection >= Proj_UTM_zone_1S && *projection <= Proj_UTM_zone_60S) {
    ref.utm_zone = *projection - Proj_UTM_zone_1S + 1;
    ref.utm_north = false;
  } else {
    const std::string code =
        projection ? (is_user_defined(projection) ? "user-defined" : epsg(*projection))
                   : "unstated";
    throw FormatError(source, "unsupported projection (" + code +
                                  " projection in a user-defined projected CRS, not a UTM zone); " +
                                  kSupported);
  }
  const std::string zone = "UTM zone " + std::to_string(ref.utm_zone) + (ref.utm_north ? "N" : "S");
  if (auto note = check_wgs84(gt, source, zone + " on ")) notes.push_back(*note);
  return ref;
}

// Vertical datum as far as the file says (spec 6.2.4, 6.3.4.1).
std::string read_vertical_datum(GTIF* gt) {
  const auto vcs = short_key(gt, VerticalCSTypeGeoKey);
  if (!vcs) return "unknown (GeoTIFF does not say)";
  switch (*vcs) {
    case kEpsgEgm96:
      return "EGM96 geoid (EPSG:5773)";
    case kEpsgEgm2008:
      return "EGM2008 geoid (EPSG:3855)";
    case kEpsgEgm84:
      return "EGM84 geoid (EPSG:5798)";
    case kEpsgNavd88:
      return "NAVD88 (EPSG:5703)";
    case kEpsgMsl:
      return "mean sea level (EPSG:5714)";
    case VertCS_WGS_84_ellipsoid:
      return "WGS84 ellipsoid (GeoTIFF 1.0 code 5030)";
    case kEpsgWgs84Ellipsoidal3d:
      return "WGS84 ellipsoid (EPSG:4979)";
    case KvUserDefined: {
      const std::string citation = ascii_key(gt, VerticalCitationGeoKey);
      return citation.empty() ? "user-defined (GeoTIFF gives no name)" : citation;
    }
    default:
      return epsg(*vcs);
  }
}

// Heights are metres; feet are converted.
double read_vertical_scale(GTIF* gt, const std::string& source, std::vector<std::string>& notes) {
  const auto units = short_key(gt, VerticalUnitsGeoKey);
  if (!units || *units == Linear_Meter) return 1.0;
  if (*units == Linear_Foot) {
    notes.push_back("heights converted from feet");
    return 0.3048;
  }
  if (*units == Linear_Foot_US_Survey) {
    notes.push_back("heights converted from US survey feet");
    return 1200.0 / 3937.0;
  }
  throw FormatError(source, "vertical units " + epsg(*units) + " are neither metres nor feet");
}

// Where the samples are (spec 2.5.2.2, 2.6.1). Fills x0, y0, dx, dy of `ref` and says whether
// rows (columns) are stored south-up (east-to-west) and must be flipped.
struct Placement {
  bool flip_rows = false;
  bool flip_cols = false;
};

Placement read_placement(TIFF* tif, GTIF* gt, const std::string& source, int rows, int cols,
                         Georef& ref) {
  const std::vector<double> scale = double_array_tag(tif, TIFFTAG_GEOPIXELSCALE);
  const std::vector<double> ties = double_array_tag(tif, TIFFTAG_GEOTIEPOINTS);
  const std::vector<double> matrix = double_array_tag(tif, TIFFTAG_GEOTRANSMATRIX);
  // Raster position (i, j) of the tie point and its model position (x, y); then
  // x(i) = x + (i - ti) * sx and y(j) = y - (j - tj) * sy.
  double ti = 0, tj = 0, tx = 0, ty = 0, sx = 0, sy = 0;
  if (scale.size() >= 2 && ties.size() >= 6) {
    ti = ties[0];
    tj = ties[1];
    tx = ties[3];
    ty = ties[4];
    sx = scale[0];
    sy = scale[1];
  } else if (matrix.size() >= 16) {
    // Row-major 4x4: X = m0 i + m1 j + m3, Y = m4 i + m5 j + m7.
    if (matrix[1] != 0.0 || matrix[4] != 0.0) {
      throw FormatError(
          source,
          "ModelTransformationTag rotates or shears the grid; only north-up grids are supported");
    }
    sx = matrix[0];
    sy = -matrix[5];
    tx = matrix[3];
    ty = matrix[7];
  } else if (ties.size() >= 12) {
    throw FormatError(
        source, "georeferenced by " + std::to_string(ties.size() / 6) +
                    " tie points without ModelPixelScaleTag; only regular grids are supported");
  } else {
    throw FormatError(source,
                      "no georeference (needs ModelTiepointTag with ModelPixelScaleTag, or "
                      "ModelTransformationTag)");
  }
  for (const double v : {ti, tj, tx, ty, sx, sy}) {
    if (!std::isfinite(v)) throw FormatError(source, "georeference holds a non-finite number");
  }
  if (sx == 0.0 || sy == 0.0) {
    throw FormatError(
        source, "pixel scale is zero (x " + std::to_string(sx) + ", y " + std::to_string(sy) + ")");
  }
  const auto raster_type = short_key(gt, GTRasterTypeGeoKey);
  // PixelIsArea (the default): raster (0,0) is the outer corner of pixel (0,0), whose centre
  // is at raster (0.5, 0.5). PixelIsPoint: pixel (0,0) is the point raster (0,0).
  const double centre = (raster_type && *raster_type == RasterPixelIsPoint) ? 0.0 : 0.5;
  const double x_first = tx + (centre - ti) * sx;
  const double y_first = ty - (centre - tj) * sy;
  Placement p;
  p.flip_cols = sx < 0.0;
  p.flip_rows = sy < 0.0;
  ref.dx = std::fabs(sx);
  ref.dy = std::fabs(sy);
  ref.x0 = p.flip_cols ? x_first + (cols - 1) * sx : x_first;
  ref.y0 = p.flip_rows ? y_first - (rows - 1) * sy : y_first;
  if (!std::isfinite(ref.x0) || !std::isfinite(ref.y0)) {
    throw FormatError(source, "georeference overflows");
  }
  return p;
}

// ---- samples -------------------------------------------------------------------------------

enum class SampleType { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

struct NoData {
  bool has = false;
  double value = 0.0;   // in the sample type's precision
  bool is_nan = false;  // GDAL_NODATA "nan": NaN samples are the declared voids
};

// How many output bytes one input byte can become at most, per codec; 0 when unbounded.
// Deflate: a 258-byte match in 2 bits (1032:1). LZW: a code of >= 9 bits gives at most 4096
// bytes. PackBits: 2 bytes give at most 128. ZSTD: a 4-byte RLE block gives 128 KiB. LZMA:
// a 273-byte repeat costs at least ~0.3 bits. JPEG: an 8x8 block of 12-bit samples (128
// bytes) takes at least one bit.
std::uint64_t max_expansion(std::uint16_t compression) {
  switch (compression) {
    case COMPRESSION_NONE:
      return 1;
    case COMPRESSION_PACKBITS:
      return 64;
    case COMPRESSION_ADOBE_DEFLATE:
    case COMPRESSION_DEFLATE:
      return 1100;
    case COMPRESSION_JPEG:
      return 2048;
    case COMPRESSION_LZW:
      return 4096;
    case COMPRESSION_ZSTD:
      return 32768;
    case COMPRESSION_LZMA:
      return 65536;
    default:
      return 0;  // LERC (a constant tile is a header), exotic codecs: no bound
  }
}

template <typename T>
void store_chunk(const std::uint8_t* buf, int chunk_w, int row0, int col0, int n_rows, int n_cols,
                 const Placement& p, const NoData& nodata, double unit, Grid& g,
                 std::size_t& non_finite) {
  for (int r = 0; r < n_rows; ++r) {
    const int src_row = row0 + r;
    const int dst_row = p.flip_rows ? g.rows - 1 - src_row : src_row;
    const std::uint8_t* line =
        buf + static_cast<std::size_t>(r) * static_cast<std::size_t>(chunk_w) * sizeof(T);
    for (int c = 0; c < n_cols; ++c) {
      T v;
      std::memcpy(&v, line + static_cast<std::size_t>(c) * sizeof(T), sizeof(T));
      const int src_col = col0 + c;
      const std::size_t i = g.index(dst_row, p.flip_cols ? g.cols - 1 - src_col : src_col);
      const double d = static_cast<double>(v);
      const double h = d * unit;
      if (nodata.has && d == nodata.value) {
        g.mask[i] = Sample::kVoid;
      } else if (std::isnan(d)) {
        g.mask[i] = Sample::kVoid;
        if (!nodata.is_nan) ++non_finite;
      } else if (!std::isfinite(d) || std::fabs(h) > std::numeric_limits<float>::max()) {
        g.mask[i] = Sample::kVoid;
        ++non_finite;
      } else {
        g.heights[i] = static_cast<float>(h);
      }
    }
  }
}

void store(SampleType type, const std::uint8_t* buf, int chunk_w, int row0, int col0, int n_rows,
           int n_cols, const Placement& p, const NoData& nodata, double unit, Grid& g,
           std::size_t& non_finite) {
  switch (type) {
    case SampleType::kI8:
      return store_chunk<std::int8_t>(buf, chunk_w, row0, col0, n_rows, n_cols, p, nodata, unit, g,
                                      non_finite);
    case SampleType::kU8:
      return store_chunk<std::uint8_t>(buf, chunk_w, row0, col0, n_rows, n_cols, p, nodata, unit, g,
                                       non_finite);
    case SampleType::kI16:
      return store_chunk<std::int16_t>(buf, chunk_w, row0, col0, n_rows, n_cols, p, nodata, unit, g,
                                       non_finite);
    case SampleType::kU16:
      return store_chunk<std::uint16_t>(buf, chunk_w, row0, col0, n_rows, n_cols, p, nodata, unit,
                                        g, non_finite);
    case SampleType::kI32:
      return store_chunk<std::int32_t>(buf, chunk_w, row0, col0, n_rows, n_cols, p, nodata, unit, g,
                                       non_finite);
    case SampleType::kU32:
      return store_chunk<std::uint32_t>(buf, chunk_w, row0, col0, n_rows, n_cols, p, nodata, unit,
                                        g, non_finite);
    case SampleType::kF32:
      return store_chunk<float>(buf, chunk_w, row0, col0, n_rows, n_cols, p, nodata, unit, g,
                                non_finite);
    case SampleType::kF64:
      return store_chunk<double>(buf, chunk_w, row0, col0, n_rows, n_cols, p, nodata, unit, g,
                                 non_finite);
  }
}

SampleType sample_type(const std::string& source, std::uint16_t format, std::uint16_t bits) {
  if (format == SAMPLEFORMAT_INT) {
    if (bits == 8) return SampleType::kI8;
    if (bits == 16) return SampleType::kI16;
    if (bits == 32) return SampleType::kI32;
  } else if (format == SAMPLEFORMAT_UINT) {
    if (bits == 8) return SampleType::kU8;
    if (bits == 16) return SampleType::kU16;
    if (bits == 32) return SampleType::kU32;
  } else if (format == SAMPLEFORMAT_IEEEFP) {
    if (bits == 32) return SampleType::kF32;
    if (bits == 64) return SampleType::kF64;
  }
  static const char* const kNames[] = {
      "?",    "unsigned integer", "signed integer",        "floating-point",
      "void", "complex integer",  "complex floating-point"};
  const std::string name = format < 7 ? kNames[format] : "format " + std::to_string(format);
  throw FormatError(source,
                    std::to_string(bits) + "-bit " + name +
                        " samples are not supported (8/16/32-bit integers, 32/64-bit floats)");
}

NoData read_nodata(TIFF* tif, SampleType type, std::vector<std::string>& notes) {
  NoData nd;
  const TIFFField* field = TIFFFindField(tif, TIFFTAG_GDAL_NODATA, TIFF_ANY);
  if (field == nullptr || TIFFFieldPassCount(field) || TIFFFieldDataType(field) != TIFF_ASCII)
    return nd;
  const char* text = nullptr;
  if (!TIFFGetField(tif, TIFFTAG_GDAL_NODATA, &text) || text == nullptr) return nd;
  std::string s = to_lower(std::string(text, strnlen(text, 64)));
  s.erase(std::remove_if(s.begin(), s.end(), [](char c) { return c == ' ' || c == '\t'; }),
          s.end());
  if (s == "nan" || s == "-nan" || s == "+nan") {
    nd.is_nan = true;
    return nd;
  }
  const auto v = parse_number(s);
  if (!v) {
    // Infinite samples are voids anyway.
    if (s != "inf" && s != "-inf" && s != "+inf")
      notes.push_back("GDAL_NODATA value '" + s + "' is not a number; ignored");
    return nd;
  }
  nd.has = true;
  // Compare in the samples' precision: GDAL writes float32 no-data as a double string.
  nd.value = type == SampleType::kF32 ? static_cast<double>(static_cast<float>(*v)) : *v;
  return nd;
}

}  // namespace

Grid parse_geotiff(Bytes data, const std::string& source) {
  if (data.size() < 8 ||
      !((data[0] == 'I' && data[1] == 'I' && (data[2] == 42 || data[2] == 43) && data[3] == 0) ||
        (data[0] == 'M' && data[1] == 'M' && data[2] == 0 && (data[3] == 42 || data[3] == 43)))) {
    throw FormatError(source, "not a TIFF file (no II*/MM* header)");
  }
  tiff::Diagnostics diag;
  const auto with_libtiff = [&](std::string what) {
    if (!diag.last_error.empty()) what += " (" + diag.last_error + ")";
    return FormatError(source, what);
  };

  tiff::MemoryFile file{data};
  const tiff::TiffPtr tif = tiff::open(file, "r", source, diag, kMaxLibtiffAlloc);
  if (!tif) throw with_libtiff("cannot read the TIFF header and first directory");
  TIFF* t = tif.get();

  // Image structure.
  std::uint32_t width = 0, height = 0;
  if (!TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &width) ||
      !TIFFGetField(t, TIFFTAG_IMAGELENGTH, &height)) {
    throw with_libtiff("no ImageWidth/ImageLength");
  }
  // Absurd sizes fail here, before anything depends on them.
  check_dimensions(source, height, width, kMaxSamples);
  const int rows = static_cast<int>(height);
  const int cols = static_cast<int>(width);
  // PlanarConfiguration does not matter with one sample per pixel.
  std::uint16_t spp = 1, bits = 1, format = SAMPLEFORMAT_UINT, compression = COMPRESSION_NONE;
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLESPERPIXEL, &spp);
  TIFFGetFieldDefaulted(t, TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLEFORMAT, &format);
  TIFFGetFieldDefaulted(t, TIFFTAG_COMPRESSION, &compression);
  if (spp != 1) {
    throw FormatError(
        source,
        std::to_string(spp) + " samples per pixel; a DEM GeoTIFF has 1 (a single band of heights)");
  }
  const SampleType type = sample_type(source, format, bits);
  const std::size_t sample_bytes = bits / 8u;
  if (!TIFFIsCODECConfigured(compression)) {
    throw FormatError(
        source, "compression " + std::to_string(compression) + " is not supported by this libtiff");
  }

  // Chunk layout: strips are full-width bands of chunk_h rows (the last may be shorter);
  // tiles are chunk_w x chunk_h blocks, padded at the right and bottom edges.
  const bool tiled = TIFFIsTiled(t) != 0;
  std::uint32_t chunk_w = width, chunk_h = height;
  if (tiled) {
    if (!TIFFGetField(t, TIFFTAG_TILEWIDTH, &chunk_w) ||
        !TIFFGetField(t, TIFFTAG_TILELENGTH, &chunk_h) || chunk_w == 0 || chunk_h == 0) {
      throw with_libtiff("tiled TIFF without a valid TileWidth/TileLength");
    }
  } else {
    std::uint32_t rps = 0;
    TIFFGetFieldDefaulted(t, TIFFTAG_ROWSPERSTRIP, &rps);
    chunk_h = rps == 0 ? height : std::min(rps, height);
  }
  const std::uint64_t chunk_samples = std::uint64_t{chunk_w} * chunk_h;
  const std::uint64_t grid_samples = std::uint64_t{width} * height;
  // GDAL writes 256 x 256 tiles even for smaller images; anything far larger is nonsense.
  if (tiled && (chunk_samples > std::max<std::uint64_t>(4 * grid_samples, std::uint64_t{1} << 20) ||
                chunk_samples * sample_bytes > kMaxTileBytes)) {
    throw FormatError(source, "tile of " + std::to_string(chunk_w) + " x " +
                                  std::to_string(chunk_h) + " samples is absurdly large for a " +
                                  std::to_string(width) + " x " + std::to_string(height) +
                                  " image");
  }
  const std::uint32_t across = tiled ? (width + chunk_w - 1) / chunk_w : 1;
  const std::uint32_t down = (height + chunk_h - 1) / chunk_h;
  const std::uint64_t n_chunks = std::uint64_t{across} * down;
  const std::uint64_t n_libtiff = tiled ? TIFFNumberOfTiles(t) : TIFFNumberOfStrips(t);
  const char* chunk_name = tiled ? "tile" : "strip";
  if (n_libtiff != n_chunks) {
    throw FormatError(source, "has " + std::to_string(n_libtiff) + " " + chunk_name + "s where " +
                                  std::to_string(n_chunks) + " are expected");
  }

  // Every chunk must lie inside the file and no two may share bytes; that, and the codec's
  // largest expansion, bound how many samples the file can really hold.
  std::uint64_t stored = 0;
  diag.last_error.clear();
  for (std::uint32_t i = 0; i < n_chunks; ++i) {
    int err = 0;
    const std::uint64_t offset = TIFFGetStrileOffsetWithErr(t, i, &err);
    const std::uint64_t count = err ? 0 : TIFFGetStrileByteCountWithErr(t, i, &err);
    if (err)
      throw with_libtiff("cannot read the position of " + std::string(chunk_name) + " " +
                         std::to_string(i));
    if (count == 0) {
      throw FormatError(source, std::string(chunk_name) + " " + std::to_string(i) +
                                    " has no data (sparse GeoTIFFs are not supported)");
    }
    if (offset > data.size() || count > data.size() - offset) {
      throw FormatError(source, "truncated: " + std::string(chunk_name) + " " + std::to_string(i) +
                                    " ends at byte " + std::to_string(offset + count) +
                                    " but the file has " + std::to_string(data.size()) + " bytes");
    }
    stored += count;
  }
  if (stored > data.size()) {
    throw FormatError(source, std::string(chunk_name) + "s overlap: their byte counts add up to " +
                                  std::to_string(stored) + ", more than the file's " +
                                  std::to_string(data.size()));
  }
  const std::uint64_t expansion = max_expansion(compression);
  const std::uint64_t max_samples = std::min<std::uint64_t>(
      expansion == 0 ? kMaxSamples : stored * expansion / sample_bytes, kMaxSamples);
  check_dimensions(source, rows, cols, static_cast<std::size_t>(max_samples));
  // Edge tiles decode whole, padding included; the last strip only has its own rows.
  const std::uint64_t decoded = tiled ? n_chunks * chunk_samples : grid_samples;
  if (expansion != 0 && decoded > max_samples) {
    throw FormatError(
        source, std::to_string(n_chunks) + " " + chunk_name + "s of " + std::to_string(chunk_w) +
                    " x " + std::to_string(chunk_h) + " samples cannot come from " +
                    std::to_string(stored) + " bytes of " +
                    (compression == COMPRESSION_NONE ? "uncompressed" : "compressed") + " data");
  }

  // Georeference, CRS and heights' meaning.
  const tiff::GtifPtr gt = tiff::open_keys(t, diag);
  if (!gt) throw with_libtiff("GeoKeyDirectoryTag is malformed");
  int key_count = 0;
  GTIFDirectoryInfo(gt.get(), nullptr, &key_count);
  if (key_count == 0) {
    throw FormatError(
        source, "no GeoTIFF keys: a plain TIFF, or a GeoTIFF whose GeoKeyDirectoryTag is missing");
  }
  Grid g;
  g.format = "geotiff";
  g.georef = read_crs(gt.get(), source, g.notes);
  const Placement placement = read_placement(t, gt.get(), source, rows, cols, g.georef);
  g.vertical_datum = read_vertical_datum(gt.get());
  const double unit = read_vertical_scale(gt.get(), source, g.notes);
  const NoData nodata = read_nodata(t, type, g.notes);
  if (placement.flip_rows) g.notes.push_back("rows stored south-up; flipped to north-up");
  if (placement.flip_cols) g.notes.push_back("columns stored east-to-west; flipped");

  // Samples. The first tile or row is decoded before the grid is allocated, so that a header
  // over data that does not decode fails without taking the grid's memory.
  std::size_t non_finite = 0;
  if (tiled) {
    // A tile always decodes whole, padding included; only its part inside the image is kept.
    std::vector<std::uint8_t> buf(static_cast<std::size_t>(chunk_samples * sample_bytes));
    for (std::uint32_t i = 0; i < n_chunks; ++i) {
      diag.last_error.clear();
      const auto want = static_cast<tmsize_t>(buf.size());
      if (TIFFReadEncodedTile(t, i, buf.data(), want) != want) {
        throw with_libtiff("cannot decode tile " + std::to_string(i) + " of " +
                           std::to_string(n_chunks));
      }
      if (i == 0) g.allocate(rows, cols);
      const std::uint32_t row0 = i / across * chunk_h;
      const std::uint32_t col0 = i % across * chunk_w;
      store(type, buf.data(), static_cast<int>(chunk_w), static_cast<int>(row0),
            static_cast<int>(col0), static_cast<int>(std::min(chunk_h, height - row0)),
            static_cast<int>(std::min(chunk_w, width - col0)), placement, nodata, unit, g,
            non_finite);
    }
  } else {
    // Row by row: a strip of a whole image needs no strip-sized buffer.
    std::vector<std::uint8_t> line(static_cast<std::size_t>(width) * sample_bytes);
    for (std::uint32_t r = 0; r < height; ++r) {
      diag.last_error.clear();
      if (TIFFReadScanline(t, line.data(), r, 0) != 1) {
        throw with_libtiff("cannot decode row " + std::to_string(r) + " (strip " +
                           std::to_string(r / chunk_h) + " of " + std::to_string(n_chunks) + ")");
      }
      if (r == 0) g.allocate(rows, cols);
      store(type, line.data(), cols, static_cast<int>(r), 0, 1, cols, placement, nodata, unit, g,
            non_finite);
    }
  }
  if (non_finite > 0) {
    g.notes.push_back(std::to_string(non_finite) +
                      " sample(s) NaN, infinite or beyond float range; marked as voids");
  }
  return g;
}

}  // namespace terravol::io
