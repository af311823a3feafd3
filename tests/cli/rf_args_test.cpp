// The transmitter and height options of rf, splat-volume and profile (app/rf_args.h).
#include "app/cli/rf_args.h"

#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>
#include <string>

#include "temp_dir.h"

namespace terravol::app::cli {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_tx(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(ParseTx, NumbersThenNamedFieldsInAnyOrder) {
  test::TempDir dir;
  std::ofstream(dir.path() / "a.az") << "10\n0 1\n180 0.5\n";
  std::ofstream(dir.path() / "a.el") << "1 10\n-10 1\n90 0.5\n";
  const std::string pattern = (dir.path() / "a.az").string() + ":" + (dir.path() / "a.el").string();
  const volume::Transmitter tx = parse_tx("40.5,-111.9,30,450,25,tilt=3,name=peak-1,pattern=" + pattern + ",azimuth=200");
  EXPECT_EQ(tx.lat, 40.5);
  EXPECT_EQ(tx.lon, -111.9);
  EXPECT_EQ(tx.height_agl, 30.0);
  EXPECT_EQ(tx.frequency_mhz, 450.0);
  EXPECT_EQ(tx.erp_w, 25.0);
  EXPECT_EQ(tx.name, "peak-1");
  ASSERT_TRUE(tx.antenna);
  EXPECT_EQ(tx.antenna->rotation_deg, 200.0);
  EXPECT_EQ(tx.antenna->tilt_deg, 3.0);
  EXPECT_EQ(tx.antenna->tilt_azimuth_deg, 200.0);  // 10 + (200 - 10)
  const volume::Transmitter plain = parse_tx("40.5,-111.9,30");
  EXPECT_EQ(plain.frequency_mhz, 900.0);
  EXPECT_FALSE(plain.erp_w);
  EXPECT_TRUE(plain.name.empty());
  EXPECT_FALSE(plain.antenna);
}

TEST(ParseTx, EveryFaultIsNamed) {
  EXPECT_EQ(error_of("1,2"), "--tx 1,2: expected LAT,LON,HEIGHT_AGL[,FREQ_MHZ[,ERP_W]][,name=NAME][,pattern=FILE.az[:FILE.el]][,azimuth=DEG][,tilt=DEG]");
  EXPECT_EQ(error_of("1,2,3,azimuth=x,pattern=a.az"), "--tx 1,2,3,azimuth=x,pattern=a.az: azimuth 'x' is not a number of degrees");
  EXPECT_EQ(error_of("1,2,3,azimuth=5"), "--tx 1,2,3,azimuth=5: azimuth needs pattern=FILE.az[:FILE.el]");
  EXPECT_EQ(error_of("1,2,3,name="), "--tx 1,2,3,name=: name '': 1 to 32 letters, digits, '_', '-' or '.'");
  EXPECT_EQ(error_of("1,2,3,pattern=:"), "--tx 1,2,3,pattern=:: pattern ':': expected FILE.az[:FILE.el] or :FILE.el");
  EXPECT_EQ(parse_tx("1,2,3", "sites.txt: line 4").lat, 1.0);
  try {
    parse_tx("1,2", "sites.txt: line 4");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("sites.txt: line 4: expected LAT,LON", 0), 0u);
  }
}

TEST(ReadTxFile, SkipsCommentsAndBlankLines) {
  test::TempDir dir;
  const auto path = dir.path() / "sites.txt";
  std::ofstream(path) << "# sites\n\n1,2,3,900,5,name=a\r\n   \n  4,5,6,900,5 \n";
  const auto txs = read_tx_file(path.string());
  ASSERT_EQ(txs.size(), 2u);
  EXPECT_EQ(txs[0].name, "a");
  EXPECT_EQ(txs[1].lat, 4.0);
  std::ofstream(path) << "# nothing\n";
  EXPECT_THROW(read_tx_file(path.string()), std::runtime_error);
  EXPECT_THROW(read_tx_file((dir.path() / "none").string()), std::runtime_error);
}

TEST(ParseHeights, RangesAndLists) {
  EXPECT_EQ(parse_heights("0:100:50"), (std::vector<double>{0.0, 50.0, 100.0}));
  EXPECT_EQ(parse_heights("10,20"), (std::vector<double>{10.0, 20.0}));
  EXPECT_THROW(parse_heights("10,20,40"), std::runtime_error);
  EXPECT_THROW(parse_heights("5:1:1"), std::runtime_error);
}

}  // namespace
}  // namespace terravol::app::cli
