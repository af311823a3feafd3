// terravol_itm_sampling_bench: how much the built-in ITM's agreement with SPLAT!'s ITM on the
// lattice depends on how the terrain profile is sampled (docs/rf-model.md, "The built-in ITM
// against SPLAT!'s ITM"). A standing measurement, not a test.
//
// For every lattice column where a `splat-volume --olditm` volume has values, the ITM (SPLAT!'s
// default parameters) is run on the profile to that column sampled four ways:
//  - rf: what `terravol rf --model itm` uses (volume::sample_profile: the straight line in
//    latitude and longitude, the DEM's finer spacing in metres, bilinear heights);
//  - half step: the same at half that step;
//  - nearest cell: the same line and step, each sample the height of its nearest DEM cell (as
//    SPLAT! takes its samples, though along its own radials);
//  - reference: the WGS84 geodesic at an eighth of the step, bilinear heights: the profile of
//    the DEM's bilinear surface, to which finer sampling converges.
// and each is compared with SPLAT! and with the reference, per height and distance band:
// points, Pearson's r, median |difference|. SPLAT! against the reference is the last column.
//
// Usage: terravol_itm_sampling_bench --splat SPLAT.vdb --tx LAT,LON[,HEIGHT_AGL[,FREQ_MHZ]] DEM...
// (the transmitter as splat-volume had it; 30 m and 900 MHz by default).
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/GeodesicLine.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "io/mosaic.h"
#include "io/scene_frame.h"
#include "volume/compare.h"
#include "volume/itm.h"
#include "volume/propagation.h"
#include "volume/readers.h"

namespace {

using namespace terravol;
using namespace terravol::volume;

// Heights at equal steps from (lat0, lon0) to (lat1, lon1); the path's length in `distance`.
using Sampler = std::function<void(const io::Grid& dem, double lat0, double lon0, double lat1, double lon1,
                                   double step_m, std::vector<double>& ground, double& distance)>;

double nearest_cell(const io::Grid& g, double lat, double lon) {
  const int c = std::clamp(static_cast<int>(std::lround((lon - g.georef.x0) / g.georef.dx)), 0, g.cols - 1);
  const int r = std::clamp(static_cast<int>(std::lround((g.georef.y0 - lat) / g.georef.dy)), 0, g.rows - 1);
  return g.heights[g.index(r, c)];
}

Sampler rf_sampler(double step_factor) {
  return [step_factor](const io::Grid& g, double lat0, double lon0, double lat1, double lon1, double step_m,
                       std::vector<double>& ground, double& distance) {
    TerrainProfile p;
    sample_profile(g, lat0, lon0, lat1, lon1, step_m * step_factor, p);
    ground = p.ground_m;
    distance = p.distance_m;
  };
}

Sampler nearest_sampler() {
  return [](const io::Grid& g, double lat0, double lon0, double lat1, double lon1, double step_m,
            std::vector<double>& ground, double& distance) {
    GeographicLib::Geodesic::WGS84().Inverse(lat0, lon0, lat1, lon1, distance);
    const int n = std::max(1, static_cast<int>(std::ceil(distance / step_m)));
    ground.resize(static_cast<std::size_t>(n) + 1);
    for (int i = 0; i <= n; ++i) {
      const double t = static_cast<double>(i) / n;
      ground[static_cast<std::size_t>(i)] = nearest_cell(g, lat0 + t * (lat1 - lat0), lon0 + t * (lon1 - lon0));
    }
  };
}

Sampler reference_sampler() {
  return [](const io::Grid& g, double lat0, double lon0, double lat1, double lon1, double step_m,
            std::vector<double>& ground, double& distance) {
    const GeographicLib::GeodesicLine line = GeographicLib::Geodesic::WGS84().InverseLine(lat0, lon0, lat1, lon1);
    distance = line.Distance();
    const int n = std::max(1, static_cast<int>(std::ceil(distance / (step_m / 8.0))));
    ground.resize(static_cast<std::size_t>(n) + 1);
    for (int i = 0; i <= n; ++i) {
      double lat = 0.0, lon = 0.0;
      line.Position(distance * i / n, lat, lon);
      ground[static_cast<std::size_t>(i)] = dem_height(g, lat, lon);
    }
  };
}

std::vector<double> numbers(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  for (std::string field; std::getline(in, field, ',');) v.push_back(std::stod(field));
  return v;
}

int run(int argc, char** argv) {
  std::string splat_path;
  std::vector<double> tx_fields;
  std::vector<std::filesystem::path> dems;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--splat" && a + 1 < argc) {
      splat_path = argv[++a];
    } else if (arg == "--tx" && a + 1 < argc) {
      tx_fields = numbers(argv[++a]);
    } else {
      dems.emplace_back(arg);
    }
  }
  if (splat_path.empty() || tx_fields.size() < 2 || dems.empty()) {
    std::fprintf(stderr, "usage: terravol_itm_sampling_bench --splat SPLAT.vdb --tx LAT,LON[,HEIGHT_AGL[,FREQ_MHZ]] DEM...\n");
    return 2;
  }
  Transmitter tx;
  tx.lat = tx_fields[0];
  tx.lon = tx_fields[1];
  tx.height_agl = tx_fields.size() > 2 ? tx_fields[2] : 30.0;
  tx.frequency_mhz = tx_fields.size() > 3 ? tx_fields[3] : 900.0;
  const Volume splat = read_volume(splat_path);
  const Lattice& l = splat.lattice;
  const int nx = l.dims[0], ny = l.dims[1], nz = l.dims[2];
  std::vector<double> heights;
  for (int k = 0; k < nz; ++k) heights.push_back(l.world(2, k));
  const double radius_km = 0.5 * std::max(nx, ny) * l.spacing[1] * 111.2 + 1.0;  // covers the lattice
  const io::Mosaic mosaic = io::Mosaic::open(dems);
  const RfWindow window = read_rf_window(mosaic, rf_area(tx, radius_km));
  const io::Grid& dem = window.grid;
  const io::SceneFrame frame(tx.lat, tx.lon);
  const double step_m = std::min(dem.georef.dx * frame.metres_per_degree_lon(), dem.georef.dy * frame.metres_per_degree_lat());

  const std::vector<std::pair<std::string, Sampler>> samplers = {
      {"rf", rf_sampler(1.0)}, {"half step", rf_sampler(0.5)}, {"nearest cell", nearest_sampler()}, {"reference", reference_sampler()}};
  std::vector<std::vector<double>> values(samplers.size(), std::vector<double>(l.size(), std::nan("")));
  for (std::size_t s = 0; s < samplers.size(); ++s) {
    tbb::parallel_for(0, ny, [&](int j) {
      ItmPath path(tx.frequency_mhz, ItmParameters{});
      std::vector<double> ground, column(static_cast<std::size_t>(nz));
      for (int i = 0; i < nx; ++i) {
        bool reported = false;
        for (int k = 0; k < nz; ++k) reported = reported || !std::isnan(splat.values[l.index(i, j, k)]);
        if (!reported) continue;
        double distance = 0.0;
        samplers[s].second(dem, tx.lat, tx.lon, l.world(1, j), l.world(0, i), step_m, ground, distance);
        if (distance < 1.0) continue;
        path.set_profile(ground, distance / static_cast<double>(ground.size() - 1), tx.height_agl);
        path.losses(heights, column);
        for (int k = 0; k < nz; ++k) values[s][l.index(i, j, k)] = column[static_cast<std::size_t>(k)];
      }
    });
  }
  std::vector<double> distance_km(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny));
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      double d = 0.0;
      GeographicLib::Geodesic::WGS84().Inverse(tx.lat, tx.lon, l.world(1, j), l.world(0, i), d);
      distance_km[static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * static_cast<std::size_t>(j)] = d / 1000.0;
    }
  }
  const std::vector<double> splat_values(splat.values.begin(), splat.values.end());
  const std::vector<double>& reference = values.back();
  auto compare = [&](const std::vector<double>& a, const std::vector<double>& b, int k, double from_km, double to_km) {
    std::vector<double> x, y;
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const std::size_t o = l.index(i, j, k);
        const double d = distance_km[static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * static_cast<std::size_t>(j)];
        if (d < from_km || d > to_km || std::isnan(splat_values[o]) || std::isnan(a[o]) || std::isnan(b[o])) continue;
        x.push_back(a[o]);
        y.push_back(b[o]);
      }
    }
    return compare_values(x, y, l.world(2, k));
  };
  std::printf("tx %.6f, %.6f, %g m, %g MHz; profile step %.2f m; r and median |difference| (dB) against SPLAT! / against the reference\n",
              tx.lat, tx.lon, tx.height_agl, tx.frequency_mhz, step_m);
  for (const auto& [from_km, to_km] : {std::pair{0.0, 1e9}, std::pair{1.0, 12.5}, std::pair{12.5, 1e9}}) {
    if (to_km < 1e8) {
      std::printf("paths of %.1f to %.1f km\n", from_km, to_km);
    } else {
      std::printf("paths from %.1f km\n", from_km);
    }
    for (int k = 0; k < nz; ++k) {
      std::printf("  %5.0f m:", heights[static_cast<std::size_t>(k)]);
      for (std::size_t s = 0; s < samplers.size(); ++s) {
        const LayerComparison a = compare(values[s], splat_values, k, from_km, to_km);
        const LayerComparison b = compare(values[s], reference, k, from_km, to_km);
        std::printf(" | %s %.3f %.2f / %.3f %.2f", samplers[s].first.c_str(), a.pearson, a.median_abs_difference, b.pearson,
                    b.median_abs_difference);
      }
      const LayerComparison c = compare(splat_values, reference, k, from_km, to_km);
      std::printf(" | SPLAT! against the reference %.3f %.2f (%zu points)\n", c.pearson, c.median_abs_difference, c.points);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "terravol_itm_sampling_bench: %s\n", e.what());
    return 1;
  }
}
