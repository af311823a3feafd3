// libFuzzer target for one DEM reader; TERRAVOL_FUZZ_FORMAT selects it at compile time
// (fuzz/CMakeLists.txt builds one executable per format). Input that the reader rejects must
// come back as FormatError; anything else (a crash, a sanitizer report, another exception,
// a grid whose arrays disagree with its size) is a finding.
#include <cstdint>
#include <cstdlib>

#include "io/compressed.h"
#include "io/dem_file.h"
#include "io/error.h"

using terravol::io::Format;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const terravol::io::Bytes bytes(data, size);
  try {
#ifdef TERRAVOL_FUZZ_DECOMPRESS
    (void)terravol::io::gunzip(bytes, "fuzz", 1u << 26);
    (void)terravol::io::bunzip2(bytes, "fuzz", 1u << 26);
    (void)terravol::io::unzip_entry(bytes, "fuzz", ".hgt", 1u << 26);
#else
    const terravol::io::Grid g = terravol::io::parse_dem(Format::TERRAVOL_FUZZ_FORMAT, bytes, "fuzz",
                                                         TERRAVOL_FUZZ_NAME);
    if (g.heights.size() != g.size() || g.mask.size() != g.size()) std::abort();
#endif
  } catch (const terravol::io::FormatError&) {
  }
  return 0;
}
