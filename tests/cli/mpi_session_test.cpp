// `terravol rf` under `mpirun -np N --oversubscribe`: the same bits as one process, rank 0
// alone writing and speaking, and a failure reported in one line with nothing written.
// Open MPI refuses to run as root unless told (CI runs as root): the two OMPI_ALLOW_RUN_AS_ROOT
// variables tell it.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "cli_test_util.h"
#include "run_command.h"
#include "temp_dir.h"
#include "volume/readers.h"

namespace terravol::app::cli {
namespace {

using test::bundled_dem;
using test::run_terravol;
using test::run_terravol_under;

std::string mpirun(int ranks) {
  return "env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 "
         "mpirun -q --oversubscribe -np " +
         std::to_string(ranks);
}

std::vector<std::string> grid_names(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> names;
  for (const auto& g : volume::vdb_grids(bytes, path.string())) names.push_back(g.name);
  return names;
}

// The lines of mpirun's stderr that terravol wrote ("terravol: ..."). Open MPI may add notices
// of its own under load (a slow daemon, a rank killed after rank 0 aborted); they are not ours
// to test, but a second rank speaking would show here as a second line.
std::vector<std::string> terravol_lines(const std::string& err) {
  std::vector<std::string> lines;
  std::size_t begin = 0;
  while (begin < err.size()) {
    std::size_t end = err.find('\n', begin);
    if (end == std::string::npos) end = err.size();
    const std::string line = err.substr(begin, end - begin);
    if (line.rfind("terravol: ", 0) == 0) lines.push_back(line);
    begin = end + 1;
  }
  return lines;
}

void expect_same_grids(const std::filesystem::path& a, const std::filesystem::path& b) {
  const auto names = grid_names(a);
  ASSERT_EQ(names, grid_names(b));
  for (const auto& name : names) {
    volume::ReadOptions o;
    o.field = name;
    const volume::Volume va = volume::read_volume(a, o), vb = volume::read_volume(b, o);
    EXPECT_EQ(va.lattice, vb.lattice) << name;
    ASSERT_EQ(va.values.size(), vb.values.size()) << name;
    EXPECT_EQ(std::memcmp(va.values.data(), vb.values.data(), va.values.size() * sizeof(float)), 0) << name;
    EXPECT_EQ(va.attributes, vb.attributes) << name;
  }
}

TEST(MpiRf, TwoRanksGiveTheBitsOfOneProcess) {
  if (!std::filesystem::exists("/usr/bin/mpirun")) FAIL() << "/usr/bin/mpirun missing: install openmpi-bin (scripts/packages.txt)";
  test::TempDir dir;
  const std::string args = "rf --tx 45.5,6.5,30,900,50,name=a --tx 45.46,6.56,20,900,10,name=b --tx 45.53,6.44,25,900,20 --dem " +
                           bundled_dem() + " --radius-km 4 --heights 10:210:100 -o ";
  const auto one = dir.path() / "one.vdb", two = dir.path() / "two.vdb";
  const auto r1 = run_terravol(args + one.string());
  ASSERT_EQ(r1.status, 0) << r1.err;
  const auto r2 = run_terravol_under(mpirun(2), args + two.string(), 120);
  ASSERT_EQ(r2.status, 0) << r2.err;
  EXPECT_EQ(r2.err, "");
  // Rank 0 alone reports, once.
  EXPECT_EQ(r2.out.find("wrote "), r2.out.rfind("wrote ")) << r2.out;
  EXPECT_NE(r2.out.find("2 ranks x 1 thread"), std::string::npos) << r2.out;
  expect_same_grids(one, two);
  EXPECT_EQ(grid_names(two).size(), 5u);
}

TEST(MpiRf, OneTransmitterSplitOverThreeRanks) {
  test::TempDir dir;
  const std::string args = "rf --tx 45.5,6.5,30,900,50 --dem " + bundled_dem() + " --radius-km 3 --heights 10:110:50 -o ";
  const auto one = dir.path() / "one.vdb", three = dir.path() / "three.vdb";
  ASSERT_EQ(run_terravol(args + one.string()).status, 0);
  const auto r = run_terravol_under(mpirun(3), args + three.string(), 120);
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_grids(one, three);
  EXPECT_EQ(grid_names(three), (std::vector<std::string>{"path_loss_db", "signal_dbm"}));
}

TEST(MpiRf, AFailureIsOneLineFromRankZeroAndNothingIsWritten) {
  test::TempDir dir;
  const auto out = dir.path() / "x.vdb";
  // Every rank finds the same fault: rank 0 says it, the others exit quietly.
  auto r = run_terravol_under(mpirun(2), "rf --tx 45.5,6.5,30,900 --tx 45.4,6.5,30,900,1 --dem " + bundled_dem() + " -o " +
                                             out.string(), 60);
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(terravol_lines(r.err),
            std::vector<std::string>{"terravol: transmitter tx1: several transmitters need an ERP each "
                                     "(LAT,LON,HEIGHT_AGL,FREQ_MHZ,ERP_W) for their signals and the best server"})
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  r = run_terravol_under(mpirun(2), "rf --tx 45.5,6.5,30 --dem " + (dir.path() / "N00E000.hgt").string() + " -o " +
                                        out.string(), 60);
  EXPECT_NE(r.status, 0);
  const auto lines = terravol_lines(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_EQ(lines[0].rfind("terravol: ", 0), 0u) << r.err;
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace terravol::app::cli
