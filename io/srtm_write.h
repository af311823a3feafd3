// SRTM tile names and writing .hgt content (for the generated sample DEM and for tests).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/grid.h"

namespace terravol::io {

// South-west corner of a 1x1 degree tile, integer degrees (east and north positive).
struct TileCorner {
  int south = 0;
  int west = 0;
};

// The corner named by the first 7 characters of an SRTM name ("N44W072", "s46w066", ...).
std::optional<TileCorner> srtm_corner_from_name(std::string_view name);

// "N44W072" for south = 44, west = -72.
std::string srtm_tile_name(int south, int west);

// The .hgt bytes of a 1201^2 or 3601^2 grid: heights rounded to int16, non-valid samples as
// -32768. Throws std::invalid_argument for other sizes.
std::vector<std::uint8_t> encode_srtm(const Grid& grid);

}  // namespace terravol::io
