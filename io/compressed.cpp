#include "io/compressed.h"

#include <bzlib.h>
#include <lzma.h>
#include <zip.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <memory>
#include <system_error>

#include "io/error.h"

namespace terravol::io {

namespace {

// The decoders' output grows by what it holds so far, from 64 KiB up to 16 MiB at a time.
constexpr std::size_t kFirstChunk = std::size_t{64} << 10, kMaxChunk = std::size_t{16} << 20;
constexpr std::uint64_t kXzMemory = std::uint64_t{256} << 20;

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

std::string size_text(std::size_t bytes) {
  if (bytes % (std::size_t{1} << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

// The growing output of a decoder: chunks handed out to be filled, trimmed to what was
// written, never more than `limit` bytes in all.
class Output {
 public:
  Output(const std::string& source, std::size_t limit) : source_(source), limit_(limit) {}

  // Room for the next chunk: up to one byte past the limit, so that exceeding it is seen.
  std::span<std::uint8_t> grow() {
    const std::size_t old = bytes_.size();
    const std::size_t n = std::min(std::clamp(old, kFirstChunk, kMaxChunk), limit_ - old + 1);
    bytes_.resize(old + n);
    return {bytes_.data() + old, n};
  }
  // After the decoder has left `unused` bytes of the last chunk unwritten.
  void trim(std::size_t unused) {
    bytes_.resize(bytes_.size() - unused);
    if (bytes_.size() > limit_) throw FormatError(source_, "decompresses to more than " + size_text(limit_));
  }
  std::vector<std::uint8_t> take() { return std::move(bytes_); }

 private:
  const std::string& source_;
  std::size_t limit_;
  std::vector<std::uint8_t> bytes_;
};

// After the end of one stream: whether `rest` starts another of the same kind. Nothing or
// zero padding ends the data; anything else is an error.
bool another_stream(Bytes rest, Compression kind, const std::string& source) {
  if (std::all_of(rest.begin(), rest.end(), [](std::uint8_t b) { return b == 0; })) return false;
  if (compression_from_magic(rest) == kind) return true;
  throw FormatError(source, std::to_string(rest.size()) + " bytes after the end of the " +
                                std::string(compression_label(kind)) + " data are not another " +
                                std::string(compression_label(kind)) + " stream");
}

// zip: the index of the entry unzip_entry picks, nullopt when none matches.
std::optional<zip_uint64_t> find_entry(zip_t* archive, std::span<const std::string_view> suffixes) {
  const zip_int64_t n = zip_get_num_entries(archive, 0);
  for (zip_int64_t i = 0; i < n; ++i) {
    const char* raw = zip_get_name(archive, static_cast<zip_uint64_t>(i), 0);
    if (raw == nullptr) continue;
    const std::string name = to_lower(raw);
    const std::string_view base = std::string_view(name).substr(name.find_last_of('/') + 1);
    if (base.empty() || name.starts_with("__macosx/") || base.starts_with("._")) continue;
    for (const std::string_view s : suffixes) {
      if (ends_with(base, s)) return static_cast<zip_uint64_t>(i);
    }
  }
  return std::nullopt;
}

std::optional<zip_uint64_t> find_named(zip_t* archive, std::string_view wanted) {
  const std::string target = to_lower(wanted);
  const zip_int64_t n = zip_get_num_entries(archive, 0);
  for (zip_int64_t i = 0; i < n; ++i) {
    const char* raw = zip_get_name(archive, static_cast<zip_uint64_t>(i), 0);
    if (raw != nullptr && to_lower(raw) == target) return static_cast<zip_uint64_t>(i);
  }
  return std::nullopt;
}

using ZipPtr = std::unique_ptr<zip_t, void (*)(zip_t*)>;

ZipPtr open_zip(Bytes data, const std::string& source) {
  zip_error_t err;
  zip_error_init(&err);
  zip_source_t* src = zip_source_buffer_create(data.data(), data.size(), 0, &err);
  if (src == nullptr) {
    zip_error_fini(&err);
    throw FormatError(source, "cannot read zip archive");
  }
  zip_t* archive = zip_open_from_source(src, ZIP_RDONLY, &err);
  if (archive == nullptr) {
    const std::string why = zip_error_strerror(&err);
    zip_source_free(src);
    zip_error_fini(&err);
    throw FormatError(source, "not a readable zip archive (" + why + ")");
  }
  zip_error_fini(&err);
  return ZipPtr(archive, zip_discard);
}

std::vector<std::uint8_t> read_zip_entry(zip_t* archive, zip_uint64_t index, const std::string& source,
                                         std::size_t limit) {
  zip_stat_t st;
  zip_stat_init(&st);
  if (zip_stat_index(archive, index, 0, &st) != 0) {
    throw FormatError(source, std::string("cannot read zip entry (") + zip_strerror(archive) + ")");
  }
  // The name as stored, for messages: a hostile archive's control characters become '?'.
  std::string name = st.name != nullptr ? st.name : "?";
  for (char& c : name) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  if (!(st.valid & ZIP_STAT_SIZE)) throw FormatError(source, "zip entry " + name + " has no size");
  if (st.size > limit) throw FormatError(source, "decompresses to more than " + size_text(limit));
  zip_file_t* f = zip_fopen_index(archive, index, 0);
  if (f == nullptr) {
    throw FormatError(source, "cannot open zip entry " + name + " (" + zip_strerror(archive) + ")");
  }
  std::unique_ptr<zip_file_t, int (*)(zip_file_t*)> guard(f, zip_fclose);
  std::vector<std::uint8_t> out(static_cast<std::size_t>(st.size));
  const zip_int64_t got = zip_fread(f, out.data(), out.size());
  // One more read: 0 at the end of the entry, which is also where libzip checks the CRC.
  std::uint8_t extra = 0;
  const zip_int64_t more = got >= 0 && static_cast<zip_uint64_t>(got) == st.size ? zip_fread(f, &extra, 1) : -1;
  if (more != 0) {
    const char* why = zip_file_strerror(f);
    throw FormatError(source, "zip entry " + name + " is corrupt or truncated (" + (why ? why : "short read") + ")");
  }
  return out;
}

std::optional<std::uint64_t> gzip_recorded_size(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in || in.tellg() < 18) return std::nullopt;
  in.seekg(-4, std::ios::end);
  unsigned char b[4];
  if (!in.read(reinterpret_cast<char*>(b), 4)) return std::nullopt;
  return std::uint64_t{b[0]} | (std::uint64_t{b[1]} << 8) | (std::uint64_t{b[2]} << 16) | (std::uint64_t{b[3]} << 24);
}

// xz: the stream footer (last 12 bytes) gives the index's size; the index, the stream's
// total and uncompressed sizes (xz file format 1.0.4, sections 2.1.2 and 4).
std::optional<std::uint64_t> xz_recorded_size(const std::filesystem::path& path) {
  std::error_code ec;
  const std::uintmax_t file_size = std::filesystem::file_size(path, ec);
  if (ec || file_size < 2 * LZMA_STREAM_HEADER_SIZE) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  std::array<std::uint8_t, LZMA_STREAM_HEADER_SIZE> footer{};
  in.seekg(static_cast<std::streamoff>(file_size - LZMA_STREAM_HEADER_SIZE));
  if (!in.read(reinterpret_cast<char*>(footer.data()), footer.size())) return std::nullopt;
  lzma_stream_flags flags;
  if (lzma_stream_footer_decode(&flags, footer.data()) != LZMA_OK) return std::nullopt;
  if (flags.backward_size > (std::uint64_t{16} << 20) ||
      flags.backward_size + 2 * LZMA_STREAM_HEADER_SIZE > file_size)
    return std::nullopt;
  std::vector<std::uint8_t> index(static_cast<std::size_t>(flags.backward_size));
  in.seekg(static_cast<std::streamoff>(file_size - LZMA_STREAM_HEADER_SIZE - index.size()));
  if (!in.read(reinterpret_cast<char*>(index.data()), static_cast<std::streamsize>(index.size()))) return std::nullopt;
  lzma_index* idx = nullptr;
  std::uint64_t memlimit = std::uint64_t{64} << 20;
  std::size_t pos = 0;
  if (lzma_index_buffer_decode(&idx, &memlimit, nullptr, index.data(), &pos, index.size()) != LZMA_OK)
    return std::nullopt;
  std::unique_ptr<lzma_index, void (*)(lzma_index*)> guard(idx, [](lzma_index* i) { lzma_index_end(i, nullptr); });
  if (lzma_index_stream_size(idx) != file_size) return std::nullopt;  // several streams, or padding
  return lzma_index_uncompressed_size(idx);
}

std::optional<std::uint64_t> zip_recorded_size(const std::filesystem::path& path,
                                               std::span<const std::string_view> suffixes) {
  int err = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_RDONLY, &err);
  if (archive == nullptr) return std::nullopt;
  ZipPtr guard(archive, zip_discard);
  const auto index = find_entry(archive, suffixes);
  if (!index) return std::nullopt;
  zip_stat_t st;
  zip_stat_init(&st);
  if (zip_stat_index(archive, *index, 0, &st) != 0 || !(st.valid & ZIP_STAT_SIZE)) return std::nullopt;
  return st.size;
}

}  // namespace

Compression compression_from_name(std::string_view file_name) {
  const std::string name = to_lower(file_name);
  for (const Compression c : {Compression::kGzip, Compression::kBzip2, Compression::kXz, Compression::kZip}) {
    if (ends_with(name, compression_extension(c))) return c;
  }
  return Compression::kNone;
}

std::string_view strip_compression(std::string_view file_name) {
  const Compression c = compression_from_name(file_name);
  file_name.remove_suffix(compression_extension(c).size());
  return file_name;
}

Compression compression_from_magic(Bytes data) {
  auto starts = [&](std::initializer_list<std::uint8_t> magic) {
    return data.size() >= magic.size() && std::equal(magic.begin(), magic.end(), data.begin());
  };
  if (starts({0x1f, 0x8b, 0x08})) return Compression::kGzip;
  if (starts({'B', 'Z', 'h'}) && data.size() >= 4 && data[3] >= '1' && data[3] <= '9') return Compression::kBzip2;
  if (starts({0xfd, '7', 'z', 'X', 'Z', 0x00})) return Compression::kXz;
  if (starts({'P', 'K', 0x03, 0x04}) || starts({'P', 'K', 0x05, 0x06})) return Compression::kZip;
  return Compression::kNone;
}

std::string_view compression_label(Compression compression) {
  switch (compression) {
    case Compression::kGzip: return "gzip";
    case Compression::kBzip2: return "bzip2";
    case Compression::kXz: return "xz";
    case Compression::kZip: return "zip";
    case Compression::kNone: break;
  }
  return "uncompressed";
}

std::string_view compression_extension(Compression compression) {
  switch (compression) {
    case Compression::kGzip: return ".gz";
    case Compression::kBzip2: return ".bz2";
    case Compression::kXz: return ".xz";
    case Compression::kZip: return ".zip";
    case Compression::kNone: break;
  }
  return "";
}

void check_magic(Compression named, Bytes data, const std::string& source) {
  if (named == Compression::kNone) return;
  const Compression found = compression_from_magic(data);
  if (found == named) return;
  const std::string label(compression_label(named)), ext(compression_extension(named));
  // The magic bytes each format starts with, to tell a cut file from a wrong one.
  static constexpr std::array<std::uint8_t, 3> kGzip{0x1f, 0x8b, 0x08};
  static constexpr std::array<std::uint8_t, 3> kBzip2{'B', 'Z', 'h'};
  static constexpr std::array<std::uint8_t, 6> kXz{0xfd, '7', 'z', 'X', 'Z', 0x00};
  static constexpr std::array<std::uint8_t, 4> kZip{'P', 'K', 0x03, 0x04};
  auto prefix_of = [&](std::span<const std::uint8_t> magic) {
    return data.size() <= magic.size() && std::equal(data.begin(), data.end(), magic.begin());
  };
  const bool cut = (named == Compression::kGzip && prefix_of(kGzip)) ||
                   (named == Compression::kBzip2 && prefix_of(kBzip2)) ||
                   (named == Compression::kXz && prefix_of(kXz)) || (named == Compression::kZip && prefix_of(kZip));
  if (cut) throw FormatError(source, label + " data is truncated (" + std::to_string(data.size()) + " bytes)");
  if (found != Compression::kNone) {
    throw FormatError(source, "named " + ext + " but holds " + std::string(compression_label(found)) + " data");
  }
  throw FormatError(source, "named " + ext + " but is not " + label + " data");
}

std::vector<std::uint8_t> gunzip(Bytes data, const std::string& source, std::size_t limit) {
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 16) != Z_OK) throw FormatError(source, "zlib initialisation failed");
  std::unique_ptr<z_stream, int (*)(z_stream*)> guard(&zs, inflateEnd);
  zs.next_in = const_cast<Bytef*>(data.data());
  zs.avail_in = static_cast<uInt>(data.size());
  Output out(source, limit);
  for (;;) {
    const std::span<std::uint8_t> room = out.grow();
    zs.next_out = room.data();
    zs.avail_out = static_cast<uInt>(room.size());
    const int rc = inflate(&zs, Z_NO_FLUSH);
    out.trim(zs.avail_out);
    if (rc == Z_STREAM_END) {
      if (!another_stream(data.last(zs.avail_in), Compression::kGzip, source)) break;
      inflateReset(&zs);
      continue;
    }
    if (rc != Z_OK && rc != Z_BUF_ERROR) {
      throw FormatError(source, std::string("corrupt gzip data (") + (zs.msg ? zs.msg : "zlib error") + ")");
    }
    if (zs.avail_in == 0 && zs.avail_out != 0) throw FormatError(source, "gzip data is truncated");
  }
  return out.take();
}

std::vector<std::uint8_t> bunzip2(Bytes data, const std::string& source, std::size_t limit) {
  bz_stream bs{};
  if (BZ2_bzDecompressInit(&bs, 0, 0) != BZ_OK) throw FormatError(source, "bzip2 initialisation failed");
  std::unique_ptr<bz_stream, int (*)(bz_stream*)> guard(&bs, BZ2_bzDecompressEnd);
  bs.next_in = reinterpret_cast<char*>(const_cast<std::uint8_t*>(data.data()));
  bs.avail_in = static_cast<unsigned>(data.size());
  Output out(source, limit);
  for (;;) {
    const std::span<std::uint8_t> room = out.grow();
    bs.next_out = reinterpret_cast<char*>(room.data());
    bs.avail_out = static_cast<unsigned>(room.size());
    const int rc = BZ2_bzDecompress(&bs);
    out.trim(bs.avail_out);
    if (rc == BZ_STREAM_END) {
      const Bytes rest = data.last(bs.avail_in);
      if (!another_stream(rest, Compression::kBzip2, source)) break;
      BZ2_bzDecompressEnd(&bs);
      bs = bz_stream{};
      if (BZ2_bzDecompressInit(&bs, 0, 0) != BZ_OK) throw FormatError(source, "bzip2 initialisation failed");
      bs.next_in = reinterpret_cast<char*>(const_cast<std::uint8_t*>(rest.data()));
      bs.avail_in = static_cast<unsigned>(rest.size());
      continue;
    }
    if (rc != BZ_OK) throw FormatError(source, "corrupt bzip2 data (code " + std::to_string(rc) + ")");
    if (bs.avail_in == 0 && bs.avail_out != 0) throw FormatError(source, "bzip2 data is truncated");
  }
  return out.take();
}

std::vector<std::uint8_t> unxz(Bytes data, const std::string& source, std::size_t limit) {
  lzma_stream xs = LZMA_STREAM_INIT;
  if (lzma_stream_decoder(&xs, kXzMemory, LZMA_CONCATENATED) != LZMA_OK) {
    throw FormatError(source, "xz initialisation failed");
  }
  std::unique_ptr<lzma_stream, void (*)(lzma_stream*)> guard(&xs, lzma_end);
  xs.next_in = data.data();
  xs.avail_in = data.size();
  Output out(source, limit);
  for (;;) {
    const std::span<std::uint8_t> room = out.grow();
    xs.next_out = room.data();
    xs.avail_out = room.size();
    const lzma_ret rc = lzma_code(&xs, LZMA_FINISH);
    out.trim(xs.avail_out);
    if (rc == LZMA_STREAM_END) break;
    if (rc == LZMA_OK) continue;
    switch (rc) {
      case LZMA_BUF_ERROR: throw FormatError(source, "xz data is truncated");
      case LZMA_MEMLIMIT_ERROR:
        throw FormatError(source, "xz data needs more than " + size_text(kXzMemory) + " of memory to decompress");
      case LZMA_FORMAT_ERROR: throw FormatError(source, "corrupt xz data (not an xz stream)");
      case LZMA_OPTIONS_ERROR: throw FormatError(source, "corrupt xz data (unsupported options)");
      default: throw FormatError(source, "corrupt xz data (liblzma code " + std::to_string(int(rc)) + ")");
    }
  }
  return out.take();
}

ZipEntry unzip_entry(Bytes data, const std::string& source, std::span<const std::string_view> suffixes,
                     std::size_t limit) {
  const ZipPtr archive = open_zip(data, source);
  const auto index = find_entry(archive.get(), suffixes);
  if (!index) {
    std::string wanted;
    for (const std::string_view s : suffixes) wanted += (wanted.empty() ? "*" : " or *") + std::string(s);
    throw FormatError(source, "zip archive holds no " + wanted + " file");
  }
  ZipEntry entry;
  entry.name = zip_get_name(archive.get(), *index, 0);
  entry.bytes = read_zip_entry(archive.get(), *index, source, limit);
  return entry;
}

std::optional<std::vector<std::uint8_t>> unzip_named(Bytes data, const std::string& source, std::string_view name,
                                                     std::size_t limit) {
  const ZipPtr archive = open_zip(data, source);
  const auto index = find_named(archive.get(), name);
  if (!index) return std::nullopt;
  return read_zip_entry(archive.get(), *index, source, limit);
}

std::optional<std::uint64_t> recorded_size(const std::filesystem::path& path, Compression compression,
                                           std::span<const std::string_view> zip_suffixes) {
  switch (compression) {
    case Compression::kGzip: return gzip_recorded_size(path);
    case Compression::kXz: return xz_recorded_size(path);
    case Compression::kZip: return zip_recorded_size(path, zip_suffixes);
    case Compression::kBzip2:
    case Compression::kNone: break;
  }
  return std::nullopt;
}

}  // namespace terravol::io
