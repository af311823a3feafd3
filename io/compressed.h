// Decompressing whole files in memory (zlib, libzip, libbz2), with a bound on the output.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "io/bytes.h"

namespace terravol::io {

// Decompressed output larger than this is refused (a decompression bomb, not a DEM).
inline constexpr std::size_t kMaxDecompressed = std::size_t{1} << 30;

// Each throws FormatError(source, ...) for corrupt or truncated input or output over `limit`.
std::vector<std::uint8_t> gunzip(Bytes data, const std::string& source,
                                 std::size_t limit = kMaxDecompressed);
std::vector<std::uint8_t> bunzip2(Bytes data, const std::string& source,
                                  std::size_t limit = kMaxDecompressed);
// The first entry of a .zip archive whose name ends in `suffix` (case-insensitive).
std::vector<std::uint8_t> unzip_entry(Bytes data, const std::string& source,
                                      const std::string& suffix,
                                      std::size_t limit = kMaxDecompressed);

}  // namespace terravol::io
