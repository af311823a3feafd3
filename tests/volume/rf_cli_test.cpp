// `terravol rf` through the executable: the bundled DEM, --force, bad options.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>
#include <string>

#include "cli_test_util.h"
#include "run_command.h"
#include "temp_dir.h"
#include "volume/readers.h"

namespace terravol::volume {
namespace {

using test::bundled_dem;
using test::expect_one_line_error;
using test::run_terravol;

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

TEST(RfCli, SeveralTransmittersWriteEachSignalAndTheBestServer) {
  test::TempDir dir;
  const auto out = dir.path() / "plan.vdb";
  const auto file = dir.path() / "sites.txt";
  std::ofstream(file) << "# two more sites\n45.45,6.55,20,900,10,name=south\n\n  45.52,6.45,25,900,20\n";
  const auto r = run_terravol("rf --tx 45.5,6.5,30,900,50,name=peak --tx-file " + file.string() + " --dem " +
                              bundled_dem() + " --radius-km 4 --heights 10:110:50 -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("3 transmitters"), std::string::npos) << r.out;
  const auto grids = [&] {
    std::ifstream in(out, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return vdb_grids(bytes, out.string());
  }();
  std::vector<std::string> names;
  for (const auto& g : grids) names.push_back(g.name);
  EXPECT_EQ(names, (std::vector<std::string>{"signal_dbm_peak", "signal_dbm_south", "signal_dbm_tx3", "best_signal_dbm",
                                             "best_server"}));
  ReadOptions o;
  o.field = "signal_dbm_peak";
  const Volume peak = read_volume(out, o);
  // The first transmitter's signal is what rf gives it alone.
  const auto alone = dir.path() / "alone.vdb";
  ASSERT_EQ(run_terravol("rf --tx 45.5,6.5,30,900,50 --dem " + bundled_dem() + " --radius-km 4 --heights 10:110:50 -o " +
                         alone.string()).status, 0);
  o.field = "signal_dbm";
  const Volume single = read_volume(alone, o);
  EXPECT_EQ(peak.lattice, single.lattice);
  EXPECT_EQ(peak.values, single.values);
  o.field = "best_server";
  const Volume server = read_volume(out, o);
  EXPECT_EQ(server.attributes.at("transmitters").substr(0, 5), "peak,");
  std::size_t counts[4] = {0, 0, 0, 0};
  for (const float s : server.values) counts[std::isnan(s) ? 0 : static_cast<int>(s)]++;
  for (int t = 1; t <= 3; ++t) EXPECT_GT(counts[t], 1000u) << t;
  EXPECT_GT(counts[0], 0u);  // corners of the union no box holds
}

TEST(RfCli, AntennaPatternInTheTransmitter) {
  test::TempDir dir;
  std::ofstream(dir.path() / "s.az") << "0\n0 1\n90 0.3\n180 0.05\n270 0.3\n";
  const auto out = dir.path() / "p.vdb", plain = dir.path() / "q.vdb";
  const std::string tx = "45.5,6.5,30,900,50";
  ASSERT_EQ(run_terravol("rf --tx " + tx + ",pattern=" + (dir.path() / "s.az").string() + ",azimuth=90 --dem " +
                         bundled_dem() + " --radius-km 3 --heights 10 -o " + out.string()).status, 0);
  ASSERT_EQ(run_terravol("rf --tx " + tx + " --dem " + bundled_dem() + " --radius-km 3 --heights 10 -o " + plain.string()).status, 0);
  const Volume a = read_volume(out), b = read_volume(plain);
  ASSERT_EQ(a.lattice, b.lattice);
  EXPECT_NE(a.attributes.at("antenna_pattern").find("rotation 90"), std::string::npos);
  // Pointed east: east of the mast the loss is (nearly) as without; west it is 26 dB more.
  const int j = a.lattice.dims[1] / 2;
  EXPECT_NEAR(a.at(a.lattice.dims[0] - 1, j, 0) - b.at(a.lattice.dims[0] - 1, j, 0), 0.0, 0.5);
  EXPECT_NEAR(a.at(0, j, 0) - b.at(0, j, 0), -20.0 * std::log10(0.05), 0.5);
}

TEST(RfCli, BadTransmittersFailWithOneLine) {
  test::TempDir dir;
  const std::string dem = " --dem " + bundled_dem();
  const std::string out = " -o " + (dir.path() / "x.vdb").string();
  const auto file = dir.path() / "sites.txt";
  std::ofstream(file) << "45.5,6.5,30,900,5\n45.5,abc,30\n";
  std::ofstream(dir.path() / "bad.az") << "0\n0 1\n90 2\n";
  const std::pair<std::string, std::string> cases[] = {
      {"--tx 45.5,6.5,30,color=red" + dem + out, "--tx 45.5,6.5,30,color=red: unknown field 'color'"},
      {"--tx 45.5,6.5,30,name=a,name=b" + dem + out, "--tx 45.5,6.5,30,name=a,name=b: name given twice"},
      {"--tx 45.5,6.5,30,name=a/b" + dem + out, "--tx 45.5,6.5,30,name=a/b: name 'a/b': 1 to 32"},
      {"--tx 45.5,6.5,30,tilt=3" + dem + out, "--tx 45.5,6.5,30,tilt=3: tilt needs pattern="},
      {"--tx 45.5,6.5,30,name=a,900" + dem + out, "--tx 45.5,6.5,30,name=a,900: '900': numbers come first"},
      {"--tx 45.5,6.5,30,pattern=" + (dir.path() / "bad.az").string() + dem + out,
       "--tx 45.5,6.5,30,pattern=" + (dir.path() / "bad.az").string() + ": " + (dir.path() / "bad.az").string() +
           ": line 3: field 2 is outside [0, 1]"},
      {"--tx 45.5,6.5,30,900,5 --tx 45.4,6.5,30" + dem + out, "transmitter tx2: several transmitters need an ERP each"},
      {"--tx 45.5,6.5,30,900,5,name=a --tx 45.4,6.5,30,900,5,name=a" + dem + out, "transmitter name a is given twice"},
      {"--tx-file " + file.string() + dem + out, file.string() + ": line 2: longitude 'abc' is not a number"},
      {"--tx-file " + (dir.path() / "none.txt").string() + dem + out, (dir.path() / "none.txt").string() + ": cannot read"},
      {"--tx 45.5,6.5,30,900,5 --tx 10,10,30,900,5" + dem + out, "transmitter tx2: the transmitter lies outside the DEM"},
      {dem + out, "give the transmitters: --tx (once or more) or --tx-file"},
      {"--tx 45.5,6.5,30 --threads -1" + dem + out, "--threads -1: must be within [0, 1024]"},
  };
  for (const auto& [args, prefix] : cases) {
    SCOPED_TRACE(args);
    expect_one_line_error(run_terravol("rf " + args), prefix);
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "x.vdb"));
}

}  // namespace
}  // namespace terravol::volume
