#include "io/dem_file.h"

#include <algorithm>
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

constexpr Format kFormats[] = {Format::kSrtm,     Format::kDted,    Format::kUsgsDem,
                               Format::kEsriAscii, Format::kGeoTiff, Format::kSdf};

// decompress_content; *zip_entry (when given) gets the name of the entry a .zip gave.
std::vector<std::uint8_t> unpack(Bytes file_bytes, const std::string& source, std::string_view file_name,
                                 std::string* zip_entry) {
  const Compression compression = compression_from_name(file_name);
  check_magic(compression, file_bytes, source);
  switch (compression) {
    case Compression::kNone: return {file_bytes.begin(), file_bytes.end()};
    case Compression::kGzip: return gunzip(file_bytes, source);
    case Compression::kBzip2: return bunzip2(file_bytes, source);
    case Compression::kXz: return unxz(file_bytes, source);
    case Compression::kZip: break;
  }
  std::vector<std::string_view> suffixes;
  if (const auto format = format_from_name(std::string(file_name))) {
    const auto ext = format_extensions(*format);
    suffixes.assign(ext.begin(), ext.end());
  } else {
    for (const Format f : kFormats) {
      const auto ext = format_extensions(f);
      suffixes.insert(suffixes.end(), ext.begin(), ext.end());
    }
  }
  ZipEntry entry = unzip_entry(file_bytes, source, suffixes);
  if (zip_entry != nullptr) *zip_entry = entry.name;
  return std::move(entry.bytes);
}

// The message of a parser's error on content that is compressed although the name said it
// was not: the parser's complaint, and what the content is.
std::string misnamed(const FormatError& e, Compression found, const std::string& file_name) {
  const std::string what = e.what();
  const std::string problem = what.substr(std::min(what.size(), e.source().size() + 2));
  return problem + " (the file holds " + std::string(compression_label(found)) + " data: name it " + file_name +
         std::string(compression_extension(found)) + ")";
}

}  // namespace

std::span<const std::string_view> format_extensions(Format format) {
  static constexpr std::string_view kSrtm[] = {".hgt"};
  static constexpr std::string_view kDted[] = {".dt0", ".dt1", ".dt2"};
  static constexpr std::string_view kUsgs[] = {".dem"};
  static constexpr std::string_view kAsc[] = {".asc"};
  static constexpr std::string_view kTiff[] = {".tif", ".tiff"};
  static constexpr std::string_view kSdf[] = {".sdf"};
  switch (format) {
    case Format::kSrtm: return kSrtm;
    case Format::kDted: return kDted;
    case Format::kUsgsDem: return kUsgs;
    case Format::kEsriAscii: return kAsc;
    case Format::kGeoTiff: return kTiff;
    case Format::kSdf: return kSdf;
  }
  return {};
}

std::optional<Format> format_from_name(const std::filesystem::path& path) {
  const std::string name = to_lower(strip_compression(path.filename().string()));
  for (const Format f : kFormats) {
    for (const std::string_view ext : format_extensions(f)) {
      if (ends_with(name, ext)) return f;
    }
  }
  return std::nullopt;
}

std::vector<std::uint8_t> decompress_content(Bytes file_bytes, const std::string& source,
                                             std::string_view file_name) {
  return unpack(file_bytes, source, file_name, nullptr);
}

std::vector<std::uint8_t> read_content(const std::filesystem::path& path) {
  const std::string source = path.string();
  std::vector<std::uint8_t> bytes = read_bytes(path, source);
  const std::string name = path.filename().string();
  if (compression_from_name(name) == Compression::kNone) return bytes;
  return unpack(bytes, source, name, nullptr);
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
  const std::string name = path.filename().string();
  const auto format = format_from_name(path);
  if (!format) {
    throw FormatError(source,
                      "unknown DEM format (expected .hgt, .dt0/1/2, .dem, .asc, .tif, .sdf, each also "
                      "compressed as .gz, .bz2, .xz or .zip)");
  }
  const std::vector<std::uint8_t> bytes = read_bytes(path, source);
  const Compression compression = compression_from_name(name);
  std::string entry;
  std::vector<std::uint8_t> unpacked;
  if (compression != Compression::kNone) unpacked = unpack(bytes, source, name, &entry);
  const Bytes content = compression != Compression::kNone ? Bytes(unpacked) : Bytes(bytes);
  std::string prj;
  if (*format == Format::kEsriAscii) {
    std::optional<std::vector<std::uint8_t>> in_zip;
    if (!entry.empty()) {
      in_zip = unzip_named(bytes, source, std::filesystem::path(entry).replace_extension(".prj").string(), 1u << 20);
    }
    if (in_zip) {
      prj.assign(in_zip->begin(), in_zip->end());
    } else {
      std::filesystem::path prj_path = path.parent_path() / std::string(strip_compression(name));
      prj = read_text_if_exists(prj_path.replace_extension(".prj"));
    }
  }
  try {
    return parse_dem(*format, content, source, name, options, prj);
  } catch (const FormatError& e) {
    const Compression found = compression_from_magic(content);
    if (compression != Compression::kNone || found == Compression::kNone) throw;
    throw FormatError(source, misnamed(e, found, name));
  }
}

}  // namespace terravol::io
