// libtiff and libgeotiff over bytes in memory, shared by the GeoTIFF reader (geotiff.cpp) and
// writer (geotiff_write.cpp): a TIFF read from a span or written into a vector, the GDAL tags
// registered, and libtiff's and libgeotiff's messages kept instead of printed. Internal to io/.
#pragma once

#include <geotiff.h>
#include <tiffio.h>
#include <xtiffio.h>  // the GeoTIFF tags (TIFFTAG_GEOTIEPOINTS, ...)

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/bytes.h"

namespace terravol::io::tiff {

// GDAL's metadata tag (XML items, e.g. units), as GDAL writes it; not in libtiff's table.
inline constexpr ttag_t kGdalMetadata = 42112;

// The last error libtiff or libgeotiff reported, as one line; warnings are dropped.
struct Diagnostics {
  std::string last_error;
};

// The file libtiff sees: `data` (reading) or `sink`, which grows as libtiff writes.
struct MemoryFile {
  Bytes data;
  std::vector<std::uint8_t>* sink = nullptr;
  std::uint64_t pos = 0;
};

struct TiffCloser {
  void operator()(TIFF* t) const { TIFFClose(t); }
};
struct GtifFreer {
  void operator()(GTIF* g) const { GTIFFree(g); }
};
using TiffPtr = std::unique_ptr<TIFF, TiffCloser>;
using GtifPtr = std::unique_ptr<GTIF, GtifFreer>;

// Opens `file` in `mode` ("r" or "w"), with libgeotiff's tags and GDAL_NODATA and
// GDAL_METADATA registered, errors recorded in `diag`, and no single allocation over
// `max_alloc` bytes. nullptr when libtiff refuses (diag says why). `file` and `diag` must
// outlive the TIFF.
TiffPtr open(MemoryFile& file, const char* mode, const std::string& name, Diagnostics& diag,
             tmsize_t max_alloc);

// libgeotiff's key access on an open TIFF, its errors recorded in `diag`. nullptr when the
// GeoKeyDirectoryTag is malformed.
GtifPtr open_keys(TIFF* tif, Diagnostics& diag);

}  // namespace terravol::io::tiff
