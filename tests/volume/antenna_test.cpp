// SPLAT! antenna patterns: exact gains of tiny patterns worked out by hand, the files' errors,
// and SPLAT! 1.4.2 itself applying the same pattern (splat with and without it, over the Utah
// tiles).
#include "volume/antenna.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>

#include "io/error.h"
#include "shared_data.h"
#include "temp_dir.h"
#include "volume/splat.h"
#include "volume_test_util.h"

namespace terravol::volume {
namespace {

double db(double field) { return 20.0 * std::log10(field); }

const char* kAz = "90 ; rotation\n0 1\n90 0.5\n180 0.1\n270 0.5\n";
const char* kEl = "2 90\n-10 1\n0 1\n5 0.5\n10 0.25\n";

AntennaPattern tiny(bool with_az, bool with_el) {
  AntennaPattern p;
  if (with_az) {
    auto [cut, rotation] = parse_az(kAz, "t.az");
    p.azimuth = cut;
    p.rotation_deg = rotation;
  }
  if (with_el) {
    const ElevationFile f = parse_el(kEl, "t.el");
    p.elevation = f.cut;
    p.tilt_deg = f.tilt_deg;
    p.tilt_azimuth_deg = f.tilt_azimuth_deg;
  }
  return p;
}

TEST(AntennaPattern, AzimuthCutIsRotatedAndInterpolatedAroundTheCircle) {
  const AntennaPattern p = tiny(true, false);
  EXPECT_EQ(p.rotation_deg, 90.0);
  EXPECT_NEAR(p.gain_db(90.0, 0.0), 0.0, 1e-12);               // the pattern's 0 points east
  EXPECT_NEAR(p.gain_db(180.0, 0.0), db(0.5), 1e-12);          // its 90
  EXPECT_NEAR(p.gain_db(135.0, 0.0), db(0.75), 1e-12);         // halfway from its 0 to its 90
  EXPECT_NEAR(p.gain_db(45.0, 0.0), db(0.75), 1e-12);          // its 315: between 270 and 360 = 0
  EXPECT_NEAR(p.gain_db(270.0, 0.0), db(0.1), 1e-12);          // behind
  EXPECT_NEAR(p.gain_db(-90.0, 0.0), p.gain_db(270.0, 0.0), 1e-12);
  EXPECT_NEAR(p.gain_db(90.0, 45.0), 0.0, 1e-12);              // no .el: every elevation alike
}

TEST(AntennaPattern, TiltLowersTheBeamTowardsItsAzimuthAndRaisesItBehind) {
  const AntennaPattern p = tiny(false, true);
  EXPECT_EQ(p.tilt_deg, 2.0);
  EXPECT_EQ(p.tilt_azimuth_deg, 90.0);
  // Towards the tilt (east) the pattern's 5 degrees of depression appear at 7.
  EXPECT_NEAR(p.gain_db(90.0, -7.0), db(0.5), 1e-12);
  EXPECT_NEAR(p.gain_db(90.0, 0.0), 0.0, 1e-12);
  // At right angles (north) nothing moves; behind (west) they appear at 3.
  EXPECT_NEAR(p.gain_db(0.0, -5.0), db(0.5), 1e-12);
  EXPECT_NEAR(p.gain_db(270.0, -3.0), db(0.5), 1e-12);
  // Halfway (45 degrees off the tilt) it moves by half the tilt, SPLAT!'s linear profile.
  EXPECT_NEAR(p.gain_db(45.0, -6.0), db(0.5), 1e-12);
  // Beyond the cut's ends its end values hold: 10 degrees of depression and more, and above.
  EXPECT_NEAR(p.gain_db(0.0, -60.0), db(0.25), 1e-12);
  EXPECT_NEAR(p.gain_db(0.0, 40.0), 0.0, 1e-12);
}

TEST(AntennaPattern, GainIsTheProductOfTheCutsFlooredAtMinus60Db) {
  const AntennaPattern p = tiny(true, true);
  EXPECT_NEAR(p.gain_db(180.0, -5.0), db(0.5 * 0.5), 1e-12);
  AntennaPattern deaf;
  deaf.azimuth = parse_az("0\n0 0\n", "z.az").first;
  EXPECT_NEAR(deaf.gain_db(10.0, 0.0), -60.0, 1e-12);
}

TEST(AntennaPattern, DuplicatesAverageAndThe360Rule) {
  const auto [cut, rotation] = parse_az("0\n0 0.2\n0 0.4 ; twice\n360 0.9\n180 0.5\n", "d.az");
  ASSERT_EQ(cut.points.size(), 2u);
  EXPECT_NEAR(cut.points[0].second, 0.3, 1e-12);  // 360 ignored: 0 has values
  const auto only360 = parse_az("0\n360 0.8\n180 0.4\n", "e.az").first;
  EXPECT_EQ(only360.points.front().first, 0.0);
  EXPECT_EQ(only360.points.front().second, 0.8);
}

TEST(AntennaPattern, OverridesTurnTheWholeAntenna) {
  test::TempDir dir;
  std::ofstream(dir.path() / "a.az") << kAz;
  std::ofstream(dir.path() / "a.el") << kEl;
  const std::string spec = (dir.path() / "a.az").string() + ":" + (dir.path() / "a.el").string();
  const AntennaPattern p = read_antenna_pattern(spec, 120.0, 4.0);
  EXPECT_EQ(p.rotation_deg, 120.0);
  EXPECT_EQ(p.tilt_azimuth_deg, 120.0);  // 90 + (120 - 90)
  EXPECT_EQ(p.tilt_deg, 4.0);
  EXPECT_NEAR(p.gain_db(120.0, -9.0), db(0.5), 1e-12);  // 5 + 4 below the horizon, in the beam
  EXPECT_EQ(splat_az_text(p).substr(0, 4), "120\n");
  EXPECT_EQ(splat_el_text(p).substr(0, 6), "4 120\n");
  EXPECT_NE(splat_az_text(p).find("180 0.1"), std::string::npos);  // the data lines as read
  const AntennaPattern el_only = read_antenna_pattern(":" + (dir.path() / "a.el").string(), std::nullopt, std::nullopt);
  EXPECT_FALSE(el_only.azimuth);
  EXPECT_TRUE(splat_az_text(el_only).empty());
  EXPECT_THROW(read_antenna_pattern(":" + (dir.path() / "a.el").string(), 10.0, std::nullopt), std::invalid_argument);
  EXPECT_THROW(read_antenna_pattern((dir.path() / "a.az").string(), std::nullopt, 3.0), std::invalid_argument);
  EXPECT_THROW(read_antenna_pattern(spec, std::nullopt, 95.0), std::invalid_argument);
  EXPECT_THROW(read_antenna_pattern(":", std::nullopt, std::nullopt), std::invalid_argument);
  EXPECT_THROW(read_antenna_pattern((dir.path() / "missing.az").string(), std::nullopt, std::nullopt), io::FormatError);
}

TEST(AntennaPattern, MalformedFilesNameTheLine) {
  const std::map<std::string, std::string> az = {
      {"", "x.az: empty file"},
      {"10\n", "x.az: no pattern lines"},
      {"abc\n0 1\n", "x.az: line 1: 'abc' is not a number"},
      {"1 2\n0 1\n", "x.az: line 1: expected one number"},
      {"0\n0 1\n45\n", "x.az: line 3: expected \"azimuth FIELD\""},
      {"0\n0 1\n400 0.5\n", "x.az: line 3: azimuth 400 is outside [0, 360]"},
      {"0\n0 1.5\n", "x.az: line 2: field 1.5 is outside [0, 1]"},
      {"0\n0 x\n", "x.az: line 2: field 'x' is not a number"},
  };
  for (const auto& [text, message] : az) {
    try {
      parse_az(text, "x.az");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const io::FormatError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(message, 0), 0u) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
  EXPECT_THROW(parse_el("2 90\n-20 1\n", "x.el"), io::FormatError);
  EXPECT_THROW(parse_el("120 0\n0 1\n", "x.el"), io::FormatError);
  EXPECT_EQ(parse_el("1.5\n0 1\n", "x.el").tilt_azimuth_deg, 0.0);
}

// SPLAT! with and without the same pattern: the loss it adds at each point is 20 log10 of its
// tabulated pattern at (azimuth rounded to a degree, elevation cell of 0.1 degree); the cell's
// value is the mean of ten 0.01-degree samples from its lower edge, i.e. the pattern 0.045
// degree into the cell (PlotLRPath, LoadPAT). Evaluated there, ours must agree.
TEST(AntennaPatternAgainstSplat, GainEqualsWhatSplatApplies) {
  const auto sdf = test::shared_dem("utah_sdf");
  TERRAVOL_REQUIRE_SHARED(sdf);
  if (!std::filesystem::exists("/usr/bin/splat")) GTEST_SKIP() << "/usr/bin/splat not installed (Debian package splat)";
  test::TempDir dir;
  // The smooth sector, tilted down 2 degrees towards the north.
  const auto [az, el] = test::smooth_sector_texts();
  std::ofstream(dir.path() / "s.az") << az;
  std::ofstream(dir.path() / "s.el") << el;
  const AntennaPattern pattern = read_antenna_pattern((dir.path() / "s.az").string() + ":" + (dir.path() / "s.el").string(),
                                                      std::nullopt, 2.0);
  SplatRunOptions run;
  run.sdf_folder = sdf;
  run.site = {"tx", 40.76, -111.89, 30.0};
  run.heights_agl = {10.0};
  run.radius_km = 4.0;
  run.work_root = dir.path();
  run.lrp.erp_w = 50.0;
  run.antenna = pattern;
  const SplatRunResult with = run_splat(run);
  run.antenna = AntennaPattern{};  // no cuts: SPLAT! gets no files, and the same -dbm run
  const SplatRunResult without = run_splat(run);
  ASSERT_EQ(with.maps[0].points.size(), without.maps[0].points.size());
  std::size_t compared = 0;
  double worst = 0.0;
  for (std::size_t n = 0; n < with.maps[0].points.size(); ++n) {
    const AnoPoint& a = with.maps[0].points[n];
    const AnoPoint& b = without.maps[0].points[n];
    ASSERT_EQ(a.lat, b.lat);
    const double splat_gain = b.value - a.value;  // loss without - loss with
    const double cell_f = 10.0 * (10.0 - a.elevation_deg);
    const int cell = static_cast<int>(std::rint(cell_f));
    if (cell < 0 || cell > 1000) continue;  // above 10 degrees SPLAT! applies no pattern
    // The file prints 3 decimals: where SPLAT!'s rounding of the true angle is ambiguous, skip.
    auto near_half = [](double x, double within) { return std::abs(x - std::floor(x) - 0.5) < within; };
    if (near_half(a.azimuth_deg, 0.001) || near_half(cell_f, 0.01)) continue;
    const double elevation = -(cell / 10.0 - 10.0 + 0.045);
    const double ours = pattern.gain_db(std::rint(a.azimuth_deg), elevation);
    worst = std::max(worst, std::abs(ours - splat_gain));
    ++compared;
  }
  std::printf("pattern against SPLAT!: %zu points, largest difference %.4f dB\n", compared, worst);
  EXPECT_GT(compared, 5000u);
  EXPECT_LT(worst, 0.02) << "over " << compared << " points";
}

}  // namespace
}  // namespace terravol::volume
