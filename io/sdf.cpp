// SPLAT! Data Files (.sdf) as documented by SPLAT! (John A. Magliacane, KD2BD: the splat(1)
// manual and the README of its srtm2sdf utility) and defined by its LoadSDF() and srtm2sdf's
// WriteSDF(): ASCII, four header lines (max west, min north, min west, max north; integer
// degrees, longitudes west-positive in 0..360), then ippd * ippd integer heights in metres,
// one a line, ippd = 1200 (3") or 3600 (1", "-hd" tiles). Value k lies at latitude index
// x = k / ippd from the south and longitude index y = k % ippd, where y = ippd - 1 is max west:
// rows run south to north, each from east to west. No shared edge with neighbouring tiles.
// Hand-written: no library Terravol may use reads SDF (GDAL does not either).
#include <string>

#include "io/compressed.h"
#include "io/error.h"
#include "io/readers.h"
#include "io/sdf_name.h"

namespace terravol::io {

namespace {

constexpr int kIppd3 = 1200;  // samples per degree, 3 arc-second tiles
constexpr int kIppd1 = 3600;  // samples per degree, 1 arc-second ("-hd") tiles
constexpr std::size_t kCount3 = std::size_t{kIppd3} * kIppd3;
constexpr std::size_t kCount1 = std::size_t{kIppd1} * kIppd1;
constexpr long long kVoid = -32768;  // SRTM's void; srtm2sdf fills voids, but a file may keep one

// A token for a message: quoted, at most 24 characters, non-printable bytes as '?'.
std::string quoted(std::string_view token) {
  std::string s = "\"";
  for (std::size_t i = 0; i < token.size() && i < 24; ++i) {
    const char c = token[i];
    s += (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  if (token.size() > 24) s += "...";
  return s + "\"";
}

// West-positive degrees (0..360) as the east-positive longitude in [-180, 180).
int east_from_west(int west) {
  int east = (360 - west) % 360;
  if (east >= 180) east -= 360;
  return east;
}

// Whether four integers are a consistent SDF tile: north = south + 1, south in -90..89,
// west_max = west_min + 1 modulo 360, both in 0..360. Empty when consistent, else the problem.
std::string tile_problem(long long south, long long north, long long west_min, long long west_max) {
  if (south < -90 || south > 89)
    return "min north " + std::to_string(south) + " is outside -90..89";
  if (north != south + 1) {
    return "max north " + std::to_string(north) + " is not min north " + std::to_string(south) +
           " + 1";
  }
  if (west_min < 0 || west_min > 360 || west_max < 0 || west_max > 360) {
    return "west longitudes " + std::to_string(west_min) + " and " + std::to_string(west_max) +
           " are not both in 0..360";
  }
  if ((west_min + 1) % 360 != west_max % 360) {
    return "max west " + std::to_string(west_max) + " is not min west " + std::to_string(west_min) +
           " + 1 (modulo 360)";
  }
  return {};
}

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

// A decimal integer of 1 to 3 digits with an optional '-' at the front of `s`, removed from s.
std::optional<int> take_degrees(std::string_view& s) {
  std::size_t n = 0;
  if (n < s.size() && s[n] == '-') ++n;
  const std::size_t first_digit = n;
  while (n < s.size() && s[n] >= '0' && s[n] <= '9' && n - first_digit < 3) ++n;
  if (n == first_digit) return std::nullopt;
  const auto v = parse_integer(s.substr(0, n));
  s.remove_prefix(n);
  if (!v) return std::nullopt;
  return static_cast<int>(*v);
}

}  // namespace

std::optional<TileCorner> sdf_corner_from_name(std::string_view name) {
  const std::size_t slash = name.find_last_of("/\\");
  if (slash != std::string_view::npos) name.remove_prefix(slash + 1);
  const std::string lower = to_lower(name);
  std::string_view s = strip_compression(lower);
  if (s.size() != lower.size() && !ends_with(s, ".sdf")) return std::nullopt;  // "x.gz" is no SDF
  for (const std::string_view suffix : {".sdf", "-hd"}) {
    if (ends_with(s, suffix)) s.remove_suffix(suffix.size());
  }
  if (s.empty()) return std::nullopt;
  int v[4];
  char separator = 0;
  for (int i = 0; i < 4; ++i) {
    if (i > 0) {
      if (s.empty() || (s.front() != '_' && s.front() != ':')) return std::nullopt;
      if (separator != 0 && s.front() != separator) return std::nullopt;
      separator = s.front();
      s.remove_prefix(1);
    }
    const auto d = take_degrees(s);
    if (!d) return std::nullopt;
    v[i] = *d;
  }
  if (!s.empty() || !tile_problem(v[0], v[1], v[2], v[3]).empty()) return std::nullopt;
  return TileCorner{v[0], east_from_west(v[3])};
}

Grid parse_sdf(std::string_view text, const std::string& source) {
  TextCursor cursor(text);
  static constexpr const char* kHeaderNames[4] = {"max west", "min north", "min west", "max north"};
  long long header[4] = {};
  for (int i = 0; i < 4; ++i) {
    const std::string_view token = cursor.next();
    if (token.empty()) {
      throw FormatError(source, "truncated in the header: " + std::to_string(i) +
                                    " of 4 values (max west, min north, min west, max north)");
    }
    const auto v = parse_integer(token);
    if (!v) {
      throw FormatError(source, "line " + std::to_string(cursor.line()) + ": header value " +
                                    kHeaderNames[i] + " " + quoted(token) +
                                    " is not an integer number of degrees");
    }
    header[i] = *v;
  }
  const long long max_west = header[0], min_north = header[1], min_west = header[2],
                  max_north = header[3];
  if (const std::string problem = tile_problem(min_north, max_north, min_west, max_west);
      !problem.empty()) {
    throw FormatError(source, "inconsistent header: " + problem);
  }

  // First pass: count the heights, which tells the resolution, before allocating anything.
  const std::size_t body_start = cursor.offset();
  const int body_first_line = cursor.line();
  std::size_t n = 0;
  while (!cursor.next().empty()) ++n;
  int ippd = 0;
  if (n == kCount3) {
    ippd = kIppd3;
  } else if (n == kCount1) {
    ippd = kIppd1;
  } else if (n < kCount3) {
    throw FormatError(source, "truncated: " + std::to_string(n) + " of " + std::to_string(kCount3) +
                                  " heights of a 3\" tile");
  } else {
    throw FormatError(source, "holds " + std::to_string(n) + " heights; a 3\" tile has " +
                                  std::to_string(kCount3) + " and a 1\" tile " +
                                  std::to_string(kCount1));
  }
  // Every line SPLAT! writes ends with a line break; without one the last height may be cut.
  const std::string_view tail =
      text.substr(text.find_last_not_of(std::string_view(" \t\r\n\0", 5)) + 1);
  if (tail.find('\n') == std::string_view::npos && tail.find('\r') == std::string_view::npos) {
    throw FormatError(source, "truncated: the last height has no line break after it");
  }
  check_dimensions(source, ippd, ippd, n);

  Grid g;
  g.format = "sdf";
  g.vertical_datum =
      "unknown (SPLAT! SDF does not say; srtm2sdf tiles hold SRTM heights, EGM96 geoid)";
  g.georef.crs = Crs::kGeographic;
  g.georef.dx = g.georef.dy = 1.0 / ippd;
  g.georef.x0 = east_from_west(static_cast<int>(max_west));
  g.georef.y0 = static_cast<double>(min_north) + (ippd - 1.0) / ippd;
  g.allocate(ippd, ippd);

  // Second pass. Only the text after the header is scanned again.
  TextCursor body(text.substr(body_start));
  for (int x = 0; x < ippd; ++x) {    // latitude index from the south
    for (int y = 0; y < ippd; ++y) {  // longitude index from the east (ippd - 1 = max west)
      const std::string_view token = body.next();
      const auto v = parse_integer(token);
      if (!v || *v < kVoid || *v > 32767) {
        throw FormatError(source, "line " + std::to_string(body_first_line + body.line() - 1) +
                                      ": height " + quoted(token) +
                                      " is not an integer number of metres in -32768..32767");
      }
      const std::size_t k = g.index(ippd - 1 - x, ippd - 1 - y);
      if (*v == kVoid) {
        g.mask[k] = Sample::kVoid;
      } else {
        g.heights[k] = static_cast<float>(*v);
      }
    }
  }
  return g;
}

}  // namespace terravol::io
