// GeoTIFF reader: small GeoTIFFs written in memory with libtiff + libgeotiff (as GDAL writes
// them), a few hand-made hostile headers, and the real Olinda DEM.
#include <gtest/gtest.h>

#include <geotiff.h>
#include <geovalues.h>
#include <tiffio.h>
#include <xtiffio.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "io/error.h"
#include "io/readers.h"
#include "shared_data.h"

namespace terravol::io {
namespace {

// ---- writing GeoTIFFs in memory ------------------------------------------------------------

struct Sink {
  std::vector<std::uint8_t> bytes;
  std::uint64_t pos = 0;
};

tmsize_t sink_read(thandle_t h, void* buf, tmsize_t n) {
  auto* s = static_cast<Sink*>(h);
  if (s->pos >= s->bytes.size()) return 0;
  const auto count =
      std::min<std::uint64_t>(static_cast<std::uint64_t>(n), s->bytes.size() - s->pos);
  std::memcpy(buf, s->bytes.data() + s->pos, count);
  s->pos += count;
  return static_cast<tmsize_t>(count);
}

tmsize_t sink_write(thandle_t h, void* buf, tmsize_t n) {
  auto* s = static_cast<Sink*>(h);
  const auto count = static_cast<std::uint64_t>(n);
  if (s->pos + count > s->bytes.size()) s->bytes.resize(s->pos + count);
  std::memcpy(s->bytes.data() + s->pos, buf, count);
  s->pos += count;
  return n;
}

toff_t sink_seek(thandle_t h, toff_t off, int whence) {
  auto* s = static_cast<Sink*>(h);
  const auto delta = static_cast<std::int64_t>(off);
  if (whence == SEEK_SET) s->pos = off;
  if (whence == SEEK_CUR)
    s->pos = static_cast<std::uint64_t>(static_cast<std::int64_t>(s->pos) + delta);
  if (whence == SEEK_END)
    s->pos = static_cast<std::uint64_t>(static_cast<std::int64_t>(s->bytes.size()) + delta);
  return s->pos;
}

int sink_close(thandle_t) {
  return 0;
}
toff_t sink_size(thandle_t h) {
  return static_cast<Sink*>(h)->bytes.size();
}
int sink_map(thandle_t, void**, toff_t*) {
  return 0;
}
void sink_unmap(thandle_t, void*, toff_t) {}

// What to write. Samples are row-major, spp per pixel, native byte order.
struct TestTiff {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::uint16_t bits = 16;
  std::uint16_t format = SAMPLEFORMAT_INT;
  std::uint16_t spp = 1;
  std::uint16_t planar = PLANARCONFIG_CONTIG;
  std::uint16_t compression = COMPRESSION_NONE;
  std::uint32_t rows_per_strip = 0;  // strips of this many rows, or
  std::uint32_t tile = 0;            // square tiles of this side
  std::vector<double> tiepoint;      // I, J, K, X, Y, Z
  std::vector<double> scale;         // sx, sy, sz
  std::vector<double> transform;     // 16 values, row-major
  std::vector<std::pair<geokey_t, int>> short_keys;
  std::vector<std::pair<geokey_t, double>> double_keys;
  std::string nodata;
  std::vector<std::uint8_t> samples;
};

template <typename T>
std::vector<std::uint8_t> raw(const std::vector<T>& values) {
  std::vector<std::uint8_t> out(values.size() * sizeof(T));
  std::memcpy(out.data(), values.data(), out.size());
  return out;
}

std::vector<std::uint8_t> write_tiff(const TestTiff& t) {
  Sink sink;
  TIFF* tif = XTIFFClientOpen("test.tif", "w", &sink, sink_read, sink_write, sink_seek, sink_close,
                              sink_size, sink_map, sink_unmap);
  EXPECT_NE(tif, nullptr);
  if (tif == nullptr) return {};
  static const TIFFFieldInfo kNoData[] = {{TIFFTAG_GDAL_NODATA, TIFF_VARIABLE, TIFF_VARIABLE,
                                           TIFF_ASCII, FIELD_CUSTOM, 1, 0,
                                           const_cast<char*>("GDALNoDataValue")}};
  TIFFMergeFieldInfo(tif, kNoData, 1);
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, t.width);
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, t.height);
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, t.bits);
  TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, t.format);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, t.spp);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, t.planar);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, t.compression);
  if (!t.tiepoint.empty())
    TIFFSetField(tif, TIFFTAG_GEOTIEPOINTS, static_cast<int>(t.tiepoint.size()), t.tiepoint.data());
  if (!t.scale.empty())
    TIFFSetField(tif, TIFFTAG_GEOPIXELSCALE, static_cast<int>(t.scale.size()), t.scale.data());
  if (!t.transform.empty())
    TIFFSetField(tif, TIFFTAG_GEOTRANSMATRIX, static_cast<int>(t.transform.size()),
                 t.transform.data());
  if (!t.nodata.empty()) TIFFSetField(tif, TIFFTAG_GDAL_NODATA, t.nodata.c_str());
  if (!t.short_keys.empty() || !t.double_keys.empty()) {
    GTIF* gt = GTIFNew(tif);
    for (const auto& [key, value] : t.short_keys) GTIFKeySet(gt, key, TYPE_SHORT, 1, value);
    for (const auto& [key, value] : t.double_keys) GTIFKeySet(gt, key, TYPE_DOUBLE, 1, value);
    GTIFWriteKeys(gt);
    GTIFFree(gt);
  }
  const std::size_t pixel = t.bits / 8u * t.spp;
  if (t.tile != 0) {
    TIFFSetField(tif, TIFFTAG_TILEWIDTH, t.tile);
    TIFFSetField(tif, TIFFTAG_TILELENGTH, t.tile);
    // Padding beyond the image edge is junk the reader must not use.
    std::vector<std::uint8_t> buf(std::size_t{t.tile} * t.tile * pixel);
    for (std::uint32_t y = 0; y < t.height; y += t.tile) {
      for (std::uint32_t x = 0; x < t.width; x += t.tile) {
        std::fill(buf.begin(), buf.end(), std::uint8_t{0x55});
        for (std::uint32_t r = 0; r < t.tile && y + r < t.height; ++r) {
          const std::uint32_t n = std::min(t.tile, t.width - x);
          std::memcpy(buf.data() + r * t.tile * pixel,
                      t.samples.data() + ((y + r) * t.width + x) * pixel, n * pixel);
        }
        EXPECT_GT(TIFFWriteEncodedTile(tif, TIFFComputeTile(tif, x, y, 0, 0), buf.data(),
                                       static_cast<tmsize_t>(buf.size())),
                  0);
      }
    }
  } else {
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, t.rows_per_strip);
    for (std::uint32_t y = 0, s = 0; y < t.height; y += t.rows_per_strip, ++s) {
      const std::uint32_t n = std::min(t.rows_per_strip, t.height - y);
      EXPECT_GT(TIFFWriteEncodedStrip(
                    tif, s, const_cast<std::uint8_t*>(t.samples.data()) + y * t.width * pixel,
                    static_cast<tmsize_t>(n * t.width * pixel)),
                0);
    }
  }
  XTIFFClose(tif);
  return sink.bytes;
}

// A WGS84 geographic GeoTIFF, 0.25 degree pixels, north-west corner at (10 E, 50 N).
TestTiff geographic(std::uint32_t width, std::uint32_t height) {
  TestTiff t;
  t.width = width;
  t.height = height;
  t.rows_per_strip = 2;
  t.tiepoint = {0, 0, 0, 10.0, 50.0, 0};
  t.scale = {0.25, 0.25, 0};
  t.short_keys = {{GTModelTypeGeoKey, ModelTypeGeographic},
                  {GTRasterTypeGeoKey, RasterPixelIsArea},
                  {GeographicTypeGeoKey, GCS_WGS_84}};
  return t;
}

// The message of the FormatError parse_geotiff throws, or "" (a test failure) when it does not.
std::string error_of(const std::vector<std::uint8_t>& bytes,
                     const std::string& source = "mem.tif") {
  try {
    parse_geotiff(bytes, source);
  } catch (const FormatError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a FormatError";
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// ---- hand-made headers ---------------------------------------------------------------------

struct Entry {
  std::uint16_t tag;
  std::uint16_t type;  // 3 SHORT, 4 LONG
  std::uint32_t value;
};

// A little-endian TIFF with one IFD of single inline values, followed by `tail` bytes of junk.
// Offsets that point at the tail are (8 + 2 + 12 * entries + 4).
std::vector<std::uint8_t> hand_tiff(std::vector<Entry> entries, std::size_t tail) {
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return a.tag < b.tag; });
  std::vector<std::uint8_t> out = {'I', 'I', 42, 0, 8, 0, 0, 0};
  const auto put = [&](std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  put(entries.size(), 2);
  for (const Entry& e : entries) {
    put(e.tag, 2);
    put(e.type, 2);
    put(1, 4);
    put(e.value, 4);  // a SHORT sits in the first two bytes, little-endian
  }
  put(0, 4);
  out.resize(out.size() + tail, 0x78);
  return out;
}

std::uint32_t hand_tail_offset(std::size_t n_entries) {
  return static_cast<std::uint32_t>(8 + 2 + 12 * n_entries + 4);
}

// ---- behaviour -----------------------------------------------------------------------------

TEST(GeoTiff, Int16StripsWithGdalNodataMarkVoids) {
  TestTiff t;
  t.width = 5;
  t.height = 7;  // strips of 3 rows: the last has 1
  t.rows_per_strip = 3;
  t.compression = COMPRESSION_ADOBE_DEFLATE;
  t.tiepoint = {0, 0, 0, 500000.0, 4000000.0, 0};
  t.scale = {30.0, 30.0, 0};
  t.short_keys = {{GTModelTypeGeoKey, ModelTypeProjected}, {ProjectedCSTypeGeoKey, 32633}};
  t.nodata = "-32768";
  std::vector<std::int16_t> v(35);
  for (int i = 0; i < 35; ++i) v[i] = static_cast<std::int16_t>(100 * i - 1000);
  v[3] = v[34] = -32768;
  t.samples = raw(v);
  const Grid g = parse_geotiff(write_tiff(t), "mem.tif");
  EXPECT_EQ(g.format, "geotiff");
  ASSERT_EQ(g.rows, 7);
  ASSERT_EQ(g.cols, 5);
  EXPECT_EQ(g.georef.crs, Crs::kUtm);
  EXPECT_EQ(g.georef.utm_zone, 33);
  EXPECT_TRUE(g.georef.utm_north);
  EXPECT_EQ(g.vertical_datum, "unknown (GeoTIFF does not say)");
  EXPECT_EQ(count(g, Sample::kVoid), 2u);
  EXPECT_EQ(g.mask[g.index(0, 3)], Sample::kVoid);
  EXPECT_EQ(g.mask[g.index(6, 4)], Sample::kVoid);
  EXPECT_EQ(g.heights[g.index(0, 0)], -1000.0f);
  EXPECT_EQ(g.heights[g.index(6, 3)], 2300.0f);  // the last, one-row strip
  EXPECT_TRUE(g.notes.empty());
}

TEST(GeoTiff, PixelIsAreaTiepointMovesSamplesHalfAPixelIn) {
  TestTiff t = geographic(4, 3);
  t.bits = 32;
  t.format = SAMPLEFORMAT_IEEEFP;
  t.samples = raw(std::vector<float>(12, 1.0f));
  const Grid g = parse_geotiff(write_tiff(t), "mem.tif");
  EXPECT_EQ(g.georef.crs, Crs::kGeographic);
  EXPECT_DOUBLE_EQ(g.georef.x0, 10.125);
  EXPECT_DOUBLE_EQ(g.georef.y0, 49.875);
  EXPECT_DOUBLE_EQ(g.georef.dx, 0.25);
  EXPECT_DOUBLE_EQ(g.georef.dy, 0.25);
}

TEST(GeoTiff, Float32PixelIsPointTiepointIsTheFirstSampleAndNanIsVoid) {
  TestTiff t = geographic(4, 3);
  t.bits = 32;
  t.format = SAMPLEFORMAT_IEEEFP;
  t.planar = PLANARCONFIG_SEPARATE;  // the same as contiguous for one sample
  t.compression = COMPRESSION_LZW;
  t.short_keys = {{GTModelTypeGeoKey, ModelTypeGeographic},
                  {GTRasterTypeGeoKey, RasterPixelIsPoint},
                  {GeographicTypeGeoKey, GCS_WGS_84},
                  {VerticalCSTypeGeoKey, 5773}};
  std::vector<float> v = {1.5f, -2.25f, 3, 4, 5, 6, 7, 8, 9, 10, 11, 1234.5f};
  v[5] = std::numeric_limits<float>::quiet_NaN();
  t.samples = raw(v);
  const Grid g = parse_geotiff(write_tiff(t), "mem.tif");
  EXPECT_DOUBLE_EQ(g.georef.x0, 10.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, 50.0);
  EXPECT_EQ(g.vertical_datum, "EGM96 geoid (EPSG:5773)");
  EXPECT_EQ(g.heights[g.index(0, 1)], -2.25f);
  EXPECT_EQ(g.heights[g.index(2, 3)], 1234.5f);
  EXPECT_EQ(g.mask[g.index(1, 1)], Sample::kVoid);
  EXPECT_EQ(g.heights[g.index(1, 1)], 0.0f);
  EXPECT_EQ(count(g, Sample::kVoid), 1u);
  ASSERT_EQ(g.notes.size(), 1u);  // NaN without a GDAL_NODATA "nan" is worth saying
  EXPECT_EQ(g.notes[0], "1 sample(s) NaN, infinite or beyond float range; marked as voids");
}

TEST(GeoTiff, Int32TilesWithPartialEdgeTilesReadEverySample) {
  TestTiff t;
  t.width = 40;  // 16 x 16 tiles: 3 across, the last 8 wide; 3 down, the last 5 high
  t.height = 37;
  t.tile = 16;
  t.bits = 32;
  t.format = SAMPLEFORMAT_INT;
  t.compression = COMPRESSION_LZW;
  t.tiepoint = {0, 0, 0, 300000.0, 9000000.0, 0};
  t.scale = {90.0, 90.0, 0};
  t.short_keys = {{GTModelTypeGeoKey, ModelTypeProjected}, {ProjectedCSTypeGeoKey, 32725}};
  std::vector<std::int32_t> v(40 * 37);
  for (int r = 0; r < 37; ++r)
    for (int c = 0; c < 40; ++c) v[r * 40 + c] = 100000 * r + c - 70000;
  t.samples = raw(v);
  const Grid g = parse_geotiff(write_tiff(t), "mem.tif");
  ASSERT_EQ(g.rows, 37);
  ASSERT_EQ(g.cols, 40);
  EXPECT_EQ(g.georef.utm_zone, 25);
  EXPECT_FALSE(g.georef.utm_north);
  EXPECT_DOUBLE_EQ(g.georef.x0, 300045.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, 8999955.0);
  int wrong = 0;
  for (int r = 0; r < 37; ++r)
    for (int c = 0; c < 40; ++c)
      wrong += g.heights[g.index(r, c)] != static_cast<float>(100000 * r + c - 70000);
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(count(g, Sample::kVoid), 0u);
}

TEST(GeoTiff, Float64AndUint16SamplesAreRead) {
  TestTiff t = geographic(3, 2);
  t.bits = 64;
  t.format = SAMPLEFORMAT_IEEEFP;
  t.nodata = "-9999";
  t.samples = raw(std::vector<double>{1.25, -9999, 3, 4, 5, 8848.86});
  Grid g = parse_geotiff(write_tiff(t), "mem.tif");
  EXPECT_EQ(g.heights[0], 1.25f);
  EXPECT_EQ(g.mask[1], Sample::kVoid);
  EXPECT_EQ(g.heights[5], 8848.86f);
  t.bits = 16;
  t.format = SAMPLEFORMAT_UINT;
  t.nodata = "65535";
  t.samples = raw(std::vector<std::uint16_t>{0, 65535, 40000, 4, 5, 6});
  g = parse_geotiff(write_tiff(t), "mem.tif");
  EXPECT_EQ(g.heights[2], 40000.0f);
  EXPECT_EQ(g.mask[1], Sample::kVoid);
}

TEST(GeoTiff, Float32NodataFromGdalDoubleStringMatchesTheFloatSamples) {
  TestTiff t = geographic(2, 1);
  t.bits = 32;
  t.format = SAMPLEFORMAT_IEEEFP;
  t.nodata = "-3.4028234663852886e+38";  // GDAL's spelling of -FLT_MAX
  t.samples = raw(std::vector<float>{-std::numeric_limits<float>::max(), 7.0f});
  const Grid g = parse_geotiff(write_tiff(t), "mem.tif");
  EXPECT_EQ(g.mask[0], Sample::kVoid);
  EXPECT_EQ(g.heights[1], 7.0f);
  EXPECT_TRUE(g.notes.empty());
}

TEST(GeoTiff, NegativeYScaleRowsAreFlippedToNorthUp) {
  TestTiff t = geographic(2, 3);
  t.tiepoint = {0, 0, 0, 10.0, 40.0, 0};  // raster (0,0) is the south-west corner
  t.scale = {0.5, -0.5, 0};
  t.samples = raw(std::vector<std::int16_t>{1, 2, 3, 4, 5, 6});  // first stored row is the south
  const Grid g = parse_geotiff(write_tiff(t), "mem.tif");
  EXPECT_DOUBLE_EQ(g.georef.y0, 41.25);  // north sample centre
  EXPECT_DOUBLE_EQ(g.georef.dy, 0.5);
  EXPECT_DOUBLE_EQ(g.georef.x0, 10.25);
  EXPECT_EQ(g.heights[g.index(0, 0)], 5.0f);
  EXPECT_EQ(g.heights[g.index(2, 1)], 2.0f);
}

TEST(GeoTiff, ModelTransformationWithoutRotationGivesTheSameGrid) {
  TestTiff t = geographic(2, 2);
  t.tiepoint.clear();
  t.scale.clear();
  t.transform = {0.25, 0, 0, 10.0, 0, -0.25, 0, 50.0, 0, 0, 0, 0, 0, 0, 0, 1};
  t.samples = raw(std::vector<std::int16_t>{1, 2, 3, 4});
  const Grid g = parse_geotiff(write_tiff(t), "mem.tif");
  EXPECT_DOUBLE_EQ(g.georef.x0, 10.125);
  EXPECT_DOUBLE_EQ(g.georef.y0, 49.875);
  t.transform[1] = 0.01;
  EXPECT_TRUE(contains(error_of(write_tiff(t)), "rotates")) << error_of(write_tiff(t));
}

TEST(GeoTiff, UserDefinedUtmOnWgs84SizedEllipsoidIsReadWithANote) {
  TestTiff t = geographic(2, 2);  // as the Olinda file: GRS 1980 axes, datum not named
  t.short_keys = {{GTModelTypeGeoKey, ModelTypeProjected},  {GeographicTypeGeoKey, KvUserDefined},
                  {GeogGeodeticDatumGeoKey, KvUserDefined}, {GeogEllipsoidGeoKey, KvUserDefined},
                  {ProjectedCSTypeGeoKey, KvUserDefined},   {ProjectionGeoKey, Proj_UTM_zone_25S},
                  {ProjLinearUnitsGeoKey, Linear_Meter}};
  t.double_keys = {{GeogSemiMajorAxisGeoKey, 6378137.0}, {GeogInvFlatteningGeoKey, 298.257222101}};
  t.samples = raw(std::vector<std::int16_t>{1, 2, 3, 4});
  const Grid g = parse_geotiff(write_tiff(t), "mem.tif");
  EXPECT_EQ(g.georef.crs, Crs::kUtm);
  EXPECT_EQ(g.georef.utm_zone, 25);
  EXPECT_FALSE(g.georef.utm_north);
  ASSERT_EQ(g.notes.size(), 1u);
  EXPECT_TRUE(contains(g.notes[0], "taken as WGS84")) << g.notes[0];
}

TEST(GeoTiff, UnsupportedEpsgCodeIsNamedInTheError) {
  TestTiff t = geographic(2, 2);
  t.short_keys = {{GTModelTypeGeoKey, ModelTypeProjected}, {ProjectedCSTypeGeoKey, 3857}};
  t.samples = raw(std::vector<std::int16_t>{1, 2, 3, 4});
  EXPECT_EQ(error_of(write_tiff(t)),
            "mem.tif: unsupported projection EPSG:3857; Terravol reads EPSG:4326 and WGS84 UTM "
            "326xx/327xx");
  t.short_keys = {{GTModelTypeGeoKey, ModelTypeGeographic}, {GeographicTypeGeoKey, 4269}};
  EXPECT_EQ(error_of(write_tiff(t)),
            "mem.tif: unsupported geographic CRS EPSG:4269; Terravol reads EPSG:4326 and WGS84 UTM "
            "326xx/327xx");
}

TEST(GeoTiff, PlainTiffWithoutGeoKeysIsRejected) {
  TestTiff t = geographic(2, 2);
  t.short_keys.clear();
  t.samples = raw(std::vector<std::int16_t>{1, 2, 3, 4});
  EXPECT_TRUE(contains(error_of(write_tiff(t)), "no GeoTIFF keys"));
}

TEST(GeoTiff, TwoSamplesPerPixelAreRejected) {
  TestTiff t = geographic(2, 2);
  t.spp = 2;
  t.samples = raw(std::vector<std::int16_t>(8, 1));
  EXPECT_EQ(error_of(write_tiff(t)),
            "mem.tif: 2 samples per pixel; a DEM GeoTIFF has 1 (a single band of heights)");
}

TEST(GeoTiff, NonTiffBytesAreRejected) {
  const std::string text = "ncols 10\nnrows 10\n";
  EXPECT_EQ(error_of(std::vector<std::uint8_t>(text.begin(), text.end())),
            "mem.tif: not a TIFF file (no II*/MM* header)");
  EXPECT_EQ(error_of({}), "mem.tif: not a TIFF file (no II*/MM* header)");
  // A TIFF signature with nothing behind it: libtiff's complaint, on one line.
  const std::string message = error_of({'I', 'I', 42, 0, 0xff, 0xff, 0, 0});
  EXPECT_TRUE(contains(message, "mem.tif: cannot read the TIFF header")) << message;
  EXPECT_FALSE(contains(message, "\n"));
}

TEST(GeoTiff, BillionColumnHeaderFailsAtOnceWithoutAllocating) {
  const auto bytes = hand_tiff({{256, 4, 1000000000},
                                {257, 4, 1},
                                {258, 3, 16},
                                {259, 3, 1},
                                {273, 4, hand_tail_offset(8)},
                                {277, 3, 1},
                                {278, 4, 1},
                                {279, 4, 2}},
                               2);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(error_of(bytes), "mem.tif: grid of 1 x 1000000000 samples is absurdly large");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
}

TEST(GeoTiff, CompressedHeaderClaimingMoreThanItsBytesCanHoldFails) {
  // 16384 x 16384 float32 in one deflate strip of 10 bytes: at most 1100:1 expansion.
  const auto bytes = hand_tiff({{256, 4, 16384},
                                {257, 4, 16384},
                                {258, 3, 32},
                                {259, 3, COMPRESSION_ADOBE_DEFLATE},
                                {273, 4, hand_tail_offset(9)},
                                {277, 3, 1},
                                {278, 4, 16384},
                                {279, 4, 10},
                                {339, 3, SAMPLEFORMAT_IEEEFP}},
                               10);
  EXPECT_EQ(error_of(bytes),
            "mem.tif: header claims 16384 x 16384 samples but the file holds at most 2750");
}

TEST(GeoTiff, StripPastTheEndOfTheFileIsATruncation) {
  const auto bytes = hand_tiff({{256, 4, 100},
                                {257, 4, 100},
                                {258, 3, 16},
                                {259, 3, 1},
                                {273, 4, hand_tail_offset(8)},
                                {277, 3, 1},
                                {278, 4, 100},
                                {279, 4, 20000}},
                               100);
  // libtiff cuts a single uncompressed strip into ~8 KB strips; the first already overruns.
  EXPECT_EQ(error_of(bytes),
            "mem.tif: truncated: strip 0 ends at byte 8110 but the file has 210 bytes");
}

// Every prefix of a valid file must give a one-line FormatError (or a grid), nothing else.
void expect_every_truncation_fails_cleanly(const std::vector<std::uint8_t>& bytes,
                                           std::size_t step) {
  for (std::size_t n = 0; n < bytes.size(); n += (n < 1024 ? 1 : step)) {
    const std::vector<std::uint8_t> head(bytes.begin(),
                                         bytes.begin() + static_cast<std::ptrdiff_t>(n));
    try {
      parse_geotiff(head, "cut.tif");
    } catch (const FormatError& e) {
      const std::string m = e.what();
      ASSERT_EQ(m.rfind("cut.tif: ", 0), 0u) << m;
      ASSERT_FALSE(contains(m, "\n")) << "at " << n << ": " << m;
    }
  }
}

TEST(GeoTiff, EveryTruncationOfATiledDeflateFileFailsCleanly) {
  TestTiff t = geographic(40, 37);
  t.rows_per_strip = 0;
  t.tile = 16;
  t.compression = COMPRESSION_ADOBE_DEFLATE;
  t.nodata = "-32768";
  std::vector<std::int16_t> v(40 * 37);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::int16_t>(i * 7919 % 3001);
  t.samples = raw(v);
  const auto bytes = write_tiff(t);
  ASSERT_EQ(parse_geotiff(bytes, "cut.tif").rows, 37);
  expect_every_truncation_fails_cleanly(bytes, 1);
}

TEST(GeoTiff, ReadsTheOlindaUtm25sDem) {
  const auto path = test::shared_dem("olinda_dem_utm25s.tif");
  TERRAVOL_REQUIRE_SHARED(path);
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                        std::istreambuf_iterator<char>());
  const Grid g = parse_geotiff(bytes, path.string());
  EXPECT_EQ(g.rows, 111);
  EXPECT_EQ(g.cols, 111);
  EXPECT_EQ(g.georef.crs, Crs::kUtm);
  EXPECT_EQ(g.georef.utm_zone, 25);
  EXPECT_FALSE(g.georef.utm_north);
  // ModelTiepoint (0,0) -> (288776.25, 9120760.75), PixelIsArea, 89.994 m pixels.
  const double d = 89.9940673494512;
  EXPECT_NEAR(g.georef.dx, d, 1e-9);
  EXPECT_NEAR(g.georef.dy, d, 1e-9);
  EXPECT_NEAR(g.georef.x0, 288776.250000803 + d / 2, 1e-6);
  EXPECT_NEAR(g.georef.y0, 9120760.75002874 - d / 2, 1e-6);
  EXPECT_EQ(g.vertical_datum, "unknown (GeoTIFF does not say)");
  // Bounds of the cells: W 288776.25, E 298765.59, N 9120760.75, S 9110771.41.
  const auto r = height_range(g);
  EXPECT_EQ(r.min, -1.0f);
  EXPECT_EQ(r.max, 88.0f);
  EXPECT_EQ(count(g, Sample::kVoid), 0u);
  // Samples checked against the raw float32 strips, decoded by hand.
  EXPECT_EQ(g.heights[g.index(0, 0)], 38.0f);
  EXPECT_EQ(g.heights[g.index(3, 100)], 15.0f);
  EXPECT_EQ(g.heights[g.index(55, 55)], 33.0f);
  // GRS 1980 axes with no datum named: read as WGS84, and the user is told.
  ASSERT_EQ(g.notes.size(), 1u);
  EXPECT_TRUE(contains(g.notes[0], "taken as WGS84")) << g.notes[0];
  expect_every_truncation_fails_cleanly(bytes, 1);
}

}  // namespace
}  // namespace terravol::io
