// `terravol export-map` as a user runs it: GeoTIFFs read back with libtiff and libgeotiff,
// KMZs unzipped with libzip and their KML parsed as XML, values checked against trilinear
// interpolation of the lattice written out here, and bad input.
#include <gtest/gtest.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLUtilities.h>
#include <zip.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "compress.h"
#include "geotiff_read.h"
#include "image_compare.h"
#include "io/srtm_write.h"
#include "run_command.h"
#include "temp_dir.h"
#include "volume/colormap.h"
#include "volume/vdb_write.h"

namespace terravol {
namespace {

using test::run_terravol;

constexpr double kSpacing = 1.0 / 1200.0;  // 3", the lattice's and the DEM's
constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();

// The lattice value at (i, j, k): smooth, and not linear in k, so interpolation shows.
float lattice_value(int i, int j, int k) { return 60.0f + 0.75f * i - 0.5f * j + 0.9f * k * k; }

// A 30 x 20 x 6 volume over 45.4 N, 6.4 E at 3", heights h0 + 50 k (above ground or the datum),
// with one NaN point.
volume::Volume make_volume(volume::HeightRef height, double h0) {
  volume::Volume v;
  v.name = "path_loss_db";
  v.units = "dB";
  v.frame.kind = volume::FrameKind::kGeographic;
  v.frame.height = height;
  v.lattice.dims = {30, 20, 6};
  v.lattice.origin = {6.4, 45.4, h0};
  v.lattice.spacing = {kSpacing, kSpacing, 50.0};
  v.values.resize(v.lattice.size());
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j < 20; ++j)
      for (int i = 0; i < 30; ++i) v.values[v.lattice.index(i, j, k)] = lattice_value(i, j, k);
  v.values[v.lattice.index(12, 7, 2)] = kNaNf;
  v.active_points = v.values.size();
  return v;
}

// The value on a height h of the lattice's third coordinate in column (i, j): linear between
// the two layers around it (the lattice columns are the pixel centres, so trilinear
// interpolation reduces to this); NaN outside the layers or next to the NaN point.
double expected_in_column(const volume::Volume& v, int i, int j, double h) {
  const double x = (h - v.lattice.origin[2]) / v.lattice.spacing[2];
  if (x < -1e-9 || x > 5 + 1e-9) return std::numeric_limits<double>::quiet_NaN();
  const int k0 = std::min(static_cast<int>(std::floor(std::max(x, 0.0))), 4);
  const double f = x - k0;
  const double a = v.at(i, j, k0), b = v.at(i, j, k0 + 1);
  if ((f < 1.0 && std::isnan(a)) || (f > 0.0 && std::isnan(b))) return std::numeric_limits<double>::quiet_NaN();
  return (f < 1.0 ? (1.0 - f) * a : 0.0) + (f > 0.0 ? f * b : 0.0);
}

// The synthetic DEM: N45E006 with heights 500 + row + 2 col (a plane), so bilinear
// interpolation gives it exactly anywhere.
double dem_ground(double lat, double lon) { return 500.0 + (46.0 - lat) * 1200.0 + 2.0 * (lon - 6.0) * 1200.0; }

std::filesystem::path write_dem(const std::filesystem::path& dir) {
  io::Grid g;
  g.allocate(1201, 1201);
  for (int r = 0; r < 1201; ++r)
    for (int c = 0; c < 1201; ++c) g.heights[g.index(r, c)] = static_cast<float>(500 + r + 2 * c);
  const auto path = dir / "N45E006.hgt";
  test::write_file_bytes(path, io::encode_srtm(g));
  return path;
}

std::map<std::string, test::ByteVector> unzip_all(const std::filesystem::path& path) {
  std::map<std::string, test::ByteVector> out;
  int err = 0;
  zip_t* z = zip_open(path.c_str(), ZIP_RDONLY, &err);
  if (z == nullptr) return out;
  for (zip_int64_t i = 0; i < zip_get_num_entries(z, 0); ++i) {
    zip_stat_t st;
    zip_stat_index(z, static_cast<zip_uint64_t>(i), 0, &st);
    test::ByteVector bytes(st.size);
    zip_file_t* f = zip_fopen_index(z, static_cast<zip_uint64_t>(i), 0);
    zip_fread(f, bytes.data(), bytes.size());
    zip_fclose(f);
    out[st.name] = bytes;
  }
  zip_discard(z);
  return out;
}

double child_number(vtkXMLDataElement* e, const char* name) {
  vtkXMLDataElement* c = e ? e->FindNestedElementWithName(name) : nullptr;
  return c && c->GetCharacterData() ? std::stod(c->GetCharacterData()) : std::numeric_limits<double>::quiet_NaN();
}

class ExportMapCli : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return (dir_.path() / name).string(); }
  std::string volume_file(volume::HeightRef height, double h0) {
    const volume::Volume v = make_volume(height, h0);
    const std::string p = path(height == volume::HeightRef::kGround ? "agl.vdb" : "datum.vdb");
    volume::write_vdb(p, {&v}, true);
    return p;
  }
  test::TempDir dir_;
};

TEST_F(ExportMapCli, GeoTiffOfATerrainFollowingVolumeHoldsTheInterpolatedValuesAtThePixelCentres) {
  const std::string vdb = volume_file(volume::HeightRef::kGround, 0.0);
  const auto r = run_terravol("export-map --volume " + vdb + " --agl 87.5 -o " + path("m.tif"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("30 x 20 pixels"), std::string::npos) << r.out;
  const test::GeoTiffContents c = test::read_geotiff_file(path("m.tif"));
  ASSERT_TRUE(c.opened);
  EXPECT_EQ(c.width, 30u);
  EXPECT_EQ(c.height, 20u);
  EXPECT_EQ(c.bits, 32);
  EXPECT_EQ(c.sample_format, SAMPLEFORMAT_IEEEFP);
  EXPECT_EQ(c.model_type, ModelTypeGeographic);
  EXPECT_EQ(c.raster_type, RasterPixelIsArea);
  EXPECT_EQ(c.geographic_type, 4326);
  EXPECT_EQ(c.nodata, "nan");
  // Pixel-is-area: the tiepoint is the outer corner, half a pixel west and north of the
  // north-west lattice column; one pixel per lattice column.
  ASSERT_EQ(c.tiepoint.size(), 6u);
  ASSERT_EQ(c.scale.size(), 3u);
  EXPECT_NEAR(c.tiepoint[3], 6.4 - kSpacing / 2, 1e-12);
  EXPECT_NEAR(c.tiepoint[4], 45.4 + 19 * kSpacing + kSpacing / 2, 1e-12);
  EXPECT_NEAR(c.scale[0], kSpacing, 1e-15);
  EXPECT_NEAR(c.scale[1], kSpacing, 1e-15);
  EXPECT_NE(c.description.find("path_loss_db (dB) at 87.5 m above ground"), std::string::npos) << c.description;
  const volume::Volume v = make_volume(volume::HeightRef::kGround, 0.0);
  ASSERT_EQ(c.values.size(), 600u);
  int nan_pixels = 0;
  for (int row = 0; row < 20; ++row)
    for (int col = 0; col < 30; ++col) {
      const double want = expected_in_column(v, col, 19 - row, 87.5);
      const float got = c.values[static_cast<std::size_t>(row) * 30 + col];
      if (std::isnan(want)) {
        ++nan_pixels;
        EXPECT_TRUE(std::isnan(got)) << row << "," << col;
      } else {
        EXPECT_NEAR(got, want, 1e-4) << row << "," << col;
      }
    }
  EXPECT_EQ(nan_pixels, 1) << "the column with the NaN point, whose layer 2 weighs at 87.5 m";

  // And equal to `terravol query` at pixel centres (the centre of pixel (row, col) is its
  // lattice column: the tiepoint plus half a pixel).
  const std::string dem = write_dem(std::filesystem::path(path("."))).string();
  for (const auto& [row, col] : std::vector<std::pair<int, int>>{{0, 0}, {3, 7}, {10, 15}, {19, 29}, {12, 4}}) {
    const double lat = c.tiepoint[4] - (row + 0.5) * c.scale[1], lon = c.tiepoint[3] + (col + 0.5) * c.scale[0];
    char at[96];
    std::snprintf(at, sizeof at, "%.12f,%.12f,87.5", lat, lon);
    const auto q = run_terravol("query --volume " + vdb + " --dem " + dem + " --at " + at);
    ASSERT_EQ(q.status, 0) << q.err;
    const std::string line = q.out.substr(q.out.find('\n') + 1);
    const double queried = std::stod(line.substr(line.rfind(',') + 1));
    const float got = c.values[static_cast<std::size_t>(row) * 30 + col];
    if (std::isnan(got)) {
      EXPECT_TRUE(std::isnan(queried)) << row << "," << col;
    } else {
      EXPECT_NEAR(got, queried, 1e-4) << row << "," << col << ": " << q.out;
    }
  }
}

TEST_F(ExportMapCli, HeightsAboveGroundOfADatumVolumeTakeTheGroundFromTheDem) {
  const std::string vdb = volume_file(volume::HeightRef::kDatum, 2250.0);  // 2250 .. 2500 m
  const auto missing = run_terravol("export-map --volume " + vdb + " --agl 150 -o " + path("g.tif"));
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("--agl 150: the volume's heights above the datum 2250 .. 2500 m, so this surface needs "
                             "the ground under it: give --dem"),
            std::string::npos)
      << missing.err;
  EXPECT_FALSE(std::filesystem::exists(path("g.tif")));
  const std::string dem = write_dem(dir_.path()).string();
  // Ground here: 500 + (46 - lat) 1200 + 2 (lon - 6) 1200, 2160 .. 2240 m; 150 m above it.
  const auto r = run_terravol("export-map --volume " + vdb + " --agl 150 --dem " + dem + " -o " + path("g.tif"));
  ASSERT_EQ(r.status, 0) << r.err;
  const test::GeoTiffContents c = test::read_geotiff_file(path("g.tif"));
  ASSERT_EQ(c.values.size(), 600u);
  const volume::Volume v = make_volume(volume::HeightRef::kDatum, 2250.0);
  int with_value = 0;
  for (int row = 0; row < 20; ++row)
    for (int col = 0; col < 30; ++col) {
      const double lat = 45.4 + (19 - row) * kSpacing, lon = 6.4 + col * kSpacing;
      const double want = expected_in_column(v, col, 19 - row, 150.0 + dem_ground(lat, lon));
      const float got = c.values[static_cast<std::size_t>(row) * 30 + col];
      if (std::isnan(want)) {
        EXPECT_TRUE(std::isnan(got)) << row << "," << col;
      } else {
        ++with_value;
        EXPECT_NEAR(got, want, 1e-3) << row << "," << col;
      }
    }
  EXPECT_EQ(with_value, 599) << "every pixel but the one whose column holds the NaN point, at 2350 m";
}

TEST_F(ExportMapCli, KmzUnzipsToAKmlWhoseBoxMatchesTheGeoTiffAndAColourMappedOverlayWithALegend) {
  const std::string vdb = volume_file(volume::HeightRef::kGround, 0.0);
  ASSERT_EQ(run_terravol("export-map --volume " + vdb + " --agl 60 -o " + path("m.tif")).status, 0);
  const auto r = run_terravol("export-map --volume " + vdb + " --agl 60 --colormap plasma --range 60:100 -o " +
                              path("m.kmz"));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto files = unzip_all(path("m.kmz"));
  ASSERT_EQ(files.size(), 3u);
  ASSERT_TRUE(files.count("doc.kml") && files.count("files/overlay.png") && files.count("files/legend.png"));
  const std::string kml(files.at("doc.kml").begin(), files.at("doc.kml").end());
  vtkXMLDataElement* root = vtkXMLUtilities::ReadElementFromString(kml.c_str());
  ASSERT_NE(root, nullptr) << "doc.kml is not well-formed XML:\n" << kml;
  EXPECT_STREQ(root->GetName(), "kml");
  EXPECT_STREQ(root->GetAttribute("xmlns"), "http://www.opengis.net/kml/2.2");
  vtkXMLDataElement* overlay = root->LookupElementWithName("GroundOverlay");
  ASSERT_NE(overlay, nullptr);
  vtkXMLDataElement* href = overlay->LookupElementWithName("href");
  ASSERT_NE(href, nullptr);
  EXPECT_STREQ(href->GetCharacterData(), "files/overlay.png");
  vtkXMLDataElement* box = overlay->FindNestedElementWithName("LatLonBox");
  const test::GeoTiffContents tif = test::read_geotiff_file(path("m.tif"));
  ASSERT_EQ(tif.tiepoint.size(), 6u);
  EXPECT_NEAR(child_number(box, "west"), tif.tiepoint[3], 1e-9);
  EXPECT_NEAR(child_number(box, "north"), tif.tiepoint[4], 1e-9);
  EXPECT_NEAR(child_number(box, "east"), tif.tiepoint[3] + tif.width * tif.scale[0], 1e-9);
  EXPECT_NEAR(child_number(box, "south"), tif.tiepoint[4] - tif.height * tif.scale[1], 1e-9);
  vtkXMLDataElement* screen = root->LookupElementWithName("ScreenOverlay");
  ASSERT_NE(screen, nullptr);
  EXPECT_STREQ(screen->LookupElementWithName("href")->GetCharacterData(), "files/legend.png");
  root->Delete();

  // The overlay: one pixel per GeoTIFF pixel, its value through plasma over 60 .. 100.
  const test::Image image = test::decode_png(files.at("files/overlay.png"));
  ASSERT_EQ(image.width, 30);
  ASSERT_EQ(image.height, 20);
  const volume::Colormap plasma = volume::colormap_by_name("plasma");
  for (std::size_t p = 0; p < tif.values.size(); ++p) {
    const float v = tif.values[p];
    if (std::isnan(v)) {
      EXPECT_EQ(image.alpha[p], 0) << p;
      continue;
    }
    const glm::u8vec3 want = plasma.map((v - 60.0) / 40.0);
    EXPECT_EQ(image.alpha[p], 255) << p;
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(image.pixels[p][ch], want[ch], 1) << p;
  }
  const test::Image legend = test::decode_png(files.at("files/legend.png"));
  EXPECT_GT(legend.width, 60);
  EXPECT_GT(legend.height, 200);
}

// The best server of a two-transmitter plan (terravol rf on the bundled DEM): the GeoTIFF holds
// the indices, and the KMZ colours each pixel of index k with tab20's k-th colour (written out
// here by hand), with one swatch per transmitter.
TEST_F(ExportMapCli, BestServerMapsKeepTheIndicesAndColourEachServerByCategory) {
  const std::string dem = std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt";
  const std::string plan = path("plan.vdb");
  const auto rf = run_terravol("rf --quiet --dem " + dem +
                                   " --tx 45.50,6.45,30,900,50 --tx 45.50,6.55,30,900,50 --radius-km 3 --heights 0:200:100 -o " + plan,
                               300);
  ASSERT_EQ(rf.status, 0) << rf.err;
  ASSERT_EQ(run_terravol("export-map --volume " + plan + " --field best_server --agl 100 -o " + path("bs.tif")).status, 0);
  const auto r = run_terravol("export-map --volume " + plan + " --field best_server --agl 100 --colormap categorical -o " +
                              path("bs.kmz"));
  ASSERT_EQ(r.status, 0) << r.err;
  const test::GeoTiffContents tif = test::read_geotiff_file(path("bs.tif"));
  const auto files = unzip_all(path("bs.kmz"));
  ASSERT_TRUE(files.count("files/overlay.png") && files.count("files/legend.png"));
  const test::Image image = test::decode_png(files.at("files/overlay.png"));
  ASSERT_EQ(static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height), tif.values.size());
  const int tab20[3][3] = {{0, 0, 0}, {0x1f, 0x77, 0xb4}, {0xff, 0x7f, 0x0e}};
  std::size_t counts[3] = {0, 0, 0};
  for (std::size_t p = 0; p < tif.values.size(); ++p) {
    const float v = tif.values[p];
    if (std::isnan(v)) {
      EXPECT_EQ(image.alpha[p], 0) << p;
      continue;
    }
    ASSERT_TRUE(v == 1.0f || v == 2.0f) << "an index, not " << v;
    const int k = static_cast<int>(v);
    ++counts[k];
    EXPECT_EQ(image.alpha[p], 255) << p;
    for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(image.pixels[p][ch], tab20[k][ch]) << p;
  }
  EXPECT_GT(counts[1], 100u) << "the western transmitter serves the west";
  EXPECT_GT(counts[2], 100u) << "the eastern transmitter serves the east";
  // West of the middle meridian the western one wins more often, east of it the eastern one.
  std::size_t west_by_1 = 0, west_by_2 = 0;
  for (int row = 0; row < image.height; ++row)
    for (int col = 0; col < image.width / 3; ++col) {
      const float v = tif.values[static_cast<std::size_t>(row) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(col)];
      west_by_1 += v == 1.0f;
      west_by_2 += v == 2.0f;
    }
  EXPECT_GT(west_by_1, west_by_2);
  EXPECT_GT(test::decode_png(files.at("files/legend.png")).height, 40);
  EXPECT_NE(run_terravol("export-map --volume " + plan + " --field best_server --agl 100 --colormap categorical --range 0:3 -o " +
                         path("x.kmz"))
                .status,
            0)
      << "a categorical map has no range";
}

// Bad input: one line naming the option or file, exit status 1 (2 for CLI11's own checks),
// and nothing written.
TEST_F(ExportMapCli, BadInputFailsWithOneLineAndWritesNothing) {
  const std::string vdb = volume_file(volume::HeightRef::kGround, 0.0);
  const std::string out = path("x.tif");
  const std::pair<std::string, std::string> cases[] = {
      {"--volume " + vdb + " --agl 10 -o " + path("x.png"), "x.png: expected a .tif, .tiff or .kmz"},
      {"--volume " + vdb + " -o " + out, "give the surface: one of --agl H"},
      {"--volume " + vdb + " --agl 10 --alt 10 -o " + out, "give the surface: one of --agl H"},
      {"--volume " + vdb + " --agl 10 --colormap jet -o " + out, "--colormap and --range colour a .kmz"},
      {"--volume " + vdb + " --agl 10 --range 1:x -o " + path("x.kmz"), "--range 1:x: 'x' is not a number"},
      {"--volume " + vdb + " --agl 10 --colormap nope -o " + path("x.kmz"), "--colormap nope: unknown colour map 'nope'"},
      {"--volume " + vdb + " --agl 900 -o " + out,
       "--agl 900: the surface lies outside the volume 'path_loss_db' (heights above ground 0 .. 250 m)"},
      {"--volume " + vdb + " --alt 2000 -o " + out, "--alt 2000: the volume's heights above ground 0 .. 250 m"},
      {"--volume " + path("missing.vdb") + " --agl 10 -o " + out, "missing.vdb"},
      {"--volume " + vdb + " --agl 10 -o " + path("no/such/folder/x.tif"), "does not exist"},
  };
  for (const auto& [args, message] : cases) {
    const auto r = run_terravol("export-map " + args);
    EXPECT_TRUE(r.status == 1 || r.status == 2) << args << ": " << r.status;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(path("x.kmz")));
  ASSERT_EQ(run_terravol("export-map --volume " + vdb + " --agl 10 -o " + out).status, 0);
  const auto again = run_terravol("export-map --volume " + vdb + " --agl 10 -o " + out);
  EXPECT_EQ(again.status, 1);
  EXPECT_NE(again.err.find("exists (use --force to overwrite)"), std::string::npos) << again.err;
  EXPECT_EQ(run_terravol("export-map --volume " + vdb + " --agl 10 --force -o " + out).status, 0);
}

}  // namespace
}  // namespace terravol
