// The DEM format parsers. Each takes the whole (already decompressed) file content and a
// source name used in messages, and returns a Grid in the file's own reference system, with
// voids marked (not filled). Each throws FormatError("SOURCE: what is wrong") for input it
// cannot accept and never allocates more than the input can justify (see bytes.h).
// Files are found, decompressed and dispatched by read_dem() in dem_file.h.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "io/bytes.h"
#include "io/grid.h"

namespace terravol::io {

// A UTM zone given by the user (`--crs utm:10N`) or found in a .prj file.
struct UtmZone {
  int zone = 0;  // 1..60
  bool north = true;
};

// Parses "utm:10N", "utm:25s", "UTM:33n" (case-insensitive): "utm:", a zone 1..60 in one or
// two digits, N or S. nullopt when malformed (no hemisphere, signs, blanks, zone out of range).
std::optional<UtmZone> parse_utm_zone(std::string_view text);

// SRTM .hgt (SRTM1 3601^2 or SRTM3 1201^2 big-endian int16, rows north to south, -32768 void).
// tile_name is the file name whose first 7 characters give the south-west corner
// ("N44W072", any case). Vertical datum: EGM96 geoid.
Grid parse_srtm(Bytes data, const std::string& source, std::string_view tile_name);

// DTED level 0, 1 or 2 (UHL/DSI/ACC headers, column records with sentinel and checksum,
// signed-magnitude int16). Checksum failures are counted in Grid::checksum_errors and the
// record's data kept. Rows and columns come from the UHL (cols differs from rows above 50
// degrees); georef: x0, y0 = origin longitude, origin latitude + (rows - 1) * dy, dx and dy the
// UHL intervals. 0xFFFF (-32767) is void. Vertical datum from the DSI ("E96", "MSL").
// Also accepted, each noted in Grid::notes: VOL/HDR tape labels before the UHL (skipped),
// bytes after the last record (ignored), a DSI horizontal datum other than WGS84 (read as
// WGS84), negative samples written in two's complement (magnitude over 16000, read as two's
// complement). Throws FormatError for a missing or malformed UHL/DSI/ACC, a record without the
// 0xAA sentinel, a tile beyond the pole or antimeridian, and truncation; columns in messages
// count from 0, west to east, as the records' own longitude counts do.
Grid parse_dted(Bytes data, const std::string& source);

// USGS ASCII DEM: Type A header and Type B profiles in 1024-byte records (record breaks may
// also be newlines), Fortran D exponents, geographic (arc-seconds) or UTM planimetric
// system, feet or metres. Profiles become columns of a regular grid; samples outside every
// profile are kOutside.
// - Fixed 1024-byte records when the file has no line break (fields read at their positions);
//   otherwise Type A at its fixed columns up to its first line break and Type B as
//   whitespace-separated tokens (a sign also ends an I6 field). Type C and trailing data ignored.
// - Grid: cols = number of profiles (Type A bytes 859-864); x0 = first profile's x, dx = x
//   resolution, each profile exactly dx from the last (1% slack); rows from the lowest profile
//   start to the highest profile end at dy = y resolution, row 0 north; every profile start
//   must lie on that dy lattice (1% slack). Column numbers must run 1, 2, ...; n must be 1.
// - Heights: (local datum + value * z resolution), times 0.3048 for feet; values <= -32767 void.
// - UTM (code 1, metres or feet): zone from bytes 163-168, negative = south; negative
//   northings also mean south and get the 10,000,000 m false northing added (with a note).
//   Geographic (code 0, arc-seconds or radians) becomes degrees and must lie in +-180, +-90.
//   State Plane and other systems are rejected.
// - Vertical datum from bytes 889-890 (1 local MSL, 2 NGVD 29, 3 NAVD 88), "unknown (USGS DEM,
//   mean sea level)" when blank. A horizontal datum other than WGS 84 / NAD 83 (bytes 891-892),
//   or a blank one, is noted in Grid::notes; coordinates are not shifted.
// - Throws FormatError for a truncated file ("truncated in profile 4 of 327 (...)"), bad or
//   out-of-range fields (naming the Type A bytes or the profile), or profiles spread over more
//   than 4 times the cells their elevations fill (checked before the grid is allocated).
Grid parse_usgs_dem(Bytes data, const std::string& source);

// ESRI ASCII grid. Geographic when the header's numbers fit degrees and no zone is given;
// otherwise `zone` (from a .prj beside the file or --crs) makes it UTM. prj_text is the
// content of the .prj file when there is one (empty otherwise).
// - Header: "key value" lines, keys case-insensitive in any order: ncols, nrows, xllcorner or
//   xllcenter, yllcorner or yllcenter, cellsize (or dx and dy), optional NODATA_value; the first
//   line starting with a number begins the data. Unknown or repeated keys are rejected.
// - Data: nrows rows of ncols numbers, north first; a row may wrap over several lines but each
//   row starts on a new line; values equal to NODATA_value are void; nothing but blank lines may
//   follow the last row.
// - Georef: sample centres, so corner registration moves x0 and y0 half a cell in:
//   x0 = xllcorner + dx / 2, y0 = yllcorner + (nrows - 0.5) * dy.
// - CRS: `zone` if given, else the .prj's UTM zone (noted in Grid::notes), else geographic when
//   the cell-edge extent lies within +-180, +-90 and dx, dy < 1; otherwise FormatError
//   ("coordinates are not degrees; give the projection with a .prj ... or --crs utm:ZZN"), or
//   naming the .prj's projection if it is projected but not UTM.
// - Vertical datum "unknown (ESRI ASCII grid does not say)".
// - Throws FormatError "line N: ..." for short or long rows and bad values; dimensions are
//   checked against text.size() / 2 samples before anything is allocated.
Grid parse_esri_ascii(std::string_view text, const std::string& source,
                      std::optional<UtmZone> zone, std::string_view prj_text);

// UTM zone named by an ESRI .prj (WKT "UTM_Zone_10N", "UTM zone 10S", or the old
// "Projection UTM / Zone 10" form). nullopt when the .prj is not UTM.
// WKT: the PROJCS (or PROJCRS) name must contain "UTM" then "zone" and 1..60; the hemisphere
// is the letter or word after the number (N/S, North/Southern...), else south only when the
// False_Northing parameter is non-zero. Old form: "Projection UTM" and "Zone Z" lines
// (negative Z, a non-zero "Yshift", or a "Hemisphere S..." line mean south). The datum is not
// checked (NAD 27 zones are returned like WGS 84 ones).
std::optional<UtmZone> utm_zone_from_prj(std::string_view prj_text);

// GeoTIFF through libtiff and libgeotiff: strips or tiles; int16, int32, float32 samples;
// ModelTiepoint + ModelPixelScale; EPSG 4326 or WGS84 UTM (326xx north, 327xx south);
// GDAL_NODATA tag.
Grid parse_geotiff(Bytes data, const std::string& source);

// SPLAT! .sdf: four header lines (max west, min north, min west, max north; longitudes
// west-positive, degrees), then 1200 x 1200 (or 3600 x 3600) integer heights in SPLAT!'s
// order: latitude rows from the south, each from east to west. The count of heights tells
// the resolution. The header must be consistent (max north = min north + 1 with min north in
// -90..89; max west = min west + 1 modulo 360, both in 0..360). Georef: x0 = -max west
// (wrapped into [-180, 180)), y0 = min north + (ippd - 1) / ippd, dx = dy = 1 / ippd; the tile
// holds no sample on its north or east edge. Heights must be integers in -32768..32767;
// -32768 (SRTM's void, which srtm2sdf normally fills) is marked void. Any whitespace
// separates values, but the last height must be followed by a line break (as SPLAT! writes
// it), so a file cut inside its last height is rejected as truncated. Vertical datum: unknown.
Grid parse_sdf(std::string_view text, const std::string& source);

}  // namespace terravol::io
