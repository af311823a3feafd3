// `terravol rf` through the executable: the bundled DEM, --force, bad options.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "run_command.h"
#include "temp_dir.h"
#include "volume/readers.h"

namespace terravol::volume {
namespace {

using test::run_terravol;

std::string bundled_dem() { return std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"; }

void expect_one_line_error(const test::CommandResult& r, const std::string& prefix) {
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err.rfind("terravol: " + prefix, 0), 0u) << r.err;
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  EXPECT_LT(r.seconds, 5.0);
}

TEST(RfCli, DefaultRunOnTheBundledDemWritesAReadableVdb) {
  test::TempDir dir;
  const auto out = dir.path() / "rf.vdb";
  const auto r = run_terravol("rf --tx 45.5,6.5,30,900,50 --dem " + bundled_dem() + " -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + out.string() + ": path_loss_db and signal_dbm"), std::string::npos) << r.out;
  const Volume loss = read_volume(out);
  EXPECT_EQ(loss.name, "path_loss_db");
  EXPECT_EQ(loss.units, "dB");
  EXPECT_EQ(loss.frame, parse_frame("geographic-agl"));
  EXPECT_EQ(loss.lattice.dims[2], 41);
  EXPECT_GT(loss.lattice.dims[0], 250);
  EXPECT_GT(loss.lattice.dims[1], 200);
  ReadOptions o;
  o.field = "signal_dbm";
  const Volume signal = read_volume(out, o);
  EXPECT_EQ(signal.lattice, loss.lattice);
  EXPECT_NEAR(signal.values[0] + loss.values[0], 10.0 * std::log10(50.0) + 30.0 + 2.15, 1e-3);
}

TEST(RfCli, NeverOverwritesWithoutForce) {
  test::TempDir dir;
  const auto out = dir.path() / "small.vdb";
  const std::string args = "rf --tx 45.5,6.5,30 --dem " + bundled_dem() + " --radius-km 2 -o " + out.string();
  ASSERT_EQ(run_terravol(args + " --heights 10,20").status, 0);
  EXPECT_EQ(read_volume(out).lattice.dims[2], 2);
  const auto again = run_terravol(args + " --heights 10,20");
  expect_one_line_error(again, out.string() + ": exists (use --force to overwrite)");
  const auto forced = run_terravol(args + " --force --heights 30");
  ASSERT_EQ(forced.status, 0) << forced.err;
  EXPECT_EQ(read_volume(out).lattice.dims[2], 1);
  EXPECT_FALSE(read_volume(out).attributes.contains("erp_w"));
}

TEST(RfCli, ItmRunHasNoValueOnlyAtTheTransmitter) {
  test::TempDir dir;
  const auto out = dir.path() / "itm.vdb";
  const auto r = run_terravol("rf --model itm --tx 45.5,6.5,30,450 --dem " + bundled_dem() +
                              " --radius-km 3 --heights 10:110:50 --climate 6 --time 0.9 -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("note: ITM has no value at the transmitter's own column (NaN)"), std::string::npos) << r.out;
  const Volume loss = read_volume(out);
  EXPECT_EQ(loss.lattice.dims[2], 3);
  std::size_t nan = 0;
  for (const float v : loss.values) nan += std::isnan(v) ? 1 : 0;
  EXPECT_EQ(nan, 3u);
  const std::string model = loss.attributes.at("model");
  EXPECT_NE(model.find("Longley-Rice ITM"), std::string::npos) << model;
  EXPECT_NE(model.find("maritime temperate over land climate, time 0.9"), std::string::npos) << model;
}

TEST(RfCli, BadOptionsFailWithOneLine) {
  test::TempDir dir;
  const std::string dem = " --dem " + bundled_dem();
  const std::string out = " -o " + (dir.path() / "x.vdb").string();
  const std::pair<std::string, std::string> cases[] = {
      {"--tx 45.5,6.5" + dem + out, "--tx 45.5,6.5: expected LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]]"},
      {"--tx abc,6.5,30" + dem + out, "--tx abc,6.5,30: latitude 'abc' is not a number"},
      {"--tx 95,6.5,30" + dem + out, "--tx 95,6.5,30: latitude must be within [-85, 85] degrees"},
      {"--tx 45.5,6.5,-3" + dem + out, "--tx 45.5,6.5,-3: height must be within"},
      {"--tx 45.5,6.5,30,0" + dem + out, "--tx 45.5,6.5,30,0: frequency must be within"},
      {"--tx 45.5,6.5,30,900,-1" + dem + out, "--tx 45.5,6.5,30,900,-1: ERP must be within"},
      {"--tx 45.5,6.5,30,900,50,7" + dem + out, "--tx 45.5,6.5,30,900,50,7: expected"},
      {"--tx 10,10,30" + dem + out, "--tx 10,10,30: the transmitter lies outside the DEM"},
      {"--tx 45.5,6.5,30 --heights 10,20,40" + dem + out, "--heights 10,20,40: heights must be evenly spaced"},
      {"--tx 45.5,6.5,30 --heights a:b:c" + dem + out, "--heights a:b:c: expected START:STOP:STEP"},
      {"--tx 45.5,6.5,30 --radius-km 0" + dem + out, "--radius-km 0: must be within (0, 500]"},
      {"--tx 45.5,6.5,30" + dem + " -o " + (dir.path() / "x.png").string(), "-o " + (dir.path() / "x.png").string() + ": expected a .vdb"},
      {"--model foo --tx 45.5,6.5,30" + dem + out, "--model foo: must be itm or deygout"},
      {"--model itm --tx 45.5,6.5,30,10" + dem + out, "--tx 45.5,6.5,30,10: ITM takes frequencies within [20, 20000] MHz"},
      {"--model itm --tx 45.5,6.5,30,25000" + dem + out, "--tx 45.5,6.5,30,25000: ITM takes frequencies within [20, 20000] MHz"},
      {"--model itm --tx 45.5,6.5,0.2" + dem + out, "--tx 45.5,6.5,0.2: ITM takes antenna heights within [0.5, 3000] m"},
      {"--model itm --tx 45.5,6.5,30 --heights 0:100:50" + dem + out,
       "--heights 0:100:50: ITM takes receiver heights within [0.5, 3000] m above ground"},
      {"--model itm --tx 45.5,6.5,30 --climate 9" + dem + out, "--climate 9: must be within 1..7 (1 equatorial"},
      {"--model itm --tx 45.5,6.5,30 --time 1.5" + dem + out, "--time 1.5: must be within (0, 1)"},
      {"--model itm --tx 45.5,6.5,30 --situation 0" + dem + out, "--situation 0: must be within (0, 1)"},
      {"--model itm --tx 45.5,6.5,30 --permittivity 0.5" + dem + out, "--permittivity 0.5: must be within (1, 100]"},
      {"--model itm --tx 45.5,6.5,30 --conductivity 0" + dem + out, "--conductivity 0: must be within (0, 100] S/m"},
      {"--model itm --tx 45.5,6.5,30 --refractivity 200" + dem + out, "--refractivity 200: must be within [250, 400] N-units"},
      {"--model itm --tx 45.5,6.5,30 --polarization circular" + dem + out, "--polarization circular: must be horizontal or vertical"},
      {"--model itm --tx 45.5,6.5,30 --mdvar 5" + dem + out, "--mdvar 5: must be 0..3"},
      {"--model itm --tx 45.5,6.5,30 --k-factor 1.2" + dem + out, "--k-factor: only with --model deygout"},
      {"--tx 45.5,6.5,30 --climate 5" + dem + out, "--climate: only with --model itm"},
      {"--tx 45.5,6.5,30 --dem " + (dir.path() / "N00E000.hgt").string() + out, (dir.path() / "N00E000.hgt").string()},
  };
  for (const auto& [args, prefix] : cases) {
    SCOPED_TRACE(args);
    expect_one_line_error(run_terravol("rf " + args), prefix);
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "x.vdb"));
}

}  // namespace
}  // namespace terravol::volume
