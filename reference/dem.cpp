#include "reference/dem.h"

#include <bzlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <regex>
#include <stdexcept>
#include <string>

namespace terravol::reference {

namespace {

namespace fs = std::filesystem;

// One tile's samples: row 0 south, column 0 west, NaN for voids.
struct Tile {
  double south = 0, west = 0, spacing = 1;  // position of sample (0, 0); degrees
  int n = 0;                                // samples per side
  std::vector<float> samples;
};

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
  throw std::runtime_error(path.string() + ": " + what);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The whole bzip2 stream of `packed`.
std::string bunzip2(const std::string& packed, const fs::path& path) {
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) fail(path, "bzip2 initialisation failed");
  std::string out(packed.size() * 4 + 4096, '\0');
  s.next_in = const_cast<char*>(packed.data());
  s.avail_in = static_cast<unsigned>(packed.size());
  std::size_t done = 0;
  for (;;) {
    if (done == out.size()) out.resize(out.size() * 2);
    s.next_out = out.data() + done;
    s.avail_out = static_cast<unsigned>(std::min<std::size_t>(out.size() - done, 1u << 30));
    const int rc = BZ2_bzDecompress(&s);
    done = static_cast<std::size_t>(s.next_out - out.data());
    if (rc == BZ_STREAM_END) break;
    if (rc != BZ_OK || (s.avail_in == 0 && s.avail_out > 0)) {
      BZ2_bzDecompressEnd(&s);
      fail(path, "corrupt or truncated bzip2 data");
    }
    if (done > (std::size_t{1} << 30)) {
      BZ2_bzDecompressEnd(&s);
      fail(path, "more than 1 GiB decompressed");
    }
  }
  BZ2_bzDecompressEnd(&s);
  out.resize(done);
  return out;
}

// The south-west corner from an SRTM name ("N44W072.hgt"), degrees.
std::optional<std::pair<int, int>> srtm_corner(const std::string& name) {
  static const std::regex re("([ns])(\\d{2})([ew])(\\d{3})", std::regex::icase);
  std::smatch m;
  if (!std::regex_search(name, m, re)) return std::nullopt;
  const int lat = std::stoi(m[2]) * (lower(m[1]) == "s" ? -1 : 1);
  const int lon = std::stoi(m[4]) * (lower(m[3]) == "w" ? -1 : 1);
  return std::pair{lat, lon};
}

// West-positive degrees (SPLAT!) as east-positive in [-180, 180).
int east_of_west(int west) {
  int east = ((360 - west) % 360 + 360) % 360;
  return east >= 180 ? east - 360 : east;
}

// The south-west corner from an SDF name ("40_41_111_112.sdf.bz2", or with colons).
std::optional<std::pair<int, int>> sdf_corner(const std::string& name) {
  static const std::regex re("(-?\\d+)[_:](-?\\d+)[_:](\\d+)[_:](\\d+)");
  std::smatch m;
  if (!std::regex_search(name, m, re)) return std::nullopt;
  return std::pair{std::stoi(m[1]), east_of_west(std::stoi(m[4]))};
}

Tile read_hgt(const fs::path& path, std::pair<int, int> corner) {
  const std::string bytes = slurp(path);
  Tile t;
  if (bytes.size() == 2u * 1201 * 1201) {
    t.n = 1201;
  } else if (bytes.size() == 2u * 3601 * 3601) {
    t.n = 3601;
  } else {
    fail(path, std::to_string(bytes.size()) + " bytes is neither a 1201^2 nor a 3601^2 SRTM tile");
  }
  t.south = corner.first;
  t.west = corner.second;
  t.spacing = 1.0 / (t.n - 1);
  t.samples.resize(static_cast<std::size_t>(t.n) * t.n);
  for (int r = 0; r < t.n; ++r) {  // file rows from the north
    for (int c = 0; c < t.n; ++c) {
      const std::size_t at = 2 * (static_cast<std::size_t>(r) * t.n + c);
      const auto v = static_cast<std::int16_t>((static_cast<unsigned char>(bytes[at]) << 8) |
                                               static_cast<unsigned char>(bytes[at + 1]));
      t.samples[static_cast<std::size_t>(t.n - 1 - r) * t.n + c] =
          v == -32768 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(v);
    }
  }
  return t;
}

// Integers separated by white space, from `text`.
class Numbers {
 public:
  Numbers(const std::string& text, const fs::path& path)
      : begin_(text.data()), p_(begin_), end_(begin_ + text.size()), path_(path) {}
  long next() {
    while (p_ < end_ && (*p_ == ' ' || *p_ == '\n' || *p_ == '\r' || *p_ == '\t')) ++p_;
    long v = 0;
    const auto [q, ec] = std::from_chars(p_, end_, v);
    if (ec != std::errc() || q == p_) fail(path_, "expected an integer at byte " + std::to_string(p_ - begin_));
    p_ = q;
    return v;
  }
  std::size_t left() {
    std::size_t count = 0;
    bool in = false;
    for (const char* q = p_; q < end_; ++q) {
      const bool space = *q == ' ' || *q == '\n' || *q == '\r' || *q == '\t';
      count += !space && !in;
      in = !space;
    }
    return count;
  }

 private:
  const char* begin_;
  const char* p_;
  const char* end_;
  const fs::path& path_;
};

Tile read_sdf(const fs::path& path, std::pair<int, int> corner) {
  std::string text = slurp(path);
  if (lower(path.extension().string()) == ".bz2") text = bunzip2(text, path);
  Numbers in(text, path);
  const long max_west = in.next(), min_north = in.next(), min_west = in.next(), max_north = in.next();
  if (max_north != min_north + 1 || east_of_west(static_cast<int>(max_west)) != corner.second ||
      min_north != corner.first || (min_west + 1) % 360 != max_west % 360) {
    fail(path, "header (" + std::to_string(max_west) + ", " + std::to_string(min_north) + ", " +
                   std::to_string(min_west) + ", " + std::to_string(max_north) + ") does not match the name");
  }
  const std::size_t count = in.left();
  Tile t;
  if (count == 1200u * 1200u) {
    t.n = 1200;
  } else if (count == 3600u * 3600u) {
    t.n = 3600;
  } else {
    fail(path, std::to_string(count) + " heights, expected 1200^2 or 3600^2");
  }
  t.south = corner.first;
  t.west = corner.second;
  t.spacing = 1.0 / t.n;
  t.samples.resize(count);
  for (int x = 0; x < t.n; ++x) {    // rows from the south
    for (int y = 0; y < t.n; ++y) {  // from the east: y = n - 1 is the west edge
      const long v = in.next();
      t.samples[static_cast<std::size_t>(x) * t.n + (t.n - 1 - y)] =
          v == -32768 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(v);
    }
  }
  return t;
}

bool is_sdf(const std::string& name) {
  const std::string n = lower(name);
  return n.ends_with(".sdf") || n.ends_with(".sdf.bz2");
}
bool is_hgt(const std::string& name) { return lower(name).ends_with(".hgt"); }

}  // namespace

Dem Dem::read(const std::vector<fs::path>& paths, const Box& box) {
  std::vector<fs::path> files;
  for (const fs::path& p : paths) {
    if (fs::is_directory(p)) {
      std::vector<fs::path> in;
      for (const auto& e : fs::directory_iterator(p))
        if (is_hgt(e.path().filename().string()) || is_sdf(e.path().filename().string())) in.push_back(e.path());
      std::sort(in.begin(), in.end());
      files.insert(files.end(), in.begin(), in.end());
    } else {
      files.push_back(p);
    }
  }
  constexpr double kMargin = 0.01;  // degrees: the bilinear stencil at a tile's edge
  std::vector<Tile> tiles;
  for (const fs::path& f : files) {
    const std::string name = f.filename().string();
    const bool sdf = is_sdf(name);
    if (!sdf && !is_hgt(name)) fail(f, "not an SRTM .hgt or SPLAT! .sdf tile (the reference reads only those)");
    const auto corner = sdf ? sdf_corner(name) : srtm_corner(name);
    if (!corner) fail(f, "no tile corner in the name");
    if (corner->first > box.north + kMargin || corner->first + 1 < box.south - kMargin ||
        corner->second > box.east + kMargin || corner->second + 1 < box.west - kMargin) {
      continue;
    }
    tiles.push_back(sdf ? read_sdf(f, *corner) : read_hgt(f, *corner));
    if (std::abs(tiles.back().spacing - tiles.front().spacing) > 1e-12) fail(f, "a spacing unlike the other tiles'");
  }
  if (tiles.empty()) {
    throw std::runtime_error("reference DEM: no tile meets " + std::to_string(box.south) + ".." +
                             std::to_string(box.north) + " N, " + std::to_string(box.west) + ".." +
                             std::to_string(box.east) + " E");
  }
  Dem d;
  d.spacing_ = tiles.front().spacing;
  d.south_ = tiles.front().south;
  d.west_ = tiles.front().west;
  double north = d.south_, east = d.west_;
  for (const Tile& t : tiles) {
    d.south_ = std::min(d.south_, t.south);
    d.west_ = std::min(d.west_, t.west);
    north = std::max(north, t.south + (t.n - 1) * t.spacing);
    east = std::max(east, t.west + (t.n - 1) * t.spacing);
  }
  d.rows_ = static_cast<int>(std::lround((north - d.south_) / d.spacing_)) + 1;
  d.cols_ = static_cast<int>(std::lround((east - d.west_) / d.spacing_)) + 1;
  d.samples_.assign(static_cast<std::size_t>(d.rows_) * d.cols_, std::numeric_limits<float>::quiet_NaN());
  for (const Tile& t : tiles) {  // the first tile holding a sample gives it (shared SRTM edges)
    const long r0 = std::lround((t.south - d.south_) / d.spacing_);
    const long c0 = std::lround((t.west - d.west_) / d.spacing_);
    for (int r = 0; r < t.n; ++r) {
      for (int c = 0; c < t.n; ++c) {
        float& s = d.samples_[static_cast<std::size_t>(r0 + r) * d.cols_ + static_cast<std::size_t>(c0 + c)];
        if (std::isnan(s)) s = t.samples[static_cast<std::size_t>(r) * t.n + c];
      }
    }
  }
  return d;
}

double Dem::height(double lat, double lon) const {
  const double fr = (lat - south_) / spacing_, fc = (lon - west_) / spacing_;
  if (!(fr >= 0.0 && fc >= 0.0 && fr <= rows_ - 1 && fc <= cols_ - 1)) {
    throw std::runtime_error("reference DEM: " + std::to_string(lat) + ", " + std::to_string(lon) +
                             " lies outside the tiles read");
  }
  const int r = std::min(static_cast<int>(fr), rows_ - 2), c = std::min(static_cast<int>(fc), cols_ - 2);
  const double u = fc - c, v = fr - r;
  const double h00 = sample(r, c), h01 = sample(r, c + 1), h10 = sample(r + 1, c), h11 = sample(r + 1, c + 1);
  const double h = (1 - v) * ((1 - u) * h00 + u * h01) + v * ((1 - u) * h10 + u * h11);
  if (std::isnan(h)) {
    throw std::runtime_error("reference DEM: a void or a gap next to " + std::to_string(lat) + ", " +
                             std::to_string(lon) + " (the reference does not fill voids)");
  }
  return h;
}

}  // namespace terravol::reference
