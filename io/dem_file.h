// Reading a DEM file of any supported format from disk.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
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

// The extensions of a format, lower case with the dot: {".hgt"}, {".dt0", ".dt1", ".dt2"},
// {".dem"}, {".asc"}, {".tif", ".tiff"}, {".sdf"}.
std::span<const std::string_view> format_extensions(Format format);

// The format implied by a file name (case-insensitive) once any compression extension
// (.gz, .bz2, .xz, .zip; compressed.h) is set aside: "N44W072.hgt", "40_41_111_112.sdf.gz",
// "front_range.asc.bz2", "n33_w116.dt1.zip". nullopt when unknown.
std::optional<Format> format_from_name(const std::filesystem::path& path);

// Parses the (decompressed) content of a DEM of a known format. file_name gives the SRTM
// tile's corner; prj_text is the .prj beside an ESRI grid (empty when none). Throws FormatError.
Grid parse_dem(Format format, Bytes content, const std::string& source, std::string_view file_name,
               const ReadOptions& options = {}, std::string_view prj_text = {});

// The content of a DEM file held in memory, decompressed as `file_name` says: .gz, .bz2, .xz
// whole; .zip the first entry with the extension of the format the name gives (format_extensions;
// any DEM extension when the name gives none). The magic bytes must agree with the name
// (check_magic). A name without a compression extension returns the bytes as they are. Throws
// FormatError(source, ...) for a mismatch, corrupt or truncated data and output over 1 GiB.
std::vector<std::uint8_t> decompress_content(Bytes file_bytes, const std::string& source,
                                             std::string_view file_name);

// decompress_content of the file at `path`. Also throws FormatError for a missing, unreadable
// or over-large (2 GiB) file.
std::vector<std::uint8_t> read_content(const std::filesystem::path& path);

// Reads, decompresses and parses one DEM file. Voids are marked, not filled. An ESRI grid's
// projection comes from a .prj entry of the same name in its zip archive, else from the .prj
// beside the file ("grid.prj" for "grid.asc" and "grid.asc.gz").
// Throws FormatError("PATH: what is wrong") for a missing or unreadable file, an unknown
// format, compressed data that is corrupt, truncated or of another kind than the name says, a
// decompressed size over 1 GiB, and whatever the parser rejects; when the name promises no
// compression but the content is compressed, the parser's message says so.
Grid read_dem(const std::filesystem::path& path, const ReadOptions& options = {});

}  // namespace terravol::io
