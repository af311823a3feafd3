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

// Parses "utm:10N", "utm:25s", "UTM:33n" (case-insensitive). nullopt when malformed.
std::optional<UtmZone> parse_utm_zone(std::string_view text);

// SRTM .hgt (SRTM1 3601^2 or SRTM3 1201^2 big-endian int16, rows north to south, -32768 void).
// tile_name is the file name whose first 7 characters give the south-west corner
// ("N44W072", any case). Vertical datum: EGM96 geoid.
Grid parse_srtm(Bytes data, const std::string& source, std::string_view tile_name);

// DTED level 0, 1 or 2 (UHL/DSI/ACC headers, column records with sentinel and checksum,
// signed-magnitude int16). Checksum failures are counted in Grid::checksum_errors and the
// record's data kept.
Grid parse_dted(Bytes data, const std::string& source);

// USGS ASCII DEM: Type A header and Type B profiles in 1024-byte records (record breaks may
// also be newlines), Fortran D exponents, geographic (arc-seconds) or UTM planimetric
// system, feet or metres. Profiles become columns of a regular grid; samples outside every
// profile are kOutside.
Grid parse_usgs_dem(Bytes data, const std::string& source);

// ESRI ASCII grid. Geographic when the header's numbers fit degrees and no zone is given;
// otherwise `zone` (from a .prj beside the file or --crs) makes it UTM. prj_text is the
// content of the .prj file when there is one (empty otherwise).
Grid parse_esri_ascii(std::string_view text, const std::string& source,
                      std::optional<UtmZone> zone, std::string_view prj_text);

// UTM zone named by an ESRI .prj (WKT "UTM_Zone_10N", "UTM zone 10S", or the old
// "Projection UTM / Zone 10" form). nullopt when the .prj is not UTM.
std::optional<UtmZone> utm_zone_from_prj(std::string_view prj_text);

// GeoTIFF through libtiff and libgeotiff: strips or tiles; int16, int32, float32 samples;
// ModelTiepoint + ModelPixelScale; EPSG 4326 or WGS84 UTM (326xx north, 327xx south);
// GDAL_NODATA tag.
Grid parse_geotiff(Bytes data, const std::string& source);

// SPLAT! .sdf: four header lines (max west, min north, min west, max north; longitudes
// west-positive, degrees), then 1200 x 1200 (or 3600 x 3600) integer heights in SPLAT!'s
// order: latitude rows from the south, each from east to west.
Grid parse_sdf(std::string_view text, const std::string& source);

}  // namespace terravol::io
