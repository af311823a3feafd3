#include "volume/reader_common.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "io/error.h"

namespace terravol::volume {

namespace detail {

std::string printable(std::string_view text, std::size_t max) {
  std::string out(text.substr(0, max));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return text.size() > max ? out + "..." : out;
}

void check_dims(const std::array<long long, 3>& dims, std::size_t max_points, const std::string& source) {
  const std::string text =
      std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " + std::to_string(dims[2]);
  for (long long d : dims) {
    if (d < 1) throw io::FormatError(source, "dimensions " + text + ": each must be at least 1");
    if (d > static_cast<long long>(kMaxPoints)) throw io::FormatError(source, "dimensions " + text + " are absurd");
  }
  // Each factor is at most 2^28, so the product of the first two fits; check before the third.
  const double product = static_cast<double>(dims[0]) * static_cast<double>(dims[1]) * static_cast<double>(dims[2]);
  if (product > static_cast<double>(kMaxPoints)) {
    throw io::FormatError(source, "dimensions " + text + " are too large (at most 2^28 points)");
  }
  if (product > static_cast<double>(max_points)) {
    throw io::FormatError(source, "dimensions " + text + " need more data than the file holds");
  }
}

void check_geometry(const Lattice& lattice, const std::string& source) {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(lattice.origin[a]) || !std::isfinite(lattice.spacing[a])) {
      throw io::FormatError(source, "origin or spacing is not a finite number");
    }
    if (lattice.spacing[a] == 0.0) throw io::FormatError(source, "spacing of axis " + std::to_string(a) + " is 0");
  }
}

void normalise_axes(Volume& volume) {
  Lattice& l = volume.lattice;
  for (int a = 0; a < 3; ++a) {
    if (l.spacing[a] > 0.0) continue;
    l.origin[a] += (l.dims[a] - 1) * l.spacing[a];
    l.spacing[a] = -l.spacing[a];
    for (int k = 0; k < l.dims[2]; ++k) {
      for (int j = 0; j < l.dims[1]; ++j) {
        for (int i = 0; i < l.dims[0]; ++i) {
          int m[3] = {i, j, k};
          if (m[a] >= (l.dims[a] - 1 - m[a])) continue;  // each pair once
          int o[3] = {i, j, k};
          o[a] = l.dims[a] - 1 - m[a];
          std::swap(volume.values[l.index(i, j, k)], volume.values[l.index(o[0], o[1], o[2])]);
        }
      }
    }
  }
}

void apply_metadata(Volume& volume, const FileMetadata& m, const ReadOptions& options, const std::string& source) {
  VolumeFrame f;
  if (m.frame) {
    if (*m.frame == "geographic") {
      f.kind = FrameKind::kGeographic;
    } else if (*m.frame == "enu") {
      f.kind = FrameKind::kEnu;
    } else if (*m.frame != "none") {
      throw io::FormatError(source, std::string(keys::kFrame) + " is '" + printable(*m.frame) + "', expected geographic or enu");
    }
  }
  if (m.height) {
    if (*m.height == "ground") {
      f.height = HeightRef::kGround;
    } else if (*m.height != "datum") {
      throw io::FormatError(source, std::string(keys::kHeight) + " is '" + printable(*m.height) + "', expected datum or ground");
    }
  }
  if (f.kind == FrameKind::kEnu) {
    if (!m.origin) throw io::FormatError(source, "frame enu without " + std::string(keys::kOrigin));
    const auto& o = *m.origin;
    if (!std::isfinite(o[0]) || !std::isfinite(o[1]) || !std::isfinite(o[2]) || std::abs(o[0]) > 90.0) {
      throw io::FormatError(source, std::string(keys::kOrigin) + " is not a valid lat, lon, h");
    }
    f.origin_lat = o[0];
    f.origin_lon = o[1];
    f.origin_h = o[2];
    if (f.height == HeightRef::kGround) {
      throw io::FormatError(source, "an enu frame cannot have heights above ground");
    }
  }
  volume.frame = options.frame ? *options.frame : f;
  volume.units = options.units ? *options.units : m.units.value_or("");
  volume.attributes = m.attributes;

  if (volume.frame.kind == FrameKind::kGeographic) {
    const Lattice& l = volume.lattice;
    const double lat_a = l.world(1, 0), lat_b = l.world(1, l.dims[1] - 1);
    if (std::min(lat_a, lat_b) < -90.0 || std::max(lat_a, lat_b) > 90.0) {
      throw io::FormatError(source, "geographic frame, but latitudes " + std::to_string(std::min(lat_a, lat_b)) +
                                        " .. " + std::to_string(std::max(lat_a, lat_b)) + " leave [-90, 90]");
    }
  }
}

namespace {

void put(std::string& out, const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); }
template <class T>
void put(std::string& out, const T& v) {
  put(out, &v, sizeof v);
}
void put_string(std::string& out, const std::string& s) {
  put(out, static_cast<std::uint64_t>(s.size()));
  put(out, s.data(), s.size());
}

class Cursor {
 public:
  Cursor(std::string_view bytes, const std::string& source) : bytes_(bytes), source_(source) {}
  void get(void* p, std::size_t n) {
    if (n > bytes_.size() - at_) throw io::FormatError(source_, "incomplete volume from the reader process");
    std::memcpy(p, bytes_.data() + at_, n);
    at_ += n;
  }
  template <class T>
  T get() {
    T v;
    get(&v, sizeof v);
    return v;
  }
  std::string get_string() {
    const auto n = get<std::uint64_t>();
    if (n > bytes_.size() - at_) throw io::FormatError(source_, "incomplete volume from the reader process");
    std::string s(bytes_.substr(at_, n));
    at_ += n;
    return s;
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  std::string_view bytes_;
  const std::string& source_;
  std::size_t at_ = 0;
};

}  // namespace

std::string serialize_volume(const Volume& v) {
  std::string out;
  put_string(out, v.name);
  put_string(out, v.units);
  put(out, v.frame.kind);
  put(out, v.frame.height);
  put(out, v.frame.origin_lat);
  put(out, v.frame.origin_lon);
  put(out, v.frame.origin_h);
  put(out, v.lattice.dims);
  put(out, v.lattice.origin);
  put(out, v.lattice.spacing);
  put(out, v.background);
  put(out, static_cast<std::uint64_t>(v.active_points));
  put(out, static_cast<std::uint64_t>(v.attributes.size()));
  for (const auto& [key, value] : v.attributes) {
    put_string(out, key);
    put_string(out, value);
  }
  put(out, static_cast<std::uint64_t>(v.values.size()));
  put(out, v.values.data(), v.values.size() * sizeof(float));
  return out;
}

Volume deserialize_volume(std::string_view bytes, const std::string& source) {
  Cursor c(bytes, source);
  Volume v;
  v.name = c.get_string();
  v.units = c.get_string();
  v.frame.kind = c.get<FrameKind>();
  v.frame.height = c.get<HeightRef>();
  v.frame.origin_lat = c.get<double>();
  v.frame.origin_lon = c.get<double>();
  v.frame.origin_h = c.get<double>();
  v.lattice.dims = c.get<std::array<int, 3>>();
  v.lattice.origin = c.get<std::array<double, 3>>();
  v.lattice.spacing = c.get<std::array<double, 3>>();
  v.background = c.get<float>();
  v.active_points = static_cast<std::size_t>(c.get<std::uint64_t>());
  const auto n_attributes = c.get<std::uint64_t>();
  for (std::uint64_t n = 0; n < n_attributes; ++n) {
    std::string key = c.get_string();
    v.attributes[key] = c.get_string();
  }
  const auto n_values = c.get<std::uint64_t>();
  for (int a = 0; a < 3; ++a) {
    if (v.lattice.dims[a] < 1) throw io::FormatError(source, "bad volume from the reader process");
  }
  if (n_values != v.lattice.size() || n_values > kMaxPoints) throw io::FormatError(source, "bad volume from the reader process");
  v.values.resize(n_values);
  c.get(v.values.data(), n_values * sizeof(float));
  if (!c.done()) throw io::FormatError(source, "bad volume from the reader process");
  return v;
}

}  // namespace detail

std::optional<VolumeFormat> volume_format_from_name(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".vdb") return VolumeFormat::kVdb;
  if (ext == ".vti") return VolumeFormat::kVti;
  if (ext == ".vtk") return VolumeFormat::kLegacyVtk;
  return std::nullopt;
}

Volume read_volume(const std::filesystem::path& path, const ReadOptions& options) {
  const std::string source = path.string();
  const auto format = volume_format_from_name(path);
  if (!format) throw io::FormatError(source, "unknown volume format (expected .vdb, .vti or .vtk)");
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw io::FormatError(source, "no such file");
  if (std::filesystem::is_directory(path, ec)) throw io::FormatError(source, "is a folder, not a volume file");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw io::FormatError(source, "cannot read (" + ec.message() + ")");
  if (size > (std::uintmax_t{1} << 30)) throw io::FormatError(source, "larger than 1 GiB");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw io::FormatError(source, "cannot open");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) throw io::FormatError(source, "cannot read");
  switch (*format) {
    case VolumeFormat::kVdb:
      return parse_vdb(bytes, source, options);
    case VolumeFormat::kVti:
      return parse_vti(bytes, source, options);
    case VolumeFormat::kLegacyVtk:
      return parse_legacy_vtk(bytes, source, options);
  }
  throw io::FormatError(source, "unknown volume format");
}

}  // namespace terravol::volume
