// `terravol query` through the executable, on a volume `terravol rf` wrote: exact at lattice
// points, trilinear between them (against an interpolation written out here from the values
// read back), NaN outside, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_util.h"
#include "run_command.h"
#include "temp_dir.h"
#include "volume/readers.h"

namespace terravol::app::cli {
namespace {

using test::bundled_dem;
using test::expect_one_line_error;
using test::run_terravol;

struct Row {
  double lat, lon, agl, ground, value;
};

std::vector<Row> parse_rows(const std::string& out) {
  std::vector<Row> rows;
  std::stringstream s(out);
  std::string line;
  std::getline(s, line);
  EXPECT_EQ(line, "lat,lon,height_agl_m,ground_m,path_loss_db_dB");
  while (std::getline(s, line)) {
    Row r{};
    EXPECT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf", &r.lat, &r.lon, &r.agl, &r.ground, &r.value), 5) << line;
    rows.push_back(r);
  }
  return rows;
}

class QueryCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir;
    vdb_ = dir_->path() / "rf.vdb";
    const auto r = run_terravol("rf --tx 45.5,6.5,30 --dem " + bundled_dem() +
                                " --radius-km 4 --spacing 15 --heights 10:310:100 -o " + vdb_.string());
    ASSERT_EQ(r.status, 0) << r.err;
    volume_ = new volume::Volume(volume::read_volume(vdb_));
  }
  static void TearDownTestSuite() {
    delete volume_;
    delete dir_;
  }
  static test::TempDir* dir_;
  static std::filesystem::path vdb_;
  static volume::Volume* volume_;
};
test::TempDir* QueryCli::dir_ = nullptr;
std::filesystem::path QueryCli::vdb_;
volume::Volume* QueryCli::volume_ = nullptr;

TEST_F(QueryCli, ExactAtLatticePointsAndTrilinearBetween) {
  const volume::Volume& v = *volume_;
  const volume::Lattice& l = v.lattice;
  std::mt19937 rng(4);
  std::string csv = "lat,lon,height_agl\n# lattice points, then points between them\n";
  std::vector<std::array<double, 3>> fractional;
  for (int n = 0; n < 40; ++n) {
    const int i = std::uniform_int_distribution<int>(0, l.dims[0] - 1)(rng);
    const int j = std::uniform_int_distribution<int>(0, l.dims[1] - 1)(rng);
    const int k = std::uniform_int_distribution<int>(0, l.dims[2] - 1)(rng);
    fractional.push_back({double(i), double(j), double(k)});
  }
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 200; ++n) {
    fractional.push_back({u(rng) * (l.dims[0] - 1), u(rng) * (l.dims[1] - 1), u(rng) * (l.dims[2] - 1)});
  }
  char b[128];
  for (const auto& f : fractional) {
    std::snprintf(b, sizeof b, "%.12f,%.12f,%.9f\n", l.world(1, f[1]), l.world(0, f[0]), l.world(2, f[2]));
    csv += b;
  }
  const auto points = dir_->path() / "points.csv";
  std::ofstream(points) << csv;
  const auto r = run_terravol("query --volume " + vdb_.string() + " --dem " + bundled_dem() + " --points " + points.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<Row> rows = parse_rows(r.out);
  ASSERT_EQ(rows.size(), fractional.size());
  double worst = 0.0;
  for (std::size_t n = 0; n < rows.size(); ++n) {
    const auto& f = fractional[n];
    if (n < 40) {  // lattice points: the very float
      EXPECT_EQ(static_cast<float>(rows[n].value), v.at(int(f[0]), int(f[1]), int(f[2]))) << n;
      continue;
    }
    // Trilinear by its definition, from the values read back.
    const int i0 = std::min(int(f[0]), l.dims[0] - 2), j0 = std::min(int(f[1]), l.dims[1] - 2), k0 = std::min(int(f[2]), l.dims[2] - 2);
    const double ti = f[0] - i0, tj = f[1] - j0, tk = f[2] - k0;
    double want = 0.0;
    for (int c = 0; c < 8; ++c) {
      const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
      want += (di ? ti : 1 - ti) * (dj ? tj : 1 - tj) * (dk ? tk : 1 - tk) * v.at(i0 + di, j0 + dj, k0 + dk);
    }
    EXPECT_NEAR(rows[n].value, want, 1e-4) << n;  // the target
    worst = std::max(worst, std::abs(rows[n].value - want));
  }
  std::printf("query between lattice points: largest difference from trilinear %.2e dB\n", worst);
  // The ground is the DEM's, the model's bilinear height: 30 m below the transmitter's top.
  EXPECT_GT(rows[0].ground, 100.0);
}

TEST_F(QueryCli, NanOutsideTheLatticeAndOutsideTheDem) {
  const auto r = run_terravol("query --volume " + vdb_.string() + " --dem " + bundled_dem() +
                              " --at 45.5,6.5,5000 --at 45.9,6.5,10 --at 44.5,6.5,10 --at 45.5,6.5,10");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = parse_rows(r.out);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_TRUE(std::isnan(rows[0].value));   // above the lattice
  EXPECT_FALSE(std::isnan(rows[0].ground));
  EXPECT_TRUE(std::isnan(rows[1].value));   // north of it, over the DEM
  EXPECT_TRUE(std::isnan(rows[2].value));   // off the DEM too
  EXPECT_TRUE(std::isnan(rows[2].ground));
  EXPECT_FALSE(std::isnan(rows[3].value));  // the transmitter's own column
}

TEST_F(QueryCli, WritesAFileAtomicallyAndBadInputFailsWithOneLine) {
  const auto out = dir_->path() / "q.csv";
  const std::string base = "query --volume " + vdb_.string() + " --dem " + bundled_dem();
  ASSERT_EQ(run_terravol(base + " --at 45.5,6.5,10 -o " + out.string()).status, 0);
  EXPECT_EQ(parse_rows([&] { std::ifstream in(out); std::stringstream s; s << in.rdbuf(); return s.str(); }()).size(), 1u);
  const auto bad_points = dir_->path() / "bad.csv";
  std::ofstream(bad_points) << "lat,lon,agl\n45.5,6.5,10\n45.5,x,10\n";
  const std::pair<std::string, std::string> cases[] = {
      {base + " --at 45.5,6.5", "--at 45.5,6.5: expected LAT,LON,HEIGHT_AGL, found 2 fields"},
      {base + " --at 95,6.5,10", "--at 95,6.5,10: latitude must be within"},
      {base + " --points " + bad_points.string(), bad_points.string() + ": line 3: 'x' is not a number"},
      {base + " --points " + (dir_->path() / "none.csv").string(), "--points " + (dir_->path() / "none.csv").string() + ": cannot read"},
      {base, "give the points: --points FILE.csv or --at LAT,LON,AGL"},
      {base + " --at 45.5,6.5,10 -o " + out.string(), out.string() + ": exists (use --force to overwrite)"},
      {base + " --at 45.5,6.5,10 --field nope", vdb_.string()},
      {"query --volume " + (dir_->path() / "missing.vdb").string() + " --dem " + bundled_dem() + " --at 45.5,6.5,10",
       (dir_->path() / "missing.vdb").string()},
  };
  for (const auto& [args, prefix] : cases) {
    SCOPED_TRACE(args);
    expect_one_line_error(run_terravol(args), prefix);
  }
}

}  // namespace
}  // namespace terravol::app::cli
