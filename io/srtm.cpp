// SRTM .hgt tiles: a headerless square of big-endian int16 samples, rows from north to south,
// -32768 for voids. Size tells the resolution; the file name tells the south-west corner.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "io/error.h"
#include "io/readers.h"
#include "io/srtm_write.h"

namespace terravol::io {

namespace {
constexpr std::int16_t kVoid = -32768;
}

std::optional<TileCorner> srtm_corner_from_name(std::string_view name) {
  if (name.size() < 7) return std::nullopt;
  const std::string s = to_lower(name.substr(0, 7));
  if ((s[0] != 'n' && s[0] != 's') || (s[3] != 'e' && s[3] != 'w')) return std::nullopt;
  const auto lat = parse_integer(s.substr(1, 2));
  const auto lon = parse_integer(s.substr(4, 3));
  if (!lat || !lon || *lat > 89 || *lon > 180 || s[1] == '+' || s[4] == '+' || s[1] == '-' || s[4] == '-')
    return std::nullopt;
  TileCorner c;
  c.south = static_cast<int>(s[0] == 'n' ? *lat : -*lat);
  c.west = static_cast<int>(s[3] == 'e' ? *lon : -*lon);
  if (c.west >= 180) return std::nullopt;
  return c;
}

Grid parse_srtm(Bytes data, const std::string& source, std::string_view tile_name) {
  const auto corner = srtm_corner_from_name(tile_name);
  if (!corner) {
    throw FormatError(source, "SRTM file name must start with the tile's south-west corner, like N44W072");
  }
  int n = 0;
  if (data.size() == 1201u * 1201u * 2u) {
    n = 1201;
  } else if (data.size() == 3601u * 3601u * 2u) {
    n = 3601;
  } else {
    throw FormatError(source, "size " + std::to_string(data.size()) +
                                  " bytes is neither SRTM3 (2884802) nor SRTM1 (25934402)");
  }
  Grid g;
  g.format = "srtm";
  g.vertical_datum = "EGM96 geoid";
  g.georef.crs = Crs::kGeographic;
  g.georef.x0 = corner->west;
  g.georef.y0 = corner->south + 1.0;
  g.georef.dx = g.georef.dy = 1.0 / (n - 1);
  g.allocate(n, n);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const std::int16_t v = read_be_i16(data.data() + 2 * i);
    if (v == kVoid) {
      g.mask[i] = Sample::kVoid;
    } else {
      g.heights[i] = v;
    }
  }
  return g;
}

std::vector<std::uint8_t> encode_srtm(const Grid& grid) {
  if (grid.rows != grid.cols || (grid.rows != 1201 && grid.rows != 3601)) {
    throw std::invalid_argument("encode_srtm: grid must be 1201^2 or 3601^2, is " +
                                std::to_string(grid.rows) + " x " + std::to_string(grid.cols));
  }
  std::vector<std::uint8_t> out(grid.size() * 2);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    long v = kVoid;
    if (grid.mask[i] == Sample::kValid) v = std::lround(std::clamp(grid.heights[i], -32767.0f, 32767.0f));
    const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
    out[2 * i] = static_cast<std::uint8_t>(u >> 8);
    out[2 * i + 1] = static_cast<std::uint8_t>(u & 0xff);
  }
  return out;
}

std::string srtm_tile_name(int south, int west) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%c%02d%c%03d", south >= 0 ? 'N' : 'S', std::abs(south),
                west >= 0 ? 'E' : 'W', std::abs(west));
  return buf;
}

}  // namespace terravol::io
