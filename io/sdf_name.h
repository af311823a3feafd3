// SPLAT! SDF tile names.
#pragma once

#include <optional>
#include <string_view>

#include "io/srtm_write.h"

namespace terravol::io {

// The corner named by an SDF file name "LATMIN_LATMAX_WESTMIN_WESTMAX.sdf[.bz2]" (SPLAT! itself
// writes colons: "40:41:111:112.sdf"); longitudes in the name are west-positive, so
// "40_41_111_112" gives south = 40, west = -112. nullopt when the name is not of that form.
std::optional<TileCorner> sdf_corner_from_name(std::string_view name);

}  // namespace terravol::io
