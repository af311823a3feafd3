// Reading a DEM file of any supported format from disk.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

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

// Parses the (decompressed) content of a DEM of a known format. file_name gives the SRTM
// tile's corner; prj_text is the .prj beside an ESRI grid (empty when none). Throws FormatError.
Grid parse_dem(Format format, Bytes content, const std::string& source, std::string_view file_name,
               const ReadOptions& options = {}, std::string_view prj_text = {});

// The content of a DEM file, decompressed according to its name (.gz, .bz2, .zip). Throws
// FormatError for a missing, unreadable or over-large file and corrupt compressed data.
std::vector<std::uint8_t> read_content(const std::filesystem::path& path);

// Reads, decompresses (.gz, .zip, .bz2) and parses one DEM file. Voids are marked, not filled.
// Throws FormatError("PATH: what is wrong") for a missing or unreadable file, an unknown
// format, a decompressed size over 1 GiB, and whatever the parser rejects.
Grid read_dem(const std::filesystem::path& path, const ReadOptions& options = {});

}  // namespace terravol::io
