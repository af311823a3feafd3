// Helpers of the volume tests: random volumes, the readers' hostile-input contract, and a
// capture of what the process writes to stderr.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <utility>

#include "io/error.h"
#include "io/grid.h"
#include "temp_dir.h"
#include "volume/volume.h"

namespace terravol::test {

// A geographic 3" grid over 45..46 N, 6..7 E whose height is f(lat, lon) at every sample.
template <class F>
io::Grid synthetic_dem(F f) {
  io::Grid g;
  g.format = "test";
  g.allocate(1201, 1201);
  g.georef.x0 = 6.0;
  g.georef.y0 = 46.0;
  g.georef.dx = g.georef.dy = 1.0 / 1200.0;
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) g.heights[g.index(r, c)] = static_cast<float>(f(46.0 - r / 1200.0, 6.0 + c / 1200.0));
  return g;
}

// A smooth sector antenna as SPLAT!'s .az and .el texts: in azimuth a cardioid, field 0.05 + 0.95
// ((1 + cos a) / 2)^2, every 5 degrees; in elevation a beam whose field is cos(4 x depression),
// at least 0.1, every 0.5 degree from -10 to 90; rotation 0, no tilt.
inline std::pair<std::string, std::string> smooth_sector_texts() {
  std::string az = "0\n", el = "0 0\n";
  for (int a = 0; a < 360; a += 5) {
    const double c = 0.5 + 0.5 * std::cos(a * M_PI / 180.0);
    az += std::to_string(a) + " " + std::to_string(0.05 + 0.95 * c * c) + "\n";
  }
  for (int i = -20; i <= 180; ++i) {
    const double e = i / 2.0;
    el += std::to_string(e) + " " + std::to_string(std::max(0.1, std::cos(std::min(80.0, std::abs(e) * 4.0) * M_PI / 180.0))) + "\n";
  }
  return {az, el};
}

// A volume of random values, fixed by the seed.
inline volume::Volume random_volume(unsigned seed, std::array<int, 3> dims, volume::VolumeFrame frame) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(-200.0f, 200.0f);
  volume::Volume v;
  v.name = "field_" + std::to_string(seed);
  v.units = "dB";
  v.frame = frame;
  v.lattice.dims = dims;
  v.lattice.origin = {6.25 + 0.001 * seed, 45.125, -37.5};
  v.lattice.spacing = {1.0 / 1200.0, 1.0 / 1800.0, 12.5};
  v.values.resize(v.lattice.size());
  for (float& x : v.values) x = value(rng);
  v.active_points = v.values.size();
  v.attributes = {{"source", "test"}, {"seed", std::to_string(seed)}};
  return v;
}

// The readers' contract on hostile input: a consistent volume, or a one-line FormatError
// starting with the source's name.
template <class Parse>
void expect_volume_or_one_line_error(Parse parse, const std::string& source, const std::string& context) {
  try {
    const volume::Volume v = parse();
    EXPECT_EQ(v.values.size(), v.lattice.size()) << context;
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(v.lattice.dims[a], 1) << context;
      EXPECT_GT(v.lattice.spacing[a], 0.0) << context;
    }
  } catch (const io::FormatError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(source + ": ", 0), 0u) << context << ": " << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << context << ": " << what;
  }
}

// Redirects the process's stderr (file descriptor 2) to a file while alive.
class StderrCapture {
 public:
  StderrCapture() : path_(dir_.path() / "stderr") {
    std::fflush(stderr);
    saved_ = ::dup(2);
    FILE* f = std::fopen(path_.c_str(), "w");
    ::dup2(::fileno(f), 2);
    std::fclose(f);
  }
  ~StderrCapture() { restore(); }
  // Restores stderr and returns what was written to it.
  std::string finish() {
    restore();
    std::ifstream in(path_);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }

 private:
  void restore() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    ::dup2(saved_, 2);
    ::close(saved_);
    saved_ = -1;
  }
  TempDir dir_;
  std::filesystem::path path_;
  int saved_ = -1;
};

}  // namespace terravol::test
