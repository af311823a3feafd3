// Compressing bytes in tests with the libraries' own encoders (zlib, libbz2, liblzma, libzip):
// separate code from the decoders under test (io/compressed.h), so a round trip checks them.
#pragma once

#include <bzlib.h>
#include <lzma.h>
#include <zip.h>
#include <zlib.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace terravol::test {

using ByteVector = std::vector<std::uint8_t>;

inline ByteVector gzip_bytes(const ByteVector& in, int level = 1) {
  z_stream zs{};
  if (deflateInit2(&zs, level, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) throw std::runtime_error("deflateInit2");
  ByteVector out(deflateBound(&zs, static_cast<uLong>(in.size())) + 64);
  zs.next_in = const_cast<Bytef*>(in.data());
  zs.avail_in = static_cast<uInt>(in.size());
  zs.next_out = out.data();
  zs.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  if (rc != Z_STREAM_END) throw std::runtime_error("deflate");
  return out;
}

inline ByteVector bzip2_bytes(const ByteVector& in, int block_100k = 1) {
  unsigned size = static_cast<unsigned>(in.size() + in.size() / 100 + 600);
  ByteVector out(size);
  char empty = 0;  // libbz2 refuses a null source even for no bytes
  if (BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(out.data()), &size,
                               in.empty() ? &empty : const_cast<char*>(reinterpret_cast<const char*>(in.data())),
                               static_cast<unsigned>(in.size()), block_100k, 0, 0) != BZ_OK)
    throw std::runtime_error("BZ2_bzBuffToBuffCompress");
  out.resize(size);
  return out;
}

inline ByteVector xz_bytes(const ByteVector& in, std::uint32_t preset = 0) {
  ByteVector out(lzma_stream_buffer_bound(in.size()));
  std::size_t pos = 0;
  if (lzma_easy_buffer_encode(preset, LZMA_CHECK_CRC64, nullptr, in.data(), in.size(), out.data(), &pos,
                              out.size()) != LZMA_OK)
    throw std::runtime_error("lzma_easy_buffer_encode");
  out.resize(pos);
  return out;
}

// A zip archive of (name, content) entries, deflated, in that order.
inline ByteVector zip_bytes(const std::vector<std::pair<std::string, ByteVector>>& entries) {
  zip_error_t err;
  zip_error_init(&err);
  zip_source_t* buffer = zip_source_buffer_create(nullptr, 0, 0, &err);
  zip_t* archive = zip_open_from_source(buffer, ZIP_TRUNCATE, &err);
  if (archive == nullptr) throw std::runtime_error("zip_open_from_source");
  zip_source_keep(buffer);
  for (const auto& [name, content] : entries) {
    zip_source_t* s = zip_source_buffer(archive, content.data(), content.size(), 0);
    if (s == nullptr || zip_file_add(archive, name.c_str(), s, ZIP_FL_ENC_UTF_8) < 0) throw std::runtime_error("zip_file_add");
  }
  if (zip_close(archive) != 0) throw std::runtime_error("zip_close");
  zip_source_open(buffer);
  zip_source_seek(buffer, 0, SEEK_END);
  const zip_int64_t size = zip_source_tell(buffer);
  zip_source_seek(buffer, 0, SEEK_SET);
  ByteVector out(static_cast<std::size_t>(size));
  zip_source_read(buffer, out.data(), static_cast<zip_uint64_t>(size));
  zip_source_close(buffer);
  zip_source_free(buffer);
  zip_error_fini(&err);
  return out;
}

// The same bytes compressed as a file named with `extension` (".gz", ".bz2", ".xz", ".zip")
// would be; a zip holds them as one entry named `entry`.
inline ByteVector compress_as(const std::string& extension, const ByteVector& in, const std::string& entry) {
  if (extension == ".gz") return gzip_bytes(in);
  if (extension == ".bz2") return bzip2_bytes(in);
  if (extension == ".xz") return xz_bytes(in);
  if (extension == ".zip") return zip_bytes({{entry, in}});
  throw std::invalid_argument("compress_as: " + extension);
}

inline ByteVector read_file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return ByteVector(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void write_file_bytes(const std::filesystem::path& path, const ByteVector& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace terravol::test
