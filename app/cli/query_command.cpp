// `terravol query --volume V.vdb [--field F] --dem DEM... (--points FILE.csv | --at LAT,LON,AGL)`:
// each point's ground height and the volume's value there (volume/point_query.h), as CSV.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/cli/commands.h"
#include "app/output/write_file.h"
#include "io/mosaic.h"
#include "volume/point_query.h"
#include "volume/propagation.h"
#include "volume/readers.h"

namespace terravol::app::cli {

namespace {

constexpr std::size_t kMaxPoints = 10'000'000;

struct QueryOptions {
  std::filesystem::path volume, points, output;
  std::string field, frame;
  std::vector<std::string> at;
  std::vector<std::filesystem::path> dems;
  bool force = false;
};

struct Point {
  double lat = 0.0, lon = 0.0, agl = 0.0;
};

bool to_number(const std::string& text, double& out) {
  std::size_t a = text.find_first_not_of(" \t"), b = text.find_last_not_of(" \t\r");
  if (a == std::string::npos) return false;
  const std::string t = text.substr(a, b - a + 1);
  char* end = nullptr;
  out = std::strtod(t.c_str(), &end);
  return *end == '\0' && std::isfinite(out);
}

// "LAT,LON,AGL": nullopt when the first field is not a number (a header), else the point or an
// error message in `error`.
std::optional<Point> parse_point(const std::string& line, std::string& error) {
  std::vector<std::string> f;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = line.find(',', start);
    f.push_back(line.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  double v[3];
  if (!to_number(f[0], v[0])) {
    error = "'" + f[0] + "' is not a latitude";
    return std::nullopt;
  }
  if (f.size() != 3) {
    error = "expected LAT,LON,HEIGHT_AGL, found " + std::to_string(f.size()) + " fields";
    return std::nullopt;
  }
  for (int n = 1; n < 3; ++n) {
    if (!to_number(f[static_cast<std::size_t>(n)], v[n])) {
      error = "'" + f[static_cast<std::size_t>(n)] + "' is not a number";
      return std::nullopt;
    }
  }
  if (std::abs(v[0]) > 90.0) error = "latitude must be within [-90, 90] degrees";
  else if (std::abs(v[1]) > 360.0) error = "longitude must be within [-360, 360] degrees";
  else if (v[2] < -1000.0 || v[2] > 100000.0) error = "height must be within [-1000, 100000] m above ground";
  if (!error.empty()) return std::nullopt;
  return Point{v[0], v[1], v[2]};
}

std::vector<Point> read_points(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("--points " + path.string() + ": cannot read");
  std::vector<Point> points;
  std::string line;
  bool first = true;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::size_t a = line.find_first_not_of(" \t\r");
    if (a == std::string::npos || line[a] == '#') continue;
    std::string error;
    const auto p = parse_point(line, error);
    const bool header = first && !p && error.find("is not a latitude") != std::string::npos;
    first = false;
    if (header) continue;
    if (!p) throw std::runtime_error(path.string() + ": line " + std::to_string(n) + ": " + error);
    if (points.size() == kMaxPoints) throw std::runtime_error(path.string() + ": more than 10^7 points");
    points.push_back(*p);
  }
  if (in.bad()) throw std::runtime_error("--points " + path.string() + ": cannot read");
  if (points.empty()) throw std::runtime_error(path.string() + ": no point (lines LAT,LON,HEIGHT_AGL)");
  return points;
}

void run_query(const QueryOptions& o) {
  if (o.points.empty() == o.at.empty()) throw std::runtime_error("give the points: --points FILE.csv or --at LAT,LON,AGL");
  std::vector<Point> points;
  if (!o.points.empty()) points = read_points(o.points);
  for (const auto& a : o.at) {
    std::string error;
    const auto p = parse_point(a, error);
    if (!p) throw std::runtime_error("--at " + a + ": " + error);
    points.push_back(*p);
  }
  if (!o.output.empty()) output::check_output_path(o.output, "-o", "", o.force);
  volume::ReadOptions ro;
  ro.field = o.field;
  if (!o.frame.empty()) {
    try {
      ro.frame = volume::parse_frame(o.frame);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error("--frame " + o.frame + ": " + e.what());
    }
  }
  const volume::Volume v = volume::read_volume(o.volume, ro);
  std::optional<volume::PointQuery> query;
  try {
    query.emplace(v);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(o.volume.string() + ": " + e.what());
  }

  // The ground: the DEM's samples around every point inside it, voids filled (as the model).
  const io::Mosaic mosaic = io::Mosaic::open(o.dems);
  const volume::DemExtent e = volume::dem_extent(mosaic.georef(), mosaic.rows(), mosaic.cols());
  auto inside = [&](const Point& p) { return p.lat >= e.south && p.lat <= e.north && p.lon >= e.west && p.lon <= e.east; };
  volume::DemExtent box{90.0, -90.0, 360.0, -360.0};
  for (const Point& p : points) {
    if (!inside(p)) continue;
    box = {std::min(box.south, p.lat), std::max(box.north, p.lat), std::min(box.west, p.lon), std::max(box.east, p.lon)};
  }
  std::optional<volume::RfWindow> window;
  if (box.south <= box.north) window = volume::read_rf_window(mosaic, box);

  std::string out = "lat,lon,height_agl_m,ground_m," + v.name + (v.units.empty() ? "" : "_" + v.units) + "\n";
  char b[160];
  for (const Point& p : points) {
    const double ground = window && inside(p) ? volume::dem_height(window->grid, p.lat, p.lon)
                                              : std::numeric_limits<double>::quiet_NaN();
    const double value = query->value(p.lat, p.lon, p.agl, ground);
    std::snprintf(b, sizeof b, "%.8f,%.8f,%.3f,%.3f,%.9g\n", p.lat, p.lon, p.agl, ground, value);
    out += b;
  }
  if (o.output.empty()) {
    std::fwrite(out.data(), 1, out.size(), stdout);
  } else {
    output::write_file_atomically(o.output, std::vector<std::uint8_t>(out.begin(), out.end()), o.force);
    std::printf("wrote %s: %zu points\n", o.output.string().c_str(), points.size());
  }
  if (window) {
    for (const auto& n : window->notes) std::fprintf(stderr, "terravol query: note: %s\n", n.c_str());
  }
}

}  // namespace

void add_query_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("query",
                                 "A volume's value and the ground height at points (trilinear between lattice points, "
                                 "NaN outside), as CSV");
  auto o = std::make_shared<QueryOptions>();
  cmd->add_option("--volume", o->volume, "The volume (.vdb, .vti, .vtk)")->required();
  cmd->add_option("--field", o->field, "Its grid or array (default: the first)");
  cmd->add_option("--frame", o->frame, "Its frame when the file has none: geographic, geographic-agl, enu:LAT,LON,H");
  cmd->add_option("--dem", o->dems, "DEM files or folders of tiles, for the ground under the points")->required();
  cmd->add_option("--points", o->points, "A CSV of points, LAT,LON,HEIGHT_AGL per line (a header line may come first)");
  cmd->add_option("--at", o->at, "One point LAT,LON,HEIGHT_AGL (may be repeated)");
  cmd->add_option("-o,--output", o->output, "Write the CSV there instead of stdout");
  cmd->add_flag("--force", o->force, "Replace an existing output file");
  cmd->callback([o] { run_query(*o); });
}

}  // namespace terravol::app::cli
