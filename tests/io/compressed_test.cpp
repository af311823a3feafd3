#include "io/compressed.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <random>

#include "compress.h"
#include "io/error.h"
#include "parse_check.h"
#include "temp_dir.h"

namespace terravol::io {
namespace {

using test::ByteVector;

ByteVector random_bytes(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  // Low entropy (a few symbols in runs) so that the compressors have something to do.
  std::uniform_int_distribution<int> symbol(0, 7), run(1, 40);
  ByteVector out;
  out.reserve(n);
  while (out.size() < n) {
    const auto v = static_cast<std::uint8_t>(symbol(rng) * 31);
    for (int k = run(rng); k > 0 && out.size() < n; --k) out.push_back(v);
  }
  return out;
}

ByteVector concat(ByteVector a, const ByteVector& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

constexpr std::string_view kHgt[] = {".hgt"};

// Decompresses as a file named with `extension` would be.
ByteVector decompress(const std::string& extension, const ByteVector& data, std::size_t limit = kMaxDecompressed) {
  if (extension == ".gz") return gunzip(data, "src", limit);
  if (extension == ".bz2") return bunzip2(data, "src", limit);
  if (extension == ".xz") return unxz(data, "src", limit);
  return unzip_entry(data, "src", kHgt, limit).bytes;
}

void expect_one_line_error(const std::string& what, const std::string& context) {
  EXPECT_EQ(what.rfind("src: ", 0), 0u) << context << ": " << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << context << ": " << what;
}

const std::string kExtensions[] = {".gz", ".bz2", ".xz", ".zip"};

TEST(CompressionName, TheLastExtensionNamesTheCompressionInAnyCase) {
  EXPECT_EQ(compression_from_name("40_41_111_112.sdf.gz"), Compression::kGzip);
  EXPECT_EQ(compression_from_name("a.asc.BZ2"), Compression::kBzip2);
  EXPECT_EQ(compression_from_name("dir/n33.dt1.Xz"), Compression::kXz);
  EXPECT_EQ(compression_from_name("N44W072.hgt.zip"), Compression::kZip);
  for (const char* plain : {"N44W072.hgt", "x.gzip", "x.tgz", "gz", "x.gz.tif", ""}) {
    EXPECT_EQ(compression_from_name(plain), Compression::kNone) << plain;
  }
  EXPECT_EQ(strip_compression("40_41_111_112.sdf.gz"), "40_41_111_112.sdf");
  EXPECT_EQ(strip_compression("N44W072.HGT.ZIP"), "N44W072.HGT");
  EXPECT_EQ(strip_compression("N44W072.hgt"), "N44W072.hgt");
}

TEST(CompressionMagic, EachFormatIsKnownByItsFirstBytes) {
  const ByteVector text = random_bytes(1000, 1);
  EXPECT_EQ(compression_from_magic(test::gzip_bytes(text)), Compression::kGzip);
  EXPECT_EQ(compression_from_magic(test::bzip2_bytes(text)), Compression::kBzip2);
  EXPECT_EQ(compression_from_magic(test::xz_bytes(text)), Compression::kXz);
  EXPECT_EQ(compression_from_magic(test::zip_bytes({{"a.hgt", text}})), Compression::kZip);
  EXPECT_EQ(compression_from_magic(text), Compression::kNone);
  EXPECT_EQ(compression_from_magic(ByteVector{0x1f, 0x8b}), Compression::kNone) << "shorter than the magic";
  EXPECT_EQ(compression_from_magic(ByteVector{'B', 'Z', 'h', 'x'}), Compression::kNone) << "no block size digit";
  const std::string sdf = "112\n40\n111\n41\n";
  EXPECT_EQ(compression_from_magic(ByteVector(sdf.begin(), sdf.end())), Compression::kNone);
}

TEST(CompressionMagic, ANameThatDisagreesWithTheBytesIsAOneLineError) {
  const ByteVector bz = test::bzip2_bytes(random_bytes(1000, 2));
  EXPECT_EQ(test::format_error_of([&] { check_magic(Compression::kGzip, bz, "src"); }), "src: named .gz but holds bzip2 data");
  const std::string text = "ncols 3\n";
  EXPECT_EQ(test::format_error_of([&] { check_magic(Compression::kXz, ByteVector(text.begin(), text.end()), "src"); }),
            "src: named .xz but is not xz data");
  EXPECT_EQ(test::format_error_of([&] { check_magic(Compression::kGzip, ByteVector{0x1f}, "src"); }),
            "src: gzip data is truncated (1 bytes)");
  EXPECT_EQ(test::format_error_of([&] { check_magic(Compression::kZip, ByteVector{}, "src"); }),
            "src: zip data is truncated (0 bytes)");
  EXPECT_EQ(test::format_error_of([&] { check_magic(Compression::kBzip2, bz, "src"); }), "");
  EXPECT_EQ(test::format_error_of([&] { check_magic(Compression::kNone, bz, "src"); }), "") << "no name, no check";
}

TEST(Decompress, EveryFormatRoundTripsEmptySmallAndMultiChunkData) {
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{4097}, (std::size_t{3} << 19) + 17}) {
    const ByteVector original = random_bytes(n, static_cast<unsigned>(n));
    for (const std::string& ext : kExtensions) {
      EXPECT_EQ(decompress(ext, test::compress_as(ext, original, "N44W072.hgt")), original) << ext << " " << n;
    }
  }
}

TEST(Decompress, ConcatenatedStreamsGiveTheirConcatenation) {
  const ByteVector a = random_bytes(70000, 3), b = random_bytes(5000, 4);
  EXPECT_EQ(gunzip(concat(test::gzip_bytes(a), test::gzip_bytes(b)), "src"), concat(a, b));
  EXPECT_EQ(bunzip2(concat(test::bzip2_bytes(a), test::bzip2_bytes(b)), "src"), concat(a, b));
  EXPECT_EQ(unxz(concat(test::xz_bytes(a), test::xz_bytes(b)), "src"), concat(a, b));
}

TEST(Decompress, ZeroPaddingAfterTheDataIsIgnoredAndOtherTrailingBytesAreAnError) {
  const ByteVector a = random_bytes(5000, 5);
  const ByteVector zeros(8, 0), junk{'j', 'u', 'n', 'k'};
  EXPECT_EQ(gunzip(concat(test::gzip_bytes(a), zeros), "src"), a);
  EXPECT_EQ(bunzip2(concat(test::bzip2_bytes(a), zeros), "src"), a);
  EXPECT_EQ(unxz(concat(test::xz_bytes(a), zeros), "src"), a);
  EXPECT_EQ(test::format_error_of([&] { gunzip(concat(test::gzip_bytes(a), junk), "src"); }),
            "src: 4 bytes after the end of the gzip data are not another gzip stream");
  EXPECT_EQ(test::format_error_of([&] { bunzip2(concat(test::bzip2_bytes(a), junk), "src"); }),
            "src: 4 bytes after the end of the bzip2 data are not another bzip2 stream");
  expect_one_line_error(test::format_error_of([&] { unxz(concat(test::xz_bytes(a), junk), "src"); }), "xz junk");
}

TEST(Decompress, OutputOfExactlyTheLimitPassesAndOneByteMoreIsRefused) {
  const ByteVector a = random_bytes(3000, 6);
  for (const std::string& ext : kExtensions) {
    const ByteVector packed = test::compress_as(ext, a, "x.hgt");
    EXPECT_EQ(decompress(ext, packed, a.size()), a) << ext;
    EXPECT_EQ(test::format_error_of([&] { decompress(ext, packed, a.size() - 1); }), "src: decompresses to more than 2999 bytes")
        << ext;
  }
}

TEST(Decompress, EveryTruncationIsAOneLineError) {
  const ByteVector a = random_bytes(20000, 7);
  for (const std::string& ext : kExtensions) {
    const ByteVector packed = test::compress_as(ext, a, "x.hgt");
    for (std::size_t n = 0; n < packed.size(); n += (n < 64 ? 1 : 7)) {
      const ByteVector cut(packed.begin(), packed.begin() + static_cast<std::ptrdiff_t>(n));
      const std::string what = test::format_error_of([&] { decompress(ext, cut); });
      ASSERT_FALSE(what.empty()) << ext << " cut at " << n << " decompressed without an error";
      expect_one_line_error(what, ext + " cut at " + std::to_string(n));
    }
  }
}

TEST(Decompress, AFlippedByteIsCaughtByTheFormatsCheck) {
  const ByteVector a = random_bytes(20000, 8);
  std::mt19937 rng(9);
  for (const std::string& ext : kExtensions) {
    const ByteVector packed = test::compress_as(ext, a, "x.hgt");
    for (int trial = 0; trial < 40; ++trial) {
      ByteVector bad = packed;
      // Past the headers: zip's local header is 30 bytes plus the name.
      std::uniform_int_distribution<std::size_t> at(ext == ".zip" ? 40 : 12, packed.size() / 2);
      bad[at(rng)] ^= 0x55;
      const std::string what = test::format_error_of([&] { decompress(ext, bad); });
      ASSERT_FALSE(what.empty()) << ext << ": a corrupt stream decompressed without an error";
      expect_one_line_error(what, ext);
    }
  }
}

// xz: a block header whose LZMA2 dictionary is 1.5 GiB (the largest the format allows),
// with its CRC32 made right, as a hostile file would be.
ByteVector with_huge_dictionary(ByteVector xz) {
  std::size_t p = 12;  // the stream header
  const std::size_t header_size = (std::size_t{xz[p]} + 1) * 4;
  const std::uint8_t flags = xz[p + 1];
  std::size_t q = p + 2;
  auto skip_vli = [&] {
    while (xz[q] & 0x80) ++q;
    ++q;
  };
  if (flags & 0x40) skip_vli();  // compressed size
  if (flags & 0x80) skip_vli();  // uncompressed size
  EXPECT_EQ(xz[q], 0x21) << "LZMA2 filter id";
  EXPECT_EQ(xz[q + 1], 1) << "one byte of properties";
  xz[q + 2] = 40;  // dictionary 1.5 GiB
  const uLong crc = crc32(0, xz.data() + p, static_cast<uInt>(header_size - 4));
  for (int k = 0; k < 4; ++k) xz[p + header_size - 4 + k] = static_cast<std::uint8_t>(crc >> (8 * k));
  return xz;
}

TEST(Decompress, XzAskingForAHugeDictionaryIsRefusedBeforeAllocating) {
  const ByteVector packed = with_huge_dictionary(test::xz_bytes(random_bytes(1000, 10)));
  EXPECT_EQ(test::format_error_of([&] { unxz(packed, "src"); }), "src: xz data needs more than 256 MiB of memory to decompress");
}

TEST(Unzip, TheFirstEntryWithAWantedSuffixIsReadAndMacCopiesAreSkipped) {
  const ByteVector a = random_bytes(100, 11), b = random_bytes(200, 12), c = random_bytes(300, 13);
  const ByteVector archive = test::zip_bytes({{"readme.txt", a},
                                              {"__MACOSX/tiles/._N44W072.hgt", a},
                                              {"tiles/._N44W072.hgt", a},
                                              {"tiles/N44W072.HGT", b},
                                              {"N45W072.hgt", c}});
  const ZipEntry e = unzip_entry(archive, "src", kHgt);
  EXPECT_EQ(e.name, "tiles/N44W072.HGT");
  EXPECT_EQ(e.bytes, b);
  constexpr std::string_view kDted[] = {".dt0", ".dt1", ".dt2"};
  EXPECT_EQ(test::format_error_of([&] { unzip_entry(archive, "src", kDted); }),
            "src: zip archive holds no *.dt0 or *.dt1 or *.dt2 file");
  EXPECT_EQ(unzip_named(archive, "src", "README.TXT"), a);
  EXPECT_FALSE(unzip_named(archive, "src", "tiles/readme.txt"));
}

TEST(Unzip, AnEntryOverTheLimitIsRefusedFromItsRecordedSize) {
  const ByteVector archive = test::zip_bytes({{"x.hgt", ByteVector(5000, 1)}});
  EXPECT_EQ(test::format_error_of([&] { unzip_entry(archive, "src", kHgt, 4999); }), "src: decompresses to more than 4999 bytes");
}

TEST(Unzip, ACorruptEntryIsNamedOnOneLineEvenWithControlCharactersInItsName) {
  const ByteVector content = random_bytes(20000, 15);
  ByteVector archive = test::zip_bytes({{"a\nb.hgt", content}});
  archive[60] ^= 0xff;  // inside the deflated data, after the 30-byte local header and the name
  const std::string what = test::format_error_of([&] { unzip_entry(archive, "src", kHgt); });
  EXPECT_EQ(what.rfind("src: zip entry a?b.hgt is corrupt or truncated", 0), 0u) << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
}

TEST(RecordedSize, GzipXzAndZipSayTheirSizeAndBzip2DoesNot) {
  test::TempDir dir;
  const ByteVector a = random_bytes(123457, 14);
  for (const std::string& ext : kExtensions) {
    const auto path = dir.path() / ("N44W072.hgt" + ext);
    test::write_file_bytes(path, test::compress_as(ext, a, "N44W072.hgt"));
    const auto size = recorded_size(path, compression_from_name(path.string()), kHgt);
    if (ext == ".bz2") {
      EXPECT_FALSE(size);
    } else {
      ASSERT_TRUE(size) << ext;
      EXPECT_EQ(*size, a.size()) << ext;
    }
  }
  const auto two = dir.path() / "two.hgt.xz";
  test::write_file_bytes(two, concat(test::xz_bytes(a), test::xz_bytes(a)));
  EXPECT_FALSE(recorded_size(two, Compression::kXz)) << "the last stream's index is not the file's size";
  const auto other = dir.path() / "other.zip";
  test::write_file_bytes(other, test::zip_bytes({{"x.dt1", a}}));
  EXPECT_FALSE(recorded_size(other, Compression::kZip, kHgt));
  EXPECT_FALSE(recorded_size(dir.path() / "missing.hgt.gz", Compression::kGzip));
}

}  // namespace
}  // namespace terravol::io
