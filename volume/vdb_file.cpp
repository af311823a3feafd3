// OpenVDB .vdb reading (readers.h) and writing (vdb_write.h): the only file of volume/ that
// includes OpenVDB, whose headers are slow to compile.
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Count.h>
#include <openvdb/tools/Dense.h>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <streambuf>

#include "io/error.h"
#include "volume/isolated.h"
#include "volume/reader_common.h"
#include "volume/readers.h"
#include "volume/vdb_write.h"

namespace terravol::volume {

namespace {

void ensure_initialized() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// Held around every use of OpenVDB here, so that no other thread of ours is inside OpenVDB
// (holding its registries' locks) when parse_vdb forks.
std::mutex& vdb_mutex() {
  static std::mutex m;
  return m;
}

// A read-only stream buffer over memory, seekable.
class MemoryBuffer : public std::streambuf {
 public:
  MemoryBuffer(const char* data, std::size_t size) {
    char* p = const_cast<char*>(data);
    setg(p, p, p + size);
  }

 protected:
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override {
    if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
    char* target = dir == std::ios_base::beg ? eback() + off : dir == std::ios_base::cur ? gptr() + off : egptr() + off;
    if (target < eback() || target > egptr()) return pos_type(off_type(-1));
    setg(eback(), target, egptr());
    return pos_type(target - eback());
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    return seekoff(off_type(pos), std::ios_base::beg, which);
  }
};

// Every grid of the file, read eagerly (no delayed loading: the bytes are in memory).
openvdb::GridPtrVecPtr read_all(std::string_view bytes, const std::string& source) {
  ensure_initialized();
  if (bytes.size() < 8) throw io::FormatError(source, "too short for a VDB file");
  // OpenVDB's magic number, 0x56444220 ("VDB "), little-endian int32 at offset 0.
  if (!(bytes[0] == ' ' && bytes[1] == 'B' && bytes[2] == 'D' && bytes[3] == 'V')) {
    throw io::FormatError(source, "not a VDB file (bad magic number)");
  }
  MemoryBuffer buffer(bytes.data(), bytes.size());
  std::istream in(&buffer);
  in.exceptions(std::ios::failbit | std::ios::badbit);  // a short read throws instead of going on
  openvdb::io::Stream stream(in, /*delayLoad=*/false);
  openvdb::GridPtrVecPtr grids = stream.getGrids();
  if (!grids) throw io::FormatError(source, "no grids");
  return grids;
}

// Runs f, turning whatever OpenVDB throws on a corrupt file into a one-line FormatError.
template <class F>
auto converting_errors(const std::string& source, F f) -> decltype(f()) {
  try {
    return f();
  } catch (const io::FormatError&) {
    throw;
  } catch (const std::ios_base::failure&) {
    throw io::FormatError(source, "truncated or corrupt VDB file (read past the end)");
  } catch (const openvdb::Exception& e) {
    throw io::FormatError(source, "corrupt VDB file (" + detail::printable(e.what(), 300) + ")");
  } catch (const std::bad_alloc&) {
    throw io::FormatError(source, "corrupt VDB file (absurd sizes)");
  } catch (const std::exception& e) {
    throw io::FormatError(source, "corrupt VDB file (" + detail::printable(e.what(), 300) + ")");
  }
}

// Exact copies of the transform's scale and translation (see parse_vdb).
constexpr char kExactScale[] = "terravol:scale";
constexpr char kExactTranslation[] = "terravol:translation";

template <typename MetaT>
typename MetaT::ConstPtr meta_of(const openvdb::GridBase& grid, const std::string& key) {
  openvdb::Metadata::ConstPtr m = grid[key];
  if (!m) return nullptr;
  return openvdb::DynamicPtrCast<const MetaT>(m);
}

detail::FileMetadata metadata_of(const openvdb::GridBase& grid) {
  detail::FileMetadata m;
  if (auto s = meta_of<openvdb::StringMetadata>(grid, keys::kFrame)) m.frame = s->value();
  if (auto s = meta_of<openvdb::StringMetadata>(grid, keys::kHeight)) m.height = s->value();
  if (auto s = meta_of<openvdb::StringMetadata>(grid, keys::kUnits)) m.units = s->value();
  if (auto v = meta_of<openvdb::Vec3DMetadata>(grid, keys::kOrigin)) {
    m.origin = std::array<double, 3>{v->value()[0], v->value()[1], v->value()[2]};
  }
  const std::string prefix = keys::kAttributePrefix;
  for (auto it = grid.beginMeta(); it != grid.endMeta(); ++it) {
    if (it->first.rfind(prefix, 0) != 0) continue;
    if (auto s = openvdb::DynamicPtrCast<openvdb::StringMetadata>(it->second)) {
      m.attributes[it->first.substr(prefix.size())] = s->value();
    }
  }
  return m;
}

std::string grid_list(const openvdb::GridPtrVec& grids) {
  std::string names;
  for (const auto& g : grids) {
    if (!names.empty()) names += ", ";
    names += "'" + detail::printable(g->getName()) + "' (" + detail::printable(g->valueType()) + ")";
  }
  return names.empty() ? "none" : names;
}

Volume parse_grid(std::string_view bytes, const std::string& source, const ReadOptions& options) {
  const openvdb::GridPtrVecPtr grids = read_all(bytes, source);
  openvdb::FloatGrid::ConstPtr grid;
  for (const auto& g : *grids) {
    if (options.field.empty() ? g->isType<openvdb::FloatGrid>() : g->getName() == options.field) {
      grid = openvdb::GridBase::constGrid<openvdb::FloatGrid>(g);
      if (!grid) {
        throw io::FormatError(source, "grid '" + detail::printable(options.field) + "' holds " + detail::printable(g->valueType()) + ", not float");
      }
      break;
    }
  }
  if (!grid) {
    throw io::FormatError(source, (options.field.empty() ? std::string("no float grid")
                                                         : "no grid named '" + detail::printable(options.field) + "'") +
                                      " (grids: " + grid_list(*grids) + ")");
  }
  const std::string what = "grid '" + detail::printable(grid->getName()) + "': ";

  // The transform: only axis-aligned scale and translation make a regular lattice.
  const openvdb::math::MapBase::ConstPtr map = grid->transform().baseMap();
  if (!map->isLinear()) throw io::FormatError(source, what + "non-linear (frustum) transform is not supported");
  // Row-vector convention: world = index * m, the translation in row 3.
  const openvdb::Mat4d m = map->getAffineMap()->getConstMat4();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (r != c && std::abs(m(r, c)) > 1e-12 * (std::abs(m(r, r)) + std::abs(m(c, c)))) {
        throw io::FormatError(source, what + "rotated or sheared transform is not supported (axis-aligned only)");
      }
    }
  }

  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  if (box.empty()) throw io::FormatError(source, what + "no active voxels");
  const openvdb::Coord dim = box.dim();
  detail::check_dims({dim[0], dim[1], dim[2]}, kMaxPoints, source);

  // Scale and translation as stored, for the map types that hold them; other linear maps
  // through their matrix.
  namespace m4 = openvdb::math;
  openvdb::Vec3d scale(m(0, 0), m(1, 1), m(2, 2)), translation(m(3, 0), m(3, 1), m(3, 2));
  if (map->isType<m4::ScaleTranslateMap>() || map->isType<m4::UniformScaleTranslateMap>()) {
    const auto& st = static_cast<const m4::ScaleTranslateMap&>(*map);
    scale = st.getScale();
    translation = st.getTranslation();
  } else if (map->isType<m4::ScaleMap>() || map->isType<m4::UniformScaleMap>()) {
    scale = static_cast<const m4::ScaleMap&>(*map).getScale();
    translation = openvdb::Vec3d(0.0);
  } else if (map->isType<m4::TranslationMap>()) {
    scale = openvdb::Vec3d(1.0);
    translation = static_cast<const m4::TranslationMap&>(*map).getTranslation();
  }

  // OpenVDB's Transform re-derives every map through a 4x4 matrix and its inverse, which moves
  // scale and translation by about 1e-13 relative; encode_vdb also stores them exactly as
  // metadata, used when they agree with the transform.
  const auto exact_scale = meta_of<openvdb::Vec3DMetadata>(*grid, kExactScale);
  const auto exact_translation = meta_of<openvdb::Vec3DMetadata>(*grid, kExactTranslation);
  if (exact_scale && exact_translation) {
    const openvdb::Vec3d es = exact_scale->value(), et = exact_translation->value();
    bool agree = true;
    for (int a = 0; a < 3; ++a) {
      agree = agree && std::abs(es[a] - scale[a]) <= 1e-9 * std::abs(scale[a]) &&
              std::abs(et[a] - translation[a]) <= 1e-9 * (std::abs(translation[a]) + std::abs(scale[a]));
    }
    if (agree) {
      scale = es;
      translation = et;
    }
  }

  Volume v;
  v.name = grid->getName();
  v.background = grid->background();
  v.active_points = static_cast<std::size_t>(openvdb::tools::countActiveVoxels(grid->tree(), /*threaded=*/false));
  v.lattice.dims = {dim[0], dim[1], dim[2]};
  for (int a = 0; a < 3; ++a) {
    v.lattice.spacing[a] = scale[a];
    v.lattice.origin[a] = translation[a] + static_cast<double>(box.min()[a]) * scale[a];
  }
  detail::check_geometry(v.lattice, source);
  v.values.resize(v.lattice.size());
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, v.values.data());
  openvdb::tools::copyToDense(*grid, dense, /*serial=*/true);
  detail::normalise_axes(v);
  detail::apply_metadata(v, metadata_of(*grid), options, source);
  return v;
}

}  // namespace

std::vector<GridInfo> vdb_grids(std::string_view bytes, const std::string& source) {
  std::lock_guard<std::mutex> lock(vdb_mutex());
  ensure_initialized();
  // The names travel as the name of a one-point volume's attributes, in file order.
  const Volume list = detail::parse_isolated(bytes, source, "VDB", [&] {
    return converting_errors(source, [&] {
      Volume v;
      v.lattice.dims = {1, 1, 1};
      v.values = {0.0f};
      const openvdb::GridPtrVecPtr grids = read_all(bytes, source);
      for (std::size_t n = 0; n < grids->size(); ++n) {
        char key[32];
        std::snprintf(key, sizeof key, "%08zu", n);
        v.attributes[std::string(key) + "n"] = (*grids)[n]->getName();
        v.attributes[std::string(key) + "t"] = (*grids)[n]->valueType();
      }
      return v;
    });
  });
  std::vector<GridInfo> grids;
  for (auto it = list.attributes.begin(); it != list.attributes.end(); ++it) {
    const std::string& name = it->second;
    if (++it == list.attributes.end()) break;
    grids.push_back({name, it->second});
  }
  return grids;
}

// OpenVDB 10's reader corrupts the heap or crashes on some corrupt files
// (tests/volume/readers_test.cpp, VdbHostile), so it runs in a child process; everything the
// child runs is serial (no TBB after fork).
Volume parse_vdb(std::string_view bytes, const std::string& source, const ReadOptions& options) {
  std::lock_guard<std::mutex> lock(vdb_mutex());
  ensure_initialized();
  return detail::parse_isolated(bytes, source, "VDB", [&] {
    return converting_errors(source, [&] { return parse_grid(bytes, source, options); });
  });
}

std::string encode_vdb(const std::vector<const Volume*>& volumes) {
  std::lock_guard<std::mutex> lock(vdb_mutex());
  ensure_initialized();
  openvdb::GridPtrVec grids;
  std::set<std::string> names;
  for (const Volume* v : volumes) {
    if (v->name.empty() || !names.insert(v->name).second) {
      throw std::invalid_argument("encode_vdb: grid names must be non-empty and distinct ('" + v->name + "')");
    }
    if (v->values.size() != v->lattice.size()) throw std::invalid_argument("encode_vdb: values do not fill the lattice");
    const Lattice& l = v->lattice;
    auto grid = openvdb::FloatGrid::create(v->background);
    grid->setName(v->name);
    grid->setTransform(openvdb::math::Transform::Ptr(new openvdb::math::Transform(
        openvdb::math::MapBase::Ptr(new openvdb::math::ScaleTranslateMap(
            openvdb::Vec3d(l.spacing[0], l.spacing[1], l.spacing[2]),
            openvdb::Vec3d(l.origin[0], l.origin[1], l.origin[2]))))));
    auto acc = grid->getAccessor();
    for (int k = 0; k < l.dims[2]; ++k)
      for (int j = 0; j < l.dims[1]; ++j)
        for (int i = 0; i < l.dims[0]; ++i) acc.setValueOn(openvdb::Coord(i, j, k), v->values[l.index(i, j, k)]);

    grid->insertMeta(kExactScale, openvdb::Vec3DMetadata(openvdb::Vec3d(l.spacing[0], l.spacing[1], l.spacing[2])));
    grid->insertMeta(kExactTranslation, openvdb::Vec3DMetadata(openvdb::Vec3d(l.origin[0], l.origin[1], l.origin[2])));
    const VolumeFrame& f = v->frame;
    if (f.kind != FrameKind::kNone) {
      grid->insertMeta(keys::kFrame, openvdb::StringMetadata(f.kind == FrameKind::kEnu ? "enu" : "geographic"));
      grid->insertMeta(keys::kHeight, openvdb::StringMetadata(f.height == HeightRef::kGround ? "ground" : "datum"));
      if (f.kind == FrameKind::kEnu) {
        grid->insertMeta(keys::kOrigin, openvdb::Vec3DMetadata(openvdb::Vec3d(f.origin_lat, f.origin_lon, f.origin_h)));
      }
    }
    if (!v->units.empty()) grid->insertMeta(keys::kUnits, openvdb::StringMetadata(v->units));
    for (const auto& [key, value] : v->attributes) {
      grid->insertMeta(keys::kAttributePrefix + key, openvdb::StringMetadata(value));
    }
    grid->setSaveFloatAsHalf(false);
    grids.push_back(grid);
  }
  std::ostringstream out(std::ios::binary);
  openvdb::io::Stream stream(out);
  stream.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
  stream.write(grids);
  return std::move(out).str();
}

void write_vdb(const std::filesystem::path& path, const std::vector<const Volume*>& volumes, bool overwrite) {
  if (!overwrite && std::filesystem::exists(path)) {
    throw std::runtime_error(path.string() + ": exists (use --force to overwrite)");
  }
  const std::string bytes = encode_vdb(volumes);
  std::filesystem::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw std::runtime_error(path.string() + ": cannot write");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(path.string() + ": cannot write (" + ec.message() + ")");
  }
}

}  // namespace terravol::volume
