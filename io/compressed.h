// Compressed DEM files: which compression a name and its bytes say, and decompressing whole
// files in memory (zlib, libbz2, liblzma, libzip) with a bound on the output.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "io/bytes.h"

namespace terravol::io {

// Decompressed output larger than this is refused (a decompression bomb, not a DEM).
inline constexpr std::size_t kMaxDecompressed = std::size_t{1} << 30;

enum class Compression { kNone, kGzip, kBzip2, kXz, kZip };

// The compression a file name ends in (case-insensitive): .gz, .bz2, .xz, .zip; kNone otherwise.
Compression compression_from_name(std::string_view file_name);

// The file name without its compression extension ("a.sdf.gz" -> "a.sdf"); unchanged when it
// has none.
std::string_view strip_compression(std::string_view file_name);

// The compression data's first bytes announce: gzip 1F 8B 08 (RFC 1952, deflate), bzip2 "BZh"
// and a block size '1'..'9', xz FD "7zXZ" 00, zip "PK" 03 04 (or "PK" 05 06, an empty archive).
// kNone for anything else, including fewer bytes than the magic.
Compression compression_from_magic(Bytes data);

// "gzip", "bzip2", "xz", "zip" or "uncompressed"; and the extension ".gz", ".bz2", ".xz",
// ".zip" ("" for kNone).
std::string_view compression_label(Compression compression);
std::string_view compression_extension(Compression compression);

// Throws FormatError(source, "named .gz but holds bzip2 data" or "... but is not gzip data")
// unless data's magic bytes are those of `named` (kNone: no check).
void check_magic(Compression named, Bytes data, const std::string& source);

// Each throws FormatError(source, ...) with one line for corrupt or truncated input, for
// output over `limit` bytes, and for bytes after the end of the data that start no further
// stream (all-zero padding is allowed). Concatenated streams (gzip members, as pigz and bgzip
// write; bzip2 streams, as pbzip2 and lbzip2 write; xz streams) decompress to their
// concatenation, as gzip -d, bzip2 -d and xz -d do.
std::vector<std::uint8_t> gunzip(Bytes data, const std::string& source,
                                 std::size_t limit = kMaxDecompressed);
std::vector<std::uint8_t> bunzip2(Bytes data, const std::string& source,
                                  std::size_t limit = kMaxDecompressed);
// xz needs at most 256 MiB of memory for its dictionary (xz -9 needs 64 MiB); a header
// asking for more is refused.
std::vector<std::uint8_t> unxz(Bytes data, const std::string& source,
                               std::size_t limit = kMaxDecompressed);

// The first file of a .zip archive, in archive order, whose name ends in one of `suffixes`
// (case-insensitive, e.g. {".dt0", ".dt1", ".dt2"}); directories and the "__MACOSX/" and
// "._NAME" copies macOS adds are skipped. The entry's CRC is checked.
struct ZipEntry {
  std::string name;  // as stored in the archive, directory part included
  std::vector<std::uint8_t> bytes;
};
ZipEntry unzip_entry(Bytes data, const std::string& source, std::span<const std::string_view> suffixes,
                     std::size_t limit = kMaxDecompressed);
// The file of that exact name (case-insensitive), nullopt when the archive has none.
std::optional<std::vector<std::uint8_t>> unzip_named(Bytes data, const std::string& source,
                                                     std::string_view name,
                                                     std::size_t limit = kMaxDecompressed);

// The decompressed size a compressed file records without being decompressed, read from
// the file at `path`: gzip's last member's size modulo 2^32 (ISIZE, RFC 1952 2.3.1), xz's
// index (single-stream files only), zip's central directory (the entry unzip_entry would
// pick). nullopt when the file does not say (bzip2 never does; several xz streams; no
// matching zip entry) or cannot be read: callers then decompress to learn it.
std::optional<std::uint64_t> recorded_size(const std::filesystem::path& path, Compression compression,
                                           std::span<const std::string_view> zip_suffixes = {});

}  // namespace terravol::io
