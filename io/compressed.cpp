#include "io/compressed.h"

#include <bzlib.h>
#include <zip.h>
#include <zlib.h>

#include <memory>

#include "io/error.h"

namespace terravol::io {

namespace {
constexpr std::size_t kChunk = std::size_t{1} << 20;

[[noreturn]] void too_big(const std::string& source, std::size_t limit) {
  throw FormatError(source, "decompresses to more than " + std::to_string(limit >> 20) + " MiB");
}
}  // namespace

std::vector<std::uint8_t> gunzip(Bytes data, const std::string& source, std::size_t limit) {
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 16) != Z_OK) throw FormatError(source, "zlib initialisation failed");
  std::unique_ptr<z_stream, int (*)(z_stream*)> guard(&zs, inflateEnd);
  zs.next_in = const_cast<Bytef*>(data.data());
  zs.avail_in = static_cast<uInt>(data.size());
  std::vector<std::uint8_t> out;
  int rc = Z_OK;
  while (rc != Z_STREAM_END) {
    if (out.size() >= limit) too_big(source, limit);
    const std::size_t old = out.size();
    out.resize(old + kChunk);
    zs.next_out = out.data() + old;
    zs.avail_out = static_cast<uInt>(kChunk);
    rc = inflate(&zs, Z_NO_FLUSH);
    out.resize(old + kChunk - zs.avail_out);
    if (rc == Z_STREAM_END) break;
    if (rc != Z_OK) {
      throw FormatError(source, std::string("corrupt gzip data (") + (zs.msg ? zs.msg : "zlib error") + ")");
    }
    if (zs.avail_in == 0 && zs.avail_out != 0) throw FormatError(source, "gzip data is truncated");
  }
  return out;
}

std::vector<std::uint8_t> bunzip2(Bytes data, const std::string& source, std::size_t limit) {
  bz_stream bs{};
  if (BZ2_bzDecompressInit(&bs, 0, 0) != BZ_OK) throw FormatError(source, "bzip2 initialisation failed");
  std::unique_ptr<bz_stream, int (*)(bz_stream*)> guard(&bs, BZ2_bzDecompressEnd);
  bs.next_in = reinterpret_cast<char*>(const_cast<std::uint8_t*>(data.data()));
  bs.avail_in = static_cast<unsigned>(data.size());
  std::vector<std::uint8_t> out;
  int rc = BZ_OK;
  while (rc != BZ_STREAM_END) {
    if (out.size() >= limit) too_big(source, limit);
    const std::size_t old = out.size();
    out.resize(old + kChunk);
    bs.next_out = reinterpret_cast<char*>(out.data() + old);
    bs.avail_out = static_cast<unsigned>(kChunk);
    rc = BZ2_bzDecompress(&bs);
    out.resize(old + kChunk - bs.avail_out);
    if (rc == BZ_STREAM_END) break;
    if (rc != BZ_OK) throw FormatError(source, "corrupt bzip2 data (code " + std::to_string(rc) + ")");
    if (bs.avail_in == 0 && bs.avail_out != 0) throw FormatError(source, "bzip2 data is truncated");
  }
  return out;
}

std::vector<std::uint8_t> unzip_entry(Bytes data, const std::string& source,
                                      const std::string& suffix, std::size_t limit) {
  zip_error_t err;
  zip_error_init(&err);
  zip_source_t* src = zip_source_buffer_create(data.data(), data.size(), 0, &err);
  if (src == nullptr) throw FormatError(source, "cannot read zip archive");
  zip_t* archive = zip_open_from_source(src, ZIP_RDONLY, &err);
  if (archive == nullptr) {
    zip_source_free(src);
    zip_error_fini(&err);
    throw FormatError(source, "not a readable zip archive");
  }
  std::unique_ptr<zip_t, int (*)(zip_t*)> guard(archive, zip_close);
  const zip_int64_t n = zip_get_num_entries(archive, 0);
  for (zip_int64_t i = 0; i < n; ++i) {
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_stat_index(archive, static_cast<zip_uint64_t>(i), 0, &st) != 0 || st.name == nullptr) continue;
    std::string name = to_lower(st.name);
    if (name.size() < suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    if (!(st.valid & ZIP_STAT_SIZE)) throw FormatError(source, "zip entry " + std::string(st.name) + " has no size");
    if (st.size > limit) too_big(source, limit);
    zip_file_t* f = zip_fopen_index(archive, static_cast<zip_uint64_t>(i), 0);
    if (f == nullptr) throw FormatError(source, "cannot open zip entry " + std::string(st.name));
    std::unique_ptr<zip_file_t, int (*)(zip_file_t*)> fguard(f, zip_fclose);
    std::vector<std::uint8_t> out(static_cast<std::size_t>(st.size));
    const zip_int64_t got = zip_fread(f, out.data(), out.size());
    if (got < 0 || static_cast<zip_uint64_t>(got) != st.size) {
      throw FormatError(source, "zip entry " + std::string(st.name) + " is corrupt or truncated");
    }
    return out;
  }
  throw FormatError(source, "zip archive holds no *" + suffix + " file");
}

}  // namespace terravol::io
