// USGS ASCII DEM reader. Spec: USGS National Mapping Program, Standards for Digital Elevation
// Models, Part 2: Specifications (logical record Type A, the header; Type B, one profile per
// column; Type C, accuracy, is not needed and is ignored). Hand-written because no library we
// may use reads this format (GDAL, which does, is not a dependency of Terravol).
//
// Layouts accepted:
// - the spec's fixed-width 1024-byte records (no line breaks in the file): every field is read
//   at its fixed position; an I6 elevation never straddles a record (146 in a profile's first
//   record, 170 in each further record), a profile starts at a new record;
// - files with line breaks (records ended by newlines, or written line by line): Type A is still
//   read at its fixed columns up to its first line break, Type B as whitespace-separated tokens
//   (a sign also ends an integer, so glued I6 fields like "-32767-32767" split correctly).
//   Like GDAL, Type B may also start right after byte 864 or 893 of such files.
// Positions in messages are 1-based byte columns of the Type A record, as in the spec.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/error.h"
#include "io/readers.h"

namespace terravol::io {

namespace {

constexpr std::size_t kRecord = 1024;
constexpr std::size_t kTypeARequired = 864;  // Type A up to the rows/columns field (853-864)
constexpr long long kVoidValue = -32767;     // spec's void elevation; smaller values also void
constexpr double kFeet = 0.3048;
constexpr double kPi = 3.14159265358979323846;

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\0';
}
bool is_break(char c) {
  return c == '\n' || c == '\r';
}

// A field's text made safe for a one-line message: blanks trimmed, control bytes replaced,
// at most 32 characters.
std::string shown(std::string_view text) {
  while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  std::string s;
  for (const char c : text.substr(0, 32)) {
    const auto u = static_cast<unsigned char>(c);
    s += (u < 0x20 || u >= 0x7f) ? '?' : c;
  }
  if (text.size() > 32) s += "...";
  return "'" + s + "'";
}

std::string number_text(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// The Type A record, its fields addressed by 1-based inclusive byte columns as in the spec.
class TypeA {
 public:
  TypeA(std::string_view record, const std::string& source) : record_(record), source_(source) {}

  std::string_view field(int first, int last) const {
    const auto begin = static_cast<std::size_t>(first - 1);
    if (begin >= record_.size()) return {};
    return record_.substr(begin, static_cast<std::size_t>(last - first + 1));
  }
  std::optional<long long> optional_integer(int first, int last) const {
    return parse_integer(field(first, last));
  }
  long long integer(int first, int last, const char* name) const {
    const auto v = optional_integer(first, last);
    if (!v) throw bad_field(first, last, name, "an integer");
    return *v;
  }
  std::optional<double> optional_number(int first, int last) const {
    return parse_number(field(first, last));
  }
  double number(int first, int last, const char* name) const {
    const auto v = optional_number(first, last);
    if (!v) throw bad_field(first, last, name, "a number");
    return *v;
  }

 private:
  FormatError bad_field(int first, int last, const char* name, const char* what) const {
    return FormatError(source_, std::string("Type A ") + name + " (bytes " + std::to_string(first) +
                                    "-" + std::to_string(last) + ") is not " + what + ": " +
                                    shown(field(first, last)));
  }
  std::string_view record_;
  const std::string& source_;
};

// Reads Type B fields in order, either at the spec's fixed positions or as free tokens.
class FieldReader {
 public:
  FieldReader(std::string_view text, std::size_t start, bool fixed)
      : text_(text), pos_(start), fixed_(fixed) {}

  // Moves to the next record boundary (fixed layout); profiles start on a new record.
  void start_profile() {
    if (fixed_ && pos_ % kRecord != 0) pos_ += kRecord - pos_ % kRecord;
  }

  // The next field of `width` bytes (fixed) or the next token (free); nullopt when the text
  // ends before the field does. For an integer token, a sign after the first character ends it.
  std::optional<std::string_view> next(std::size_t width, bool integer) {
    if (fixed_) {
      if (pos_ % kRecord + width > kRecord) pos_ += kRecord - pos_ % kRecord;
      if (pos_ >= text_.size() || text_.size() - pos_ < width) return std::nullopt;
      last_ = pos_;
      pos_ += width;
      return text_.substr(last_, width);
    }
    while (pos_ < text_.size() && is_blank(text_[pos_])) ++pos_;
    if (pos_ >= text_.size()) return std::nullopt;
    last_ = pos_;
    std::size_t end = pos_ + 1;
    while (end < text_.size() && !is_blank(text_[end]) &&
           !(integer && (text_[end] == '-' || text_[end] == '+'))) {
      ++end;
    }
    pos_ = end;
    return text_.substr(last_, end - last_);
  }

  std::size_t last_field() const { return last_; }  // 0-based offset of the last field read

  // The most profiles the rest of the text could hold: a record each (fixed; the last may lack
  // its padding), or 10 tokens of at least one character and a separator each (free).
  std::size_t max_profiles() const {
    const std::size_t rest = pos_ < text_.size() ? text_.size() - pos_ : 0;
    return fixed_ ? (rest + kRecord - 1) / kRecord : (rest + 1) / 20;
  }

 private:
  std::string_view text_;
  std::size_t pos_;
  bool fixed_;
  std::size_t last_ = 0;
};

// Whether Type B starts at `start` in this layout: its first two fields are row 1, column 1.
bool profile_starts_at(std::string_view text, std::size_t start, bool fixed) {
  FieldReader r(text, start, fixed);
  for (int i = 0; i < 2; ++i) {
    const auto f = r.next(6, true);
    if (!f || parse_integer(*f) != 1) return false;
  }
  return true;
}

struct Profile {
  double x = 0.0;         // planimetric coordinates of the first (southernmost) elevation,
  double y = 0.0;         // in the file's units
  long long m = 0;        // number of elevations
  std::size_t first = 0;  // index of the first elevation in the collected heights
};

const char* vertical_datum_name(std::optional<long long> code) {
  if (!code) return "unknown (USGS DEM, mean sea level)";
  switch (*code) {
    case 1:
      return "local mean sea level (USGS DEM)";
    case 2:
      return "NGVD 29";
    case 3:
      return "NAVD 88";
    default:
      return nullptr;
  }
}

}  // namespace

Grid parse_usgs_dem(Bytes data, const std::string& source) {
  const std::string_view text(reinterpret_cast<const char*>(data.data()), data.size());

  // ---- Type A: the first record, up to 1024 bytes or its first line break.
  std::size_t a_end = std::min(text.size(), kRecord);
  for (std::size_t i = 0; i < a_end; ++i) {
    if (is_break(text[i])) {
      a_end = i;
      break;
    }
  }
  if (a_end < kTypeARequired) {
    if (a_end == text.size()) {
      throw FormatError(source, "truncated in the Type A header (" + std::to_string(text.size()) +
                                    " bytes, its fields need " + std::to_string(kTypeARequired) +
                                    ")");
    }
    throw FormatError(source, "Type A header ends with a line break at byte " +
                                  std::to_string(a_end + 1) +
                                  ", before its last field (bytes 853-864)");
  }
  const TypeA a(text.substr(0, a_end), source);

  if (const auto pattern = a.optional_integer(151, 156); pattern && *pattern != 1) {
    throw FormatError(source, "elevation pattern code " + std::to_string(*pattern) +
                                  " (bytes 151-156) is not 1 (regular grid)");
  }
  const long long ref_system = a.integer(157, 162, "planimetric reference system code");
  const long long plan_units = a.integer(529, 534, "planimetric units code");
  const long long elev_units = a.integer(535, 540, "elevation units code");
  const double res_x = a.number(817, 828, "x resolution");
  const double res_y = a.number(829, 840, "y resolution");
  const double res_z = a.number(841, 852, "z resolution");
  const long long n_profiles = a.integer(859, 864, "number of profiles");

  Grid g;
  g.format = "usgs-dem";
  // Planimetric file unit -> degrees (geographic) or metres (UTM): v * unit_mul / unit_div.
  double unit_mul = 1.0;
  double unit_div = 1.0;
  long long zone = 0;
  if (ref_system == 0) {
    g.georef.crs = Crs::kGeographic;
    if (plan_units == 3) {
      unit_div = 3600.0;
    } else if (plan_units == 0) {
      unit_mul = 180.0;
      unit_div = kPi;
    } else {
      throw FormatError(source, "geographic coordinates in planimetric units code " +
                                    std::to_string(plan_units) +
                                    " (expected 3, arc-seconds, or 0, radians)");
    }
  } else if (ref_system == 1) {
    g.georef.crs = Crs::kUtm;
    zone = a.integer(163, 168, "zone");
    if (zone == 0 || zone < -60 || zone > 60) {
      throw FormatError(source,
                        "UTM zone " + std::to_string(zone) + " (bytes 163-168) is not 1..60");
    }
    if (plan_units == 1) {
      unit_mul = kFeet;
    } else if (plan_units != 2) {
      throw FormatError(source, "UTM coordinates in planimetric units code " +
                                    std::to_string(plan_units) +
                                    " (expected 2, metres, or 1, feet)");
    }
  } else if (ref_system == 2) {
    throw FormatError(source,
                      "State Plane coordinates (reference system code 2) are not supported; only "
                      "geographic and UTM DEMs are");
  } else {
    throw FormatError(source, "planimetric reference system code " + std::to_string(ref_system) +
                                  " is not supported (only 0, geographic, and 1, UTM)");
  }
  double to_metres = 1.0;
  if (elev_units == 1) {
    to_metres = kFeet;
  } else if (elev_units != 2) {
    throw FormatError(source, "elevation units code " + std::to_string(elev_units) +
                                  " (bytes 535-540) is neither 1 (feet) nor 2 (metres)");
  }
  if (!(res_x > 0.0) || !(res_y > 0.0) || !(res_z > 0.0)) {
    throw FormatError(source, "spatial resolution " + number_text(res_x) + ", " +
                                  number_text(res_y) + ", " + number_text(res_z) +
                                  " (bytes 817-852) is not positive");
  }
  if (n_profiles <= 0 || n_profiles > kMaxSide) {
    throw FormatError(source, "number of profiles " + std::to_string(n_profiles) +
                                  " (bytes 859-864) is not 1.." + std::to_string(kMaxSide));
  }

  // ---- Where Type B starts, and in which layout.
  const bool has_breaks = std::any_of(text.begin(), text.end(), is_break);
  std::optional<FieldReader> reader;
  // A fixed-layout file cut within the first profile's row and column numbers is read as fixed,
  // so that it is reported as truncated in profile 1.
  if (!has_breaks && (text.size() < kRecord + 12 || profile_starts_at(text, kRecord, true))) {
    reader.emplace(text, kRecord, true);
  } else {
    for (const std::size_t start : {a_end, kTypeARequired, std::size_t{893}}) {
      if (start < text.size() && profile_starts_at(text, start, false)) {
        reader.emplace(text, start, false);
        break;
      }
    }
  }
  if (!reader) {
    const bool nothing_after =
        std::all_of(text.begin() + static_cast<std::ptrdiff_t>(a_end), text.end(), is_blank);
    if (nothing_after) {
      throw FormatError(source, "truncated after the Type A header, before profile 1 of " +
                                    std::to_string(n_profiles));
    }
    throw FormatError(source,
                      "no Type B profile (row 1, column 1) after the Type A header at byte " +
                          std::to_string(a_end + 1));
  }

  // ---- Type B profiles, collected as read (so memory follows the input actually present).
  std::vector<Profile> profiles;
  profiles.reserve(std::min(static_cast<std::size_t>(n_profiles), reader->max_profiles()));
  std::vector<float> heights;  // NaN marks a void
  const std::string of_n = " of " + std::to_string(n_profiles);
  for (long long k = 0; k < n_profiles; ++k) {
    const std::string where = "profile " + std::to_string(k + 1) + of_n;
    reader->start_profile();
    auto field = [&](std::size_t width, bool integer, const std::string& what) {
      const auto f = reader->next(width, integer);
      if (!f) throw FormatError(source, "truncated in " + where + " (" + what + ")");
      return *f;
    };
    auto bad = [&](const std::string& what, std::string_view f) {
      const bool blank = std::all_of(f.begin(), f.end(), is_blank);
      return FormatError(source, where + ": " + what + " at byte " +
                                     std::to_string(reader->last_field() + 1) +
                                     (blank ? " is blank" : " is not a number: " + shown(f)));
    };
    auto integer = [&](const std::string& what) {
      const auto f = field(6, true, what);
      const auto v = parse_integer(f);
      if (!v) throw bad(what, f);
      return *v;
    };
    auto number = [&](const char* what) {
      const auto f = field(24, false, what);
      const auto v = parse_number(f);
      if (!v) throw bad(what, f);
      return *v;
    };
    integer("row number");
    const long long column = integer("column number");
    if (column != k + 1) {
      throw FormatError(source, where + " has column number " + std::to_string(column));
    }
    const long long m = integer("number of elevations");
    const long long n = integer("number of columns");
    if (m <= 0 || m > kMaxSide || n != 1) {
      throw FormatError(source, where + " claims " + std::to_string(m) + " x " + std::to_string(n) +
                                    " elevations (expected m x 1, m in 1.." +
                                    std::to_string(kMaxSide) + ")");
    }
    Profile p;
    p.x = number("x coordinate");
    p.y = number("y coordinate");
    const double datum = number("local datum elevation");
    number("minimum elevation");
    number("maximum elevation");
    p.m = m;
    p.first = heights.size();
    for (long long i = 0; i < m; ++i) {
      const auto f = reader->next(6, true);
      if (!f) {
        throw FormatError(source, "truncated in " + where + " (elevation " + std::to_string(i + 1) +
                                      " of " + std::to_string(m) + ")");
      }
      const auto v = parse_integer(*f);
      if (!v) throw bad("elevation " + std::to_string(i + 1) + " of " + std::to_string(m), *f);
      if (*v <= kVoidValue) {
        heights.push_back(std::nanf(""));
        continue;
      }
      const auto h = static_cast<float>((datum + static_cast<double>(*v) * res_z) * to_metres);
      if (!std::isfinite(h)) {
        throw FormatError(source,
                          where + ": elevation " + std::to_string(i + 1) + " is out of range");
      }
      heights.push_back(h);
    }
    profiles.push_back(p);
  }

  // ---- The regular grid the profiles fall on, in the file's units until the end.
  const double x0 = profiles.front().x;
  double min_start = profiles.front().y;
  double max_end = profiles.front().y;
  for (std::size_t k = 0; k < profiles.size(); ++k) {
    const Profile& p = profiles[k];
    const double expected_x = x0 + static_cast<double>(k) * res_x;
    if (!(std::abs(p.x - expected_x) <= 0.01 * res_x)) {
      throw FormatError(source, "profile " + std::to_string(k + 1) + of_n + " is at x " +
                                    number_text(p.x) + ", not " + number_text(expected_x) +
                                    " (profiles must be x resolution apart)");
    }
    min_start = std::min(min_start, p.y);
    max_end = std::max(max_end, p.y + static_cast<double>(p.m - 1) * res_y);
  }
  const double span = (max_end - min_start) / res_y;
  if (!(span < static_cast<double>(kMaxSide))) {
    throw FormatError(source, "profiles span " + number_text(max_end - min_start) +
                                  " in y, more than " + std::to_string(kMaxSide) + " rows");
  }
  const long long rows = std::llround(span) + 1;
  const long long cols = n_profiles;
  // The bounding grid of a DEM's footprint is a little larger than the footprint; far larger
  // means the profiles' coordinates are wrong, not that memory should be spent on them.
  const std::size_t max_cells = 4 * heights.size() + static_cast<std::size_t>(cols);
  if (static_cast<unsigned long long>(rows) * static_cast<unsigned long long>(cols) > max_cells) {
    throw FormatError(source, "profiles span " + std::to_string(rows) + " rows x " +
                                  std::to_string(cols) + " columns, far more than their " +
                                  std::to_string(heights.size()) + " elevations");
  }
  check_dimensions(source, rows, cols, max_cells);

  g.allocate(static_cast<int>(rows), static_cast<int>(cols));
  std::fill(g.mask.begin(), g.mask.end(), Sample::kOutside);
  for (std::size_t k = 0; k < profiles.size(); ++k) {
    const Profile& p = profiles[k];
    const double from_top = (max_end - p.y) / res_y;  // row of the profile's southernmost sample
    const double bottom = std::round(from_top);
    if (!(std::abs(from_top - bottom) <= 0.01) || bottom < static_cast<double>(p.m - 1) ||
        bottom >= static_cast<double>(rows)) {
      throw FormatError(source, "profile " + std::to_string(k + 1) + of_n + " starts at y " +
                                    number_text(p.y) +
                                    ", off the y resolution grid of the other profiles");
    }
    const auto bottom_row = static_cast<long long>(bottom);
    for (long long i = 0; i < p.m; ++i) {
      const float h = heights[p.first + static_cast<std::size_t>(i)];
      const std::size_t at = g.index(static_cast<int>(bottom_row - i), static_cast<int>(k));
      if (std::isnan(h)) {
        g.mask[at] = Sample::kVoid;
      } else {
        g.mask[at] = Sample::kValid;
        g.heights[at] = h;
      }
    }
  }

  const auto out = [&](double v) { return v * unit_mul / unit_div; };
  g.georef.x0 = out(x0);
  g.georef.y0 = out(max_end);
  g.georef.dx = out(res_x);
  g.georef.dy = out(res_y);
  if (g.georef.crs == Crs::kUtm) {
    g.georef.utm_zone = static_cast<int>(std::abs(zone));
    g.georef.utm_north = zone > 0 && min_start >= 0.0;
    if (min_start < 0.0) {
      g.georef.y0 += 10'000'000.0;
      g.notes.push_back(
          "negative northings: southern hemisphere, 10,000,000 m false northing added");
    }
  } else {
    const double east = g.georef.x0 + static_cast<double>(cols - 1) * g.georef.dx;
    if (g.georef.x0 < -180.0 || east > 180.0 || out(min_start) < -90.0 || g.georef.y0 > 90.0) {
      throw FormatError(source, "geographic coordinates outside -180..180, -90..90 degrees");
    }
  }

  const auto vdatum = a.optional_integer(889, 890);
  const char* vname = vertical_datum_name(vdatum);
  g.vertical_datum =
      vname ? vname : "unknown (USGS DEM vertical datum code " + std::to_string(*vdatum) + ")";
  const auto hdatum = a.optional_integer(891, 892);
  if (!hdatum) {
    g.notes.push_back(
        "horizontal datum not given (Type A bytes 891-892 blank; older USGS DEMs are "
        "often NAD 27); coordinates taken as WGS 84");
  } else if (*hdatum != 3 && *hdatum != 4) {
    static const char* const kNames[] = {"",       "NAD 27",     "WGS 72",     "WGS 84",
                                         "NAD 83", "Old Hawaii", "Puerto Rico"};
    const std::string name =
        *hdatum >= 1 && *hdatum <= 6 ? kNames[*hdatum] : "code " + std::to_string(*hdatum);
    g.notes.push_back("horizontal datum " + name + "; coordinates taken as WGS 84, not shifted");
  }
  if (const auto angle = a.optional_number(787, 810); angle && *angle != 0.0) {
    g.notes.push_back("Type A rotation angle " + number_text(*angle) + " ignored");
  }
  return g;
}

}  // namespace terravol::io
