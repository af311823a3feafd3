// SPLAT! files, -ano stacking and runs (splat.h). The file formats are those of the splat(1)
// manual of SPLAT! 1.4.2 (J. A. Magliacane, KD2BD): "SITE LOCATION (QTH) FILES", "IRREGULAR
// TERRAIN MODEL PARAMETER (LRP) FILES" and "EXPORTING AND IMPORTING REGIONAL CONTOUR DATA".
// What the -ano points are follows SPLAT!'s PlotLRMap() and PlotLRPath() (splat.cpp): paths
// run from the transmitter to every cell on the edge of the loaded region, out to the -R
// range; along each, from its third point on (so the transmitter's cell and its neighbours
// get no value), a point is computed and written only if no earlier path has marked its SDF
// cell, at the position along the path rather than at the cell's centre: hence the rounding
// to SPLAT!'s grid in stack_ano(), where a few points per 100,000 round onto a cell another
// point already took. Which tiles SPLAT! loads follows its main(): a "ball park" box of
// range_miles / 57 degrees of latitude (and that / cos(latitude) of longitude) around the
// transmitter (capped by its page count, irrelevant at the radii used here).
#include "volume/splat.h"

#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <future>
#include <iterator>
#include <limits>
#include <map>
#include <stdexcept>
#include <thread>
#include <utility>

#include "io/compressed.h"
#include "io/dem_file.h"
#include "io/error.h"
#include "io/sdf_name.h"
#include "volume/text.h"

namespace terravol::volume {

namespace {

using text::for_each_line;
using text::quote_token;
using text::split_on;
using text::split_whitespace;
using text::strip_comment;
using text::to_number;
using text::trim;

constexpr double kSplatDipoleGainDbi = 2.14;  // SPLAT!'s own (PlotLRPath: "ERP + 2.14")
constexpr double kFeet = 0.3048;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

double wrap180(double lon) {
  double v = std::fmod(lon + 180.0, 360.0);
  if (v < 0.0) v += 360.0;
  return v - 180.0;
}

double wrap360(double lon) {
  double v = std::fmod(lon, 360.0);
  if (v < 0.0) v += 360.0;
  return v >= 360.0 ? 0.0 : v;
}

std::string lower(std::string_view s) {
  std::string r(s);
  std::transform(r.begin(), r.end(), r.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return r;
}

// "D", or "D M S" (a minus sign on D applies to all three).
std::optional<double> parse_angle(std::string_view text) {
  const auto parts = split_whitespace(trim(text));
  if (parts.size() == 1) return to_number(parts[0]);
  if (parts.size() != 3) return std::nullopt;
  const auto d = to_number(parts[0]), m = to_number(parts[1]), s = to_number(parts[2]);
  if (!d || !m || !s || *m < 0.0 || *m >= 60.0 || *s < 0.0 || *s >= 60.0) return std::nullopt;
  const bool negative = parts[0].front() == '-';
  const double v = std::abs(*d) + *m / 60.0 + *s / 3600.0;
  return negative ? -v : v;
}

}  // namespace

SplatSite parse_qth(std::string_view text, const std::string& source) {
  std::vector<std::pair<std::size_t, std::string_view>> lines;
  for_each_line(text, [&](std::size_t n, std::string_view line) {
    line = trim(line);
    if (lines.empty() && line.empty()) return;  // blank lines before the name
    lines.emplace_back(n, line);
  });
  if (lines.size() < 4) {
    throw io::FormatError(source,
                          "expected 4 lines (name, latitude, longitude, antenna height), found " +
                              std::to_string(lines.size()));
  }
  auto bad = [&](int k, const std::string& what) {
    throw io::FormatError(source, "line " + std::to_string(lines[k].first) + ": " + what);
  };
  SplatSite site;
  site.name = std::string(lines[0].second);
  if (site.name.empty()) bad(0, "empty site name");
  const auto lat = parse_angle(lines[1].second);
  if (!lat)
    bad(1, "latitude " + quote_token(lines[1].second) + " is not a number of degrees (or D M S)");
  if (std::abs(*lat) > 90.0) bad(1, "latitude " + num(*lat) + " is outside [-90, 90]");
  const auto west = parse_angle(lines[2].second);
  if (!west)
    bad(2, "longitude " + quote_token(lines[2].second) + " is not a number of degrees (or D M S)");
  if (std::abs(*west) > 360.0) bad(2, "longitude " + num(*west) + " is outside [-360, 360]");
  site.lat = *lat;
  site.lon = wrap180(-*west);

  // The height: a number, then nothing (feet) or a unit.
  const std::string_view h = lines[3].second;
  std::size_t k = 0;
  while (k < h.size() && (std::isdigit(static_cast<unsigned char>(h[k])) || h[k] == '.' ||
                          h[k] == '-' || h[k] == '+' || h[k] == 'e' || h[k] == 'E')) {
    // an 'e' only as an exponent: followed by a digit or sign
    if ((h[k] == 'e' || h[k] == 'E') &&
        !(k + 1 < h.size() && (std::isdigit(static_cast<unsigned char>(h[k + 1])) ||
                               h[k + 1] == '-' || h[k + 1] == '+'))) {
      break;
    }
    ++k;
  }
  const auto height = to_number(h.substr(0, k));
  if (!height) bad(3, "antenna height " + quote_token(h) + " is not a number");
  const std::string unit = lower(trim(h.substr(k)));
  double scale = kFeet;
  if (unit == "m" || unit == "meters" || unit == "metres" || unit == "meter" || unit == "metre") {
    scale = 1.0;
  } else if (!(unit.empty() || unit == "ft" || unit == "feet" || unit == "foot")) {
    bad(3, "antenna height unit " + quote_token(unit) + " is neither m (meters) nor feet");
  }
  site.height_agl_m = *height * scale;
  if (site.height_agl_m < 0.0 || site.height_agl_m > 100000.0) {
    bad(3, "antenna height " + num(site.height_agl_m) + " m is outside [0, 100000] m");
  }
  return site;
}

std::string format_qth(const SplatSite& site) {
  std::string name = site.name.empty() ? "tx" : site.name;
  std::replace(name.begin(), name.end(), '\n', ' ');
  std::replace(name.begin(), name.end(), '\r', ' ');
  char b[160];
  std::snprintf(b, sizeof b, "%.7f\n%.7f\n%.3f m\n", site.lat, wrap360(-site.lon),
                site.height_agl_m);
  return name + "\n" + b;
}

SplatLrp parse_lrp(std::string_view text, const std::string& source) {
  std::vector<double> v;
  for_each_line(text, [&](std::size_t n, std::string_view line) {
    if (v.size() >= 9) return;
    const auto parts = split_whitespace(strip_comment(line));
    if (parts.empty()) return;
    const auto x = to_number(parts[0]);
    if (!x)
      throw io::FormatError(
          source, "line " + std::to_string(n) + ": " + quote_token(parts[0]) + " is not a number");
    v.push_back(*x);
  });
  if (v.size() < 8) {
    throw io::FormatError(
        source,
        "expected 8 or 9 values (dielectric constant, conductivity, bending, frequency, "
        "climate, polarization, fractions of situations and time[, ERP]), found " +
            std::to_string(v.size()));
  }
  auto bad = [&](const std::string& what, double x, const std::string& range) {
    throw io::FormatError(source, what + " " + num(x) + " is outside " + range);
  };
  SplatLrp l;
  if (!(v[0] > 0.0 && v[0] <= 1000.0)) bad("dielectric constant", v[0], "(0, 1000]");
  if (!(v[1] > 0.0 && v[1] <= 1000.0)) bad("conductivity", v[1], "(0, 1000] S/m");
  if (!(v[2] >= 0.0 && v[2] <= 1000.0))
    bad("atmospheric bending constant", v[2], "[0, 1000] N-units");
  if (!(v[3] >= 20.0 && v[3] <= 20000.0)) bad("frequency", v[3], "SPLAT!'s [20, 20000] MHz");
  if (!(v[4] >= 1.0 && v[4] <= 7.0 && v[4] == std::floor(v[4])))
    bad("radio climate", v[4], "{1, ..., 7}");
  if (!(v[5] == 0.0 || v[5] == 1.0)) bad("polarization", v[5], "{0, 1}");
  if (!(v[6] > 0.0 && v[6] < 1.0)) bad("fraction of situations", v[6], "(0, 1)");
  if (!(v[7] > 0.0 && v[7] < 1.0)) bad("fraction of time", v[7], "(0, 1)");
  l.dielectric = v[0];
  l.conductivity = v[1];
  l.bending = v[2];
  l.frequency_mhz = v[3];
  l.climate = static_cast<int>(v[4]);
  l.polarization = static_cast<int>(v[5]);
  l.situations = v[6];
  l.time = v[7];
  if (v.size() == 9) {
    if (!(v[8] >= 0.0 && v[8] <= 1e9)) bad("ERP", v[8], "[0, 1e9] W");
    if (v[8] > 0.0) l.erp_w = v[8];
  }
  return l;
}

std::string format_lrp(const SplatLrp& l) {
  char b[600];
  std::snprintf(b, sizeof b,
                "%.3f ; Earth Dielectric Constant (Relative permittivity)\n"
                "%.6f ; Earth Conductivity (Siemens per meter)\n"
                "%.3f ; Atmospheric Bending Constant (N-units)\n"
                "%.6f ; Frequency in MHz (20 MHz to 20 GHz)\n"
                "%d ; Radio Climate (5 = Continental Temperate)\n"
                "%d ; Polarization (0 = Horizontal, 1 = Vertical)\n"
                "%.4f ; Fraction of situations (of locations)\n"
                "%.4f ; Fraction of time\n",
                l.dielectric, l.conductivity, l.bending, l.frequency_mhz, l.climate, l.polarization,
                l.situations, l.time);
  return b;
}

AnoMap parse_ano(std::string_view text, const std::string& source) {
  AnoMap map;
  map.source = source;
  int header = 0;
  bool wraps = false;
  double min_w = 0.0, max_w = 0.0;
  constexpr double kTolerance = 0.01;
  for_each_line(text, [&](std::size_t n, std::string_view line) {
    const std::string_view body = strip_comment(line);
    if (body.empty()) return;
    auto bad = [&](const std::string& what) {
      throw io::FormatError(source, "line " + std::to_string(n) + ": " + what);
    };
    const auto fields = split_on(body, ',');
    if (header < 2) {
      const char* what = header == 0 ? "MAX_WEST, MIN_WEST" : "MAX_NORTH, MIN_NORTH";
      if (fields.size() != 2)
        bad(std::string("expected the header line ") + what + ", found " + quote_token(body));
      const auto a = to_number(fields[0]), b = to_number(fields[1]);
      if (!a || !b)
        bad(std::string("header ") + what + ": " + quote_token(body) + " are not two numbers");
      if (header == 0) {
        if (std::abs(*a) > 360.0 || std::abs(*b) > 360.0)
          bad("header longitudes outside [-360, 360]");
        map.max_west = *a;
        map.min_west = *b;
        min_w = wrap360(*b);
        max_w = wrap360(*a);
        wraps = max_w < min_w;
      } else {
        if (std::abs(*a) > 90.0 || std::abs(*b) > 90.0 || *a < *b)
          bad("header latitudes: need -90 <= MIN <= MAX <= 90");
        map.max_north = *a;
        map.min_north = *b;
      }
      ++header;
      return;
    }
    if (fields.size() != 5) {
      bad("expected LAT, LON, AZIMUTH, ELEVATION, VALUE[ *], found " +
          std::to_string(fields.size()) + " fields");
    }
    AnoPoint p;
    std::string_view last = trim(fields[4]);
    if (!last.empty() && last.back() == '*') {
      p.obstructed = true;
      last.remove_suffix(1);
    }
    static const char* names[] = {"latitude", "longitude", "azimuth", "elevation", "value"};
    double v[5];
    for (int f = 0; f < 5; ++f) {
      const auto x = to_number(f == 4 ? last : fields[static_cast<std::size_t>(f)]);
      if (!x)
        bad(std::string(names[f]) + " " +
            quote_token(trim(f == 4 ? last : fields[static_cast<std::size_t>(f)])) +
            " is not a number");
      v[f] = *x;
    }
    if (std::abs(v[0]) > 90.0) bad("latitude " + num(v[0]) + " is outside [-90, 90]");
    if (std::abs(v[1]) > 360.0) bad("longitude " + num(v[1]) + " is outside [-360, 360]");
    if (v[0] < map.min_north - kTolerance || v[0] > map.max_north + kTolerance) {
      bad("latitude " + num(v[0]) + " is outside the header's " + num(map.min_north) + ".." +
          num(map.max_north));
    }
    const double w = wrap360(v[1]);
    if (!wraps && (w < min_w - kTolerance || w > max_w + kTolerance)) {
      bad("longitude " + num(v[1]) + " W is outside the header's " + num(map.min_west) + ".." +
          num(map.max_west) + " W");
    }
    if (std::abs(v[4]) > std::numeric_limits<float>::max())
      bad("value " + num(v[4]) + " is too large");
    p.lat = v[0];
    p.lon = wrap180(-v[1]);
    p.azimuth_deg = v[2];
    p.elevation_deg = v[3];
    p.value = static_cast<float>(v[4]);
    map.points.push_back(p);
  });
  if (header < 2)
    throw io::FormatError(source, "no header (MAX_WEST, MIN_WEST and MAX_NORTH, MIN_NORTH lines)");
  if (map.points.empty()) throw io::FormatError(source, "no points");
  return map;
}

AnoStack stack_ano(const std::vector<AnoLayer>& layers, int cells_per_degree) {
  if (layers.empty()) throw std::invalid_argument("stack_ano: no layers");
  if (cells_per_degree < 1 || cells_per_degree > 36000) {
    throw std::invalid_argument("stack_ano: cells_per_degree " + std::to_string(cells_per_degree) +
                                " is outside [1, 36000]");
  }
  for (std::size_t n = 0; n < layers.size(); ++n) {
    const double h = layers[n].height_agl_m;
    if (!layers[n].map)
      throw std::invalid_argument("stack_ano: layer " + std::to_string(n) + " has no map");
    if (!std::isfinite(h) || h < 0.0)
      throw std::invalid_argument("stack_ano: height " + num(h) + " m is not >= 0");
    if (n > 0 && h <= layers[n - 1].height_agl_m)
      throw std::invalid_argument("stack_ano: heights must increase");
    if (n > 1 && std::abs((h - layers[n - 1].height_agl_m) -
                          (layers[1].height_agl_m - layers[0].height_agl_m)) > 1e-6) {
      throw std::invalid_argument("stack_ano: heights must be evenly spaced (a regular lattice)");
    }
  }
  const double c = cells_per_degree;
  // Longitudes unwrapped about the first point, so a map across the antimeridian stays whole.
  const double lon0 = layers[0].map->points.front().lon;
  auto unwrap = [&](double lon) { return lon0 + wrap180(lon - lon0); };
  long long i_lo = std::numeric_limits<long long>::max(),
            i_hi = std::numeric_limits<long long>::min();
  long long j_lo = i_lo, j_hi = i_hi;
  for (const auto& layer : layers) {
    for (const auto& p : layer.map->points) {
      const long long i = std::llround(unwrap(p.lon) * c), j = std::llround(p.lat * c);
      i_lo = std::min(i_lo, i);
      i_hi = std::max(i_hi, i);
      j_lo = std::min(j_lo, j);
      j_hi = std::max(j_hi, j);
    }
  }
  const long long nx = i_hi - i_lo + 1, ny = j_hi - j_lo + 1,
                  nz = static_cast<long long>(layers.size());
  if (static_cast<double>(nx) * static_cast<double>(ny) * static_cast<double>(nz) >
      static_cast<double>(kMaxPoints)) {
    throw io::FormatError(layers[0].map->source, "the points span " + std::to_string(nx) + " x " +
                                                     std::to_string(ny) + " cells x " +
                                                     std::to_string(nz) +
                                                     " heights: more than 2^28 lattice points");
  }

  AnoStack out;
  Volume& v = out.path_loss;
  v.name = "path_loss_db";
  v.units = "dB";
  v.frame.kind = FrameKind::kGeographic;
  v.frame.height = HeightRef::kGround;
  Lattice& l = v.lattice;
  l.dims = {static_cast<int>(nx), static_cast<int>(ny), static_cast<int>(nz)};
  l.origin = {static_cast<double>(i_lo) / c, static_cast<double>(j_lo) / c, layers[0].height_agl_m};
  l.spacing = {1.0 / c, 1.0 / c, nz > 1 ? layers[1].height_agl_m - layers[0].height_agl_m : 1.0};
  v.values.assign(l.size(), kNaN);
  v.background = kNaN;
  v.active_points = l.size();
  v.attributes["splat_cells_per_degree"] = std::to_string(cells_per_degree);
  v.attributes["splat_unreported"] =
      "NaN marks lattice points SPLAT! reported no value for (outside its radius, between its "
      "radials)";

  // Per lattice point of a layer: the squared distance (in cells) of the point kept there.
  std::vector<float> kept_distance;
  std::vector<char> kept_obstructed;
  for (std::size_t k = 0; k < layers.size(); ++k) {
    kept_distance.assign(static_cast<std::size_t>(nx * ny), std::numeric_limits<float>::infinity());
    kept_obstructed.assign(static_cast<std::size_t>(nx * ny), 0);
    for (const auto& p : layers[k].map->points) {
      const double x = unwrap(p.lon) * c, y = p.lat * c;
      const long long i = std::llround(x), j = std::llround(y);
      const auto cell = static_cast<std::size_t>((j - j_lo) * nx + (i - i_lo));
      const auto d =
          static_cast<float>((x - static_cast<double>(i)) * (x - static_cast<double>(i)) +
                             (y - static_cast<double>(j)) * (y - static_cast<double>(j)));
      if (std::isinf(kept_distance[cell])) {
        ++out.reported;
      } else {
        ++out.duplicates;
        if (!(d < kept_distance[cell])) continue;
      }
      kept_distance[cell] = d;
      kept_obstructed[cell] = p.obstructed ? 1 : 0;
      v.values[l.index(static_cast<int>(i - i_lo), static_cast<int>(j - j_lo),
                       static_cast<int>(k))] = p.value;
    }
    for (const char o : kept_obstructed) out.obstructed += static_cast<std::size_t>(o);
  }
  return out;
}

// ---- running SPLAT! ----

namespace {

// A temporary folder, removed with everything in it when this goes out of scope.
class WorkFolder {
 public:
  explicit WorkFolder(const std::filesystem::path& root) {
    const auto base = root.empty() ? std::filesystem::temp_directory_path() : root;
    std::string pattern = (base / "terravol-splat-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error(base.string() + ": cannot create a temporary folder (" +
                               std::strerror(errno) + ")");
    }
    path_ = pattern;
  }
  ~WorkFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  WorkFolder(const WorkFolder&) = delete;
  WorkFolder& operator=(const WorkFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

std::string slurp(const std::filesystem::path& path, bool& ok) {
  std::ifstream in(path, std::ios::binary);
  ok = static_cast<bool>(in);
  if (!ok) return {};
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ok = !in.bad();
  return s;
}

void write_text(const std::filesystem::path& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
}

// The last line with anything printable in SPLAT!'s output, trimmed to 160 characters.
std::string last_line(const std::string& log) {
  std::string best;
  for_each_line(log, [&](std::size_t, std::string_view line) {
    line = trim(line);
    bool printable = false;
    for (char ch : line) printable = printable || std::isalnum(static_cast<unsigned char>(ch));
    if (printable) best = std::string(line.substr(0, 160));
  });
  return best.empty() ? "(it printed nothing)" : "\"" + best + "\"";
}

struct TileFile {
  std::filesystem::path path;
  bool compressed = false;
};

// SPLAT!'s name of the tile with this south-west corner: "S:S+1:WMIN:WMAX.sdf", west-positive.
std::string colon_name(int south, int west) {
  const int wmin = static_cast<int>(wrap360(-(west + 1.0))), wmax = (wmin + 1) % 360;
  return std::to_string(south) + ":" + std::to_string(south + 1) + ":" + std::to_string(wmin) +
         ":" + std::to_string(wmax) + ".sdf";
}

std::map<std::pair<int, int>, TileFile> list_tiles(const std::filesystem::path& folder) {
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    throw std::runtime_error(folder.string() + ": not a folder");
  std::map<std::pair<int, int>, TileFile> tiles;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = lower(entry.path().filename().string());
    if (io::format_from_name(name) != io::Format::kSdf || name.find("-hd") != std::string::npos)
      continue;  // splat-hd tiles: not ours
    const bool plain = io::compression_from_name(name) == io::Compression::kNone;
    const auto corner = io::sdf_corner_from_name(name);
    if (!corner) continue;
    auto [it, inserted] =
        tiles.try_emplace({corner->south, corner->west}, TileFile{entry.path(), !plain});
    if (!inserted && it->second.compressed && plain)
      it->second = TileFile{entry.path(), false};  // prefer .sdf
  }
  if (ec) throw std::runtime_error(folder.string() + ": cannot list (" + ec.message() + ")");
  return tiles;
}

// Tiles (south, west) intersecting lat +- dlat, lon +- dlon.
std::vector<std::pair<int, int>> tiles_around(double lat, double lon, double dlat, double dlon) {
  std::vector<std::pair<int, int>> out;
  const int s0 = static_cast<int>(std::floor(lat - dlat)),
            s1 = static_cast<int>(std::floor(lat + dlat));
  const int w0 = static_cast<int>(std::floor(lon - dlon)),
            w1 = static_cast<int>(std::floor(lon + dlon));
  for (int s = std::max(s0, -90); s <= std::min(s1, 89); ++s) {
    for (int w = w0; w <= w1; ++w) out.emplace_back(s, static_cast<int>(wrap180(w)));
  }
  return out;
}

void place_tile(const TileFile& tile, const std::filesystem::path& target) {
  if (!tile.compressed) {
    std::error_code ec;
    std::filesystem::create_symlink(std::filesystem::absolute(tile.path), target, ec);
    if (!ec) return;
    std::filesystem::copy_file(tile.path, target, ec);
    if (ec) throw std::runtime_error(tile.path.string() + ": cannot copy (" + ec.message() + ")");
    return;
  }
  const auto data = io::read_content(tile.path);
  write_text(target, std::string_view(reinterpret_cast<const char*>(data.data()), data.size()));
}

struct ChildOutcome {
  bool started = false;
  std::string start_error;
  bool timed_out = false;
  int status = 0;  // waitpid's status
};

ChildOutcome run_child(const std::vector<std::string>& args, const std::filesystem::path& folder,
                       const std::filesystem::path& log, double timeout_seconds) {
  ChildOutcome outcome;
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const std::string dir = folder.string(), log_path = log.string();
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
    outcome.start_error = std::string("cannot create a pipe (") + std::strerror(errno) + ")";
    return outcome;
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    outcome.start_error = std::string("cannot fork (") + std::strerror(errno) + ")";
    ::close(pipe_fds[0]);
    ::close(pipe_fds[1]);
    return outcome;
  }
  if (pid == 0) {
    // The child: async-signal-safe calls only. Its own process group, so a timeout kills all.
    ::setpgid(0, 0);
    ::close(pipe_fds[0]);
    int err = 0;
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || ::chdir(dir.c_str()) != 0 || ::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 ||
        ::dup2(out, 2) < 0) {
      err = errno;
    } else {
      ::execv(argv[0], argv.data());
      err = errno;
    }
    [[maybe_unused]] const auto n = ::write(pipe_fds[1], &err, sizeof err);
    ::_exit(127);
  }
  ::close(pipe_fds[1]);
  int child_errno = 0;
  ssize_t got;
  do {
    got = ::read(pipe_fds[0], &child_errno, sizeof child_errno);
  } while (got < 0 && errno == EINTR);
  ::close(pipe_fds[0]);
  if (got == static_cast<ssize_t>(sizeof child_errno)) {
    ::waitpid(pid, nullptr, 0);
    outcome.start_error = std::strerror(child_errno);
    return outcome;
  }
  outcome.started = true;
  const auto t0 = std::chrono::steady_clock::now();
  while (true) {
    const pid_t r = ::waitpid(pid, &outcome.status, WNOHANG);
    if (r == pid) return outcome;
    if (r < 0 && errno != EINTR) {
      outcome.start_error = std::string("cannot wait for it (") + std::strerror(errno) + ")";
      outcome.started = false;
      return outcome;
    }
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >
        timeout_seconds) {
      ::kill(-pid, SIGKILL);
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &outcome.status, 0);
      outcome.timed_out = true;
      return outcome;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

std::string splat_version(const std::string& log) {
  const std::size_t at = log.find("SPLAT! v");
  if (at == std::string::npos) return {};
  std::size_t end = at + 8;
  while (end < log.size() &&
         (std::isdigit(static_cast<unsigned char>(log[end])) || log[end] == '.'))
    ++end;
  return log.substr(at + 8, end - at - 8);
}

}  // namespace

SplatRunResult run_splat(const SplatRunOptions& o) {
  if (o.heights_agl.empty()) throw std::invalid_argument("run_splat: no receiver heights");
  for (const double h : o.heights_agl) {
    if (!(h >= 0.0 && h <= 100000.0))
      throw std::invalid_argument("run_splat: height " + num(h) + " m is outside [0, 100000]");
  }
  if (!(o.radius_km > 0.0 && o.radius_km <= 1000.0)) {
    throw std::invalid_argument("run_splat: radius " + num(o.radius_km) +
                                " km is outside (0, 1000]");
  }
  if (!(o.timeout_seconds > 0.0))
    throw std::invalid_argument("run_splat: the timeout must be > 0 s");
  if (!(o.lrp.frequency_mhz >= 20.0 && o.lrp.frequency_mhz <= 20000.0)) {
    throw std::invalid_argument("run_splat: frequency " + num(o.lrp.frequency_mhz) +
                                " MHz is outside SPLAT!'s [20, 20000] MHz");
  }
  if (!(std::abs(o.site.lat) <= 89.0))
    throw std::invalid_argument("run_splat: latitude " + num(o.site.lat) + " is outside [-89, 89]");
  const std::string exe = o.executable.string();
  if (::access(exe.c_str(), X_OK) != 0) {
    throw std::runtime_error(
        exe +
        ": not found or not executable (install the Debian package splat, or give --splat PATH)");
  }

  // The tiles: every one the disc touches must be there; SPLAT! also gets the others of its
  // ball-park box that the folder has.
  const auto tiles = list_tiles(o.sdf_folder);
  const double coslat = std::cos(o.site.lat * M_PI / 180.0);
  const double need_lat = o.radius_km / 110.574, need_lon = o.radius_km / (111.320 * coslat);
  for (const auto& t : tiles_around(o.site.lat, o.site.lon, need_lat, need_lon)) {
    if (tiles.contains(t)) continue;
    const int wmin = static_cast<int>(wrap360(-(t.second + 1.0)));
    throw std::runtime_error(
        o.sdf_folder.string() + ": no SDF tile for " + std::to_string(t.first) + ".." +
        std::to_string(t.first + 1) + " N, " + std::to_string(t.second) + ".." +
        std::to_string(t.second + 1) + " E (" + colon_name(t.first, t.second) + " or " +
        std::to_string(t.first) + "_" + std::to_string(t.first + 1) + "_" + std::to_string(wmin) +
        "_" + std::to_string((wmin + 1) % 360) + ".sdf, plain or compressed), which the " + num(o.radius_km) +
        " km disc around the transmitter needs (SPLAT! would take it as sea level)");
  }
  const double load_lat = o.radius_km / 1.609344 / 57.0 + 1e-6, load_lon = load_lat / coslat;
  std::vector<std::pair<int, int>> load;
  for (const auto& t : tiles_around(o.site.lat, o.site.lon, load_lat, load_lon)) {
    if (tiles.contains(t)) load.push_back(t);
  }

  WorkFolder work(o.work_root);
  SplatRunResult result;
  {
    std::vector<std::future<void>> jobs;
    for (const auto& t : load) {
      const TileFile& file = tiles.at(t);
      result.tiles.push_back(file.path.filename().string());
      const auto target = work.path() / colon_name(t.first, t.second);
      jobs.push_back(std::async(std::launch::async, [file, target] { place_tile(file, target); }));
    }
    std::exception_ptr first;
    for (auto& j : jobs) {
      try {
        j.get();
      } catch (...) {
        if (!first) first = std::current_exception();
      }
    }
    if (first) std::rethrow_exception(first);
  }
  SplatSite site = o.site;
  for (char& ch : site.name) {
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '_' && ch != '.')
      ch = '_';
  }
  if (site.name.empty() || site.name.front() == '.') site.name = "tx" + site.name;
  write_text(work.path() / "tx.qth", format_qth(site));
  write_text(work.path() / "tx.lrp", format_lrp(o.lrp));
  // With a pattern, SPLAT! reports power (dBm) for an ERP; without, path loss (-erp 0).
  const double run_erp_w = o.antenna ? o.lrp.erp_w.value_or(1.0) : 0.0;
  if (o.antenna) {
    if (o.antenna->azimuth) write_text(work.path() / "tx.az", splat_az_text(*o.antenna));
    if (o.antenna->elevation) write_text(work.path() / "tx.el", splat_el_text(*o.antenna));
  }

  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t n = 0; n < o.heights_agl.size(); ++n) {
    const std::string h = num(o.heights_agl[n]);
    const std::string ano = "rx-" + std::to_string(n) + ".ano",
                      log_name = "splat-" + std::to_string(n) + ".log";
    std::vector<std::string> args = {exe, "-t", "tx.qth", "-L", h, "-R", num(o.radius_km), "-metric",
                                     "-erp", num(run_erp_w), "-ano", ano};
    if (o.antenna) args.push_back("-dbm");
    if (o.olditm) args.push_back("-olditm");
    const std::string what = "splat -L " + h;
    const ChildOutcome c = run_child(args, work.path(), work.path() / log_name, o.timeout_seconds);
    if (!c.started) throw std::runtime_error(exe + ": cannot run (" + c.start_error + ")");
    bool ok = false;
    const std::string log = slurp(work.path() / log_name, ok);
    if (c.timed_out) {
      throw std::runtime_error(what + ": no result after " + num(o.timeout_seconds) +
                               " s (killed; raise --timeout)");
    }
    if (WIFSIGNALED(c.status)) {
      throw std::runtime_error(what + ": killed by signal " + std::to_string(WTERMSIG(c.status)) +
                               " (" + strsignal(WTERMSIG(c.status)) + "); it last printed " +
                               last_line(log));
    }
    if (!WIFEXITED(c.status) || WEXITSTATUS(c.status) != 0) {
      throw std::runtime_error(what + ": failed with exit status " +
                               std::to_string(WEXITSTATUS(c.status)) + "; it last printed " +
                               last_line(log));
    }
    if (result.version.empty()) result.version = splat_version(log);
    std::string text = slurp(work.path() / ano, ok);
    if (!ok || text.empty())
      throw std::runtime_error(what + ": wrote no -ano file; it last printed " + last_line(log));
    result.maps.push_back(parse_ano(text, what + " output"));
    if (o.antenna) {
      // Inverts SPLAT!'s dBm = 10 log10(1000 ERP / 10^((loss - 2.14) / 10)).
      const double eirp_dbm = 10.0 * std::log10(run_erp_w * 1000.0) + kSplatDipoleGainDbi;
      for (AnoPoint& p : result.maps.back().points) p.value = static_cast<float>(eirp_dbm - p.value);
    }
    if (o.keep_ano_texts) result.ano_texts.push_back(std::move(text));
    if (o.progress) o.progress(n + 1);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace terravol::volume
