// SPLAT! SDF tile names.
#pragma once

#include <optional>
#include <string_view>

#include "io/srtm_write.h"

namespace terravol::io {

// The corner named by an SDF file name "LATMIN_LATMAX_WESTMIN_WESTMAX.sdf" (SPLAT! itself
// writes colons: "40:41:111:112.sdf"); longitudes in the name are west-positive, so
// "40_41_111_112" gives south = 40, west = -112. Also accepted: "-hd" before the extension
// (1" tiles), no extension, a compression extension after ".sdf" (".sdf.gz", ".sdf.bz2",
// ".sdf.xz", ".sdf.zip"; compressed.h), any case, a directory part (ignored), negative latitudes
// ("-34:-33:..."), and west longitudes wrapping at 360 ("10:11:359:0" gives west = 0;
// west is in [-180, 180)). The four numbers must name one 1 x 1 degree tile: lat max =
// lat min + 1 with lat min in -90..89, west max = west min + 1 modulo 360, both in 0..360,
// one separator throughout. nullopt otherwise.
std::optional<TileCorner> sdf_corner_from_name(std::string_view name);

}  // namespace terravol::io
