// ESRI ASCII raster (ArcInfo ASCII grid, .asc) reader, and the UTM zone of an ESRI .prj file.
// Spec: ESRI ASCII raster format (ArcGIS "Esri ASCII raster format" reference: a header of
// keyword/value lines, then nrows rows of ncols values, the first row northernmost).
// Hand-written because no library we may use reads it (GDAL, which does, is not a dependency of
// Terravol); the .prj is only searched for a UTM zone, not interpreted as full WKT.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include "io/error.h"
#include "io/readers.h"

namespace terravol::io {

namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\0' || c == '\v' || c == '\f';
}

// Splits text into lines and lines into whitespace-separated tokens, counting lines.
class Lines {
 public:
  explicit Lines(std::string_view text) : text_(text) {}
  bool at_end() const { return pos_ >= text_.size(); }
  // The next line (without its newline); line() becomes its 1-based number.
  std::string_view next() {
    const std::size_t start = pos_;
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    pos_ = end < text_.size() ? end + 1 : end;
    ++line_;
    return text_.substr(start, end - start);
  }
  // Puts back the line just returned by next().
  void unread(std::string_view line) {
    pos_ = static_cast<std::size_t>(line.data() - text_.data());
    --line_;
  }
  int line() const { return line_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 0;
};

// The next token of `line` from `pos`, advancing pos; empty when none is left.
std::string_view next_token(std::string_view line, std::size_t& pos) {
  while (pos < line.size() && is_space(line[pos])) ++pos;
  const std::size_t start = pos;
  while (pos < line.size() && !is_space(line[pos])) ++pos;
  return line.substr(start, pos - start);
}

// A token made safe for a one-line message.
std::string shown(std::string_view text, std::size_t max = 32) {
  std::string s;
  for (const char c : text.substr(0, max)) {
    const auto u = static_cast<unsigned char>(c);
    s += (u < 0x20 || u >= 0x7f) ? '?' : c;
  }
  if (text.size() > max) s += "...";
  return "'" + s + "'";
}

bool starts_number(std::string_view token) {
  const char c = token.front();
  return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
}

std::string zone_name(const UtmZone& z) {
  return std::to_string(z.zone) + (z.north ? "N" : "S");
}

// What a .prj says about its projection.
struct PrjInfo {
  bool projected = false;  // WKT PROJCS, or an old-style "Projection" other than GEOGRAPHIC
  std::string name;        // the projection's name, for messages
  std::optional<UtmZone> utm;
};

// Value of the PARAMETER["name", value] of a WKT text (lower case), if present.
std::optional<double> wkt_parameter(std::string_view lower, std::string_view name) {
  const std::string key = "parameter[\"" + std::string(name) + "\"";
  const std::size_t at = lower.find(key);
  if (at == std::string_view::npos) return std::nullopt;
  std::size_t pos = at + key.size();
  while (pos < lower.size() && (lower[pos] == ',' || lower[pos] == ' ')) ++pos;
  std::size_t end = pos;
  while (end < lower.size() && lower[end] != ']' && lower[end] != ',') ++end;
  return parse_number(lower.substr(pos, end - pos));
}

// UTM zone in a WKT projection name like "wgs_1984_utm_zone_10n" or "wgs 84 / utm zone 25s"
// (lower case); `lower` is the whole WKT, for a false northing when the name has no hemisphere.
std::optional<UtmZone> utm_from_wkt_name(std::string_view name, std::string_view lower) {
  const std::size_t utm = name.find("utm");
  if (utm == std::string_view::npos) return std::nullopt;
  const std::size_t zone_at = name.find("zone", utm);
  if (zone_at == std::string_view::npos) return std::nullopt;
  std::size_t pos = zone_at + 4;
  while (pos < name.size() && (name[pos] == ' ' || name[pos] == '_')) ++pos;
  std::size_t digits = pos;
  while (digits < name.size() && digits - pos < 3 && name[digits] >= '0' && name[digits] <= '9')
    ++digits;
  const auto zone = parse_integer(name.substr(pos, digits - pos));
  if (!zone || *zone < 1 || *zone > 60) return std::nullopt;
  pos = digits;
  while (pos < name.size() && (name[pos] == ' ' || name[pos] == '_' || name[pos] == ',')) ++pos;
  UtmZone z;
  z.zone = static_cast<int>(*zone);
  if (pos < name.size() && name[pos] == 's') {
    z.north = false;
  } else if (pos < name.size() && name[pos] == 'n') {
    z.north = true;
  } else {
    const auto false_northing = wkt_parameter(lower, "false_northing");
    z.north = !false_northing || *false_northing == 0.0;
  }
  return z;
}

// Value of the old-style .prj line "key value" (key case-insensitive), lower case.
std::optional<std::string> prj_line_value(std::string_view prj, std::string_view key) {
  Lines lines(prj);
  while (!lines.at_end()) {
    const std::string_view line = lines.next();
    std::size_t pos = 0;
    if (to_lower(next_token(line, pos)) != key) continue;
    return to_lower(next_token(line, pos));
  }
  return std::nullopt;
}

PrjInfo read_prj(std::string_view prj) {
  PrjInfo info;
  const std::string lower = to_lower(prj);
  for (const std::string_view key : {"projcs[", "projcrs["}) {
    const std::size_t at = lower.find(key);
    if (at == std::string::npos) continue;
    info.projected = true;
    std::size_t begin = lower.find('"', at);
    const std::size_t end = begin == std::string::npos ? begin : lower.find('"', begin + 1);
    if (end == std::string::npos) {
      info.name = "unnamed";
      return info;
    }
    ++begin;
    info.name = std::string(prj.substr(begin, end - begin));
    info.utm = utm_from_wkt_name(std::string_view(lower).substr(begin, end - begin), lower);
    return info;
  }
  const auto projection = prj_line_value(prj, "projection");
  if (!projection || *projection == "geographic") return info;
  info.projected = true;
  info.name = *projection;
  if (*projection != "utm") return info;
  const auto zone_text = prj_line_value(prj, "zone");
  const auto zone = zone_text ? parse_number(*zone_text) : std::nullopt;
  if (!zone || std::abs(*zone) < 1 || std::abs(*zone) > 60 || *zone != std::trunc(*zone))
    return info;
  UtmZone z;
  z.zone = static_cast<int>(std::abs(*zone));
  z.north = *zone > 0;
  if (const auto shift = prj_line_value(prj, "yshift")) {
    if (const auto y = parse_number(*shift); y && *y != 0.0) z.north = false;
  }
  if (const auto hemisphere = prj_line_value(prj, "hemisphere")) {
    if (hemisphere->starts_with('s')) z.north = false;
    if (hemisphere->starts_with('n')) z.north = true;
  }
  info.utm = z;
  return info;
}

struct Header {
  std::optional<long long> ncols, nrows;
  std::optional<double> xll, yll, cellsize, dx, dy, nodata;
  bool x_corner = true, y_corner = true;
};

}  // namespace

std::optional<UtmZone> parse_utm_zone(std::string_view text) {
  const std::string s = to_lower(text);
  if (s.size() < 6 || s.size() > 7 || !s.starts_with("utm:")) return std::nullopt;
  const char hemisphere = s.back();
  if (hemisphere != 'n' && hemisphere != 's') return std::nullopt;
  const std::string_view digits = std::string_view(s).substr(4, s.size() - 5);
  if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  const auto zone = parse_integer(digits);
  if (!zone || *zone < 1 || *zone > 60) return std::nullopt;
  return UtmZone{static_cast<int>(*zone), hemisphere == 'n'};
}

std::optional<UtmZone> utm_zone_from_prj(std::string_view prj_text) {
  return read_prj(prj_text).utm;
}

Grid parse_esri_ascii(std::string_view text, const std::string& source, std::optional<UtmZone> zone,
                      std::string_view prj_text) {
  Lines lines(text);
  auto error = [&](const std::string& problem) {
    return FormatError(source, "line " + std::to_string(lines.line()) + ": " + problem);
  };

  // ---- Header: "key value" lines until the first line that starts with a number.
  Header h;
  for (;;) {
    if (lines.at_end()) throw FormatError(source, "the file ends in the header, before any data");
    const std::string_view line = lines.next();
    std::size_t pos = 0;
    const std::string_view key_token = next_token(line, pos);
    if (key_token.empty()) continue;
    if (starts_number(key_token)) {
      lines.unread(line);
      break;
    }
    const std::string key = to_lower(key_token);
    const std::string_view value = next_token(line, pos);
    if (value.empty()) throw error("header key " + shown(key_token) + " has no value");
    if (!next_token(line, pos).empty()) throw error("expected one value after " + shown(key_token));
    auto set_integer = [&](std::optional<long long>& field) {
      if (field) throw error("header key " + shown(key_token) + " given twice");
      field = parse_integer(value);
      if (!field) throw error(shown(key_token) + " value " + shown(value) + " is not an integer");
    };
    auto set_number = [&](std::optional<double>& field) {
      if (field)
        throw error("header key " + shown(key_token) +
                    " given twice (or with its corner/center twin)");
      field = parse_number(value);
      if (!field) throw error(shown(key_token) + " value " + shown(value) + " is not a number");
    };
    if (key == "ncols") {
      set_integer(h.ncols);
    } else if (key == "nrows") {
      set_integer(h.nrows);
    } else if (key == "xllcorner" || key == "xllcenter") {
      set_number(h.xll);
      h.x_corner = key == "xllcorner";
    } else if (key == "yllcorner" || key == "yllcenter") {
      set_number(h.yll);
      h.y_corner = key == "yllcorner";
    } else if (key == "cellsize") {
      set_number(h.cellsize);
    } else if (key == "dx") {
      set_number(h.dx);
    } else if (key == "dy") {
      set_number(h.dy);
    } else if (key == "nodata_value" || key == "nodata") {
      set_number(h.nodata);
    } else {
      throw error("unknown header key " + shown(key_token));
    }
  }
  const char* missing = !h.ncols   ? "ncols"
                        : !h.nrows ? "nrows"
                        : !h.xll   ? "xllcorner or xllcenter"
                        : !h.yll   ? "yllcorner or yllcenter"
                                   : nullptr;
  if (missing) throw FormatError(source, std::string("header has no ") + missing);
  if (h.cellsize && (h.dx || h.dy))
    throw FormatError(source, "header gives both cellsize and dx/dy");
  if (!h.cellsize && !(h.dx && h.dy))
    throw FormatError(source, "header has no cellsize (nor dx and dy)");
  const double dx = h.cellsize ? *h.cellsize : *h.dx;
  const double dy = h.cellsize ? *h.cellsize : *h.dy;
  if (!(dx > 0.0) || !(dy > 0.0)) throw FormatError(source, "cell size is not positive");
  // Every value takes at least two characters (a digit and a separator).
  check_dimensions(source, *h.nrows, *h.ncols, text.size() / 2);
  const int rows = static_cast<int>(*h.nrows);
  const int cols = static_cast<int>(*h.ncols);

  Grid g;
  g.format = "esri-ascii";
  g.vertical_datum = "unknown (ESRI ASCII grid does not say)";
  // Cell edges of the whole grid, and sample positions (cell centres).
  const double west = h.x_corner ? *h.xll : *h.xll - dx / 2;
  const double south = h.y_corner ? *h.yll : *h.yll - dy / 2;
  const double east = west + cols * dx;
  const double north = south + rows * dy;
  g.georef.x0 = west + dx / 2;
  g.georef.y0 = north - dy / 2;
  g.georef.dx = dx;
  g.georef.dy = dy;

  // ---- Reference system: the caller's zone, else the .prj's, else degrees if they fit.
  const PrjInfo prj = read_prj(prj_text);
  if (!zone && prj.utm) {
    zone = prj.utm;
    g.notes.push_back("UTM zone " + zone_name(*zone) + " from the .prj file");
  }
  if (zone) {
    g.georef.crs = Crs::kUtm;
    g.georef.utm_zone = zone->zone;
    g.georef.utm_north = zone->north;
  } else {
    constexpr double kSlack = 1e-7;  // degrees; writers round the corner a little
    const bool degrees = west >= -180.0 - kSlack && east <= 180.0 + kSlack &&
                         south >= -90.0 - kSlack && north <= 90.0 + kSlack && dx < 1.0 && dy < 1.0;
    if (prj.projected) {
      throw FormatError(source, "the .prj names projection " + shown(prj.name, 80) +
                                    ", which is not UTM; only geographic and UTM grids are read "
                                    "(override with --crs utm:ZZN)");
    }
    if (!degrees) {
      throw FormatError(source,
                        "coordinates are not degrees; give the projection with a .prj "
                        "beside the file or --crs utm:ZZN");
    }
    g.georef.crs = Crs::kGeographic;
  }

  // ---- Data: rows of ncols values, north first; a row may wrap over lines but starts on one.
  g.allocate(rows, cols);
  const std::string of_cols = "expected " + std::to_string(cols) + " values in row ";
  for (int r = 0; r < rows; ++r) {
    int found = 0;
    int last_line = 0;  // last line holding a value of this row
    while (found < cols) {
      if (lines.at_end()) {
        if (found == 0) {
          throw FormatError(source, "the file ends after line " + std::to_string(lines.line()) +
                                        ", before row " + std::to_string(r + 1) + " of " +
                                        std::to_string(rows));
        }
        throw error(of_cols + std::to_string(r + 1) + ", found " + std::to_string(found));
      }
      const int found_before_line = found;
      const int last_line_before = last_line;
      const std::string_view line = lines.next();
      std::size_t pos = 0;
      for (std::string_view token = next_token(line, pos); !token.empty();
           token = next_token(line, pos)) {
        if (found == cols) {
          if (found_before_line == 0) {
            throw error("row " + std::to_string(r + 1) + " has more than " + std::to_string(cols) +
                        " values");
          }
          // The row ended short on the previous line and this line holds the next row.
          throw FormatError(source, "line " + std::to_string(last_line_before) + ": " + of_cols +
                                        std::to_string(r + 1) + ", found " +
                                        std::to_string(found_before_line));
        }
        const auto v = parse_number(token);
        if (!v) throw error(shown(token) + " in row " + std::to_string(r + 1) + " is not a number");
        const std::size_t at = g.index(r, found++);
        last_line = lines.line();
        if (h.nodata && *v == *h.nodata) {
          g.mask[at] = Sample::kVoid;
          continue;
        }
        const auto height = static_cast<float>(*v);
        if (!std::isfinite(height)) {
          throw error(shown(token) + " in row " + std::to_string(r + 1) + " is out of range");
        }
        g.heights[at] = height;
      }
    }
  }
  while (!lines.at_end()) {
    const std::string_view line = lines.next();
    std::size_t pos = 0;
    if (!next_token(line, pos).empty()) {
      throw error("more data after the " + std::to_string(rows) + " rows the header gives");
    }
  }
  return g;
}

}  // namespace terravol::io
