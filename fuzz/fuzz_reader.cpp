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
    // Every decoder on the same bytes (each rejects what is not its own format), then the
    // dispatch by name and magic bytes that reading a file goes through.
    static constexpr std::string_view kHgt[] = {".hgt"};
    const auto one = [&](auto decode) {
      try {
        (void)decode();
      } catch (const terravol::io::FormatError&) {
      }
    };
    one([&] { return terravol::io::gunzip(bytes, "fuzz", 1u << 26); });
    one([&] { return terravol::io::bunzip2(bytes, "fuzz", 1u << 26); });
    one([&] { return terravol::io::unxz(bytes, "fuzz", 1u << 26); });
    one([&] { return terravol::io::unzip_entry(bytes, "fuzz", kHgt, 1u << 26).bytes; });
    one([&] { return terravol::io::unzip_named(bytes, "fuzz", "x.prj", 1u << 20); });
    const auto name = std::string("x.hgt") + std::string(terravol::io::compression_extension(
                                                 terravol::io::compression_from_magic(bytes)));
    (void)terravol::io::decompress_content(bytes, "fuzz", name);
#else
    const terravol::io::Grid g = terravol::io::parse_dem(Format::TERRAVOL_FUZZ_FORMAT, bytes, "fuzz",
                                                         TERRAVOL_FUZZ_NAME);
    if (g.heights.size() != g.size() || g.mask.size() != g.size()) std::abort();
#endif
  } catch (const terravol::io::FormatError&) {
  }
  return 0;
}
