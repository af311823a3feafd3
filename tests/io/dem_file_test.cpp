#include "io/dem_file.h"

#include <gtest/gtest.h>

#include <string>

#include "compress.h"
#include "io/compressed.h"
#include "io/error.h"
#include "parse_check.h"
#include "shared_data.h"
#include "temp_dir.h"

namespace terravol::io {
namespace {

using test::ByteVector;

const std::string kExtensions[] = {".gz", ".bz2", ".xz", ".zip"};

void expect_same_grid(const Grid& a, const Grid& b, const std::string& context) {
  EXPECT_EQ(a.format, b.format) << context;
  ASSERT_EQ(a.rows, b.rows) << context;
  ASSERT_EQ(a.cols, b.cols) << context;
  EXPECT_EQ(a.georef.crs, b.georef.crs) << context;
  EXPECT_EQ(a.georef.utm_zone, b.georef.utm_zone) << context;
  EXPECT_EQ(a.georef.utm_north, b.georef.utm_north) << context;
  EXPECT_EQ(a.georef.x0, b.georef.x0) << context;
  EXPECT_EQ(a.georef.y0, b.georef.y0) << context;
  EXPECT_EQ(a.georef.dx, b.georef.dx) << context;
  EXPECT_EQ(a.georef.dy, b.georef.dy) << context;
  EXPECT_EQ(a.vertical_datum, b.vertical_datum) << context;
  EXPECT_EQ(a.checksum_errors, b.checksum_errors) << context;
  EXPECT_EQ(a.notes, b.notes) << context;
  EXPECT_TRUE(a.heights == b.heights) << context;
  EXPECT_TRUE(a.mask == b.mask) << context;
}

ByteVector text_bytes(const std::string& s) { return ByteVector(s.begin(), s.end()); }

// 3 columns x 2 rows, UTM metres: readable only with a projection.
const std::string kUtmGrid =
    "ncols 3\nnrows 2\nxllcorner 500000\nyllcorner 4000000\ncellsize 30\nNODATA_value -9999\n"
    "1 2 3\n4 -9999 6\n";
const std::string kUtmPrj = "PROJCS[\"WGS_1984_UTM_Zone_10N\",GEOGCS[\"GCS_WGS_1984\"]]";

TEST(FormatFromName, EveryFormatIsKnownPlainAndUnderEveryCompression) {
  const std::pair<const char*, Format> names[] = {
      {"N44W072.hgt", Format::kSrtm},     {"n33_w116.dt0", Format::kDted},   {"x.DT2", Format::kDted},
      {"SainteHelens.dem", Format::kUsgsDem}, {"grid.asc", Format::kEsriAscii}, {"a.tif", Format::kGeoTiff},
      {"a.tiff", Format::kGeoTiff},       {"40_41_111_112.sdf", Format::kSdf}};
  for (const auto& [name, format] : names) {
    EXPECT_EQ(format_from_name(name), format) << name;
    for (const std::string& ext : kExtensions) {
      EXPECT_EQ(format_from_name(name + ext), format) << name << ext;
      EXPECT_EQ(format_from_name(name + std::string(ext == ".gz" ? ".GZ" : ext)), format) << name << ext;
    }
  }
  for (const char* unknown : {"notes.txt", "N44W072.gz", "N44W072.zip", "x.hgt.tar", "x.hgt.gz.gz", "x.prj"}) {
    EXPECT_FALSE(format_from_name(unknown)) << unknown;
  }
}

TEST(ReadDem, CompressedTinyGridIsTheSameGridUnderEveryCompression) {
  test::TempDir dir;
  test::write_file_bytes(dir.path() / "grid.asc", text_bytes(kUtmGrid));
  test::write_file_bytes(dir.path() / "grid.prj", text_bytes(kUtmPrj));
  const Grid plain = read_dem(dir.path() / "grid.asc");
  ASSERT_EQ(plain.georef.crs, Crs::kUtm) << "the .prj beside it gives the zone";
  for (const std::string& ext : kExtensions) {
    const auto path = dir.path() / ("grid.asc" + ext);
    test::write_file_bytes(path, test::compress_as(ext, text_bytes(kUtmGrid), "grid.asc"));
    expect_same_grid(read_dem(path), plain, ext);
    EXPECT_EQ(read_content(path), text_bytes(kUtmGrid)) << ext;
  }
}

TEST(ReadDem, ZippedEsriGridTakesItsProjectionFromTheArchive) {
  test::TempDir dir;
  const auto path = dir.path() / "grid.asc.zip";
  test::write_file_bytes(path, test::zip_bytes({{"data/grid.asc", text_bytes(kUtmGrid)},
                                                {"data/grid.prj", text_bytes(kUtmPrj)}}));
  const Grid g = read_dem(path);
  EXPECT_EQ(g.georef.crs, Crs::kUtm);
  EXPECT_EQ(g.georef.utm_zone, 10);
  // Without the .prj, in the archive or beside it, the metres cannot be placed.
  test::write_file_bytes(path, test::zip_bytes({{"data/grid.asc", text_bytes(kUtmGrid)}}));
  EXPECT_NE(test::format_error_of([&] { read_dem(path); }).find("coordinates are not degrees"), std::string::npos);
}

TEST(ReadDem, ZipArchiveIsSearchedForTheFormatItsNameGives) {
  test::TempDir dir;
  const auto path = dir.path() / "grid.asc.zip";
  test::write_file_bytes(path, test::zip_bytes({{"readme.txt", text_bytes("hello")}}));
  EXPECT_EQ(test::format_error_of([&] { read_dem(path); }), path.string() + ": zip archive holds no *.asc file");
}

TEST(ReadDem, ANameThatDisagreesWithTheContentIsAOneLineError) {
  test::TempDir dir;
  const ByteVector text = text_bytes(kUtmGrid);
  const auto gz = dir.path() / "grid.asc.gz";
  test::write_file_bytes(gz, test::bzip2_bytes(text));
  EXPECT_EQ(test::format_error_of([&] { read_dem(gz); }), gz.string() + ": named .gz but holds bzip2 data");
  const auto xz = dir.path() / "grid.asc.xz";
  test::write_file_bytes(xz, text);
  EXPECT_EQ(test::format_error_of([&] { read_dem(xz); }), xz.string() + ": named .xz but is not xz data");
  // Compressed content under a plain name: the parser's complaint, and what the file holds.
  const auto plain = dir.path() / "40_41_111_112.sdf";
  test::write_file_bytes(plain, test::gzip_bytes(text));
  const std::string what = test::format_error_of([&] { read_dem(plain); });
  EXPECT_EQ(what.rfind(plain.string() + ": ", 0), 0u) << what;
  EXPECT_NE(what.find("(the file holds gzip data: name it 40_41_111_112.sdf.gz)"), std::string::npos) << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
}

TEST(ReadDem, CorruptArchivesAreOneLineErrorsNamingTheFile) {
  test::TempDir dir;
  const ByteVector text = text_bytes(kUtmGrid);
  for (const std::string& ext : kExtensions) {
    ByteVector packed = test::compress_as(ext, text, "grid.asc");
    const auto path = dir.path() / ("grid.asc" + ext);
    for (const std::size_t cut : {std::size_t{0}, std::size_t{3}, packed.size() / 2, packed.size() - 1}) {
      test::write_file_bytes(path, ByteVector(packed.begin(), packed.begin() + static_cast<std::ptrdiff_t>(cut)));
      const std::string what = test::format_error_of([&] { read_dem(path); });
      EXPECT_EQ(what.rfind(path.string() + ": ", 0), 0u) << ext << " cut at " << cut << ": " << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

// The real files of every format, compressed four ways, read back as the same grid.
class CompressedRealFile : public ::testing::TestWithParam<const char*> {};

TEST_P(CompressedRealFile, GivesTheSameGridAsTheUncompressedFile) {
  const auto original = test::shared_dem(GetParam());
  TERRAVOL_REQUIRE_SHARED(original);
  test::TempDir dir;
  // The plain file: the shared one, or (for the .sdf.bz2 tiles) its decompressed content.
  const std::string plain_name(strip_compression(original.filename().string()));
  const ByteVector content = read_content(original);
  const auto plain_path = dir.path() / plain_name;
  test::write_file_bytes(plain_path, content);
  const Grid plain = read_dem(plain_path);
  for (const std::string& ext : kExtensions) {
    const auto path = dir.path() / (plain_name + ext);
    test::write_file_bytes(path, test::compress_as(ext, content, plain_name));
    expect_same_grid(read_dem(path), plain, plain_name + ext);
    std::filesystem::remove(path);
  }
}

INSTANTIATE_TEST_SUITE_P(EveryFormat, CompressedRealFile,
                         ::testing::Values("N44W072.hgt", "n33_w116_3arc_v2.dt1", "SainteHelens.dem",
                                           "front_range_srtmgl3.asc", "olinda_dem_utm25s.tif",
                                           "utah_sdf/40_41_111_112.sdf.bz2"),
                         [](const auto& param_info) {
                           std::string name = param_info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
}  // namespace terravol::io
