// SPLAT! antenna patterns (antenna.h). The formats are those of the splat(1) manual of SPLAT!
// 1.4.2, "ANTENNA RADIATION PATTERN PARAMETERS"; how SPLAT! combines them follows its LoadPAT()
// (rotation of the azimuth cut, the tilt as an elevation offset linear in azimuth, the product
// of the two cuts) and PlotLRPath() (the loss is reduced by 20 log10 of the product).
#include "volume/antenna.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <stdexcept>

#include "io/error.h"
#include "volume/text.h"

namespace terravol::volume {

namespace {

constexpr double kMinField = 1e-3;  // -60 dB

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

double wrap360(double a) {
  double v = std::fmod(a, 360.0);
  if (v < 0.0) v += 360.0;
  return v >= 360.0 ? 0.0 : v;
}

// The header numbers and the (angle, field) lines of a pattern file.
struct RawPattern {
  std::vector<double> header;
  std::size_t header_line = 0;
  std::map<double, std::pair<double, int>> sums;  // angle -> (sum of fields, count)
};

RawPattern read_lines(std::string_view text, const std::string& source, double lo, double hi,
                      const char* angle_name, std::size_t max_header) {
  RawPattern raw;
  bool have_header = false;
  text::for_each_line(text, [&](std::size_t n, std::string_view line) {
    const std::string_view body = text::strip_comment(line);
    if (body.empty()) return;
    auto bad = [&](const std::string& what) {
      throw io::FormatError(source, "line " + std::to_string(n) + ": " + what);
    };
    const auto fields = text::split_whitespace(body);
    if (!have_header) {
      if (fields.size() > max_header)
        bad("expected " + std::string(max_header == 1 ? "one number" : "one or two numbers") +
            ", found " + std::to_string(fields.size()) + " fields");
      for (const auto f : fields) {
        const auto v = text::to_number(f);
        if (!v) bad(text::quote_token(f) + " is not a number");
        raw.header.push_back(*v);
      }
      raw.header_line = n;
      have_header = true;
      return;
    }
    if (fields.size() != 2) bad("expected \"" + std::string(angle_name) + " FIELD\", found " +
                                std::to_string(fields.size()) + " fields");
    const auto angle = text::to_number(fields[0]);
    const auto field = text::to_number(fields[1]);
    if (!angle) bad(std::string(angle_name) + " " + text::quote_token(fields[0]) + " is not a number");
    if (!field) bad("field " + text::quote_token(fields[1]) + " is not a number");
    if (*angle < lo || *angle > hi)
      bad(std::string(angle_name) + " " + num(*angle) + " is outside [" + num(lo) + ", " + num(hi) + "]");
    if (*field < 0.0 || *field > 1.0) bad("field " + num(*field) + " is outside [0, 1] (a normalised field value)");
    auto& [sum, count] = raw.sums[*angle];
    sum += *field;
    ++count;
  });
  if (!have_header) throw io::FormatError(source, "empty file (expected a first line and pattern lines)");
  if (raw.sums.empty()) throw io::FormatError(source, "no pattern lines after the first line");
  return raw;
}

PatternCut make_cut(const RawPattern& raw, std::string_view text, const std::string& source) {
  PatternCut cut;
  cut.source = source;
  cut.text = std::string(text);
  for (const auto& [angle, sc] : raw.sums) cut.points.emplace_back(angle, sc.first / sc.second);
  return cut;
}

// Linear interpolation of a sorted cut; periodic over 360 degrees or held at the ends.
double interpolate(const PatternCut& cut, double angle, bool periodic) {
  const auto& p = cut.points;
  if (p.size() == 1) return p[0].second;
  if (periodic) angle = wrap360(angle);
  const auto upper = std::lower_bound(p.begin(), p.end(), angle,
                                      [](const auto& a, double x) { return a.first < x; });
  if (upper != p.end() && upper->first == angle) return upper->second;
  if (upper == p.begin() || upper == p.end()) {
    if (!periodic) return upper == p.begin() ? p.front().second : p.back().second;
    // Between the last point and the first one, 360 degrees on.
    const double a0 = p.back().first, a1 = p.front().first + 360.0;
    const double x = angle < p.front().first ? angle + 360.0 : angle;
    return p.back().second + (p.front().second - p.back().second) * (x - a0) / (a1 - a0);
  }
  const auto lower = upper - 1;
  const double t = (angle - lower->first) / (upper->first - lower->first);
  return lower->second + t * (upper->second - lower->second);
}

// SPLAT!'s tilt profile: 1 towards the tilt, 0 at right angles, -1 behind, linear between.
double tilt_profile(double relative_azimuth) {
  const double x = wrap360(relative_azimuth);
  return x <= 180.0 ? (90.0 - x) / 90.0 : (x - 270.0) / 90.0;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw io::FormatError(path, "cannot read");
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw io::FormatError(path, "cannot read");
  if (s.size() > (std::size_t{1} << 24)) throw io::FormatError(path, "larger than 16 MiB: not a pattern file");
  return s;
}

// The text with its first non-blank, non-comment line replaced.
std::string replace_header(const std::string& text, const std::string& header) {
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    if (!text::strip_comment(std::string_view(text).substr(start, end - start)).empty()) {
      return text.substr(0, start) + header + (end < text.size() ? text.substr(end) : "\n");
    }
    start = end + 1;
  }
  return header + "\n";
}

}  // namespace

std::pair<PatternCut, double> parse_az(std::string_view text, const std::string& source) {
  RawPattern raw = read_lines(text, source, 0.0, 360.0, "azimuth", 1);
  if (raw.header.size() != 1) {
    throw io::FormatError(source, "line " + std::to_string(raw.header_line) +
                                      ": expected the pattern's rotation (degrees) first");
  }
  if (const auto it = raw.sums.find(360.0); it != raw.sums.end()) {
    if (!raw.sums.count(0.0)) raw.sums[0.0] = it->second;
    raw.sums.erase(360.0);
  }
  return {make_cut(raw, text, source), raw.header[0]};
}

ElevationFile parse_el(std::string_view text, const std::string& source) {
  RawPattern raw = read_lines(text, source, -10.0, 90.0, "elevation", 2);
  if (raw.header.empty()) {
    throw io::FormatError(source, "line " + std::to_string(raw.header_line) +
                                      ": expected the mechanical tilt (degrees) first");
  }
  ElevationFile f;
  f.tilt_deg = raw.header[0];
  if (raw.header.size() > 1) f.tilt_azimuth_deg = raw.header[1];
  if (std::abs(f.tilt_deg) > 90.0) {
    throw io::FormatError(source, "line " + std::to_string(raw.header_line) + ": tilt " +
                                      num(f.tilt_deg) + " is outside [-90, 90] degrees");
  }
  f.cut = make_cut(raw, text, source);
  return f;
}

double AntennaPattern::gain_db(double azimuth_deg, double elevation_deg) const {
  double field = 1.0;
  if (azimuth) field *= interpolate(*azimuth, azimuth_deg - rotation_deg, true);
  if (elevation) {
    const double depression = -elevation_deg - tilt_deg * tilt_profile(azimuth_deg - tilt_azimuth_deg);
    field *= interpolate(*elevation, depression, false);
  }
  return 20.0 * std::log10(std::max(field, kMinField));
}

std::string AntennaPattern::describe() const {
  std::string s = azimuth ? azimuth->source : "";
  if (elevation) s += ":" + elevation->source;
  if (azimuth) s += ", rotation " + num(rotation_deg);
  if (elevation) s += ", tilt " + num(tilt_deg) + " towards " + num(tilt_azimuth_deg);
  return s;
}

AntennaPattern read_antenna_pattern(const std::string& spec, std::optional<double> azimuth_deg,
                                    std::optional<double> tilt_deg) {
  const std::size_t colon = spec.find(':');
  const std::string az_path = spec.substr(0, colon);
  const std::string el_path = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (az_path.empty() && el_path.empty())
    throw std::invalid_argument("pattern '" + spec + "': expected FILE.az[:FILE.el] or :FILE.el");
  if (el_path.find(':') != std::string::npos)
    throw std::invalid_argument("pattern '" + spec + "': expected at most two files (FILE.az:FILE.el)");
  if (azimuth_deg && az_path.empty())
    throw std::invalid_argument("azimuth: needs a .az pattern (pattern=FILE.az[:FILE.el])");
  if (tilt_deg && el_path.empty())
    throw std::invalid_argument("tilt: needs a .el pattern (pattern=FILE.az:FILE.el)");
  if (azimuth_deg && !std::isfinite(*azimuth_deg))
    throw std::invalid_argument("azimuth " + num(*azimuth_deg) + ": must be finite");
  if (tilt_deg && !(std::abs(*tilt_deg) <= 90.0))
    throw std::invalid_argument("tilt " + num(*tilt_deg) + ": must be within [-90, 90] degrees");
  AntennaPattern p;
  if (!az_path.empty()) {
    auto [cut, rotation] = parse_az(read_file(az_path), az_path);
    p.azimuth = std::move(cut);
    p.rotation_deg = rotation;
  }
  if (!el_path.empty()) {
    ElevationFile f = parse_el(read_file(el_path), el_path);
    p.elevation = std::move(f.cut);
    p.tilt_deg = f.tilt_deg;
    p.tilt_azimuth_deg = f.tilt_azimuth_deg;
  }
  if (azimuth_deg) {
    p.tilt_azimuth_deg = wrap360(p.tilt_azimuth_deg + (*azimuth_deg - p.rotation_deg));
    p.rotation_deg = *azimuth_deg;
  }
  if (tilt_deg) p.tilt_deg = *tilt_deg;
  return p;
}

std::string splat_az_text(const AntennaPattern& p) {
  if (!p.azimuth) return {};
  return replace_header(p.azimuth->text, num(p.rotation_deg));
}

std::string splat_el_text(const AntennaPattern& p) {
  if (!p.elevation) return {};
  return replace_header(p.elevation->text, num(p.tilt_deg) + " " + num(p.tilt_azimuth_deg));
}

}  // namespace terravol::volume
