#include "io/dem_file.h"

#include <fstream>
#include <iterator>
#include <system_error>

#include "io/compressed.h"
#include "io/error.h"

namespace terravol::io {

namespace {

bool ends_with(const std::string& s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Largest file read whole: 2 GiB (an SRTM1 tile is 26 MB; a whole USGS 1-degree DEM ~10 MB).
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 31;

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path, const std::string& source) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw FormatError(source, "is a directory, not a DEM file");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw FormatError(source, "cannot read: " + ec.message());
  if (size > kMaxFileBytes) throw FormatError(source, "file is larger than 2 GiB");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FormatError(source, "cannot open for reading");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) throw FormatError(source, "read error");
  return bytes;
}

std::string read_text_if_exists(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return {};
  if (std::filesystem::file_size(path, ec) > (1u << 20)) return {};
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

std::optional<Format> format_from_name(const std::filesystem::path& path) {
  const std::string name = to_lower(path.filename().string());
  if (ends_with(name, ".hgt") || ends_with(name, ".hgt.gz") || ends_with(name, ".hgt.zip")) return Format::kSrtm;
  if (ends_with(name, ".dt0") || ends_with(name, ".dt1") || ends_with(name, ".dt2")) return Format::kDted;
  if (ends_with(name, ".dem")) return Format::kUsgsDem;
  if (ends_with(name, ".asc")) return Format::kEsriAscii;
  if (ends_with(name, ".tif") || ends_with(name, ".tiff")) return Format::kGeoTiff;
  if (ends_with(name, ".sdf") || ends_with(name, ".sdf.bz2")) return Format::kSdf;
  return std::nullopt;
}

std::vector<std::uint8_t> read_content(const std::filesystem::path& path) {
  const std::string source = path.string();
  std::vector<std::uint8_t> bytes = read_bytes(path, source);
  const std::string name = to_lower(path.filename().string());
  if (ends_with(name, ".gz")) return gunzip(bytes, source);
  if (ends_with(name, ".bz2")) return bunzip2(bytes, source);
  if (ends_with(name, ".zip")) return unzip_entry(bytes, source, ".hgt");
  return bytes;
}

Grid parse_dem(Format format, Bytes content, const std::string& source, std::string_view file_name,
               const ReadOptions& options, std::string_view prj_text) {
  const std::string_view text(reinterpret_cast<const char*>(content.data()), content.size());
  switch (format) {
    case Format::kSrtm:
      return parse_srtm(content, source, file_name);
    case Format::kDted:
      return parse_dted(content, source);
    case Format::kUsgsDem:
      return parse_usgs_dem(content, source);
    case Format::kEsriAscii:
      return parse_esri_ascii(text, source, options.utm, prj_text);
    case Format::kGeoTiff:
      return parse_geotiff(content, source);
    case Format::kSdf:
      return parse_sdf(text, source);
  }
  throw FormatError(source, "unknown DEM format");
}

Grid read_dem(const std::filesystem::path& path, const ReadOptions& options) {
  const std::string source = path.string();
  const auto format = format_from_name(path);
  if (!format) {
    throw FormatError(source, "unknown DEM format (expected .hgt[.gz|.zip], .dt0/1/2, .dem, .asc, .tif, .sdf[.bz2])");
  }
  const std::vector<std::uint8_t> content = read_content(path);
  std::string prj;
  if (*format == Format::kEsriAscii) {
    std::filesystem::path prj_path = path;
    prj_path.replace_extension(".prj");
    prj = read_text_if_exists(prj_path);
  }
  return parse_dem(*format, content, source, path.filename().string(), options, prj);
}

}  // namespace terravol::io
