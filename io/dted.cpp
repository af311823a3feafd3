// DTED levels 0, 1 and 2 as specified by MIL-PRF-89020B (Performance Specification: Digital
// Terrain Elevation Data, NIMA, 2000): an 80-byte User Header Label (UHL), a 648-byte Data Set
// Identification record (DSI), a 2700-byte Accuracy Description record (ACC), then one data
// record per longitude line (column), west to east, each holding its samples from south to
// north as signed-magnitude big-endian int16 and closed by a 32-bit checksum.
// Hand-written: no library Terravol may use reads DTED (GDAL does, but is not allowed here).
#include <algorithm>
#include <cstdio>
#include <string>

#include "io/error.h"
#include "io/readers.h"

namespace terravol::io {

namespace {

constexpr std::size_t kLabelSize = 80;  // UHL, and the optional VOL/HDR tape labels before it
constexpr std::size_t kDsiSize = 648;
constexpr std::size_t kAccSize = 2700;
constexpr int kMaxTapeLabels = 4;  // VOL/HDR labels skipped before the UHL
// Data record: sentinel (1), data block count (3), longitude count (2), latitude count (2),
// samples (2 each), checksum (4).
constexpr std::size_t kRecordHeadSize = 8;
constexpr std::size_t kChecksumSize = 4;
constexpr std::uint8_t kSentinel = 0xAA;
constexpr std::uint16_t kVoidRaw = 0xFFFF;  // -32767 in signed magnitude
// A signed-magnitude value below this cannot be terrain: the sample was written in two's
// complement by a non-conforming producer (GDAL makes the same repair).
constexpr int kTwosComplementBelow = -16000;
constexpr double kTenthsOfArcSecondPerDegree = 36000.0;

// Precondition: offset + length <= data.size().
std::string_view text_at(Bytes data, std::size_t offset, std::size_t length) {
  if (length == 0) return {};
  return {reinterpret_cast<const char*>(data.data() + offset), length};
}

// A header field for a message: quoted, with non-printable bytes as '?'.
std::string quoted(std::string_view field) {
  std::string s = "\"";
  for (const char c : field) s += (c >= 0x20 && c < 0x7f) ? c : '?';
  return s + "\"";
}

// A fixed-width unsigned decimal field (blanks around the digits allowed). nullopt otherwise.
std::optional<int> digits(std::string_view field) {
  while (!field.empty() && field.front() == ' ') field.remove_prefix(1);
  while (!field.empty() && field.back() == ' ') field.remove_suffix(1);
  if (field.empty() || field.size() > 8) return std::nullopt;
  int v = 0;
  for (const char c : field) {
    if (c < '0' || c > '9') return std::nullopt;
    v = v * 10 + (c - '0');
  }
  return v;
}

// "DDDMMSSH" in degrees, positive for hemisphere `plus` ('N' or 'E'), negative for `minus`.
std::optional<double> angle(std::string_view field, char plus, char minus, int max_degrees) {
  const auto d = digits(field.substr(0, 3));
  const auto m = digits(field.substr(3, 2));
  const auto s = digits(field.substr(5, 2));
  if (!d || !m || !s || *m >= 60 || *s >= 60) return std::nullopt;
  const double value = *d + *m / 60.0 + *s / 3600.0;
  if (value > max_degrees) return std::nullopt;
  if (field[7] == plus) return value;
  if (field[7] == minus) return -value;
  return std::nullopt;
}

std::string trimmed(std::string_view s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.remove_suffix(1);
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  return std::string(s);
}

std::string vertical_datum(std::string_view code) {
  const std::string c = trimmed(code);
  if (c == "E96") return "EGM96 geoid (DTED E96)";
  if (c == "MSL") return "mean sea level (DTED MSL)";
  if (c.empty()) return "unknown (DTED DSI names none)";
  return "DTED vertical datum " + quoted(c);
}

// Throws unless `size` bytes from `pos` hold a record starting with `tag`.
void expect_record(Bytes data, std::size_t pos, std::string_view tag, std::size_t size,
                   const std::string& source) {
  const std::size_t have = data.size() - pos;
  const std::size_t shown = std::min(have, tag.size());
  if (text_at(data, pos, shown) != tag.substr(0, shown)) {
    throw FormatError(source, "expected the DTED " + std::string(tag) + " header at byte " +
                                  std::to_string(pos) + ", found " +
                                  quoted(text_at(data, pos, shown)));
  }
  if (have < size) {
    throw FormatError(source, "truncated in the " + std::string(tag) + " header: " +
                                  std::to_string(have) + " of " + std::to_string(size) + " bytes");
  }
}

}  // namespace

Grid parse_dted(Bytes data, const std::string& source) {
  // Optional tape labels before the UHL.
  std::size_t pos = 0;
  for (int i = 0; i < kMaxTapeLabels && data.size() - pos >= 3; ++i) {
    const std::string_view tag = text_at(data, pos, 3);
    if (tag != "VOL" && tag != "HDR") break;
    if (data.size() - pos < kLabelSize) {
      throw FormatError(source, "truncated in the " + std::string(tag) + " label: " +
                                    std::to_string(data.size() - pos) + " of 80 bytes");
    }
    pos += kLabelSize;
  }
  expect_record(data, pos, "UHL", kLabelSize, source);
  const std::string_view uhl = text_at(data, pos, kLabelSize);
  const auto lon0 = angle(uhl.substr(4, 8), 'E', 'W', 180);
  if (!lon0) {
    throw FormatError(source, "UHL longitude of origin " + quoted(uhl.substr(4, 8)) +
                                  " is not DDDMMSSH with H = E or W");
  }
  const auto lat0 = angle(uhl.substr(12, 8), 'N', 'S', 90);
  if (!lat0) {
    throw FormatError(source, "UHL latitude of origin " + quoted(uhl.substr(12, 8)) +
                                  " is not DDDMMSSH with H = N or S");
  }
  const auto lon_interval = digits(uhl.substr(20, 4));
  const auto lat_interval = digits(uhl.substr(24, 4));
  if (!lon_interval || !lat_interval || *lon_interval == 0 || *lat_interval == 0) {
    throw FormatError(source, "UHL longitude and latitude intervals " + quoted(uhl.substr(20, 8)) +
                                  " are not two positive counts of tenths of arc-seconds");
  }
  const auto cols = digits(uhl.substr(47, 4));
  const auto rows = digits(uhl.substr(51, 4));
  if (!cols || !rows || *cols == 0 || *rows == 0) {
    throw FormatError(source, "UHL numbers of longitude lines and latitude points " +
                                  quoted(uhl.substr(47, 8)) + " are not two positive counts");
  }
  pos += kLabelSize;

  expect_record(data, pos, "DSI", kDsiSize, source);
  const std::string_view dsi = text_at(data, pos, kDsiSize);
  pos += kDsiSize;
  expect_record(data, pos, "ACC", kAccSize, source);
  pos += kAccSize;

  // Every record has the same size, so the file's length is known before reading any.
  // rows, cols <= 9999 (four-digit fields): no overflow below.
  const std::size_t record_size =
      kRecordHeadSize + 2 * static_cast<std::size_t>(*rows) + kChecksumSize;
  const std::size_t body = data.size() - pos;
  if (body < record_size * static_cast<std::size_t>(*cols)) {
    throw FormatError(source, "truncated in column " + std::to_string(body / record_size) + " of " +
                                  std::to_string(*cols));
  }
  check_dimensions(source, *rows, *cols, body / 2);

  Grid g;
  g.format = "dted";
  g.vertical_datum = vertical_datum(dsi.substr(141, 3));
  const std::string horizontal = trimmed(dsi.substr(144, 5));
  if (horizontal != "WGS84") {
    g.notes.push_back("DTED horizontal datum " + quoted(horizontal) + " read as WGS84");
  }
  g.georef.crs = Crs::kGeographic;
  g.georef.dx = *lon_interval / kTenthsOfArcSecondPerDegree;
  g.georef.dy = *lat_interval / kTenthsOfArcSecondPerDegree;
  g.georef.x0 = *lon0;
  g.georef.y0 = *lat0 + (*rows - 1) * g.georef.dy;
  const double east = g.georef.x0 + (*cols - 1) * g.georef.dx;
  constexpr double kSlack = 1e-9;
  if (g.georef.y0 > 90.0 + kSlack || east > 180.0 + kSlack) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "UHL puts the tile's north-east corner at %.6f, %.6f, beyond the pole or the "
                  "antimeridian",
                  g.georef.y0, east);
    throw FormatError(source, buf);
  }

  g.allocate(*rows, *cols);
  std::size_t twos_complement = 0;
  for (int c = 0; c < *cols; ++c) {
    const std::uint8_t* rec = data.data() + pos + static_cast<std::size_t>(c) * record_size;
    if (rec[0] != kSentinel) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "record %d (column %d) sentinel is 0x%02X, expected 0xAA", c,
                    c, static_cast<unsigned>(rec[0]));
      throw FormatError(source, buf);
    }
    std::uint32_t sum = 0;
    for (std::size_t i = 0; i < record_size - kChecksumSize; ++i) sum += rec[i];
    const std::uint8_t* ck = rec + record_size - kChecksumSize;
    const std::uint32_t stored = (std::uint32_t{ck[0]} << 24) | (std::uint32_t{ck[1]} << 16) |
                                 (std::uint32_t{ck[2]} << 8) | std::uint32_t{ck[3]};
    if (sum != stored) ++g.checksum_errors;
    const std::uint8_t* p = rec + kRecordHeadSize;
    for (int i = 0; i < *rows; ++i, p += 2) {
      const std::size_t k = g.index(*rows - 1 - i, c);  // sample i counts from the south
      const auto raw = static_cast<std::uint16_t>((p[0] << 8) | p[1]);
      if (raw == kVoidRaw) {
        g.mask[k] = Sample::kVoid;
        continue;
      }
      int v = raw & 0x7FFF;
      if (raw & 0x8000) {
        v = -v;
        if (v < kTwosComplementBelow) {
          v = read_be_i16(p);
          ++twos_complement;
        }
      }
      g.heights[k] = static_cast<float>(v);
    }
  }
  if (twos_complement > 0) {
    g.notes.push_back(std::to_string(twos_complement) +
                      " negative samples were in two's complement, not DTED's signed magnitude, "
                      "and were read as such");
  }
  const std::size_t trailing = body - record_size * static_cast<std::size_t>(*cols);
  if (trailing > 0) {
    g.notes.push_back(std::to_string(trailing) + " bytes after the last DTED record were ignored");
  }
  return g;
}

}  // namespace terravol::io
