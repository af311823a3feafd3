// volume/splat.h without SPLAT!: .qth/.lrp/.ano parsing (the manual's examples, hostile input),
// stacking onto SPLAT!'s grid, and run_splat() against stand-in executables (shell scripts)
// for its failure paths and its plumbing. The real engine runs in splat_cli_test.cpp.
#include "volume/splat.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <random>
#include <set>
#include <string>

#include "io/error.h"
#include "temp_dir.h"
#include "volume/readers.h"
#include "volume/vdb_write.h"

namespace terravol::volume {
namespace {

// The first lines of the manual's pathloss.dat example (man splat, "EXPORTING AND IMPORTING
// REGIONAL CONTOUR DATA").
const char kManualAno[] =
    "119, 117\t; max_west, min_west\n"
    "35, 34\t; max_north, min_north\n"
    "34.2265424, 118.0631096, 48.199, -32.747, 67.70\n"
    "34.2270358, 118.0624421, 48.199, -19.161, 73.72\n"
    "34.2290094, 118.0597723, 48.199, -11.806, 83.26 *\n"
    "34.2295028, 118.0591048, 48.199, -11.806, 135.47 *\n";

void write(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

// An executable shell script.
std::filesystem::path script(const std::filesystem::path& dir, const std::string& name,
                             const std::string& body) {
  const auto p = dir / name;
  write(p, "#!/bin/sh\n" + body);
  ::chmod(p.c_str(), 0755);
  return p;
}

void expect_format_error(const std::function<void()>& f, const std::string& prefix) {
  try {
    f();
    ADD_FAILURE() << "no error; expected " << prefix;
  } catch (const io::FormatError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(prefix, 0), 0u) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(SplatAno, ParsesTheManualsExample) {
  const AnoMap m = parse_ano(kManualAno, "pathloss.dat");
  EXPECT_EQ(m.max_west, 119.0);
  EXPECT_EQ(m.min_west, 117.0);
  EXPECT_EQ(m.max_north, 35.0);
  EXPECT_EQ(m.min_north, 34.0);
  ASSERT_EQ(m.points.size(), 4u);
  EXPECT_DOUBLE_EQ(m.points[0].lat, 34.2265424);
  EXPECT_DOUBLE_EQ(m.points[0].lon, -118.0631096);  // west-positive in the file
  EXPECT_DOUBLE_EQ(m.points[0].azimuth_deg, 48.199);
  EXPECT_DOUBLE_EQ(m.points[0].elevation_deg, -32.747);
  EXPECT_FLOAT_EQ(m.points[0].value, 67.70f);
  EXPECT_FALSE(m.points[1].obstructed);
  EXPECT_TRUE(m.points[2].obstructed);
  EXPECT_FLOAT_EQ(m.points[3].value, 135.47f);
}

TEST(SplatAno, CommentsBlankLinesAndCrlfAreIgnored) {
  const AnoMap m = parse_ano(
      "; made by hand\r\n\r\n119, 117 ; w\r\n35, 34\r\n; a comment line\r\n34.5, 118, 10, 1, "
      "99.5*\r\n\n",
      "x.ano");
  ASSERT_EQ(m.points.size(), 1u);
  EXPECT_TRUE(m.points[0].obstructed);
  EXPECT_FLOAT_EQ(m.points[0].value, 99.5f);
}

TEST(SplatAno, EasternLongitudesWrapIntoMinus180To180) {
  // West-positive 359.5 is 0.5 E; bounds that wrap through 0/360 skip the longitude check.
  const AnoMap m = parse_ano("0, 359\n11, 10\n10.5, 359.5, 1, 1, 80\n", "e.ano");
  EXPECT_DOUBLE_EQ(m.points[0].lon, 0.5);
}

TEST(SplatAno, BadLinesNameTheFileAndLine) {
  const std::string head = "119, 117\n35, 34\n";
  expect_format_error([] { parse_ano("", "a.ano"); }, "a.ano: no header");
  expect_format_error([] { parse_ano("119, 117\n35, 34\n", "a.ano"); }, "a.ano: no points");
  expect_format_error([] { parse_ano("119\n35, 34\n", "a.ano"); },
                      "a.ano: line 1: expected the header line");
  expect_format_error([] { parse_ano("119, x\n35, 34\n", "a.ano"); },
                      "a.ano: line 1: header MAX_WEST, MIN_WEST");
  expect_format_error([] { parse_ano("119, 117\n34, 35\n", "a.ano"); },
                      "a.ano: line 2: header latitudes");
  expect_format_error([&] { parse_ano(head + "34.5, 118, 1, 1\n", "a.ano"); },
                      "a.ano: line 3: expected LAT, LON");
  expect_format_error([&] { parse_ano(head + "34.5, 118, 1, 1, 2, 3\n", "a.ano"); },
                      "a.ano: line 3: expected");
  expect_format_error([&] { parse_ano(head + "34.5, 118, 1, 1, abc\n", "a.ano"); },
                      "a.ano: line 3: value 'abc'");
  expect_format_error([&] { parse_ano(head + "34.5, 118, 1, 1, nan\n", "a.ano"); },
                      "a.ano: line 3: value 'nan'");
  expect_format_error([&] { parse_ano(head + "34.5, 118, 1, 1, 1e999\n", "a.ano"); },
                      "a.ano: line 3: value");
  expect_format_error([&] { parse_ano(head + "34.5, 118, 1, 1, 80\n34.5,, 1, 1, 80\n", "a.ano"); },
                      "a.ano: line 4: longitude ''");
  expect_format_error([&] { parse_ano(head + "36.5, 118, 1, 1, 80\n", "a.ano"); },
                      "a.ano: line 3: latitude 36.5 is outside the header's 34..35");
  expect_format_error([&] { parse_ano(head + "34.5, 112, 1, 1, 80\n", "a.ano"); },
                      "a.ano: line 3: longitude 112 W is outside");
  expect_format_error([&] { parse_ano(head + "94.5, 118, 1, 1, 80\n", "a.ano"); },
                      "a.ano: line 3: latitude 94.5");
}

TEST(SplatAno, EveryTruncationParsesOrFailsWithOneLine) {
  const std::string text = kManualAno;
  for (std::size_t n = 0; n <= text.size(); ++n) {
    try {
      const AnoMap m = parse_ano(text.substr(0, n), "cut.ano");
      EXPECT_LE(m.points.size(), 4u);
      EXPECT_GE(m.points.size(), 1u);
    } catch (const io::FormatError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("cut.ano: ", 0), 0u) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(SplatAno, RandomBytesNeverCrash) {
  std::mt19937 rng(7);
  const std::string alphabet = "0123456789.,;*- \n\r\te+xN";
  for (int trial = 0; trial < 2000; ++trial) {
    std::string text = "119, 117\n35, 34\n";
    const int len = static_cast<int>(rng() % 80);
    for (int k = 0; k < len; ++k) text += alphabet[rng() % alphabet.size()];
    try {
      parse_ano(text, "r.ano");
    } catch (const io::FormatError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
}

TEST(SplatQth, ParsesTheManualsExampleInFeet) {
  const SplatSite s = parse_qth("WNJT-DT\n40.2828\n74.6864\n990.00\n", "wnjt-dt.qth");
  EXPECT_EQ(s.name, "WNJT-DT");
  EXPECT_DOUBLE_EQ(s.lat, 40.2828);
  EXPECT_DOUBLE_EQ(s.lon, -74.6864);
  EXPECT_NEAR(s.height_agl_m, 990.0 * 0.3048, 1e-9);
}

TEST(SplatQth, MetresDmsAndEasternLongitudes) {
  const SplatSite s = parse_qth("\nsite\n40 45 36\n-10 30 0\n30 m\n", "s.qth");
  EXPECT_NEAR(s.lat, 40.76, 1e-12);
  EXPECT_NEAR(s.lon, 10.5, 1e-12);  // "degrees East 0 to -360"
  EXPECT_DOUBLE_EQ(s.height_agl_m, 30.0);
  EXPECT_DOUBLE_EQ(parse_qth("a\n1\n2\n12.5 Meters\n", "s.qth").height_agl_m, 12.5);
  EXPECT_DOUBLE_EQ(parse_qth("a\n1\n270\n10\n", "s.qth").lon, 90.0);
}

TEST(SplatQth, FormatReadsBack) {
  const SplatSite in{"Farnsworth Peak", 40.6588, -112.2017, 42.25};
  const SplatSite out = parse_qth(format_qth(in), "f.qth");
  EXPECT_EQ(out.name, in.name);
  EXPECT_NEAR(out.lat, in.lat, 1e-7);
  EXPECT_NEAR(out.lon, in.lon, 1e-7);
  EXPECT_NEAR(out.height_agl_m, in.height_agl_m, 1e-3);
  EXPECT_NEAR(parse_qth(format_qth({"e", -33.9, 151.2, 5}), "e.qth").lon, 151.2, 1e-7);
}

TEST(SplatQth, BadFilesAreOneLineErrors) {
  expect_format_error([] { parse_qth("a\n1\n2\n", "s.qth"); }, "s.qth: expected 4 lines");
  expect_format_error([] { parse_qth("a\nnorth\n2\n3\n", "s.qth"); },
                      "s.qth: line 2: latitude 'north'");
  expect_format_error([] { parse_qth("a\n91\n2\n3\n", "s.qth"); },
                      "s.qth: line 2: latitude 91 is outside");
  expect_format_error([] { parse_qth("a\n1\n400\n3\n", "s.qth"); },
                      "s.qth: line 3: longitude 400 is outside");
  expect_format_error([] { parse_qth("a\n1\n2 61 0\n3\n", "s.qth"); },
                      "s.qth: line 3: longitude '2 61 0'");
  expect_format_error([] { parse_qth("a\n1\n2\n-3 m\n", "s.qth"); },
                      "s.qth: line 4: antenna height -3 m");
  expect_format_error([] { parse_qth("a\n1\n2\n3 furlongs\n", "s.qth"); },
                      "s.qth: line 4: antenna height unit");
  expect_format_error([] { parse_qth("a\n1\n2\nhigh\n", "s.qth"); },
                      "s.qth: line 4: antenna height 'high'");
}

TEST(SplatLrp, ParsesTheManualsExampleWithItsErp) {
  const SplatLrp l = parse_lrp(
      "15.000  ; Earth Dielectric Constant (Relative permittivity)\n"
      "0.005   ; Earth Conductivity (Siemens per meter)\n"
      "301.000 ; Atmospheric Bending Constant (N-units)\n"
      "647.000 ; Frequency in MHz (20 MHz to 20 GHz)\n"
      "5       ; Radio Climate (5 = Continental Temperate)\n"
      "0       ; Polarization (0 = Horizontal, 1 = Vertical)\n"
      "0.50    ; Fraction of situations (50% of locations)\n"
      "0.90    ; Fraction of time (90% of the time)\n"
      "46000.0 ; Effective Radiated Power (ERP) in Watts (optional)\n",
      "wnjt-dt.lrp");
  EXPECT_EQ(l.frequency_mhz, 647.0);
  EXPECT_EQ(l.climate, 5);
  EXPECT_EQ(l.polarization, 0);
  EXPECT_EQ(l.time, 0.9);
  ASSERT_TRUE(l.erp_w.has_value());
  EXPECT_EQ(*l.erp_w, 46000.0);
}

TEST(SplatLrp, FormatReadsBackWithoutErp) {
  SplatLrp in;
  in.frequency_mhz = 446.5;
  in.polarization = 1;
  in.erp_w = 50.0;
  const SplatLrp out = parse_lrp(format_lrp(in), "x.lrp");
  EXPECT_DOUBLE_EQ(out.frequency_mhz, 446.5);
  EXPECT_EQ(out.polarization, 1);
  EXPECT_FALSE(out.erp_w.has_value());
  EXPECT_FALSE(
      parse_lrp(format_lrp(in) + "0 ; ERP\n", "x.lrp").erp_w.has_value());  // -erp 0 semantics
}

TEST(SplatLrp, BadFilesAreOneLineErrors) {
  SplatLrp good;
  const std::string text = format_lrp(good);
  expect_format_error([] { parse_lrp("15\n0.005\n301\n", "x.lrp"); },
                      "x.lrp: expected 8 or 9 values");
  expect_format_error([] { parse_lrp("15\n0.005\nabc\n", "x.lrp"); },
                      "x.lrp: line 3: 'abc' is not a number");
  SplatLrp f = good;
  f.frequency_mhz = 10.0;
  expect_format_error([&] { parse_lrp(format_lrp(f), "x.lrp"); }, "x.lrp: frequency 10 is outside");
  f = good;
  f.polarization = 2;
  expect_format_error([&] { parse_lrp(format_lrp(f), "x.lrp"); },
                      "x.lrp: polarization 2 is outside");
  expect_format_error([&] { parse_lrp(text + "-5\n", "x.lrp"); }, "x.lrp: ERP -5 is outside");
}

AnoMap map_of(std::vector<AnoPoint> points) {
  AnoMap m;
  m.source = "test.ano";
  m.points = std::move(points);
  return m;
}

AnoPoint pt(double lat, double lon, float value, bool obstructed = false) {
  AnoPoint p;
  p.lat = lat;
  p.lon = lon;
  p.value = value;
  p.obstructed = obstructed;
  return p;
}

TEST(SplatStack, TinyMapLandsOnSplatsGrid) {
  const double c = 1200.0;
  // Three points near cells (i, j) = (-134280, 48912), (-134278, 48912), (-134280, 48913).
  const AnoMap m =
      map_of({pt(48912.2 / c, -134280.3 / c, 100.0f), pt(48911.9 / c, -134277.6 / c, 110.0f, true),
              pt(48913.4 / c, -134280.0 / c, 120.0f)});
  const AnoStack s = stack_ano({{&m, 10.0}});
  const Volume& v = s.path_loss;
  EXPECT_EQ(v.name, "path_loss_db");
  EXPECT_EQ(v.units, "dB");
  EXPECT_EQ(v.frame, parse_frame("geographic-agl"));
  EXPECT_EQ(v.lattice.dims, (std::array<int, 3>{3, 2, 1}));
  EXPECT_DOUBLE_EQ(v.lattice.origin[0], -134280.0 / c);
  EXPECT_DOUBLE_EQ(v.lattice.origin[1], 48912.0 / c);
  EXPECT_DOUBLE_EQ(v.lattice.origin[2], 10.0);
  EXPECT_DOUBLE_EQ(v.lattice.spacing[0], 1.0 / c);
  EXPECT_EQ(v.at(0, 0, 0), 100.0f);
  EXPECT_EQ(v.at(2, 0, 0), 110.0f);
  EXPECT_EQ(v.at(0, 1, 0), 120.0f);
  EXPECT_TRUE(std::isnan(v.at(1, 0, 0)));
  EXPECT_TRUE(std::isnan(v.at(1, 1, 0)));
  EXPECT_TRUE(std::isnan(v.at(2, 1, 0)));
  EXPECT_TRUE(std::isnan(v.background));
  EXPECT_EQ(s.reported, 3u);
  EXPECT_EQ(s.duplicates, 0u);
  EXPECT_EQ(s.obstructed, 1u);
}

TEST(SplatStack, TheNearestOfSeveralPointsOnOneCellWins) {
  const double c = 1200.0;
  const AnoMap m =
      map_of({pt(48912.3 / c, -134280.0 / c, 1.0f), pt(48912.1 / c, -134280.0 / c, 2.0f),
              pt(48911.8 / c, -134280.0 / c, 3.0f), pt(48912.1 / c, -134280.0 / c, 4.0f)});
  const AnoStack s = stack_ano({{&m, 0.0}});
  EXPECT_EQ(s.path_loss.lattice.dims, (std::array<int, 3>{1, 1, 1}));
  EXPECT_EQ(s.path_loss.values[0], 2.0f);  // 0.1 cell away; the later tie loses
  EXPECT_EQ(s.reported, 1u);
  EXPECT_EQ(s.duplicates, 3u);
}

TEST(SplatStack, LayersShareTheUnionLatticeAndKeepTheirHeights) {
  const double c = 1200.0;
  const AnoMap low = map_of({pt(100.0 / c, -200.0 / c, 150.0f)});
  const AnoMap mid = map_of({pt(102.0 / c, -197.0 / c, 140.0f)});
  const AnoMap high = map_of({pt(101.0 / c, -199.0 / c, 130.0f)});
  const AnoStack s = stack_ano({{&low, 10.0}, {&mid, 60.0}, {&high, 110.0}});
  const Lattice& l = s.path_loss.lattice;
  EXPECT_EQ(l.dims, (std::array<int, 3>{4, 3, 3}));
  EXPECT_DOUBLE_EQ(l.spacing[2], 50.0);
  EXPECT_EQ(s.path_loss.at(0, 0, 0), 150.0f);
  EXPECT_EQ(s.path_loss.at(3, 2, 1), 140.0f);
  EXPECT_EQ(s.path_loss.at(1, 1, 2), 130.0f);
  EXPECT_TRUE(std::isnan(s.path_loss.at(0, 0, 1)));
  EXPECT_EQ(s.reported, 3u);
}

TEST(SplatStack, RandomJitteredCellsAllLandWhereTheyBelong) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> jitter(-0.45, 0.45);
  const int c = 3600;
  std::set<std::pair<int, int>> cells;
  while (cells.size() < 500)
    cells.insert({static_cast<int>(rng() % 60), static_cast<int>(rng() % 40)});
  AnoMap m = map_of({});
  const int i0 = -400000, j0 = 150000;  // about 111.1 W, 41.7 N
  for (const auto& [i, j] : cells) {
    m.points.push_back(pt((j0 + j + jitter(rng)) / c, (i0 + i + jitter(rng)) / c,
                          static_cast<float>(i * 100 + j)));
  }
  const AnoStack s = stack_ano({{&m, 5.0}}, c);
  const Volume& v = s.path_loss;
  EXPECT_EQ(s.reported, cells.size());
  std::size_t finite = 0;
  for (const float x : v.values) finite += std::isfinite(x) ? 1 : 0;
  EXPECT_EQ(finite, cells.size());
  const int di = static_cast<int>(std::llround(v.lattice.origin[0] * c)) - i0;
  const int dj = static_cast<int>(std::llround(v.lattice.origin[1] * c)) - j0;
  for (const auto& [i, j] : cells)
    EXPECT_EQ(v.at(i - di, j - dj, 0), static_cast<float>(i * 100 + j));
}

TEST(SplatStack, AMapAcrossTheAntimeridianStaysWhole) {
  const double c = 1200.0;
  const AnoMap m = map_of({pt(10.0, 179.9995, 1.0f), pt(10.0, -179.9995, 2.0f)});
  const AnoStack s = stack_ano({{&m, 0.0}});
  EXPECT_EQ(s.path_loss.lattice.dims[0], 3);
  EXPECT_DOUBLE_EQ(s.path_loss.lattice.origin[0], 215999.0 / c);  // 179.9995 E is cell 215999.4
}

TEST(SplatStack, BadLayersAreRefused) {
  const AnoMap m = map_of({pt(1.0, 1.0, 1.0f)});
  EXPECT_THROW(stack_ano({}), std::invalid_argument);
  EXPECT_THROW(stack_ano({{nullptr, 1.0}}), std::invalid_argument);
  EXPECT_THROW(stack_ano({{&m, -1.0}}), std::invalid_argument);
  EXPECT_THROW(stack_ano({{&m, 10.0}, {&m, 5.0}}), std::invalid_argument);
  EXPECT_THROW(stack_ano({{&m, 10.0}, {&m, 20.0}, {&m, 40.0}}), std::invalid_argument);
  EXPECT_THROW(stack_ano({{&m, 1.0}}, 0), std::invalid_argument);
  // A stray point across the globe would need 2^28+ lattice points.
  const AnoMap far = map_of({pt(-60.0, -170.0, 1.0f), pt(60.0, -10.0, 1.0f)});
  expect_format_error([&] { stack_ano({{&far, 1.0}}); }, "test.ano: the points span");
}

TEST(SplatStack, NaNSurvivesTheVdbRoundTrip) {
  const double c = 1200.0;
  const AnoMap m =
      map_of({pt(48912.0 / c, -134280.0 / c, 100.0f), pt(48913.0 / c, -134279.0 / c, 90.0f)});
  const Volume v = stack_ano({{&m, 10.0}}).path_loss;
  const Volume back = parse_vdb(encode_vdb({&v}), "mem.vdb");
  EXPECT_EQ(back.lattice, v.lattice);
  EXPECT_EQ(back.frame, v.frame);
  EXPECT_EQ(back.at(0, 0, 0), 100.0f);
  EXPECT_EQ(back.at(1, 1, 0), 90.0f);
  EXPECT_TRUE(std::isnan(back.at(1, 0, 0)));
  EXPECT_TRUE(std::isnan(back.background));
}

TEST(SplatSignal, IsEirpMinusPathLossAsRfHasIt) {
  const AnoMap m = map_of({pt(1.0, 1.0, 100.0f), pt(1.0 + 2.0 / 1200.0, 1.0, 120.0f)});
  const Volume loss = stack_ano({{&m, 0.0}}).path_loss;
  const Volume s = signal_from_path_loss(loss, 50.0);
  const double eirp = 10.0 * std::log10(50.0) + 30.0 + 2.15;
  EXPECT_EQ(s.name, "signal_dbm");
  EXPECT_EQ(s.units, "dBm");
  EXPECT_NEAR(s.values[0], eirp - 100.0, 1e-4);
  EXPECT_NEAR(s.values[2], eirp - 120.0, 1e-4);
  EXPECT_TRUE(std::isnan(s.values[1]));
  EXPECT_EQ(s.lattice, loss.lattice);
  EXPECT_THROW(signal_from_path_loss(loss, 0.0), std::invalid_argument);
}

// ---- run_splat with stand-in executables ----

class SplatRunFake : public ::testing::Test {
 protected:
  void SetUp() override {
    tiles_ = dir_.path() / "tiles";
    std::filesystem::create_directories(tiles_);
    // Plain tiles around 40.76 N, 111.89 W; a stand-in splat never reads them.
    for (const char* name : {"40_41_111_112.sdf", "40_41_112_113.sdf", "41_42_111_112.sdf",
                             "41_42_112_113.sdf", "40_41_110_111.sdf", "41_42_110_111.sdf"}) {
      write(tiles_ / name, "tile\n");
    }
    options_.sdf_folder = tiles_;
    options_.site = {"test tx/../x", 40.76, -111.89, 30.0};
    options_.heights_agl = {10.0, 20.0};
    options_.radius_km = 10.0;
    options_.work_root = dir_.path();
  }
  std::string run_error() {
    try {
      run_splat(options_);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "(no error)";
  }
  std::size_t leftover_work_folders() const {
    std::size_t n = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir_.path())) {
      n += e.path().filename().string().rfind("terravol-splat-", 0) == 0 ? 1 : 0;
    }
    return n;
  }
  test::TempDir dir_;
  std::filesystem::path tiles_;
  SplatRunOptions options_;
};

// A stand-in that checks its arguments and the colon-named tiles, then writes a tiny -ano
// whose value is 100 + the -L height.
const char kFakeSplat[] = R"(
echo "--==[ Welcome To SPLAT! v9.8.7 ]==--"
[ "$1" = "-t" ] && [ "$2" = "tx.qth" ] && [ "$3" = "-L" ] && [ "$5" = "-R" ] && [ "$7" = "-metric" ] || exit 9
[ "$8" = "-erp" ] && [ "$9" = "0" ] && [ "${10}" = "-ano" ] || exit 8
[ -e "40:41:111:112.sdf" ] && [ -e "40:41:112:113.sdf" ] || { echo "no tiles"; exit 7; }
[ -e "41:42:110:111.sdf" ] && { echo "loaded a tile it does not need"; exit 6; }
grep -q "^40.7600000$" tx.qth && grep -q "^111.8900000$" tx.qth && grep -q "^30.000 m$" tx.qth || exit 5
head -1 tx.qth | grep -q "^test_tx_.._x$" || { echo "unsafe name"; exit 4; }
printf '113, 111 ; max_west, min_west\n41, 40 ; max_north, min_north\n40.76, 111.89, 0, 0, %s\n40.7608333, 111.89, 0, 0, 120 *\n' $(echo "100 + $4" | bc) > "${11}"
)";

TEST_F(SplatRunFake, RunsOncePerHeightWithColonTilesAndStacks) {
  if (std::system("command -v bc >/dev/null") != 0) GTEST_SKIP() << "needs bc";
  options_.executable = script(dir_.path(), "splat", kFakeSplat);
  options_.keep_ano_texts = true;
  std::vector<std::size_t> progress;
  options_.progress = [&](std::size_t done) { progress.push_back(done); };
  const SplatRunResult r = run_splat(options_);
  ASSERT_EQ(r.maps.size(), 2u);
  EXPECT_EQ(r.version, "9.8.7");
  EXPECT_EQ(r.maps[0].points[0].value, 110.0f);
  EXPECT_EQ(r.maps[1].points[0].value, 120.0f);
  EXPECT_EQ(r.ano_texts.size(), 2u);
  EXPECT_EQ(progress, (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(r.tiles.size(), 2u);
  EXPECT_EQ(leftover_work_folders(), 0u);
}

TEST_F(SplatRunFake, DecompressesBz2Tiles) {
  if (std::system("command -v bzip2 >/dev/null") != 0) GTEST_SKIP() << "needs bzip2";
  for (const char* name : {"40_41_111_112.sdf", "40_41_112_113.sdf"}) {
    ASSERT_EQ(std::system(("bzip2 " + (tiles_ / name).string()).c_str()), 0);
  }
  options_.executable =
      script(dir_.path(), "splat",
             "grep -q '^tile$' 40:41:111:112.sdf && [ ! -L 40:41:111:112.sdf ] || exit 3\n"
             "printf '113, 111\\n41, 40\\n40.76, 111.89, 0, 0, 99\\n' > \"${11}\"\n");
  const SplatRunResult r = run_splat(options_);
  EXPECT_EQ(r.maps[1].points[0].value, 99.0f);
}

TEST_F(SplatRunFake, FailuresAreOneLineMessagesAndLeaveNoFolder) {
  options_.executable = dir_.path() / "no-such-splat";
  EXPECT_EQ(run_error().rfind(
                (dir_.path() / "no-such-splat").string() + ": not found or not executable", 0),
            0u);

  options_.executable = script(dir_.path(), "fails",
                               "echo 'Loading...'\necho 'ERROR: something broke' >&2\nexit 3\n");
  EXPECT_EQ(run_error(),
            "splat -L 10: failed with exit status 3; it last printed \"ERROR: something broke\"");

  options_.executable = script(dir_.path(), "silent", "exit 0\n");
  EXPECT_EQ(run_error(), "splat -L 10: wrote no -ano file; it last printed (it printed nothing)");

  options_.executable =
      script(dir_.path(), "garbage", "printf '113, 111\\n41, 40\\n1, 2, 3\\n' > \"${11}\"\n");
  EXPECT_EQ(run_error(),
            "splat -L 10 output: line 3: expected LAT, LON, AZIMUTH, ELEVATION, VALUE[ *], found 3 "
            "fields");

  options_.executable = script(dir_.path(), "crash", "kill -SEGV $$\n");
  EXPECT_EQ(run_error().rfind("splat -L 10: killed by signal 11", 0), 0u) << run_error();

  options_.executable = script(dir_.path(), "slow", "sleep 20\n");
  options_.timeout_seconds = 0.3;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(run_error(), "splat -L 10: no result after 0.3 s (killed; raise --timeout)");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_EQ(leftover_work_folders(), 0u);
}

TEST_F(SplatRunFake, AMissingTileIsAnErrorNotSeaLevel) {
  options_.executable = script(dir_.path(), "splat", "exit 0\n");
  std::filesystem::remove(tiles_ / "40_41_112_113.sdf");
  options_.site.lon = -111.99;  // the 10 km disc reaches 112.11 W
  const std::string e = run_error();
  EXPECT_EQ(
      e.rfind(
          tiles_.string() +
              ": no SDF tile for 40..41 N, -113..-112 E (40:41:112:113.sdf or 40_41_112_113.sdf",
          0),
      0u)
      << e;
  EXPECT_NE(e.find("SPLAT! would take it as sea level"), std::string::npos);
}

TEST_F(SplatRunFake, BadOptionsAreInvalidArguments) {
  options_.executable = script(dir_.path(), "splat", "exit 0\n");
  auto expect_invalid = [&](auto change) {
    SplatRunOptions saved = options_;
    change(options_);
    EXPECT_THROW(run_splat(options_), std::invalid_argument);
    options_ = saved;
  };
  expect_invalid([](SplatRunOptions& o) { o.heights_agl.clear(); });
  expect_invalid([](SplatRunOptions& o) { o.heights_agl = {-1.0}; });
  expect_invalid([](SplatRunOptions& o) { o.radius_km = 0.0; });
  expect_invalid([](SplatRunOptions& o) { o.lrp.frequency_mhz = 10.0; });
  expect_invalid([](SplatRunOptions& o) { o.timeout_seconds = 0.0; });
}

}  // namespace
}  // namespace terravol::volume
