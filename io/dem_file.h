// Reading a DEM file of any supported format from disk.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "io/grid.h"
#include "io/readers.h"

namespace terravol::io {

enum class Format { kSrtm, kDted, kUsgsDem, kEsriAscii, kGeoTiff, kSdf };

// Options the user may give for files that do not say enough about themselves.
struct ReadOptions {
  std::optional<UtmZone> utm;  // --crs utm:ZZ[N|S] for ESRI ASCII grids in UTM
};

// The format implied by a file name (case-insensitive): .hgt .hgt.gz .hgt.zip, .dt0 .dt1 .dt2,
// .dem, .asc, .tif .tiff, .sdf .sdf.bz2. nullopt when unknown.
std::optional<Format> format_from_name(const std::filesystem::path& path);

// Reads, decompresses (.gz, .zip, .bz2) and parses one DEM file. Voids are marked, not filled.
// Throws FormatError("PATH: what is wrong") for a missing or unreadable file, an unknown
// format, a decompressed size over 1 GiB, and whatever the parser rejects.
Grid read_dem(const std::filesystem::path& path, const ReadOptions& options = {});

}  // namespace terravol::io
