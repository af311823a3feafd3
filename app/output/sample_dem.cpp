// The project's own small DEM (data/dem/N45E006.hgt, written by `terravol sample-dem`): a
// deterministic synthetic SRTM3 tile, so the main job runs on a fresh clone without ../shared.
// Same bytes on every run and machine: integer hashing and values rounded to whole metres.
// `--tiles RxC` writes a seamless mosaic of R x C such tiles from N45E006 northward and
// eastward (one noise field over all of them; N45E006 itself is the same bytes), which the
// scaling benchmark uses (docs/benchmarks.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>
#include <cstdint>
#include <filesystem>
#include <fstream>

#include "app/output/sample_dem.h"
#include "app/output/write_file.h"
#include "io/grid.h"
#include "io/srtm_write.h"

namespace terravol::app::output {

namespace {

// Value noise on an integer lattice, hashed (hand-written: a few lines, and it must be
// bit-for-bit the same everywhere, which a library's noise does not promise).
double lattice(int x, int y, std::uint32_t seed) {
  std::uint32_t h = static_cast<std::uint32_t>(x) * 374761393u + static_cast<std::uint32_t>(y) * 668265263u + seed * 2246822519u;
  h = (h ^ (h >> 13)) * 1274126177u;
  h ^= h >> 16;
  return (h & 0xffffu) / 65535.0;
}

double value_noise(double x, double y, std::uint32_t seed) {
  const int xi = static_cast<int>(std::floor(x));
  const int yi = static_cast<int>(std::floor(y));
  const double fx = x - xi, fy = y - yi;
  const double sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
  const double a = lattice(xi, yi, seed), b = lattice(xi + 1, yi, seed);
  const double c = lattice(xi, yi + 1, seed), d = lattice(xi + 1, yi + 1, seed);
  return (a + (b - a) * sx) * (1 - sy) + (c + (d - c) * sx) * sy;
}

// Ridged multifractal mountains rising from a lake in the south-west corner of N45E006.
// (row, col): samples from N45E006's north-west corner, row south, col east; rows north of
// that tile are negative.
float sample_height(int row, int col) {
  const double u = col / 1200.0, v = row / 1200.0;
  double amp = 1.0, freq = 4.0, sum = 0.0, norm = 0.0;
  for (std::uint32_t octave = 0; octave < 7; ++octave) {
    const double n = 1.0 - std::abs(2.0 * value_noise(u * freq, v * freq, octave + 1) - 1.0);
    sum += amp * n * n;
    norm += amp;
    amp *= 0.5;
    freq *= 2.0;
  }
  const double lake = std::hypot(u - 0.25, v - 0.75) / 0.2;  // 0 at the lake's centre
  const double rise = std::clamp(lake, 0.0, 1.0);
  const double h = 2600.0 * (sum / norm) * rise * rise + 420.0 * rise - 60.0;
  return static_cast<float>(std::max(0.0, std::round(h)));
}

}  // namespace

std::vector<std::filesystem::path> write_sample_dem(const std::filesystem::path& dir, int rows, int cols, bool force) {
  if (rows < 1 || rows > 8 || cols < 1 || cols > 8) throw std::invalid_argument("--tiles: at most 8x8 tiles");
  std::filesystem::create_directories(dir);
  std::vector<std::filesystem::path> written;
  for (int tr = 0; tr < rows; ++tr)
    for (int tc = 0; tc < cols; ++tc) {
      io::Grid g;
      g.allocate(1201, 1201);
      const int row0 = -1200 * tr, col0 = 1200 * tc;  // neighbours share their edge samples
      for (int r = 0; r < 1201; ++r)
        for (int c = 0; c < 1201; ++c) g.heights[g.index(r, c)] = sample_height(row0 + r, col0 + c);
      // A small void patch, so that void reporting and filling show on the bundled data.
      for (int r = 300; r < 306; ++r)
        for (int c = 800; c < 806; ++c) g.mask[g.index(r, c)] = io::Sample::kVoid;
      const auto path = dir / (io::srtm_tile_name(45 + tr, 6 + tc) + ".hgt");
      write_file_atomically(path, io::encode_srtm(g), force);
      written.push_back(path);
    }
  return written;
}

}  // namespace terravol::app::output
